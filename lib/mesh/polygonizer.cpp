#include "mesh/polygonizer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/parallel.hpp"
#include "mesh/marching_tetrahedra.hpp"

namespace gmpu {

namespace {

constexpr int B = 8;  // cubes per block side

struct Grid {
    Eigen::Vector3d origin;
    double h;
    int64_t n[3];       // corners per axis minus one (cubes), a multiple of B
    int64_t blocks[3];  // blocks per axis

    Eigen::Vector3d corner(int64_t x, int64_t y, int64_t z) const {
        return origin + h * Eigen::Vector3d(double(x), double(y), double(z));
    }
    uint64_t corner_id(int64_t x, int64_t y, int64_t z) const {
        return uint64_t(x + (n[0] + 1) * (y + (n[1] + 1) * z));
    }
    int64_t block_id(int64_t x, int64_t y, int64_t z) const { return x + blocks[0] * (y + blocks[1] * z); }
};

// `dilation`: how many blocks the band reaches beyond the blocks holding points.
Grid make_grid(const PointSet &points, int resolution, int dilation) {
    Grid g;
    g.h = 1.0 / resolution;  // the longest side of the normalised box is 1
    const double pad = (dilation + 1) * B * g.h;  // keeps the band a block off the grid's edge
    g.origin = points.box_min() - Eigen::Vector3d::Constant(pad);
    for (int d = 0; d < 3; ++d) {
        double extent = points.box_max()[d] - points.box_min()[d] + 2.0 * pad;
        g.blocks[d] = std::max<int64_t>(1, int64_t(std::ceil(extent / (g.h * B))));
        g.n[d] = g.blocks[d] * B;
    }
    return g;
}

// Far regions: flood fill of the blocks outside the band (6-connected). Region 0 touches
// the grid's edge and is outside; enclosed regions get their sign from the winding number.
struct Regions {
    std::vector<uint8_t> band;     // per block
    std::vector<int8_t> sign;      // per block: 0 in the band, else its region's sign
};

Regions find_regions(const Grid &g, const PointSet &points, const WindingField &winding, int dilation) {
    const int64_t nb = g.blocks[0] * g.blocks[1] * g.blocks[2];
    Regions r;
    std::vector<uint8_t> has_point(size_t(nb), 0);
    for (size_t i = 0; i < points.size(); ++i) {
        Eigen::Vector3d q = (points.point(i) - g.origin) / (g.h * B);
        int64_t b[3];
        for (int d = 0; d < 3; ++d) b[d] = std::clamp<int64_t>(int64_t(q[d]), 0, g.blocks[d] - 1);
        has_point[size_t(g.block_id(b[0], b[1], b[2]))] = 1;
    }
    r.band.assign(size_t(nb), 0);
    for (int64_t z = 0; z < g.blocks[2]; ++z)
        for (int64_t y = 0; y < g.blocks[1]; ++y)
            for (int64_t x = 0; x < g.blocks[0]; ++x) {
                if (!has_point[size_t(g.block_id(x, y, z))]) continue;
                for (int64_t dz = -dilation; dz <= dilation; ++dz)
                    for (int64_t dy = -dilation; dy <= dilation; ++dy)
                        for (int64_t dx = -dilation; dx <= dilation; ++dx) {
                            int64_t a = x + dx, b = y + dy, c = z + dz;
                            if (a < 0 || b < 0 || c < 0 || a >= g.blocks[0] || b >= g.blocks[1] || c >= g.blocks[2])
                                continue;
                            r.band[size_t(g.block_id(a, b, c))] = 1;
                        }
            }

    std::vector<int32_t> region(size_t(nb), -1);
    std::vector<int8_t> region_sign;
    std::vector<int64_t> stack;
    const int64_t step[3] = {1, g.blocks[0], g.blocks[0] * g.blocks[1]};
    int32_t regions = 0;
    for (int64_t s = 0; s < nb; ++s) {
        if (r.band[size_t(s)] || region[size_t(s)] >= 0) continue;
        // The first far block in scan order is at the grid's corner: region 0 is outside.
        // Enclosed regions (cavities, the inside of thick parts) ask the winding number.
        const int32_t id = regions++;
        {
            int64_t pos[3] = {s % g.blocks[0], (s / g.blocks[0]) % g.blocks[1], s / (g.blocks[0] * g.blocks[1])};
            Eigen::Vector3d c = g.origin + g.h * B * (Eigen::Vector3d(double(pos[0]), double(pos[1]), double(pos[2])) +
                                                      Eigen::Vector3d::Constant(0.5));
            region_sign.push_back(id > 0 && winding.winding(c) > 0.5 ? 1 : -1);
        }
        region[size_t(s)] = id;
        stack.push_back(s);
        while (!stack.empty()) {
            int64_t b = stack.back();
            stack.pop_back();
            int64_t pos[3] = {b % g.blocks[0], (b / g.blocks[0]) % g.blocks[1], b / (g.blocks[0] * g.blocks[1])};
            for (int d = 0; d < 3; ++d)
                for (int side = -1; side <= 1; side += 2) {
                    int64_t p = pos[d] + side;
                    if (p < 0 || p >= g.blocks[d]) continue;
                    int64_t nbk = b + side * step[d];
                    if (r.band[size_t(nbk)]) continue;
                    if (region[size_t(nbk)] < 0) {
                        region[size_t(nbk)] = id;
                        stack.push_back(nbk);
                    }
                }
        }
    }
    r.sign.assign(size_t(nb), 0);
    for (int64_t b = 0; b < nb; ++b)
        if (!r.band[size_t(b)]) r.sign[size_t(b)] = region_sign[size_t(region[size_t(b)])];
    return r;
}

// Sign imposed on a corner by the far blocks touching it (0: none). Depends only on the
// corner, so every block sharing the corner sees the same value.
int8_t forced_sign(const Grid &g, const Regions &r, int64_t x, int64_t y, int64_t z) {
    int64_t lo[3], hi[3];
    const int64_t c[3] = {x, y, z};
    for (int d = 0; d < 3; ++d) {
        hi[d] = std::min(c[d] / B, g.blocks[d] - 1);
        lo[d] = (c[d] % B == 0 && c[d] > 0) ? c[d] / B - 1 : hi[d];
    }
    int8_t s = 0;
    for (int64_t bz = lo[2]; bz <= hi[2]; ++bz)
        for (int64_t by = lo[1]; by <= hi[1]; ++by)
            for (int64_t bx = lo[0]; bx <= hi[0]; ++bx) {
                int8_t v = r.sign[size_t(g.block_id(bx, by, bz))];
                if (v < 0) return -1;  // outside wins a tie: it is never wrong to close a leak
                if (v > 0) s = 1;
            }
    return s;
}

struct BlockOutput {
    std::vector<uint64_t> vertex_key;         // edge key per vertex
    std::vector<Eigen::Vector3d> vertex_pos;  // normalised frame
    std::vector<uint32_t> triangles;          // local vertex indices
};

// Marching tetrahedra over one band block.
void polygonize_block(const Grid &g, const Regions &r, const SurfaceField &f, int64_t bx, int64_t by,
                      int64_t bz, BlockOutput &out) {
    constexpr int C = B + 1;
    thread_local std::vector<double> value(C * C * C);
    thread_local std::vector<int32_t> slot(C * C * C * 8);
    const int64_t x0 = bx * B, y0 = by * B, z0 = bz * B;
    auto local = [](int i, int j, int k) { return i + C * (j + C * k); };
    for (int k = 0; k < C; ++k)
        for (int j = 0; j < C; ++j)
            for (int i = 0; i < C; ++i) {
                double v = f.value(g.corner(x0 + i, y0 + j, z0 + k), nullptr, 2.0 * g.h);
                if (!std::isfinite(v)) v = -1.0;
                int8_t s = forced_sign(g, r, x0 + i, y0 + j, z0 + k);
                if (s != 0 && (v > 0) != (s > 0)) v = s > 0 ? std::max(std::abs(v), 1e-12) : -std::abs(v);
                value[size_t(local(i, j, k))] = v;
            }
    std::fill(slot.begin(), slot.end(), -1);

    auto vertex = [&](int i, int j, int k, const mt::Edge &e) -> uint32_t {
        const int ai = i + (e.from & 1), aj = j + (e.from >> 1 & 1), ak = k + (e.from >> 2 & 1);
        const int bi = i + (e.to & 1), bj = j + (e.to >> 1 & 1), bk = k + (e.to >> 2 & 1);
        const int dir = mt::edge_direction(e);
        int32_t &s = slot[size_t(local(ai, aj, ak) * 8 + dir)];
        if (s >= 0) return uint32_t(s);
        const double va = value[size_t(local(ai, aj, ak))], vb = value[size_t(local(bi, bj, bk))];
        const double t = std::clamp(va / (va - vb), 0.0, 1.0);
        Eigen::Vector3d pa = g.corner(x0 + ai, y0 + aj, z0 + ak), pb = g.corner(x0 + bi, y0 + bj, z0 + bk);
        s = int32_t(out.vertex_pos.size());
        out.vertex_pos.push_back(pa + t * (pb - pa));
        out.vertex_key.push_back(g.corner_id(x0 + ai, y0 + aj, z0 + ak) * 8 + uint64_t(dir));
        return uint32_t(s);
    };

    for (int k = 0; k < B; ++k)
        for (int j = 0; j < B; ++j)
            for (int i = 0; i < B; ++i) {
                int mask8 = 0;
                for (int c = 0; c < 8; ++c)
                    if (value[size_t(local(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)))] > 0) mask8 |= 1 << c;
                if (mask8 == 0 || mask8 == 255) continue;
                for (int t = 0; t < mt::kTetrahedra; ++t) {
                    int mask = 0;
                    for (int q = 0; q < 4; ++q)
                        if (mask8 >> mt::kTetCorners[t][q] & 1) mask |= 1 << q;
                    const mt::TetCase &tc = mt::tet_case(t, mask);
                    for (int tri = 0; tri < tc.triangle_count; ++tri)
                        for (int v = 0; v < 3; ++v) out.triangles.push_back(vertex(i, j, k, tc.triangles[tri][v]));
                }
            }
}

}  // namespace

int default_resolution(const Octree &tree, const PointSet &points) {
    (void)points;
    // Half the median size of the leaves that hold points: the grid then resolves every
    // local fit with about two cubes across.
    std::vector<double> sizes;
    for (const Cell &c : tree.cells)
        if (c.is_leaf() && c.point_end > c.point_begin) sizes.push_back(c.size);
    if (sizes.empty()) return 64;
    std::nth_element(sizes.begin(), sizes.begin() + long(sizes.size() / 2), sizes.end());
    double h = 0.5 * sizes[sizes.size() / 2];
    return std::clamp(int(std::ceil(1.0 / h)), 32, 1024);
}

Mesh polygonize(const SurfaceField &f, const WindingField &winding, const PointSet &points,
                const PointMeasures &measures, int resolution, const Params &params, Progress &progress) {
    // The band must hold every trusted corner, so it reaches past the widest trust radius
    // (its 99th percentile: one isolated outlier must not widen it everywhere).
    std::vector<float> trust(measures.trust_radius);
    std::nth_element(trust.begin(), trust.begin() + long(trust.size() * 99 / 100), trust.end());
    const double h = 1.0 / resolution;
    const int dilation = std::clamp(1 + int(double(trust[trust.size() * 99 / 100]) / (h * B)), 1, 3);
    const Grid g = make_grid(points, resolution, dilation);
    const Regions r = find_regions(g, points, winding, dilation);
    std::vector<int64_t> band;
    for (int64_t b = 0; b < int64_t(r.band.size()); ++b)
        if (r.band[size_t(b)]) band.push_back(b);
    progress.report(0.02);

    std::vector<BlockOutput> blocks(band.size());
    const unsigned threads = resolve_threads(params.threads);
    std::atomic<uint64_t> triangles{0};
    parallel_for(0, band.size(), threads, progress, [&](size_t i) {
        int64_t b = band[i];
        polygonize_block(g, r, f, b % g.blocks[0], (b / g.blocks[0]) % g.blocks[1],
                         b / (g.blocks[0] * g.blocks[1]), blocks[i]);
        uint64_t total = triangles.fetch_add(blocks[i].triangles.size() / 3) + blocks[i].triangles.size() / 3;
        if (double(total) > params.max_triangles)
            throw Error(GMPU_ERROR_LIMIT_EXCEEDED,
                        "the mesh needs more than GMPU_PARAM_MAX_TRIANGLES = " +
                            std::to_string(uint64_t(params.max_triangles)) +
                            " triangles; lower GMPU_PARAM_RESOLUTION or raise the cap");
    }, 0.02 * double(band.size()) / 0.9, double(band.size()) / 0.9, 4);
    progress.throw_if_cancelled();

    // Weld: one vertex per grid edge across blocks (sort by edge key).
    std::vector<std::pair<uint64_t, uint64_t>> keyed;  // (edge key, block << 32 | local)
    for (size_t b = 0; b < blocks.size(); ++b)
        for (size_t v = 0; v < blocks[b].vertex_key.size(); ++v)
            keyed.push_back({blocks[b].vertex_key[v], uint64_t(b) << 32 | v});
    std::sort(keyed.begin(), keyed.end());
    std::vector<std::vector<uint32_t>> remap(blocks.size());
    for (size_t b = 0; b < blocks.size(); ++b) remap[b].resize(blocks[b].vertex_key.size());
    Mesh mesh;
    const Normalisation &norm = points.normalisation();
    for (size_t k = 0; k < keyed.size(); ++k) {
        if (k == 0 || keyed[k].first != keyed[k - 1].first) {
            size_t b = keyed[k].second >> 32, v = keyed[k].second & 0xffffffffu;
            Eigen::Vector3d p = norm.to_world(blocks[b].vertex_pos[v]);
            mesh.vertices.insert(mesh.vertices.end(), {p[0], p[1], p[2]});
        }
        remap[keyed[k].second >> 32][keyed[k].second & 0xffffffffu] = uint32_t(mesh.vertex_count() - 1);
    }
    for (size_t b = 0; b < blocks.size(); ++b)
        for (uint32_t v : blocks[b].triangles) mesh.triangles.push_back(remap[b][v]);
    progress.report(0.95);

    // Outward unit normals: −∇f at each vertex.
    mesh.normals.resize(mesh.vertices.size());
    parallel_for(0, mesh.vertex_count(), threads, progress, [&](size_t v) {
        Eigen::Vector3d p(mesh.vertices[3 * v], mesh.vertices[3 * v + 1], mesh.vertices[3 * v + 2]);
        Eigen::Vector3d grad;
        f.value(norm.to_unit(p), &grad, 2.0 * g.h);
        Eigen::Vector3d n = -grad.normalized();
        if (!n.allFinite()) n = Eigen::Vector3d::UnitZ();
        for (int d = 0; d < 3; ++d) mesh.normals[3 * v + d] = n[d];
    }, 0.95 * double(mesh.vertex_count()) / 0.05, double(mesh.vertex_count()) / 0.05, 1024);
    progress.throw_if_cancelled();
    progress.report(1.0, true);
    return mesh;
}

}  // namespace gmpu
