#include "mesh/mesh_cleanup.hpp"

#include <algorithm>
#include <numeric>

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

void remove_unsupported_components(Mesh &mesh, const std::vector<uint32_t> &votes, uint32_t min_votes,
                                   Progress &progress) {
    std::vector<uint32_t> component;
    const uint32_t count = vertex_components(mesh, component, progress);
    std::vector<uint64_t> support(count, 0);
    for (size_t v = 0; v < votes.size(); ++v) support[component[v]] += votes[v];
    bool any_removed = false;
    for (uint64_t s : support) any_removed |= s < min_votes;
    if (!any_removed) return;

    std::vector<uint32_t> remap(mesh.vertex_count(), UINT32_MAX);
    Mesh kept;  // reserved: growing by doubling would copy megabytes between ticks
    kept.vertices.reserve(mesh.vertices.size());
    kept.normals.reserve(mesh.normals.size());
    kept.triangles.reserve(mesh.triangles.size());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        if (v % kTickEvery == 0) progress.tick();
        if (support[component[v]] < min_votes) continue;
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

}  // namespace gmpu
