#include "mesh/polygonizer.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "core/median.hpp"
#include "core/memory_budget.hpp"
#include "core/parallel.hpp"
#include "mesh/block_grid.hpp"
#include "mesh/edge_root.hpp"
#include "mesh/marching_cubes.hpp"
#include "mesh/mesh_cleanup.hpp"
#include "mesh/point_buckets.hpp"
#include "mesh/sharpen.hpp"
#include "mesh/size_cap.hpp"
#include "mesh/weld.hpp"

namespace gmpu {

namespace {

constexpr int B = BlockGrid::B;
// A closed piece of surface must be the nearest surface of at least this many input points
// to be kept: a real part holds at least the N_min (15) points one local fit needs; a
// bubble of the far field or a stray quadric sheet holds none or a few noisy ones.
constexpr uint32_t kMinVotes = 15;
// A closed piece that fits in a box this many cubes on a side is dropped beside a larger
// one: it encloses one or two grid corners of the other sign, a pocket the grid cannot
// resolve (the field's sign flipped there by the noise, or in a crevice where parts touch).
constexpr double kGridScalePiece = 2.0;
// Grid cube as a share of the gap between two sheets fitted in one leaf.
constexpr double kCubesPerGap = 0.4;
// Share of the points that two-sheet leaves must hold for their gap to set the grid.
constexpr double kWallShare = 0.1;
// Mesh size (default_resolution): the cube the point density asks for, in mean sample
// spacings (marching cubes then makes about 0.8 triangles per point, 3 per h² of surface).
// Finer, the thin 35k camel was refined past two cubes per leaf and gained a handle.
constexpr double kCubePerSpacing = 1.9;
// The coarsest cube, as a share of the median leaf (two cubes across a leaf): coarser
// grids bridge close sheets of the fits and add handles (the noisy and the nonuniform 35k
// bunny have one to three at 0.6 and 0.75 of a leaf).
constexpr double kCubesPerLeaf = 0.5;
// The finest cube the point density alone may ask for: time and memory at millions of points.
constexpr double kFinestSizeCube = 1.0 / 128;
// Sharp features (sharpen.hpp): how far, in cubes, a vertex may move onto a crease or
// corner (a chamfer is about a cube wide; thin walls are at least 2.5 cubes thick).
constexpr double kSharpenReach = 1.0;
// Vertices on the surface (edge_root.hpp): a few evaluations of f per vertex bring |f| from
// the interpolant's error (a share of a cube on curved parts) down to this share of a cube.
constexpr int kRootSteps = 3;
constexpr double kRootTolerance = 1e-4;
// Both apply when the noise estimate is under this share of a cube (clean data: σ̂ is 0 on
// noiseless samples; the noisy corpus clouds have 0.3 to 1.3 cubes) and the mean sample
// spacing is under a cube (between sparser samples f is a guess the interpolant smooths:
// the 5k-point thin plate lost 0.01 of F@1 % with them).
constexpr double kCleanNoise = 0.05;
constexpr double kDenseSpacing = 1.0;
// Decimation of a default mesh over its triangle budget (size_cap.hpp) may move the surface
// by at most this share of the fit's tolerance ε: the fit itself is only trusted to ε.
constexpr double kCapErrorShare = 0.5;

// Mean sample spacing: the square root of the area each point stands for.
double mean_spacing(const PointMeasures &measures) {
    double area = 0.0;
    for (float a : measures.area) area += double(a);
    return measures.area.empty() ? INFINITY : std::sqrt(area / double(measures.area.size()));
}

// Memory model of polygonize, for GMPU_PARAM_MAX_MEMORY (upper estimates of the peak):
//  - per grid block: the band flag, the far sign, the region label and flood-fill stack,
//    the far-sample cache's slot index;
//  - per band block: its id, its output record and point bucket, its far samples;
//  - per triangle: the block's vertices (key, position, gradient, votes: half a vertex per
//    triangle, more on block borders), the weld's sort keys and remap, and the mesh.
constexpr double kBytesPerGridBlock = 16 + FarValueCache::kBytesPerGridBlock;
constexpr double kBytesPerBandBlock = 200 + FarValueCache::bytes_per_block_in_use(B, SurfaceField::kFarStep);
// Before any triangle is made: a low estimate (a block the surface crosses makes about B²
// of them, and the band is at least twice as thick as the surface), so that the check
// never refuses what would fit; the triangles themselves are then counted as they come.
constexpr double kTrianglesPerBandBlock = B * B / 2.0;
constexpr double kBytesPerTriangle = 160;

double polygonize_memory(double grid_blocks, double band_blocks, double triangles) {
    return grid_blocks * kBytesPerGridBlock + band_blocks * kBytesPerBandBlock + triangles * kBytesPerTriangle;
}

std::string resolution_text(int resolution) { return "polygonize at resolution " + std::to_string(resolution); }


// The leaves blending in each of the block's 2³ sub-blocks (closed boxes of 4³ cubes):
// shorter lists than one for the whole block, so each value scans fewer candidates.
struct SubBlockLeaves {
    static constexpr int kHalf = B / 2;  // cubes along a sub-block's side
    std::vector<uint32_t> list[8];
    void gather(const MpuFunction &mpu, const BlockGrid &g, const int64_t origin[3]) {
        // A hair wider than each sub-block, so a vertex rounded just past its face still
        // finds every leaf that covers it (an extra candidate changes nothing).
        const Eigen::Vector3d pad = Eigen::Vector3d::Constant(1e-6 * g.h);
        // One octree walk for the whole block; each sub-block filters its list.
        thread_local std::vector<uint32_t> block;
        const Eigen::Vector3d origin_corner = g.corner(origin[0], origin[1], origin[2]);
        mpu.gather(Eigen::AlignedBox3d(origin_corner - pad, origin_corner + Eigen::Vector3d::Constant(2 * kHalf * g.h) + pad),
                   block);
        for (int s = 0; s < 8; ++s) {
            const Eigen::Vector3d lo = g.corner(origin[0] + kHalf * (s & 1), origin[1] + kHalf * (s >> 1 & 1),
                                                origin[2] + kHalf * (s >> 2 & 1));
            mpu.gather_among(block, Eigen::AlignedBox3d(lo - pad, lo + Eigen::Vector3d::Constant(kHalf * g.h) + pad), list[s]);
        }
    }
};

// Marching cubes over one band block.
void polygonize_block(const BlockGrid &g, const SurfaceField &f, const PointBuckets &buckets, const std::vector<int64_t> &band,
                      size_t band_index, int root_steps, FarValueCache &far_cache, BlockOutput &out) {
    const int64_t block = band[band_index];
    constexpr int C = B + 1;  // corners along a block's side
    thread_local std::vector<double> value(C * C * C);
    thread_local std::vector<uint8_t> forced(C * C * C);
    thread_local std::vector<int32_t> slot(C * C * C * 8);
    thread_local SubBlockLeaves leaves;

    int64_t pos[3];
    g.block_position(block, pos);
    const int64_t x0 = pos[0] * B, y0 = pos[1] * B, z0 = pos[2] * B;
    const int64_t origin[3] = {x0, y0, z0};
    auto local = [](int i, int j, int k) { return i + C * (j + C * k); };
    leaves.gather(f.mpu(), g, origin);
    // Every (representative) point whose trust ball reaches the block.
    const uint32_t *near = buckets.point.data() + buckets.begin(band_index);
    const uint32_t *weight = buckets.weight.data() + buckets.begin(band_index);
    const size_t near_count = buckets.end(band_index) - buckets.begin(band_index);
    const Eigen::AlignedBox3d box = g.block_box(block);
    // Corner values: a function of the corner's position alone (never of the block), so
    // neighbouring blocks agree on shared corners. A corner touching a far block takes that
    // region's sign; every other corner asks the field.
    const bool touches_far = g.touches_far(block);
    if (touches_far)
        for (int k = 0; k < C; ++k)
            for (int j = 0; j < C; ++j)
                for (int i = 0; i < C; ++i) {
                    const int8_t sign = g.forced_sign(x0 + i, y0 + j, z0 + k);
                    forced[size_t(local(i, j, k))] = sign != 0;
                    if (sign != 0) value[size_t(local(i, j, k))] = sign * g.h;
                }
    LatticeBlock lattice;
    lattice.grid_origin = g.origin;
    lattice.h = g.h;
    for (int d = 0; d < 3; ++d) lattice.start[d] = origin[d];
    lattice.n = B;
    for (int s = 0; s < 8; ++s) lattice.leaves[s] = &leaves.list[s];
    f.block_values(lattice, near, near_count, touches_far ? forced.data() : nullptr, value.data(), &far_cache);
    std::fill(slot.begin(), slot.end(), -1);

    auto vertex = [&](int i, int j, int k, const mc::Edge &e) -> uint32_t {
        const int ai = i + (e.from & 1), aj = j + (e.from >> 1 & 1), ak = k + (e.from >> 2 & 1);
        const int bi = i + (e.to & 1), bj = j + (e.to >> 1 & 1), bk = k + (e.to >> 2 & 1);
        const int dir = mc::edge_direction(e);
        int32_t &s = slot[size_t(local(ai, aj, ak) * 8 + dir)];
        if (s >= 0) return uint32_t(s);
        const double va = value[size_t(local(ai, aj, ak))], vb = value[size_t(local(bi, bj, bk))];
        const Eigen::Vector3d pa = g.corner(x0 + ai, y0 + aj, z0 + ak), pb = g.corner(x0 + bi, y0 + bj, z0 + bk);
        const std::vector<uint32_t> &cube_leaves = lattice.leaves_at(i, j, k);  // the cube (i, j, k) holds the edge
        const double t = edge_root(
            va, vb, [&](double s) { return f.mpu().value_among(cube_leaves, pa + s * (pb - pa), nullptr); },
            root_steps, kRootTolerance * g.h);
        const Eigen::Vector3d p = pa + t * (pb - pa);
        Eigen::Vector3d grad;
        f.mpu().value_among(cube_leaves, p, &grad);
        s = int32_t(out.vertex_pos.size());
        out.vertex_pos.push_back(p);
        out.vertex_grad.push_back(grad);
        out.vertex_key.push_back(g.corner_id(x0 + ai, y0 + aj, z0 + ak) * 8 + uint64_t(dir));
        return uint32_t(s);
    };

    // A quad splits along the diagonal whose two triangles face most like the outward
    // normals −∇f at their vertices.
    auto facing = [&](uint32_t a, uint32_t b, uint32_t c) {
        const std::vector<Eigen::Vector3d> &p = out.vertex_pos, &grad = out.vertex_grad;
        const Eigen::Vector3d n = (p[b] - p[a]).cross(p[c] - p[a]);
        const Eigen::Vector3d g = grad[a].normalized() + grad[b].normalized() + grad[c].normalized();
        const double scale = n.norm() * g.norm();
        return scale > 0 ? -n.dot(g) / scale : 0.0;
    };
    mc::march_block(
        B, [&](int i, int j, int k) { return value[size_t(local(i, j, k))]; },
        [&](int i, int j, int k, const mc::Edge &e) { out.triangles.push_back(vertex(i, j, k, e)); },
        [&](int i, int j, int k, const mc::Edge *q) {
            uint32_t v[4];
            for (int c = 0; c < 4; ++c) v[c] = vertex(i, j, k, q[c]);
            return facing(v[0], v[1], v[2]) + facing(v[0], v[2], v[3]) >=
                   facing(v[0], v[1], v[3]) + facing(v[1], v[2], v[3]);
        });

    // Each point inside the block votes for its nearest vertex here: the surface near the
    // data collects the votes, bubbles away from it none (see remove_unsupported_components).
    out.votes.assign(out.vertex_pos.size(), 0);
    if (out.vertex_pos.empty()) return;
    for (size_t n = 0; n < near_count; ++n) {
        const Eigen::Vector3d q = f.points().point(near[n]);
        if (!(q.array() >= box.min().array()).all() || !(q.array() < box.max().array()).all()) continue;
        size_t best = 0;
        double best_d2 = INFINITY;
        for (size_t v = 0; v < out.vertex_pos.size(); ++v) {
            const double d2 = (out.vertex_pos[v] - q).squaredNorm();
            if (d2 < best_d2) best_d2 = d2, best = v;
        }
        out.votes[best] += weight[n];
    }
}

}  // namespace

double median_leaf_size(const Octree &tree) {
    std::vector<double> sizes;
    for (const Cell &c : tree.cells)
        if (c.is_sizing_leaf()) sizes.push_back(c.size);
    return sizes.empty() ? INFINITY : median_in_place(sizes);
}

double thin_wall_gap(const Octree &tree) {
    // The walls must hold a real share of the points: a few two-sheet leaves in a narrow slot
    // would otherwise refine the whole grid.
    std::vector<std::pair<double, uint32_t>> walls;  // gap, points
    double points = 0.0;
    for (const Cell &c : tree.cells) {
        if (!c.is_sizing_leaf()) continue;
        points += double(c.point_end - c.point_begin);
        if (c.shape.model == Model::two_sheets)
            walls.push_back({tree.pieces[size_t(c.shape.piece)].sheet_gap(), c.point_end - c.point_begin});
    }
    std::sort(walls.begin(), walls.end());
    double held = 0.0;
    for (const auto &w : walls)
        if ((held += w.second) >= kWallShare * points) return w.first;
    return INFINITY;
}

int default_resolution(const Octree &tree, const PointMeasures &measures) {
    // Half the median size of the leaves that hold points (the grid then resolves every
    // local fit with about two cubes across), or finer where the points are dense:
    // kCubePerSpacing mean sample spacings (from the surface area the points stand for),
    // down to kFinestSizeCube. Where leaves hold two sheets, the cube must
    // also be well under their gap, or both sheets fall between two grid corners of the same
    // sign and vanish.
    const double leaf = median_leaf_size(tree);
    if (!std::isfinite(leaf)) return 64;
    double area = 0.0;
    for (float a : measures.area) area += double(a);
    // Without areas (nothing measured): two cubes across the median leaf.
    double h = 0.5 * leaf;
    if (area > 0.0) {
        const double sized = kCubePerSpacing * std::sqrt(area / double(measures.area.size()));
        h = std::min(std::max(sized, kFinestSizeCube), kCubesPerLeaf * leaf);
    }
    h = std::min(h, kCubesPerGap * thin_wall_gap(tree));
    return std::clamp(int(std::ceil(1.0 / h)), 32, 1024);
}

Mesh polygonize(const SurfaceField &field, int resolution, const Params &params, Workers &workers,
                Progress &progress, double noise) {
    const PointSet &points = field.points();
    const PointMeasures &measures = field.measures();
    // The steps' shares of the stage's progress: the grid and the point buckets, the blocks,
    // the weld, the cleanup.
    Progress grid_progress = progress.slice(0.0, 0.02), blocks_progress = progress.slice(0.02, 0.95),
             weld_progress = progress.slice(0.95, 0.97), cleanup_progress = progress.slice(0.97, 0.98),
             sharpen_progress = progress.slice(0.98, 0.99), cap_progress = progress.slice(0.99, 1.0);
    const double h = 1.0 / resolution, min_trust = grid_min_trust(resolution);
    const bool clean = noise < kCleanNoise * h && mean_spacing(measures) < kDenseSpacing * h;
    // Before allocating anything: the grid alone, then with the band, must fit the budget.
    const double grid_blocks = BlockGrid::blocks_for(points, resolution, std::max(measures.widest_trust, min_trust));
    check_memory(polygonize_memory(grid_blocks, 0, 0), params.max_memory, resolution_text(resolution).c_str());
    const BlockGrid g(points, resolution, measures.trust_radius, min_trust, field.winding(), grid_progress);
    // A band block meets some point's (widened) trust ball, so each of its corners has a point
    // within that radius plus the block's diagonal: the bound for every neighbour search below.
    const double search_bound = std::max(measures.widest_trust, min_trust) + B * std::sqrt(3.0) * h + h;
    const SurfaceField f = field.bounded(min_trust, search_bound);
    std::vector<int64_t> band;
    for (int64_t b = 0; b < int64_t(g.block_count()); ++b)
        if (g.band[size_t(b)]) band.push_back(b);
    const double band_blocks = double(band.size());
    check_memory(polygonize_memory(grid_blocks, band_blocks, band_blocks * kTrianglesPerBandBlock), params.max_memory,
                 resolution_text(resolution).c_str());
    grid_progress.poll(1.0);

    const PointBuckets buckets(g, band, f, grid_progress, 1.0);
    FarValueCache far_cache(g.blocks, B, SurfaceField::kFarStep, band);
    progress.throw_if_cancelled();
    std::vector<BlockOutput> blocks(band.size());
    std::atomic<uint64_t> triangles{0};
    parallel_for(0, band.size(), workers, blocks_progress, [&](size_t i) {
        polygonize_block(g, f, buckets, band, i, clean ? kRootSteps : 0, far_cache, blocks[i]);
        const uint64_t made = blocks[i].triangles.size() / 3;
        const double so_far = double(triangles.fetch_add(made) + made);
        if (so_far > params.max_triangles)
            throw Error(GMPU_ERROR_LIMIT_EXCEEDED,
                        "the mesh needs more than GMPU_PARAM_MAX_TRIANGLES = " +
                            std::to_string(uint64_t(params.max_triangles)) +
                            " triangles; lower GMPU_PARAM_RESOLUTION or raise the cap");
        // Enforced as the triangles are made, not only estimated: the surface may be larger
        // than the band suggested.
        check_memory(polygonize_memory(grid_blocks, band_blocks, so_far), params.max_memory,
                     resolution_text(resolution).c_str());
    }, 1);  // one block per chunk: a cancel waits for one block per thread
    progress.throw_if_cancelled();
    std::vector<uint32_t> votes;
    Mesh mesh = weld(blocks, points.normalisation(), weld_progress, votes);
    progress.throw_if_cancelled();
    remove_unsupported_components(mesh, votes, kMinVotes, cleanup_progress);
    remove_components_smaller_than(mesh, kGridScalePiece * h / points.normalisation().scale, cleanup_progress);
    if (clean) sharpen_features(mesh, kSharpenReach * h / points.normalisation().scale, sharpen_progress);
    // A grid the caller chose keeps all its triangles.
    if (params.resolution == 0) cap_mesh_size(mesh, points.size(), kCapErrorShare * params.error, workers, cap_progress);
    return mesh;  // the caller makes the final report, once the temporaries are freed
}

}  // namespace gmpu
