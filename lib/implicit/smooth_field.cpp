#include "implicit/smooth_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <vector>

#include "core/block_sums.hpp"
#include "core/conjugate_gradients.hpp"
#include "core/error.hpp"
#include "core/median.hpp"
#include "core/memory_budget.hpp"
#include "implicit/point_measures.hpp"

namespace gmpu {

namespace {
// Conjugate gradients stop once the residual falls below this share of the right-hand
// side, or after kMaxIterations.
constexpr double kTolerance = 1e-4;
constexpr int kMaxIterations = 300;
// The outer field (over the whole box) stops after fewer: it starts from the band's
// distances, it need only be settled near the band's edge, and far from the points only
// its sign matters; most of the solve's time would otherwise go there. This many on the
// default outer grid (OuterGrid), proportionally fewer on a coarser one: conjugate gradients
// carry a change about a node farther per iteration, and the same reach beyond the band's
// edge is fewer nodes there.
constexpr int kOuterIterations = 120;
// A re-solve of the band starts from the first solution, which differs only where the
// normals changed.
constexpr int kResolveIterations = 100;
// Coarser levels of the cascade (each twice the previous step).
constexpr int kCoarseLevels = 1;
// A point's splat reaches its trust radius, but never more than this many fine grid steps:
// a point far from the others (a sparse patch, a stray cluster) would otherwise splat onto
// a ball of (trust / h)³ nodes, and the band's size would follow the gaps in the data
// instead of the points and the grid. Beyond it the outer field answers.
constexpr double kMaxReachSteps = 12.0;
// Memory model, for GMPU_PARAM_MAX_MEMORY: per node of a touched block, the splat's sums
// (weight, distance, the normals' weight, sum and offset) and its index; per unknown, the field,
// its six neighbours, its row's start and the solver's vectors; per point, its 8 trilinear weights and nodes,
// its entries in the blocks' and the rows' lists (about 8 blocks, 8 corners) and its value
// in the products, its cell and value for the local zero level; per unknown again, the thin
// parts' correction.
constexpr double kBytesPerSlotNode = 76, kBytesPerUnknown = 208, kBytesPerPoint = 192;

// The value the zero set is put at among the samples' values (`values` reordered).
double sample_level(std::vector<double> &values, ZeroLevel level) {
    if (values.empty()) return 0.0;
    if (level == ZeroLevel::mean) {
        double sum = 0.0;
        for (double v : values) sum += v;
        return sum / double(values.size());
    }
    return median_in_place(values);
}

int outer_iterations(double outer_steps) {
    return int(std::lround(kOuterIterations * OuterGrid{}.steps / outer_steps));
}

}  // namespace

int32_t SmoothField::node(int64_t x, int64_t y, int64_t z) const {
    if (x < 0 || y < 0 || z < 0 || x >= nodes_[0] || y >= nodes_[1] || z >= nodes_[2]) return -1;
    const int32_t slot = block_slot_[size_t(x / B + blocks_[0] * (y / B + blocks_[1] * (z / B)))];
    if (slot < 0) return -1;
    return node_index_[size_t(slot) * B * B * B + size_t(x % B + B * (y % B + B * (z % B)))];
}

SmoothField::Corners SmoothField::corners(const Eigen::Vector3d &t) const {
    Corners k;
    for (int d = 0; d < 3; ++d) k.base[d] = int64_t(std::floor(t[d]));
    const double fx = t[0] - double(k.base[0]), fy = t[1] - double(k.base[1]), fz = t[2] - double(k.base[2]);
    k.complete = true;
    for (int i = 0; i < 8; ++i) {
        const int dx = i & 1, dy = i >> 1 & 1, dz = i >> 2 & 1;
        k.node[i] = node(k.base[0] + dx, k.base[1] + dy, k.base[2] + dz);
        k.complete &= k.node[i] >= 0;
        k.weight[i] = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
    }
    return k;
}

SmoothField::SmoothField(const PointSet &points, const PointMeasures &measures, double spacing, double min_trust,
                         double noise, ZeroLevel level, double max_memory, Workers &workers, Progress &progress,
                         LocalLevel local, ThinPartBias thin, Sparseness sparseness, OuterGrid outer_grid) {
    if (points.size() == 0) return;
    max_reach_ = kMaxReachSteps * spacing;
    fine_step_ = spacing;
    level_ = level;
    local_ = local;
    thin_ = thin;
    sparseness_ = sparseness;
    {
        // The fine band takes more memory than the coarser bands: laid out first, its memory
        // check fails a cloud too scattered for the budget before the outer field and the
        // coarser bands are solved for nothing.
        SmoothField fine = with_step(spacing);
        Progress layout_progress = progress.slice(0.0, 0.0);
        fine.lay_out(points, measures, min_trust, false, max_memory, layout_progress);
    }
    // The outer field: the same problem on a coarser grid over the whole box, solved first.
    auto outer = std::make_shared<SmoothField>(with_step(outer_grid.steps * spacing));
    Progress outer_progress = progress.slice(0.0, 0.1);
    outer->solve(points, measures, measures.blend_normals, min_trust, noise, max_memory, nullptr, nullptr, true,
                 outer_iterations(outer_grid.steps), workers, outer_progress);
    // The cascade: each coarser level (twice the step) solved first, its field the next
    // level's start.
    std::vector<double> steps{spacing};
    for (int l = 0; l < kCoarseLevels; ++l) steps.push_back(2.0 * steps.back());
    SmoothField coarse;
    const double levels = double(steps.size());
    for (size_t l = steps.size(); l-- > 1;) {
        SmoothField coarser = with_step(steps[l]);
        Progress slice = progress.slice(0.1 + (levels - 1 - double(l)) / levels * 0.1,
                                        0.1 + (levels - double(l)) / levels * 0.1);
        coarser.solve(points, measures, measures.blend_normals, min_trust, noise, max_memory,
                      coarse.empty() ? nullptr : &coarse, outer.get(), false, kMaxIterations, workers, slice);
        coarse = std::move(coarser);
    }
    h_ = spacing;
    Progress fine = progress.slice(steps.size() > 1 ? 0.2 : 0.0, 1.0);
    const double shift = solve(points, measures, measures.blend_normals, min_trust, noise, max_memory,
                               coarse.empty() ? nullptr : &coarse, outer.get(), false, kMaxIterations, workers, fine);
    // The fine level's zero set is the surface: the outer field follows its shift, so the
    // two agree where one hands over to the other.
    for (double &v : outer->values_) v -= shift;
    outer_ = std::move(outer);
    min_trust_ = min_trust;
}

SmoothField SmoothField::with_step(double step) const {
    SmoothField field;
    field.h_ = step;
    field.max_reach_ = max_reach_;
    field.fine_step_ = fine_step_;
    field.level_ = level_;
    field.local_ = local_;
    field.thin_ = thin_;
    field.sparseness_ = sparseness_;
    return field;
}

SmoothField SmoothField::resolved(const PointSet &points, const PointMeasures &measures,
                                  const std::vector<float> &normals, double noise, double max_memory,
                                  Workers &workers, Progress &progress) const {
    if (empty()) return SmoothField();
    SmoothField next = with_step(h_);
    next.min_trust_ = min_trust_;
    // The outer field first: it holds the band's edge, and a misoriented patch's error lives
    // in it as much as in the band (kept, the old outer field would pin the band's edge to
    // the old normals' surface). Both start from the previous solution.
    auto outer = std::make_shared<SmoothField>(with_step(outer_->h_));
    Progress outer_progress = progress.slice(0.0, 0.3);
    outer->solve(points, measures, normals, min_trust_, noise, max_memory, outer_.get(), nullptr, true,
                 outer_iterations(outer_->h_ / h_), workers, outer_progress);
    Progress band_progress = progress.slice(0.3, 1.0);
    const double shift = next.solve(points, measures, normals, min_trust_, noise, max_memory, this, outer.get(), false,
                                    kResolveIterations, workers, band_progress);
    for (double &v : outer->values_) v -= shift;
    next.outer_ = std::move(outer);
    return next;
}

double SmoothField::splat_radius(const PointMeasures &measures, size_t i, double min_trust) const {
    return std::min(std::max(double(measures.trust_radius[i]), min_trust), max_reach_) + std::sqrt(3.0) * h_;
}

void SmoothField::box_of(const Eigen::Vector3d &point, double r, int64_t lo[3], int64_t hi[3]) const {
    const Eigen::Vector3d p = point - origin_;
    for (int d = 0; d < 3; ++d) {
        lo[d] = std::max<int64_t>(0, int64_t(std::ceil((p[d] - r) / h_)));
        hi[d] = std::min<int64_t>(nodes_[d] - 1, int64_t(std::floor((p[d] + r) / h_)));
    }
}

int32_t SmoothField::lay_out(const PointSet &points, const PointMeasures &measures, double min_trust, bool whole_box,
                             double max_memory, Progress &progress) {
    const size_t n = points.size();
    double widest = 0.0;
    for (size_t i = 0; i < n; ++i) widest = std::max(widest, splat_radius(measures, i, min_trust));
    origin_ = points.box_min() - Eigen::Vector3d::Constant(widest + 2.0 * h_);
    for (int d = 0; d < 3; ++d) {
        nodes_[d] = int64_t(std::ceil((points.box_max()[d] - origin_[d] + widest + 2.0 * h_) / h_)) + 1;
        blocks_[d] = (nodes_[d] + B - 1) / B;
        if (whole_box) nodes_[d] = blocks_[d] * B;  // every slot node is then a grid node
    }
    const char *what = "the smooth surface's solve (GMPU_PARAM_SURFACE)";
    check_memory(double(blocks_[0]) * double(blocks_[1]) * double(blocks_[2]) * sizeof(int32_t), max_memory, what);
    // A sample's corners are numbered 8 × its index in 32 bits (the rows' lists below).
    if (8.0 * double(n) > double(UINT32_MAX))
        throw Error(GMPU_ERROR_LIMIT_EXCEEDED, std::string(what) + " takes at most 536,870,911 points");
    block_slot_.assign(size_t(blocks_[0] * blocks_[1] * blocks_[2]), -1);

    int32_t slots = 0;
    if (whole_box)
        for (int32_t &s : block_slot_) s = slots++;
    for (size_t i = 0; i < n && !whole_box; ++i) {
        if (i % 1024 == 0) progress.poll(0.05 * double(i) / double(n));
        int64_t lo[3], hi[3];
        box_of(points.point(i), splat_radius(measures, i, min_trust), lo, hi);
        for (int64_t z = lo[2] / B; z <= hi[2] / B; ++z)
            for (int64_t y = lo[1] / B; y <= hi[1] / B; ++y)
                for (int64_t x = lo[0] / B; x <= hi[0] / B; ++x) {
                    int32_t &s = block_slot_[size_t(x + blocks_[0] * (y + blocks_[1] * z))];
                    if (s < 0) s = slots++;
                }
    }
    // Every node of a touched block might be an unknown: an upper estimate, before the
    // big allocations.
    const double block_nodes = double(slots) * B * B * B;
    check_memory(block_nodes * (kBytesPerSlotNode + kBytesPerUnknown) + double(n) * kBytesPerPoint, max_memory, what);
    return slots;
}

double SmoothField::solve(const PointSet &points, const PointMeasures &measures, const std::vector<float> &normals,
                          double min_trust, double noise, double max_memory, const SmoothField *coarse,
                          const SmoothField *boundary, bool whole_box, int iterations, Workers &workers,
                          Progress &progress) {
    const size_t n = points.size();
    const int32_t slots = lay_out(points, measures, min_trust, whole_box, max_memory, progress);
    const double sigma = noise * points.world_diagonal() * points.normalisation().scale;
    // The band: the points' splats give each node V and a start, and its edges' equations.
    BandEquations band = band_equations(splat(points, measures, normals, min_trust, sigma, slots, workers, progress),
                                        coarse, boundary, whole_box, workers, progress);
    const int32_t unknowns = int32_t(band.rhs.size());
    // Normal equations of the energy: every grid edge inside the band asks f to rise along it
    // by h times V's component (V = −average outward normal, f grows inward), every sample
    // asks its trilinear value to be 0. The edges make a sparse matrix; the samples' part
    // α Sᵀ D S is applied in factored form (8 weights per sample), far fewer products than
    // its 27-neighbour stencil assembled.
    Eigen::VectorXd diagonal = band.edge_diagonal;  // of the whole matrix: the preconditioner
    const SampleRows samples = sample_rows(points, measures, noise, unknowns, diagonal, workers, progress);
    Progress quiet = progress.slice(0.45, 0.45);  // the loops below only check for a cancel
    std::vector<double> at_sample(n, 0.0);
    auto apply = [&](const Eigen::VectorXd &v, Eigen::VectorXd &out) {
        block_for(n, workers, quiet, [&](size_t lo, size_t hi) {
            for (size_t i = lo; i < hi; ++i) {
                if (samples.scale[i] == 0.0) continue;
                const int32_t *idx = &samples.node[8 * i];
                const double *w = &samples.weight[8 * i];
                double at = 0.0;
                for (int k = 0; k < 8; ++k) at += w[k] * v[idx[k]];
                at_sample[i] = at * samples.scale[i];
            }
        });
        block_for(size_t(unknowns), workers, quiet, [&](size_t lo, size_t hi) {
            for (size_t u = lo; u < hi; ++u) {
                double around = 0.0;
                for (int j = 0; j < 6; ++j) {
                    const int32_t b = band.neighbours[6 * u + size_t(j)];
                    if (b >= 0) around += v[b];
                }
                double sum = band.edge_diagonal[Eigen::Index(u)] * v[Eigen::Index(u)] - band.edge_weight * around;
                for (uint32_t e = samples.row_start[u]; e < samples.row_start[u + 1]; ++e)
                    sum += at_sample[samples.row_pairs[e] / 8] * samples.weight[samples.row_pairs[e]];
                out[Eigen::Index(u)] = sum;
            }
        });
    };
    progress.poll(0.45);

    Eigen::VectorXd x = band.start;
    conjugate_gradients(apply, band.rhs, diagonal, x, kTolerance, iterations, workers, progress, 0.45);
    Eigen::VectorXd thin_bias;
    if (!whole_box && thin_ == ThinPartBias::correct && sigma > 0.0)
        thin_bias = thin_part_bias(x, sigma, workers, progress);
    // The zero set through the samples (ZeroLevel): with weak screening the normals'
    // integral alone fixes f up to an offset, which would shrink or swell the whole surface.
    std::vector<double> at_samples;
    at_samples.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        if (samples.scale[i] != 0.0) at_samples.push_back(samples.value(i, x));
    }
    const double shift = sample_level(at_samples, level_);
    x.array() -= shift;
    if (!whole_box && local_ == LocalLevel::follow)
        follow_local_level(points, samples, sigma, x, workers, progress);
    if (thin_bias.size() == x.size()) x += thin_bias;
    values_.assign(x.data(), x.data() + unknowns);
    progress.report(1.0);
    return shift;
}

Eigen::Vector3d SmoothField::node_gradient(int64_t x, int64_t y, int64_t z) const {
    const int32_t c = node(x, y, z);
    Eigen::Vector3d g;
    for (int d = 0; d < 3; ++d) {
        const int64_t e[3] = {d == 0, d == 1, d == 2};
        const int32_t lo = node(x - e[0], y - e[1], z - e[2]), hi = node(x + e[0], y + e[1], z + e[2]);
        if (lo >= 0 && hi >= 0) g[d] = (values_[size_t(hi)] - values_[size_t(lo)]) / (2 * h_);
        else if (hi >= 0) g[d] = (values_[size_t(hi)] - values_[size_t(c)]) / h_;
        else if (lo >= 0) g[d] = (values_[size_t(c)] - values_[size_t(lo)]) / h_;
        else g[d] = 0.0;
    }
    return g;
}

bool SmoothField::value(const Eigen::Vector3d &x, double &f, Eigen::Vector3d *gradient) const {
    if (band_value(x, f, gradient)) return true;
    return outer_ && outer_->band_value(x, f, gradient);
}

bool SmoothField::band_value(const Eigen::Vector3d &x, double &f, Eigen::Vector3d *gradient) const {
    if (values_.empty()) return false;
    const Eigen::Vector3d t = (x - origin_) / h_;
    if (!(t.array() >= 0.0).all() || !(t.array() < 1e9).all()) return false;
    const Corners corner = corners(t);
    if (!corner.complete) return false;
    f = 0.0;
    if (gradient) gradient->setZero();
    for (int k = 0; k < 8; ++k) {
        f += corner.weight[k] * values_[size_t(corner.node[k])];
        if (gradient)
            *gradient += corner.weight[k] * node_gradient(corner.base[0] + (k & 1), corner.base[1] + (k >> 1 & 1),
                                                          corner.base[2] + (k >> 2 & 1));
    }
    return true;
}

}  // namespace gmpu