#include "mesh/grid_march.hpp"

#include <algorithm>
#include <unordered_map>

#include "mesh/marching_cubes.hpp"

namespace gmpu {

Mesh march_grid_blocks(const GlobalGrid &grid, const int64_t *blocks, size_t block_count, const double *corner_values,
                       std::vector<uint64_t> &edge_keys) {
    constexpr int B = GlobalGrid::kGridBlock, C = B + 1;
    Mesh mesh;
    edge_keys.clear();
    // One vertex per lattice edge across all the given blocks.
    std::unordered_map<uint64_t, uint32_t> vertex_of;
    for (size_t b = 0; b < block_count; ++b) {
        const int64_t x0 = blocks[3 * b] * B, y0 = blocks[3 * b + 1] * B, z0 = blocks[3 * b + 2] * B;
        const double *value = corner_values + b * size_t(C * C * C);
        auto local = [](int i, int j, int k) { return size_t(i + C * (j + C * k)); };
        auto vertex = [&](int i, int j, int k, const mc::Edge &e) -> uint32_t {
            const int ai = i + (e.from & 1), aj = j + (e.from >> 1 & 1), ak = k + (e.from >> 2 & 1);
            const int bi = i + (e.to & 1), bj = j + (e.to >> 1 & 1), bk = k + (e.to >> 2 & 1);
            const uint64_t key = grid.corner_id(x0 + ai, y0 + aj, z0 + ak) * 8 + uint64_t(mc::edge_direction(e));
            auto found = vertex_of.find(key);
            if (found != vertex_of.end()) return found->second;
            const double va = value[local(ai, aj, ak)], vb = value[local(bi, bj, bk)];
            const double t = std::clamp(va / (va - vb), 0.0, 1.0);
            const int64_t a[3] = {x0 + ai, y0 + aj, z0 + ak}, c[3] = {x0 + bi, y0 + bj, z0 + bk};
            for (int d = 0; d < 3; ++d) {
                const double pa = grid.coordinate(d, a[d]), pb = grid.coordinate(d, c[d]);
                mesh.vertices.push_back(pa + t * (pb - pa));
            }
            const uint32_t id = uint32_t(edge_keys.size());
            edge_keys.push_back(key);
            vertex_of.emplace(key, id);
            return id;
        };
        mc::march_block(
            B, [&](int i, int j, int k) { return value[local(i, j, k)]; },
            [&](int i, int j, int k, const mc::Edge &e) { mesh.triangles.push_back(vertex(i, j, k, e)); },
            [](int, int, int, const mc::Edge *) { return true; });  // no gradients here: a fixed split
    }
    return mesh;
}

}  // namespace gmpu
