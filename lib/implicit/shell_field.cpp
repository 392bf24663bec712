#include "implicit/shell_field.hpp"

#include <algorithm>
#include <cmath>
#include <queue>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "core/median.hpp"
#include "core/two_groups.hpp"

namespace gmpu {

namespace {

// A neighbourhood this large holds both sheets of a wall under two spacings thick, and enough
// points for a quadratic and the offset (7 unknowns) to leave residuals worth reading.
constexpr size_t kNeighbours = 24;
constexpr size_t kMinNeighbours = 12;
// The gap must be this many residual deviations: on a solid's neighbourhood the split only
// cuts the shape's own misfit, a few deviations apart, where a noise-free wall's two sheets
// leave residuals far below their gap.
constexpr double kSeparation = 6.0;
// Nor a gap under this share of the spacing: the residuals of an exactly flat or curved
// sheet are rounding, and rounding to float can split into two tidy groups.
constexpr double kMinGapSpacings = 0.01;
// The whole cloud is a shell when this share of its neighbourhoods read two sheets: a solid
// with thin parts (blades, fins, teeth) reads two sheets only on those, a shell nearly
// everywhere but at its corners and rims.
constexpr double kShellShare = 0.4;
// Only walls thinner than this many sample spacings: the octree's two-sheet fits resolve
// wider ones, and its blend follows them more closely than these patches.
constexpr double kUnresolvedGap = 1.0;
// Walls far thinner than that, under kThinWallGap spacings, need only kThinWallShare: a
// box-like shell at 1,000 points reads two sheets on its faces' middles alone (every other
// neighbourhood crosses a fold), and a part that is mostly blades that thin (a rotor at
// 1,000 points) is better drawn as walls than by the blend, which merges them.
constexpr double kThinWallGap = 0.6;
constexpr double kThinWallShare = 0.2;
// The first look: this many points, evenly strided, and the share among them that lets the
// whole cloud be read (a few of the sample's standard errors under kThinWallShare).
constexpr size_t kFirstLookPoints = 256;
constexpr double kFirstLookShare = 0.12;
// Split, refit, split again: the middle surface settles in a few rounds.
constexpr int kRounds = 3;
constexpr size_t kMinSide = 3;
// A patch weighs in this far, in its neighbourhood's radii: past the trust radius (1.5
// eighth-neighbour distances, about 0.9 of the 24th's), so trusted queries always find one.
constexpr double kReachScale = 1.25;
// The wall is polygonized this many grid cubes thick, on a grid of at most kMaxGrid cubes
// along the box's side; no thinner than kMinCubesAcrossWall cubes of that grid.
constexpr double kCubesAcrossWall = 2.0;
constexpr int kMaxGrid = 256;
constexpr double kMinCubesAcrossWall = 1.5;
// The rim test's weight radius, in spacings, and where it puts the rim: a uniform sample
// of a half plane has its centroid (weights (1 − r²/R²)²) 96 / (105 π) R = 0.291 R inside
// the edge. Inside the sheet the centroid of a random sample strays by about 0.22 spacings
// per axis, so at 5 spacings the rim's 1.46 spacings are 6.7 of those deviations: no hole.
constexpr double kRimReach = 5.0;
constexpr double kRimOffset = 96.0 / (105.0 * M_PI);
// The rim lattice's step, in the cloud's median spacings.
constexpr double kRimLatticeStep = 0.5;
// No patch reaches farther than this many median reaches: an isolated point's wide
// neighbourhood would widen every query's search.
constexpr double kMaxReachRatio = 2.0;
// Queries farther than this many half gaps from the nearest point's middle surface are
// outside the wall whatever the other patches say (they differ by a fraction of the gap):
// they take that patch's value and skip the blend, most of the trusted space around a wall.
constexpr double kBlendWithinHalfGaps = 3.0;
// A patch that did not read two sheets weighs this much in the blend beside those that did:
// enough to close a fold or a corner where no patch fits both faces, little enough that its
// loose middle surface does not round them off further.
constexpr double kMisfitWeight = 0.1;
// Neighbours each patch's orientation is passed to.
constexpr size_t kOrientNeighbours = 8;
// A two-sheet patch that puts a point within this many half gaps of its middle surface does
// not say which sheet the point is on.
constexpr double kSideVoteHalfGaps = 0.3;
// The side vote overrides −∇f only where the two are further apart than 120° (cosine below
// minus this).
constexpr double kSideVoteAgreement = 0.5;
// Central differences for the gradient, in normalised units (the box spans 1).
constexpr double kGradientStep = 1e-5;

using Row = Eigen::Matrix<double, 1, 6>;

Row height_terms(double x, double y) {
    Row r;
    r << x * x, x * y, y * y, x, y, 1.0;
    return r;
}

// `nearest`, if given, receives the kOrientNeighbours points nearest point i (UINT32_MAX
// where there are fewer).
ShellPatch fit_patch(const PointSet &points, size_t i, uint32_t *nearest = nullptr) {
    ShellPatch patch;
    patch.origin = points.point(i);
    thread_local std::vector<uint32_t> near;
    thread_local std::vector<float> d2;
    points.nearest(patch.origin, kNeighbours, near, d2);
    if (nearest) {
        size_t m = 0;
        for (uint32_t j : near)
            if (j != i && m < kOrientNeighbours) nearest[m++] = j;
    }
    const size_t k = near.size();
    const double radius = std::sqrt(double(d2.empty() ? 0.0f : d2.back()));
    patch.reach = kReachScale * radius;
    patch.spacing = radius * std::sqrt(M_PI / double(std::max<size_t>(1, k)));
    patch.side_normal = Eigen::Vector3d::UnitZ();
    if (k < kMinNeighbours || !(patch.reach > 0.0)) return patch;

    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (uint32_t j : near) mean += points.point(j);
    mean /= double(k);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (uint32_t j : near) {
        const Eigen::Vector3d d = points.point(j) - mean;
        cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    patch.n = eig.eigenvectors().col(0);
    patch.v = eig.eigenvectors().col(1);
    patch.u = eig.eigenvectors().col(2);

    // Heights over the plane, in the point's own frame (the point at the origin).
    Eigen::MatrixXd a(k, 7);
    Eigen::VectorXd z(k);
    for (size_t m = 0; m < k; ++m) {
        const Eigen::Vector3d d = points.point(near[m]) - patch.origin;
        a.block<1, 6>(Eigen::Index(m), 0) = height_terms(d.dot(patch.u), d.dot(patch.v));
        a(Eigen::Index(m), 6) = 0.0;
        z[Eigen::Index(m)] = d.dot(patch.n);
    }
    Eigen::VectorXd middle = a.leftCols(6).colPivHouseholderQr().solve(z);
    Eigen::VectorXd residual = z - a.leftCols(6) * middle, left = residual;
    double offset = 0.0;
    std::vector<double> sorted(k);
    for (int round = 0; round < kRounds; ++round) {
        for (size_t m = 0; m < k; ++m) sorted[m] = residual[Eigen::Index(m)];
        std::sort(sorted.begin(), sorted.end());
        const TwoGroups groups = split_two_groups(sorted, kMinSide);
        if (groups.low == 0) break;
        for (size_t m = 0; m < k; ++m) a(Eigen::Index(m), 6) = residual[Eigen::Index(m)] > groups.threshold ? 1.0 : -1.0;
        const Eigen::VectorXd c = a.colPivHouseholderQr().solve(z);
        middle = c.head(6);
        offset = c[6];
        residual = z - a.leftCols(6) * middle;
        left = z - a * c;
    }
    const double deviation = std::sqrt(left.squaredNorm() / double(k - 7));
    patch.half_gap = std::fabs(offset);
    patch.separation = 2.0 * patch.half_gap / std::max(deviation, 1e-12 * patch.reach);
    patch.two_sheets = patch.separation >= kSeparation && 2.0 * patch.half_gap >= kMinGapSpacings * patch.spacing;
    for (int m = 0; m < 6; ++m) patch.q[m] = middle[m];
    // The middle surface's normal at the point, turned to the point's side of it.
    Eigen::Vector3d g = patch.n - patch.q[3] * patch.u - patch.q[4] * patch.v;
    g.normalize();
    patch.side_normal = patch.q[5] > 0.0 ? Eigen::Vector3d(-g) : g;
    return patch;
}

// Turns the patches' middle normals to agree along the wall, as Hoppe et al. orient tangent
// planes: over a spanning tree of the neighbour graph (`neighbours`: kOrientNeighbours per
// patch, from fit_patch) that keeps the most parallel pairs, so the turn is passed around a
// fold (a box's edge) through the patches tilted between its faces, never across it where
// the two faces' normals are perpendicular and either turn fits.
// A wall's middle surface has a side even where the wall has no inside (a plate): the side
// is only for blending heights, and any consistent choice serves.
void orient_middles(const std::vector<uint32_t> &neighbours, std::vector<ShellPatch> &patches) {
    const size_t count = patches.size();
    // Each neighbour pair is an edge both ways, so the tree can enter a patch from either end.
    std::vector<std::vector<uint32_t>> edges(count);
    for (size_t i = 0; i < count; ++i)
        for (size_t m = 0; m < kOrientNeighbours; ++m) {
            const uint32_t j = neighbours[i * kOrientNeighbours + m];
            if (j == UINT32_MAX) continue;
            edges[i].push_back(j);
            edges[j].push_back(uint32_t(i));
        }
    std::vector<bool> done(count, false);
    using Entry = std::pair<double, std::pair<uint32_t, uint32_t>>;  // |n·n'|, (from, to)
    std::priority_queue<Entry> front;
    for (size_t seed = 0; seed < count; ++seed) {
        if (done[seed]) continue;
        front.push({2.0, {uint32_t(seed), uint32_t(seed)}});
        while (!front.empty()) {
            const auto [from, to] = front.top().second;
            front.pop();
            if (done[to]) continue;
            done[to] = true;
            if (from != to && patches[from].orientation * patches[from].n.dot(patches[to].n) < 0.0)
                patches[to].orientation = -1.0;
            for (uint32_t next : edges[to])
                if (!done[next]) front.push({std::fabs(patches[to].n.dot(patches[next].n)), {to, next}});
        }
    }
}

double median(std::vector<double> v) { return v.empty() ? 0.0 : median_in_place(v); }

}  // namespace

double ShellPatch::height(const Eigen::Vector3d &x) const {
    const Eigen::Vector3d d = x - origin;
    const double s = d.dot(u), t = d.dot(v);
    const double h = q[0] * s * s + q[1] * s * t + q[2] * t * t + q[3] * s + q[4] * t + q[5];
    const double gs = 2.0 * q[0] * s + q[1] * t + q[3], gt = q[1] * s + 2.0 * q[2] * t + q[4];
    return (d.dot(n) - h) / std::sqrt(1.0 + gs * gs + gt * gt);
}

ShellField::ShellField(const PointSet &points, Workers &workers, Progress &progress) {
    const size_t count = points.size();
    patches_.resize(count);
    std::vector<uint32_t> neighbours(count * kOrientNeighbours, UINT32_MAX);
    parallel_for(0, count, workers, progress,
                 [&](size_t i) { patches_[i] = fit_patch(points, i, &neighbours[i * kOrientNeighbours]); });
    orient_middles(neighbours, patches_);
    std::vector<double> gaps, spacings, reaches;
    for (const ShellPatch &p : patches_) reaches.push_back(p.reach);
    const double reach_cap = kMaxReachRatio * median(reaches);
    balls_.reserve(count);
    for (ShellPatch &p : patches_) {
        p.reach = std::min(p.reach, reach_cap);
        balls_.emplace_back(p.origin[0], p.origin[1], p.origin[2], p.reach * p.reach);
        widest_reach_ = std::max(widest_reach_, p.reach);
        spacings.push_back(p.spacing);
        if (p.two_sheets) gaps.push_back(2.0 * p.half_gap);
    }
    two_sheet_share_ = count > 0 ? double(gaps.size()) / double(count) : 0.0;
    median_gap_ = median(gaps);
    median_spacing_ = median(spacings);
    rim_step_ = kRimLatticeStep * median_spacing_;
    // Where a neighbourhood did not read two sheets (a corner, a rim), its offset is its
    // shape's misfit: it takes the wall's typical half gap.
    const double thinnest_half_gap = 0.5 * kMinCubesAcrossWall / kMaxGrid;
    for (ShellPatch &p : patches_) {
        if (!p.two_sheets) p.half_gap = 0.5 * median_gap_;
        p.half_gap = std::max(p.half_gap, thinnest_half_gap);
    }
}

bool ShellField::may_be_shell(const PointSet &points) {
    const size_t n = points.size(), step = std::max<size_t>(1, n / kFirstLookPoints);
    size_t looked = 0, two = 0;
    for (size_t i = 0; i < n; i += step, ++looked) two += fit_patch(points, i).two_sheets;
    return looked > 0 && double(two) >= kFirstLookShare * double(looked);
}

Eigen::Vector3d ShellField::outward_normal(const PointSet &points, size_t i) const {
    const Eigen::Vector3d x = points.point(i);
    // One gather serves f, its gradient and the side vote.
    thread_local std::vector<uint32_t> near;
    gather(points, x, kGradientStep, near);
    double f = 0.0;
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    if (!(value_among(points, near, x, f, &g) && g.norm() > 0.0)) return patches_[i].side_normal;
    g = -g.normalized();
    // Near a fold the blended middle surface is bent, and a point can fall on the wrong side
    // of it; where the side vote points nearly opposite −∇f, the vote wins. On a rim face −∇f
    // points past the rim, across the vote, and is kept.
    const Eigen::Vector3d vote = side_vote(near, x);
    return vote.dot(g) < -kSideVoteAgreement * vote.norm() ? Eigen::Vector3d(-g) : g;
}

Eigen::Vector3d ShellField::side_vote(const std::vector<uint32_t> &patches, const Eigen::Vector3d &x) const {
    Eigen::Vector3d vote = Eigen::Vector3d::Zero();
    for (uint32_t j : patches) {
        const ShellPatch &p = patches_[j];
        const double r2 = (x - p.origin).squaredNorm(), reach2 = balls_[j][3];
        if (!p.two_sheets || r2 >= reach2) continue;
        const double h = p.height(x);
        if (std::fabs(h) < kSideVoteHalfGaps * p.half_gap) continue;
        const double t = 1.0 - r2 / reach2;
        vote += t * t * t * (h > 0.0 ? p.n : Eigen::Vector3d(-p.n));
    }
    return vote;
}

int ShellField::grid() const {
    return median_gap_ > 0.0 ? int(std::min<double>(kMaxGrid, std::ceil(kCubesAcrossWall / median_gap_))) : 8;
}

bool ShellField::whole_shell() const {
    if (!(median_gap_ < kUnresolvedGap * median_spacing_)) return false;
    return two_sheet_share_ >= kShellShare ||
           (two_sheet_share_ >= kThinWallShare && median_gap_ < kThinWallGap * median_spacing_);
}

void ShellField::gather(const PointSet &points, const Eigen::Vector3d &centre, double radius,
                        std::vector<uint32_t> &patches) const {
    patches.clear();
    points.within(centre, radius + widest_reach_ * (1.0 + 1e-5), patches);
    std::sort(patches.begin(), patches.end());
}

bool ShellField::value_among(const PointSet &points, const std::vector<uint32_t> &patches, const Eigen::Vector3d &x,
                             double &f) const {
    // One pass over the candidates: the nearest, and those whose reach holds x.
    thread_local std::vector<std::pair<uint32_t, double>> reaching;
    reaching.clear();
    uint32_t closest = 0;
    double closest_d2 = INFINITY;
    for (uint32_t j : patches) {
        const Eigen::Vector4d &ball = balls_[j];
        const double dx = ball[0] - x[0], dy = ball[1] - x[1], dz = ball[2] - x[2];
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < closest_d2) closest = j, closest_d2 = d2;
        if (d2 < ball[3]) reaching.emplace_back(j, d2);
    }
    if (reaching.empty()) return false;
    // Far off a wall's middle, the nearest patch alone says so; a patch that did not read two
    // sheets (a fold, a corner) fits its neighbourhood too loosely to speak for the others.
    const ShellPatch &nearest = patches_[closest];
    const double nearest_height = std::fabs(nearest.height(x));
    if (nearest.two_sheets && nearest_height > kBlendWithinHalfGaps * nearest.half_gap &&
        closest_d2 < balls_[closest][3]) {
        f = nearest.half_gap - nearest_height;
    } else {
        // Heights are blended signed, each patch's turned to its orientation (which side that
        // is does not matter: f takes |h|): blended unsigned, patches whose middles differ
        // would thin the wall by their disagreement, and pierce it. For the same reason every
        // patch within reach takes part, the misfits at a fold or corner too (at
        // kMisfitWeight): left out, the faces' patches alone meet at the fold, each bent past
        // it, and leave a gap.
        double gap = 0.0, height = 0.0, weight = 0.0;
        for (const auto &[j, d2] : reaching) {
            const ShellPatch &p = patches_[j];
            const double t = 1.0 - d2 / balls_[j][3];
            const double w = t * t * t * (p.two_sheets ? 1.0 : kMisfitWeight);
            gap += w * p.half_gap;
            height += w * p.orientation * p.height(x);
            weight += w;
        }
        f = (gap - std::fabs(height)) / weight;
    }
    // Outside the slab f is negative already; the rims only cut it.
    if (f > 0.0) f = std::min(f, within_rims(points, x));
    return true;
}

double ShellField::within_rims(const PointSet &points, const Eigen::Vector3d &x) const {
    if (!(rim_step_ > 0.0)) return rim_at_node(points, x);
    const Eigen::Vector3d at = x / rim_step_;
    const Eigen::Vector3d base = at.array().floor();
    const Eigen::Vector3d t = at - base;
    double e = 0.0;
    for (int c = 0; c < 8; ++c) {
        const int64_t node[3] = {int64_t(base[0]) + (c & 1), int64_t(base[1]) + (c >> 1 & 1),
                                 int64_t(base[2]) + (c >> 2 & 1)};
        const double w = (c & 1 ? t[0] : 1 - t[0]) * (c >> 1 & 1 ? t[1] : 1 - t[1]) * (c >> 2 & 1 ? t[2] : 1 - t[2]);
        if (w == 0.0) continue;
        // 2^20 nodes a side: far more than the unit box holds at any step a cloud can have.
        const int64_t key = (node[0] & 0xfffff) | (node[1] & 0xfffff) << 20 | (node[2] & 0xfffff) << 40;
        RimShard &shard = (*rim_nodes_)[size_t(key) % rim_nodes_->size()];
        {
            std::lock_guard<std::mutex> guard(shard.lock);
            const auto found = shard.values.find(key);
            if (found != shard.values.end()) {
                e += w * double(found->second);
                continue;
            }
        }
        const float value =
            float(rim_at_node(points, rim_step_ * Eigen::Vector3d(double(node[0]), double(node[1]), double(node[2]))));
        {
            std::lock_guard<std::mutex> guard(shard.lock);
            shard.values.emplace(key, value);
        }
        e += w * double(value);
    }
    return e;
}

double ShellField::rim_at_node(const PointSet &points, const Eigen::Vector3d &x) const {
    thread_local std::vector<uint32_t> near;
    thread_local std::vector<float> d2;
    points.nearest(x, 1, near, d2);
    if (near.empty()) return 0.0;
    const ShellPatch &closest = patches_[near[0]];
    const double reach = kRimReach * closest.spacing;
    near.clear();
    points.within(x, reach, near);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double weight = 0.0;
    for (uint32_t j : near) {
        const Eigen::Vector3d p = points.point(j);
        const double t2 = (p - x).squaredNorm() / (reach * reach);
        if (t2 >= 1.0) continue;
        const double w = (1.0 - t2) * (1.0 - t2);
        sum += w * p, weight += w;
    }
    if (!(weight > 0.0)) return -reach;
    Eigen::Vector3d behind = sum / weight - x;
    behind -= closest.n * closest.n.dot(behind);
    return kRimOffset * reach - behind.norm();
}

bool ShellField::value(const PointSet &points, const Eigen::Vector3d &x, double &f, Eigen::Vector3d *gradient) const {
    // One gather serves x and the six samples of its gradient.
    thread_local std::vector<uint32_t> near;
    gather(points, x, gradient ? kGradientStep : 0.0, near);
    return value_among(points, near, x, f, gradient);
}

bool ShellField::value_among(const PointSet &points, const std::vector<uint32_t> &patches, const Eigen::Vector3d &x,
                             double &f, Eigen::Vector3d *gradient) const {
    if (!value_among(points, patches, x, f)) return false;
    if (gradient) {
        for (int d = 0; d < 3; ++d) {
            Eigen::Vector3d step = Eigen::Vector3d::Zero();
            step[d] = kGradientStep;
            double hi = 0.0, lo = 0.0;
            const bool has_hi = value_among(points, patches, x + step, hi),
                       has_lo = value_among(points, patches, x - step, lo);
            if (!has_hi) hi = f;
            if (!has_lo) lo = f;
            (*gradient)[d] = (hi - lo) / ((has_hi ? kGradientStep : 0.0) + (has_lo ? kGradientStep : 0.0) + 1e-300);
        }
    }
    return true;
}

}  // namespace gmpu
