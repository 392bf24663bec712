#include "implicit/smooth_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <array>
#include <vector>

#include "core/block_sums.hpp"
#include "core/error.hpp"
#include "core/median.hpp"
#include "core/memory_budget.hpp"
#include "implicit/point_measures.hpp"

namespace gmpu {

namespace {
// Screening weight α = s / h, s in grid units: how hard the zero set is pulled through
// each sample against the smoothness of the normals' integral. Strong on clean clouds (the
// surface goes through the samples), falling with the estimated noise σ̂ (a fraction of
// the diagonal): s = kMaxScreening · (knee / σ̂)^kNoisePower, bounded (on a sparse cloud
// s and its bound are multiplied by the Sparseness factor). The power is
// under 2 (a weight inverse to the noise's variance): at heavy noise σ̂ reads high where the
// shape has detail at the estimate's scale (a gear's teeth, a porous block), and a weight
// falling as fast as 1/σ̂² rounds that detail further; falling slower keeps more of it, at
// the cost of a little roughness on smooth shapes.
constexpr double kNoiseKnee = 0.0035, kMinScreening = 0.5, kMaxScreening = 8.0, kNoisePower = 1.75;
// The knee is never below this share of the finest grid step (which follows the points'
// spacing). Noise well under a step is finer than the grid resolves, and the gradient term
// already averages it over a step; on a sparse cloud (a few thousand points, a step of 2–5 %
// of the diagonal) σ̂ of 0.5–1 % is such noise, and a weaker pull there only rounds the
// corners and thin parts the few samples carry. On dense clouds this share of a step is
// under kNoiseKnee and changes nothing; a larger share also strengthened the pull on smooth
// shapes of 20k points at 1 % noise, whose surface then followed the noise more.
constexpr double kKneeSteps = 0.4;
// Where the nearby normals agree this well (the length of their weighted mean), V is their
// unit mean direction: a mean shortened by curvature would flatten f across curved parts.
// Below it (two sheets, a thin part's two sides) V keeps its shortened length.
constexpr double kAgreeing = 0.3;
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
// The local zero level (follow_local_level): cells of this many grid steps, each with at
// least kLevelCellSamples samples; a cell's correction is the samples' median value less
// kLevelMedianErrors standard errors of that median (1.2533 σ̂ / √n for n normal draws), so
// that the noise alone seldom moves f, and at most kLevelMaxSteps grid steps. Larger cells
// or a smaller margin follow the noise on smooth parts; smaller cells or a larger margin
// leave the rounded features as they were.
constexpr double kLevelCellSteps = 4.0, kLevelMedianErrors = 1.25, kLevelMaxSteps = 1.0;
constexpr size_t kLevelCellSamples = 12;
constexpr double kMedianError = 1.2533;
// The thin parts' bias (thin_part_bias): f is probed kThinProbe σ inward from each node; a
// part whose f rises by less than kThinRiseFull of that depth (per |∇f|) is thin and takes
// the correction in full, one rising by more than kThinRiseNone none, linearly between. On
// a tube of radius r the rise is r/σ − 1 once the probe passes the axis: full below 1.3 σ,
// none above 1.6 σ. The correction is kThinBiasShare of σ²/2 Δf (the smoothness term has
// already rounded the part in part), at most kThinBiasMax σ.
constexpr double kThinProbe = 2.0, kThinRiseFull = 0.3, kThinRiseNone = 0.6;
constexpr double kThinBiasShare = 0.5, kThinBiasMax = 0.25;
// Memory model, for GMPU_PARAM_MAX_MEMORY: per node of a touched block, the splat's sums
// (weight, distance, the normals' weight, sum and offset) and its index; per unknown, the field,
// its six neighbours, its row's start and the solver's vectors; per point, its 8 trilinear weights and nodes,
// its entries in the blocks' and the rows' lists (about 8 blocks, 8 corners) and its value
// in the products, its cell and value for the local zero level; per unknown again, the thin
// parts' correction.
constexpr double kBytesPerSlotNode = 76, kBytesPerUnknown = 208, kBytesPerPoint = 192;

// f (the solution `x`) at sample i: its cube's corners blended trilinearly.
double sample_value(const std::vector<int32_t> &sample_node, const std::vector<double> &sample_weight, size_t i,
                    const Eigen::VectorXd &x) {
    double at = 0.0;
    for (size_t k = 0; k < 8; ++k) at += sample_weight[8 * i + k] * x[sample_node[8 * i + k]];
    return at;
}

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

template <class Visit>
void SmoothField::for_each_node(Workers &workers, Progress &progress, const Visit &visit) const {
    parallel_for(0, size_t(nodes_[2]), workers, progress, [&](size_t plane) {
        const int64_t z = int64_t(plane);
        for (int64_t y = 0; y < nodes_[1]; ++y)
            for (int64_t x = 0; x < nodes_[0]; ++x) {
                const int32_t u = node(x, y, z);
                if (u >= 0) visit(x, y, z, u);
            }
    }, 1);
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
    auto radius = [&](size_t i) { return splat_radius(measures, i, min_trust); };
    auto node_box = [&](size_t i, int64_t lo[3], int64_t hi[3]) { box_of(points.point(i), radius(i), lo, hi); };

    // Splat: per node the weighted sums of the normals, of the offsets to the points and of
    // the point-to-plane distances.
    constexpr size_t BBB = size_t(B) * B * B;
    const size_t slot_nodes = size_t(slots) * BBB;
    std::vector<double> wsum(slot_nodes, 0.0), distance(slot_nodes, 0.0), normal_wsum(slot_nodes, 0.0);
    std::vector<Eigen::Vector3d> normal(slot_nodes, Eigen::Vector3d::Zero()), offset(slot_nodes, Eigen::Vector3d::Zero());
    auto slot_of = [&](int64_t x, int64_t y, int64_t z) {
        return size_t(block_slot_[size_t(x / B + blocks_[0] * (y / B + blocks_[1] * (z / B)))]) * BBB +
               size_t(x % B + B * (y % B + B * (z % B)));
    };
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
    // V's reach from a point (capped by the point's own radius in the splat).
    const double normal_reach = (kNormalReachSteps + std::sqrt(3.0)) * h_;
    const double sigma = noise * points.world_diagonal() * points.normalisation().scale;
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
                        const size_t s = slot * BBB + size_t(x - base[0] + B * (y - base[1] + B * (z - base[2])));
                        wsum[s] += w;
                        double wn = weight(d2, normal_r2);
                        if (across_stretch > 0.0) {
                            const double across = (q - p).dot(nrm);
                            wn = kAcrossIsotropic * wn +
                                 (1.0 - kAcrossIsotropic) * weight(d2 + across_stretch * across * across, normal_r2);
                        }
                        normal_wsum[s] += wn;
                        normal[s] += wn * nrm;
                        offset[s] += wn * (p - q);
                        distance[s] += w * (p - q).dot(nrm);  // inside (behind the normal): positive
                    }
                }
            }
        }
    }, 1);
    progress.throw_if_cancelled();
    node_index_.assign(slot_nodes, -1);
    int32_t unknowns = 0;
    for (size_t s = 0; s < slot_nodes; ++s)
        if (wsum[s] > 0.0 || whole_box) node_index_[s] = unknowns++;

    // Normal equations of the energy: every grid edge inside the band asks f to rise along it
    // by h times V's component (V = −average outward normal, f grows inward), every sample
    // asks its trilinear value to be 0. The edges make a sparse matrix; the samples' part
    // α Sᵀ D S is applied in factored form (8 weights per sample), far fewer products than
    // its 27-neighbour stencil assembled.
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns), start(unknowns);
    std::vector<Eigen::Vector3d> field(static_cast<size_t>(unknowns));
    Progress planes_progress = progress.slice(0.2, 0.2);  // the loops over planes only check for a cancel
    for_each_node(workers, planes_progress, [&](int64_t x, int64_t y, int64_t z, int32_t u) {
        const size_t s = slot_of(x, y, z);
        // The start: the coarser level's field where it has one, else the smoothed
        // point-to-plane distance.
        double c;
        const Eigen::Vector3d q = origin_ + h_ * Eigen::Vector3d(double(x), double(y), double(z));
        start[u] = coarse && coarse->value(q, c, nullptr) ? c : wsum[s] > 0.0 ? distance[s] / wsum[s] : 0.0;
        // The average normal, shortened where neighbours disagree (between two sheets,
        // across a thin part): there f need not rise at all.
        field[size_t(u)] =
            normal_wsum[s] > 0.0 ? Eigen::Vector3d(-normal[s] / normal_wsum[s]) : Eigen::Vector3d::Zero();
        const double length = field[size_t(u)].norm();
        if (length > kAgreeing) field[size_t(u)] /= length;
        if (normal_wsum[s] > 0.0)
            field[size_t(u)] *= overhang_fade(offset[s] / normal_wsum[s], normal[s] / normal_wsum[s], normal_reach);
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
                    if (wsum[slot_of(x, y, z)] > 0.0) {
                        reached[size_t(node(x, y, z))] = 1;
                        queue.push_back(x + nodes_[0] * (y + nodes_[1] * z));
                    }
        for (size_t head = 0; head < queue.size(); ++head) {
            const int64_t at = queue[head], x = at % nodes_[0], y = at / nodes_[0] % nodes_[1], z = at / nodes_[0] / nodes_[1];
            const double v = start[node(x, y, z)];
            for (int d = 0; d < 3; ++d)
                for (int dir = -1; dir <= 1; dir += 2) {
                    const int64_t bx = x + (d == 0) * dir, by = y + (d == 1) * dir, bz = z + (d == 2) * dir;
                    const int32_t b = node(bx, by, bz);
                    if (b < 0 || reached[size_t(b)]) continue;
                    reached[size_t(b)] = 1;
                    start[b] = v;
                    queue.push_back(bx + nodes_[0] * (by + nodes_[1] * bz));
                }
        }
    }
    std::vector<double>().swap(wsum);
    std::vector<double>().swap(distance);
    std::vector<double>().swap(normal_wsum);
    std::vector<Eigen::Vector3d>().swap(normal);
    const double edge_weight = h_;  // Σ over edges of h·(Δf − h·V)² approximates ∫|∇f − V|²
    Eigen::VectorXd edge_diagonal = Eigen::VectorXd::Zero(unknowns);
    // The edges' part of the matrix: every edge weighs the same, so it is the unknowns'
    // neighbours (−x, +x, −y, +y, −z, +z; −1 where the band ends) and that weight.
    std::vector<int32_t> neighbours(6 * size_t(unknowns), -1);
    // Each unknown sums its own six edges (in a fixed order: −z, −y, −x, +x, +y, +z), so the
    // planes run in parallel.
    for_each_node(workers, planes_progress, [&](int64_t x, int64_t y, int64_t z, int32_t a) {
        for (int side = 0; side < 6; ++side) {
            const int d = side < 3 ? 2 - side : side - 3, dir = side < 3 ? -1 : 1;
            const int32_t b = node(x + (d == 0) * dir, y + (d == 1) * dir, z + (d == 2) * dir);
            if (b < 0) continue;
            // f should rise by `rise` from the lower node of the edge to the upper one.
            const double rise = h_ * 0.5 * (field[size_t(a)][d] + field[size_t(b)][d]);
            edge_diagonal[a] += edge_weight;
            neighbours[6 * size_t(a) + 2 * size_t(d) + (dir > 0)] = b;
            rhs[a] += dir > 0 ? -edge_weight * rise : edge_weight * rise;
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
                    edge_diagonal[a] += edge_weight;
                    rhs[a] += edge_weight * (fb - rise);
                }
        });
    progress.throw_if_cancelled();
    std::vector<Eigen::Vector3d>().swap(field);

    const double box_diagonal = points.world_diagonal() * points.normalisation().scale;  // normalised
    const double knee_noise = std::max(kNoiseKnee, kKneeSteps * fine_step_ / box_diagonal);
    const double knee = noise > 0.0 ? knee_noise / noise : INFINITY;
    const double pull = kMaxScreening * sparseness_.factor;
    const double alpha = std::clamp(pull * std::pow(knee, kNoisePower), kMinScreening, pull) / h_;
    Eigen::VectorXd diagonal = edge_diagonal;  // of the whole matrix: the preconditioner
    // Every sample weighs the same (the mean area): a point's area comes from its
    // neighbours' distances, and with noise the points pushed outward of a convex part are
    // farther apart than those pushed inward, so area weights would pull the surface out.
    double mean_area = 0.0;
    for (size_t i = 0; i < n; ++i) mean_area += double(measures.area[i]) / double(n);
    std::vector<int32_t> sample_node(8 * n, -1);
    std::vector<double> sample_weight(8 * n, 0.0), sample_scale(n, 0.0);
    Progress corners_progress = progress.slice(0.3, 0.4);
    block_for(n, workers, corners_progress, [&](size_t lo, size_t hi) {
        for (size_t i = lo; i < hi; ++i) {
            const Corners corner = corners((points.point(i) - origin_) / h_);
            std::copy(corner.node, corner.node + 8, sample_node.begin() + long(8 * i));
            std::copy(corner.weight, corner.weight + 8, sample_weight.begin() + long(8 * i));
            // Always complete (the band covers a cell diagonal around every point); a sample
            // that were not would simply not pull.
            sample_scale[i] = corner.complete ? alpha * mean_area : 0.0;
        }
    });
    // The diagonal sums in the samples' order, whatever the thread count.
    for (size_t i = 0; i < n; ++i) {
        if (sample_scale[i] == 0.0) continue;
        for (int k = 0; k < 8; ++k)
            diagonal[sample_node[8 * i + size_t(k)]] +=
                sample_scale[i] * sample_weight[8 * i + size_t(k)] * sample_weight[8 * i + size_t(k)];
    }
    // The samples' part read per unknown: the (sample, corner) pairs that land on it, in
    // sample order, so that each unknown's row sums alone (in parallel, in a fixed order).
    std::vector<uint32_t> row_start(size_t(unknowns) + 1, 0), row_pairs;
    for (size_t i = 0; i < n; ++i) {
        if (i % 4096 == 0) progress.poll(0.4);
        if (sample_scale[i] != 0.0)
            for (int k = 0; k < 8; ++k) ++row_start[size_t(sample_node[8 * i + size_t(k)]) + 1];
    }
    for (size_t u = 0; u < size_t(unknowns); ++u) row_start[u + 1] += row_start[u];
    row_pairs.resize(row_start.back());
    {
        std::vector<uint32_t> fill(row_start.begin(), row_start.end() - 1);
        for (size_t i = 0; i < n; ++i) {
            if (i % 4096 == 0) progress.poll(0.4);
            if (sample_scale[i] != 0.0)
                for (int k = 0; k < 8; ++k) row_pairs[fill[size_t(sample_node[8 * i + size_t(k)])]++] = uint32_t(8 * i + size_t(k));
        }
    }
    Progress quiet = progress.slice(0.45, 0.45);  // the loops below only check for a cancel
    std::vector<double> at_sample(n, 0.0);
    auto apply = [&](const Eigen::VectorXd &v, Eigen::VectorXd &out) {
        block_for(n, workers, quiet, [&](size_t lo, size_t hi) {
            for (size_t i = lo; i < hi; ++i) {
                if (sample_scale[i] == 0.0) continue;
                const int32_t *idx = &sample_node[8 * i];
                const double *w = &sample_weight[8 * i];
                double at = 0.0;
                for (int k = 0; k < 8; ++k) at += w[k] * v[idx[k]];
                at_sample[i] = at * sample_scale[i];
            }
        });
        block_for(size_t(unknowns), workers, quiet, [&](size_t lo, size_t hi) {
            for (size_t u = lo; u < hi; ++u) {
                double around = 0.0;
                for (int j = 0; j < 6; ++j) {
                    const int32_t b = neighbours[6 * u + size_t(j)];
                    if (b >= 0) around += v[b];
                }
                double sum = edge_diagonal[Eigen::Index(u)] * v[Eigen::Index(u)] - edge_weight * around;
                for (uint32_t e = row_start[u]; e < row_start[u + 1]; ++e)
                    sum += at_sample[row_pairs[e] / 8] * sample_weight[row_pairs[e]];
                out[Eigen::Index(u)] = sum;
            }
        });
    };
    progress.poll(0.45);

    // Jacobi-preconditioned conjugate gradients, polling between iterations.
    const Eigen::VectorXd inverse_diagonal = diagonal.cwiseInverse();
    Eigen::VectorXd x = start, r(unknowns), Ap(unknowns), z(unknowns), p(unknowns);
    const size_t rows = size_t(unknowns);
    apply(x, Ap);
    std::array<double, 2> rz_rr = block_sums<2>(rows, workers, quiet, [&](size_t lo, size_t hi) {
        std::array<double, 2> sum{};
        for (Eigen::Index u = Eigen::Index(lo); u < Eigen::Index(hi); ++u) {
            r[u] = rhs[u] - Ap[u];
            p[u] = z[u] = inverse_diagonal[u] * r[u];
            sum[0] += r[u] * z[u], sum[1] += r[u] * r[u];
        }
        return sum;
    });
    const double target = kTolerance * kTolerance *
                          std::max(block_sums<1>(rows, workers, quiet, [&](size_t lo, size_t hi) {
                                       return std::array<double, 1>{rhs.segment(Eigen::Index(lo), Eigen::Index(hi - lo)).squaredNorm()};
                                   })[0],
                                   1e-300);
    for (int it = 0; it < iterations && rz_rr[1] > target; ++it) {
        progress.poll(0.45 + 0.55 * double(it) / iterations);
        apply(p, Ap);
        const double pAp = block_sums<1>(rows, workers, quiet, [&](size_t lo, size_t hi) {
            return std::array<double, 1>{p.segment(Eigen::Index(lo), Eigen::Index(hi - lo)).dot(Ap.segment(Eigen::Index(lo), Eigen::Index(hi - lo)))};
        })[0];
        const double step = rz_rr[0] / pAp;
        const std::array<double, 2> next = block_sums<2>(rows, workers, quiet, [&](size_t lo, size_t hi) {
            std::array<double, 2> sum{};
            for (Eigen::Index u = Eigen::Index(lo); u < Eigen::Index(hi); ++u) {
                x[u] += step * p[u];
                r[u] -= step * Ap[u];
                z[u] = inverse_diagonal[u] * r[u];
                sum[0] += r[u] * z[u], sum[1] += r[u] * r[u];
            }
            return sum;
        });
        const double beta = next[0] / rz_rr[0];
        block_for(rows, workers, quiet, [&](size_t lo, size_t hi) {
            for (Eigen::Index u = Eigen::Index(lo); u < Eigen::Index(hi); ++u) p[u] = z[u] + beta * p[u];
        });
        rz_rr = next;
    }
    Eigen::VectorXd thin_bias;
    if (!whole_box && thin_ == ThinPartBias::correct && sigma > 0.0)
        thin_bias = thin_part_bias(x, sigma, workers, progress);
    // The zero set through the samples (ZeroLevel): with weak screening the normals'
    // integral alone fixes f up to an offset, which would shrink or swell the whole surface.
    std::vector<double> at_samples;
    at_samples.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        if (sample_scale[i] != 0.0) at_samples.push_back(sample_value(sample_node, sample_weight, i, x));
    }
    const double shift = sample_level(at_samples, level_);
    x.array() -= shift;
    if (!whole_box && local_ == LocalLevel::follow)
        follow_local_level(points, sample_node, sample_weight, sample_scale, sigma, x, workers, progress);
    if (thin_bias.size() == x.size()) x += thin_bias;
    values_.assign(x.data(), x.data() + unknowns);
    progress.report(1.0);
    return shift;
}

void SmoothField::follow_local_level(const PointSet &points, const std::vector<int32_t> &sample_node,
                                     const std::vector<double> &sample_weight, const std::vector<double> &sample_scale,
                                     double sigma, Eigen::VectorXd &x, Workers &workers, Progress &progress) {
    const double cell = kLevelCellSteps * h_;
    int64_t cells[3];
    for (int d = 0; d < 3; ++d) cells[d] = int64_t(std::ceil(double(nodes_[d]) * h_ / cell)) + 1;
    auto cell_of = [&](const Eigen::Vector3d &q) {
        const Eigen::Vector3d t = (q - origin_) / cell;
        const int64_t c[3] = {std::clamp(int64_t(std::floor(t[0])), int64_t(0), cells[0] - 1),
                              std::clamp(int64_t(std::floor(t[1])), int64_t(0), cells[1] - 1),
                              std::clamp(int64_t(std::floor(t[2])), int64_t(0), cells[2] - 1)};
        return size_t(c[0] + cells[0] * (c[1] + cells[1] * c[2]));
    };
    // The samples' values by cell (a counting sort: cells hold their samples contiguously).
    const size_t n = points.size(), cell_count = size_t(cells[0] * cells[1] * cells[2]);
    std::vector<uint32_t> start(cell_count + 1, 0);
    std::vector<uint32_t> cell_of_sample(n, UINT32_MAX);
    for (size_t i = 0; i < n; ++i) {
        if (sample_scale[i] == 0.0) continue;
        cell_of_sample[i] = uint32_t(cell_of(points.point(i)));
        ++start[cell_of_sample[i] + 1];
    }
    for (size_t c = 0; c < cell_count; ++c) start[c + 1] += start[c];
    std::vector<double> values(start[cell_count]);
    std::vector<uint32_t> filled(start.begin(), start.end() - 1);
    for (size_t i = 0; i < n; ++i) {
        if (cell_of_sample[i] != UINT32_MAX)
            values[filled[cell_of_sample[i]]++] = sample_value(sample_node, sample_weight, i, x);
    }
    progress.throw_if_cancelled();
    std::vector<float> correction(cell_count, 0.0f);
    for (size_t c = 0; c < cell_count; ++c) {
        const size_t count = start[c + 1] - start[c];
        if (count < kLevelCellSamples) continue;
        const auto first = values.begin() + long(start[c]), middle = first + long(count / 2);
        std::nth_element(first, middle, first + long(count));
        const double margin = kLevelMedianErrors * kMedianError * sigma / std::sqrt(double(count));
        const double beyond = std::max(0.0, std::abs(*middle) - margin);
        correction[c] = float(std::copysign(std::min(beyond, kLevelMaxSteps * h_), *middle));
    }
    // Each node takes the trilinear blend of the corrections at the cells' centres.
    Progress planes_progress = progress.slice(1.0, 1.0);
    for_each_node(workers, planes_progress, [&](int64_t xi, int64_t y, int64_t z, int32_t u) {
        const Eigen::Vector3d t = h_ / cell * Eigen::Vector3d(double(xi), double(y), double(z)) -
                                  Eigen::Vector3d::Constant(0.5);
        int64_t c[3];
        double w[3];
        for (int d = 0; d < 3; ++d) {
            c[d] = int64_t(std::floor(t[d]));
            w[d] = t[d] - double(c[d]);
        }
        double g = 0.0;
        for (int k = 0; k < 8; ++k) {
            const int64_t at[3] = {c[0] + (k & 1), c[1] + (k >> 1 & 1), c[2] + (k >> 2 & 1)};
            if (at[0] < 0 || at[1] < 0 || at[2] < 0 || at[0] >= cells[0] || at[1] >= cells[1] ||
                at[2] >= cells[2])
                continue;
            const double weight = (k & 1 ? w[0] : 1 - w[0]) * (k >> 1 & 1 ? w[1] : 1 - w[1]) *
                                  (k >> 2 & 1 ? w[2] : 1 - w[2]);
            g += weight * double(correction[size_t(at[0] + cells[0] * (at[1] + cells[1] * at[2]))]);
        }
        x[u] -= g;
    });
    progress.throw_if_cancelled();
}

Eigen::VectorXd SmoothField::thin_part_bias(const Eigen::VectorXd &x, double sigma, Workers &workers,
                                            Progress &progress) const {
    // x trilinear at grid coordinates t; false where a corner is off the band.
    auto at = [&](const Eigen::Vector3d &t, double &f) {
        const Corners corner = corners(t);
        if (!corner.complete) return false;
        f = 0.0;
        for (int k = 0; k < 8; ++k) f += corner.weight[k] * x[corner.node[k]];
        return true;
    };
    Eigen::VectorXd bias = Eigen::VectorXd::Zero(x.size());
    Progress planes_progress = progress.slice(1.0, 1.0);
    for_each_node(workers, planes_progress, [&](int64_t xi, int64_t y, int64_t z, int32_t u) {
        double laplacian = -6.0 * x[u];
        Eigen::Vector3d gradient;
        for (int d = 0; d < 3; ++d) {
            const int64_t e[3] = {d == 0, d == 1, d == 2};
            const int32_t lo = node(xi - e[0], y - e[1], z - e[2]), hi = node(xi + e[0], y + e[1], z + e[2]);
            if (lo < 0 || hi < 0) return;
            laplacian += x[lo] + x[hi];
            gradient[d] = (x[hi] - x[lo]) / (2 * h_);
        }
        laplacian /= h_ * h_;
        const double slope = gradient.norm();
        if (!(slope > 0.0)) return;
        // f is positive inside: inward is up its gradient.
        const double depth = kThinProbe * sigma;
        double probed;
        if (!at(Eigen::Vector3d(double(xi), double(y), double(z)) + depth / h_ * gradient / slope, probed)) return;
        const double rise = (probed - x[u]) / (depth * slope);
        const double thin = std::clamp((kThinRiseNone - rise) / (kThinRiseNone - kThinRiseFull), 0.0, 1.0);
        const double limit = kThinBiasMax * sigma * slope;
        bias[u] = thin * std::clamp(kThinBiasShare * 0.5 * sigma * sigma * laplacian, -limit, limit);
    });
    progress.throw_if_cancelled();
    return bias;
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
