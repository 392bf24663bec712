// SmoothField's band (smooth_field.hpp): the points' splats on the grid's nodes, and from
// them V, the start and the equations of the band's edges.
#include "implicit/smooth_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <vector>

#include "core/huge_pages.hpp"
#include "implicit/point_measures.hpp"

namespace gmpu {

namespace {
// Where the nearby normals agree this well (the length of their weighted mean), V is their
// unit mean direction: a mean shortened by curvature would flatten f across curved parts.
// Below it (two sheets, a thin part's two sides) V keeps its shortened length.
constexpr double kAgreeing = 0.3;
// The normals' field V reaches this many grid steps from each point (a cell diagonal
// more), however far the band reaches: beyond it V is 0 and f only smooth, as in screened
// Poisson's narrow splat. A wider V carries one sheet's normals across a thin wall onto the
// other and, over a misoriented patch, makes f rise along the wrong normals over the
// whole band instead of a few cells.
constexpr double kNormalReachSteps = 3.0;
// Across a sheet (along a point's own normal) the normals reach only kAcrossShare of that,
// but at least kAcrossSigmas noise deviations: a node then takes its V from the sheet
// whose plane passes nearest, not from both sides of a part thinner than the reach, whose
// normals cancel there and leave f only smooth (a sparse thin part comes out thinner or
// detached). Along the sheet the reach is unchanged, so V still bridges the gaps between
// sparse samples; the noise floor keeps a noisy sheet's spread points in each node's mean,
// where a narrower kernel samples the noise and the surface grows handles. On a sparse
// cloud the floor is divided by the Sparseness factor: a node's mean holds few points there
// anyway, and what the floor cost were legs and blades. kAcrossIsotropic of each weight
// stays round, so a node that only one sheet reaches keeps its unit V.
constexpr double kAcrossShare = 1.0 / 3.0, kAcrossSigmas = 4.0, kAcrossIsotropic = 0.05;
// Only under noise does the cancelling cost a thin part its faces: without noise the
// samples' full pull holds each face, and the narrowing there only opened holes in sparse
// thin walls. It grows with σ̂ to its full effect at kAcrossNoiseSteps of a grid step.
constexpr double kAcrossNoiseSteps = 0.1;
// V fades where a node lies off the side of the points that reach it rather than over them:
// from kOverhangFull to kOverhangNone of the normals' reach between the node and the
// points' weighted centre, measured across their mean normal. Past a thin part's edge (a
// plate's rim, a blade's tip) the faces' normals reach the node from one side only, and a
// full-length V there asks f to rise towards the part's middle plane beyond the edge: the
// part grows a fin as long as the reach. Over a sheet, between two sheets or across a thin
// part the points lie on all sides of the node and V is unchanged. Only where the normals
// disagree (their weighted mean shorter than kOverhangAgreement: a thin part's two faces
// and its rim): near a single face's edge or bend (a CAD part's edges) the points' centre
// moves to the side as well, and a V faded there rounds the part.
constexpr double kOverhangFull = 0.15, kOverhangNone = 0.35, kOverhangAgreement = 0.9;

// V's reach from a point on a grid of step h (capped by the point's own radius in the
// splat).
double normal_reach_of(double h) { return (kNormalReachSteps + std::sqrt(3.0)) * h; }

double weight(double d2, double r2) {
    const double t = 1.0 - d2 / r2;
    return t > 0.0 ? t * t : 0.0;
}

// V's factor at a node whose points' weighted centre lies at `offset` from it and whose
// normals' weighted mean is `mean` (kOverhangFull above). Where the normals cancel (`mean`
// very short: both faces of a thin part alike) the whole offset counts.
double overhang_fade(const Eigen::Vector3d &offset, const Eigen::Vector3d &mean, double reach) {
    constexpr double kDirectionless = 0.05;
    const double length = mean.norm();
    if (length >= kOverhangAgreement) return 1.0;
    const Eigen::Vector3d across =
        length > kDirectionless ? Eigen::Vector3d(offset - offset.dot(mean / length) * (mean / length)) : offset;
    return std::clamp((kOverhangNone - across.norm() / reach) / (kOverhangNone - kOverhangFull), 0.0, 1.0);
}

}  // namespace

size_t SmoothField::slot_node(int64_t x, int64_t y, int64_t z) const {
    constexpr size_t BBB = size_t(B) * B * B;
    return size_t(block_slot_[size_t(x / B + blocks_[0] * (y / B + blocks_[1] * (z / B)))]) * BBB +
           size_t(x % B + B * (y % B + B * (z % B)));
}

HugePageVector<SmoothField::NodeSums> SmoothField::splat(const PointSet &points, const PointMeasures &measures,
                                                      const std::vector<float> &normals, double min_trust,
                                                      double sigma, int32_t slots, Workers &workers,
                                                      Progress &progress) const {
    const size_t n = points.size();
    auto radius = [&](size_t i) { return splat_radius(measures, i, min_trust); };
    auto node_box = [&](size_t i, int64_t lo[3], int64_t hi[3]) { box_of(points.point(i), radius(i), lo, hi); };
    constexpr size_t BBB = size_t(B) * B * B;
    HugePageVector<NodeSums> sums(size_t(slots) * BBB);
    // Each block of nodes sums the points whose boxes reach it, in the points' order (so a
    // node's sums do not depend on the thread count); the blocks run in parallel.
    std::vector<uint32_t> block_start(size_t(slots) + 1, 0), block_points;
    auto for_blocks = [&](size_t i, auto &&visit) {
        int64_t lo[3], hi[3];
        node_box(i, lo, hi);
        for (int64_t z = lo[2] / B; z <= hi[2] / B; ++z)
            for (int64_t y = lo[1] / B; y <= hi[1] / B; ++y)
                for (int64_t x = lo[0] / B; x <= hi[0] / B; ++x)
                    visit(size_t(block_slot_[size_t(x + blocks_[0] * (y + blocks_[1] * z))]));
    };
    for (size_t i = 0; i < n; ++i) {
        if (i % 4096 == 0) progress.poll(0.05);
        for_blocks(i, [&](size_t slot) { ++block_start[slot + 1]; });
    }
    for (size_t b = 0; b < size_t(slots); ++b) block_start[b + 1] += block_start[b];
    block_points.resize(block_start.back());
    {
        std::vector<uint32_t> fill(block_start.begin(), block_start.end() - 1);
        for (size_t i = 0; i < n; ++i) {
            if (i % 4096 == 0) progress.poll(0.05);
            for_blocks(i, [&](size_t slot) { block_points[fill[slot]++] = uint32_t(i); });
        }
    }
    std::vector<int64_t> slot_block(static_cast<size_t>(slots));
    for (size_t b = 0; b < block_slot_.size(); ++b)
        if (block_slot_[b] >= 0) slot_block[size_t(block_slot_[b])] = int64_t(b);
    const double normal_reach = normal_reach_of(h_);
    const double across_floor = kAcrossSigmas * sigma / sparseness_.factor;
    const double across_reach = std::min(normal_reach, std::max(kAcrossShare * normal_reach, across_floor));
    const double across_stretch = std::min(sigma / (kAcrossNoiseSteps * h_), 1.0) *
                                  ((normal_reach / across_reach) * (normal_reach / across_reach) - 1.0);
    Progress splat_progress = progress.slice(0.05, 0.2);
    parallel_for(0, size_t(slots), workers, splat_progress, [&](size_t slot) {
        const int64_t b = slot_block[slot];
        const int64_t base[3] = {B * (b % blocks_[0]), B * (b / blocks_[0] % blocks_[1]), B * (b / blocks_[0] / blocks_[1])};
        for (uint32_t e = block_start[slot]; e < block_start[slot + 1]; ++e) {
            const size_t i = block_points[e];
            int64_t lo[3], hi[3];
            node_box(i, lo, hi);
            for (int d = 0; d < 3; ++d) lo[d] = std::max(lo[d], base[d]), hi[d] = std::min(hi[d], base[d] + B - 1);
            const Eigen::Vector3d p = points.point(i);
            const Eigen::Vector3d nrm(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
            const double r = radius(i), r2 = r * r;
            const double normal_r = std::min(r, normal_reach);
            const double normal_r2 = normal_r * normal_r;
            // About half the box's nodes lie outside the ball: a row whose distance across
            // already reaches the radius is skipped whole, and a node is tested before the
            // weight's division.
            for (int64_t z = lo[2]; z <= hi[2]; ++z) {
                const double dz = origin_[2] + h_ * double(z) - p[2];
                for (int64_t y = lo[1]; y <= hi[1]; ++y) {
                    const double dy = origin_[1] + h_ * double(y) - p[1];
                    if (dy * dy + dz * dz >= r2) continue;
                    for (int64_t x = lo[0]; x <= hi[0]; ++x) {
                        const Eigen::Vector3d q = origin_ + h_ * Eigen::Vector3d(double(x), double(y), double(z));
                        const double d2 = (q - p).squaredNorm();
                        if (d2 >= r2) continue;
                        const double w = weight(d2, r2);
                        if (w <= 0.0) continue;
                        NodeSums &at = sums[slot * BBB + size_t(x - base[0] + B * (y - base[1] + B * (z - base[2])))];
                        at.wsum += w;
                        double wn = weight(d2, normal_r2);
                        if (across_stretch > 0.0) {
                            const double across = (q - p).dot(nrm);
                            wn = kAcrossIsotropic * wn +
                                 (1.0 - kAcrossIsotropic) * weight(d2 + across_stretch * across * across, normal_r2);
                        }
                        at.normal_wsum += wn;
                        at.normal += wn * nrm;
                        at.offset += wn * (p - q);
                        at.distance += w * (p - q).dot(nrm);  // inside (behind the normal): positive
                    }
                }
            }
        }
    }, 1);
    progress.throw_if_cancelled();
    return sums;
}

SmoothField::BandEquations SmoothField::band_equations(HugePageVector<NodeSums> &&sums, const SmoothField *coarse,
                                                       const SmoothField *boundary, bool whole_box, Workers &workers,
                                                       Progress &progress) {
    node_index_.assign(sums.size(), -1);
    int32_t unknowns = 0;
    for (size_t s = 0; s < sums.size(); ++s)
        if (sums[s].wsum > 0.0 || whole_box) node_index_[s] = unknowns++;
    const double normal_reach = normal_reach_of(h_);
    BandEquations eq;
    for (Eigen::VectorXd *v : {&eq.rhs, &eq.start, &eq.edge_diagonal}) {
        v->resize(unknowns);
        advise_huge_pages(*v);
    }
    eq.rhs.setZero();
    HugePageVector<Eigen::Vector3d> field(static_cast<size_t>(unknowns));
    Progress planes_progress = progress.slice(0.2, 0.2);  // the loops over planes only check for a cancel
    for_each_node(workers, planes_progress, [&](int64_t x, int64_t y, int64_t z, int32_t u) {
        const NodeSums &at = sums[slot_node(x, y, z)];
        // The start: the coarser level's field where it has one, else the smoothed
        // point-to-plane distance.
        double c;
        const Eigen::Vector3d q = origin_ + h_ * Eigen::Vector3d(double(x), double(y), double(z));
        eq.start[u] = coarse && coarse->value(q, c, nullptr) ? c : at.wsum > 0.0 ? at.distance / at.wsum : 0.0;
        // The average normal, shortened where neighbours disagree (between two sheets,
        // across a thin part): there f need not rise at all.
        field[size_t(u)] =
            at.normal_wsum > 0.0 ? Eigen::Vector3d(-at.normal / at.normal_wsum) : Eigen::Vector3d::Zero();
        const double length = field[size_t(u)].norm();
        if (length > kAgreeing) field[size_t(u)] /= length;
        if (at.normal_wsum > 0.0)
            field[size_t(u)] *= overhang_fade(at.offset / at.normal_wsum, at.normal / at.normal_wsum, normal_reach);
    });
    progress.throw_if_cancelled();
    if (whole_box && !coarse) {
        // Away from the points the start copies the nearest band node's (breadth first):
        // the exterior starts outside and enclosed regions on the side their band says,
        // which is about where the smooth solution settles (it is flat there).
        std::vector<uint8_t> reached(size_t(unknowns), 0);
        std::vector<int64_t> queue;
        for (int64_t z = 0; z < nodes_[2]; ++z)
            for (int64_t y = 0; y < nodes_[1]; ++y)
                for (int64_t x = 0; x < nodes_[0]; ++x)
                    if (sums[slot_node(x, y, z)].wsum > 0.0) {
                        reached[size_t(node(x, y, z))] = 1;
                        queue.push_back(x + nodes_[0] * (y + nodes_[1] * z));
                    }
        for (size_t head = 0; head < queue.size(); ++head) {
            const int64_t at = queue[head], x = at % nodes_[0], y = at / nodes_[0] % nodes_[1], z = at / nodes_[0] / nodes_[1];
            const double v = eq.start[node(x, y, z)];
            for (int d = 0; d < 3; ++d)
                for (int dir = -1; dir <= 1; dir += 2) {
                    const int64_t bx = x + (d == 0) * dir, by = y + (d == 1) * dir, bz = z + (d == 2) * dir;
                    const int32_t b = node(bx, by, bz);
                    if (b < 0 || reached[size_t(b)]) continue;
                    reached[size_t(b)] = 1;
                    eq.start[b] = v;
                    queue.push_back(bx + nodes_[0] * (by + nodes_[1] * bz));
                }
        }
    }
    HugePageVector<NodeSums>().swap(sums);  // before the edges' arrays
    eq.edge_weight = h_;  // Σ over edges of h·(Δf − h·V)² approximates ∫|∇f − V|²
    const double edge_weight = eq.edge_weight;
    eq.edge_diagonal.setZero();
    // The edges' part of the matrix: every edge weighs the same, so it is the unknowns'
    // neighbours (−x, +x, −y, +y, −z, +z; −1 where the band ends) and that weight.
    eq.neighbours.assign(6 * size_t(unknowns), -1);
    // Each unknown sums its own six edges (in a fixed order: −z, −y, −x, +x, +y, +z), so the
    // planes run in parallel.
    for_each_node(workers, planes_progress, [&](int64_t x, int64_t y, int64_t z, int32_t a) {
        for (int side = 0; side < 6; ++side) {
            const int d = side < 3 ? 2 - side : side - 3, dir = side < 3 ? -1 : 1;
            const int32_t b = node(x + (d == 0) * dir, y + (d == 1) * dir, z + (d == 2) * dir);
            if (b < 0) continue;
            // f should rise by `rise` from the lower node of the edge to the upper one.
            const double rise = h_ * 0.5 * (field[size_t(a)][d] + field[size_t(b)][d]);
            eq.edge_diagonal[a] += edge_weight;
            eq.neighbours[6 * size_t(a) + 2 * size_t(d) + (dir > 0)] = b;
            eq.rhs[a] += dir > 0 ? -edge_weight * rise : edge_weight * rise;
        }
    });
    progress.throw_if_cancelled();
    // The band's edge: an edge to a node outside the band asks for the same rise towards the
    // outer field's value there (a Dirichlet condition). Left free, f would keep rising
    // along the normals to the band's edge: over a misoriented patch it rises outward and
    // crosses zero where the band ends, a blister a band's width off the points. The outer
    // field, solved over the whole box like screened Poisson's, lets the patch's error
    // relax into the space around it instead.
    if (boundary)
        for_each_node(workers, planes_progress, [&](int64_t x, int64_t y, int64_t z, int32_t a) {
            for (int d = 0; d < 3; ++d)
                for (int dir = -1; dir <= 1; dir += 2) {
                    const int64_t bx = x + (d == 0) * dir, by = y + (d == 1) * dir, bz = z + (d == 2) * dir;
                    if (node(bx, by, bz) >= 0) continue;
                    double fb;
                    const Eigen::Vector3d qb = origin_ + h_ * Eigen::Vector3d(double(bx), double(by), double(bz));
                    if (!boundary->value(qb, fb, nullptr)) continue;
                    const double rise = h_ * field[size_t(a)][d] * double(dir);  // f_b − f_a wanted
                    eq.edge_diagonal[a] += edge_weight;
                    eq.rhs[a] += edge_weight * (fb - rise);
                }
        });
    progress.throw_if_cancelled();
    return eq;
}

}  // namespace gmpu
