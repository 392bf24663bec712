#include "mesh/mesh_cleanup.hpp"

#include <algorithm>
#include <numeric>

#include <Eigen/Geometry>

#include "core/resize_reporting.hpp"
#include "core/union_find.hpp"

namespace gmpu {

namespace {
constexpr size_t kTickEvery = 4096;  // items between progress ticks: well under a millisecond
}  // namespace

uint32_t vertex_components(const Mesh &mesh, std::vector<uint32_t> &component, Progress &progress) {
    const size_t n = mesh.vertex_count();
    // Sized here, not by the constructor, so that a large mesh's allocation is reported.
    UnionFind pieces(0);
    assign_reporting(pieces.parent, n, progress);
    std::iota(pieces.parent.begin(), pieces.parent.end(), 0u);
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        if (t % (3 * kTickEvery) == 0) progress.tick();
        for (int e = 1; e < 3; ++e) pieces.join(mesh.triangles[t], mesh.triangles[t + e]);
    }
    assign_reporting(component, n, progress, UINT32_MAX);
    uint32_t count = 0;
    for (size_t v = 0; v < n; ++v) {
        if (v % kTickEvery == 0) progress.tick();
        const uint32_t r = pieces.find(uint32_t(v));
        if (component[r] == UINT32_MAX) component[r] = count++;
        component[v] = component[r];
    }
    return count;
}

namespace {

// Keeps the vertices of the components `keep` marks, and the triangles among them.
void keep_components(Mesh &mesh, const std::vector<uint32_t> &component, const std::vector<bool> &keep,
                     Progress &progress) {
    if (std::all_of(keep.begin(), keep.end(), [](bool k) { return k; })) return;
    std::vector<uint32_t> remap(mesh.vertex_count(), UINT32_MAX);
    Mesh kept;  // reserved: growing by doubling would copy megabytes between ticks
    kept.vertices.reserve(mesh.vertices.size());
    kept.normals.reserve(mesh.normals.size());
    kept.triangles.reserve(mesh.triangles.size());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (v % kTickEvery == 0) progress.tick();
        if (!keep[component[v]]) continue;
        remap[v] = uint32_t(kept.vertex_count());
        kept.vertices.insert(kept.vertices.end(), mesh.vertices.begin() + long(3 * v), mesh.vertices.begin() + long(3 * v + 3));
        if (!mesh.normals.empty())
            kept.normals.insert(kept.normals.end(), mesh.normals.begin() + long(3 * v), mesh.normals.begin() + long(3 * v + 3));
    }
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        if (t % (3 * kTickEvery) == 0) progress.tick();
        if (remap[mesh.triangles[t]] == UINT32_MAX) continue;
        for (int e = 0; e < 3; ++e) kept.triangles.push_back(remap[mesh.triangles[t + e]]);
    }
    mesh = std::move(kept);
}

}  // namespace

void remove_unsupported_components(Mesh &mesh, const std::vector<uint32_t> &votes, uint32_t min_votes,
                                   Progress &progress) {
    std::vector<uint32_t> component;
    const uint32_t count = vertex_components(mesh, component, progress);
    std::vector<uint64_t> support(count, 0);
    for (size_t v = 0; v < votes.size(); ++v) support[component[v]] += votes[v];
    std::vector<bool> keep(count);
    for (uint32_t c = 0; c < count; ++c) keep[c] = support[c] >= min_votes;
    keep_components(mesh, component, keep, progress);
}

void remove_components_smaller_than(Mesh &mesh, double min_side, Progress &progress) {
    std::vector<uint32_t> component;
    const uint32_t count = vertex_components(mesh, component, progress);
    if (count < 2) return;
    std::vector<Eigen::AlignedBox3d> box(count);
    std::vector<size_t> size(count, 0);
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (v % kTickEvery == 0) progress.tick();
        box[component[v]].extend(Eigen::Vector3d(mesh.vertices[3 * v], mesh.vertices[3 * v + 1], mesh.vertices[3 * v + 2]));
        ++size[component[v]];
    }
    const size_t largest = size_t(std::max_element(size.begin(), size.end()) - size.begin());
    std::vector<bool> keep(count);
    for (uint32_t c = 0; c < count; ++c) keep[c] = c == largest || box[c].sizes().maxCoeff() >= min_side;
    keep_components(mesh, component, keep, progress);
}

}  // namespace gmpu
