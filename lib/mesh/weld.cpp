#include "mesh/weld.hpp"

#include <utility>

#include "core/cancellable_sort.hpp"

namespace gmpu {

// One vertex per grid edge across blocks: sort every block's vertices by edge key.
// `votes` receives the point votes per welded vertex.
Mesh weld(std::vector<BlockOutput> &blocks, const Normalisation &norm, Progress &progress,
          std::vector<uint32_t> &votes) {
    // Every big array is reserved up front: growing one by doubling copies tens of
    // megabytes in one go, with no progress report in between.
    size_t vertex_slots = 0, triangle_slots = 0;
    for (const BlockOutput &block : blocks) vertex_slots += block.vertex_key.size(), triangle_slots += block.triangles.size();
    std::vector<std::pair<uint64_t, uint64_t>> keyed;  // (edge key, block << 32 | local index)
    keyed.reserve(vertex_slots);
    for (size_t b = 0; b < blocks.size(); ++b) {
        progress.poll(0.0);
        for (size_t v = 0; v < blocks[b].vertex_key.size(); ++v) keyed.push_back({blocks[b].vertex_key[v], uint64_t(b) << 32 | v});
    }
    cancellable_sort(keyed, progress, 0.3);

    size_t welded = 0;
    for (size_t k = 0; k < keyed.size(); ++k) {
        if (k % 65536 == 0) progress.poll(0.6);
        welded += k == 0 || keyed[k].first != keyed[k - 1].first;
    }
    Mesh mesh;
    mesh.vertices.reserve(3 * welded);
    mesh.normals.reserve(3 * welded);
    mesh.triangles.reserve(triangle_slots);
    votes.reserve(welded);
    std::vector<std::vector<uint32_t>> remap(blocks.size());
    for (size_t b = 0; b < blocks.size(); ++b) {
        progress.poll(0.6);
        remap[b].resize(blocks[b].vertex_key.size());
    }
    for (size_t k = 0; k < keyed.size(); ++k) {
        if (k % 4096 == 0) progress.poll(0.7);
        const size_t b = keyed[k].second >> 32, v = keyed[k].second & 0xffffffffu;
        if (k == 0 || keyed[k].first != keyed[k - 1].first) {
            const Eigen::Vector3d p = norm.to_world(blocks[b].vertex_pos[v]);
            Eigen::Vector3d n = -blocks[b].vertex_grad[v].normalized();  // f grows inward
            if (!n.allFinite()) n = Eigen::Vector3d::UnitZ();
            mesh.vertices.insert(mesh.vertices.end(), {p[0], p[1], p[2]});
            mesh.normals.insert(mesh.normals.end(), {n[0], n[1], n[2]});
            votes.push_back(0);
        }
        remap[b][v] = uint32_t(mesh.vertex_count() - 1);
        votes.back() += blocks[b].votes[v];
    }
    for (size_t b = 0; b < blocks.size(); ++b) {
        progress.poll(0.9);
        for (uint32_t v : blocks[b].triangles) mesh.triangles.push_back(remap[b][v]);
    }
    return mesh;
}

}  // namespace gmpu
