#include "fit/two_sheet_fit.hpp"

#include <algorithm>
#include <cmath>

#include "core/median.hpp"
#include "core/two_groups.hpp"

namespace gmpu {

namespace {

// The groups' means must be this many pooled standard deviations apart. A smooth surface
// that one model fits badly (a wave across the support) spreads its distances evenly, with
// its two halves about 4 deviations apart; Gaussian noise split at its mean, about 2.7.
constexpr double kSeparation = 6.0;
// Residuals are looked at on an even subsample of the support (the split needs no more).
constexpr size_t kMaxSamples = 512;
// A group this small gets no quadratic of its own: its sheet is the other one, offset.
constexpr size_t kOwnFitPoints = 12;
// The two-sheet model must beat the single fit by this factor to replace it.
constexpr double kImprovement = 0.5;
// Sheets only a few σ of noise apart do not split into well-separated groups, but the
// single fit's distances are then a two-peaked mixture, flatter than the Gaussian noise of
// one sheet (kurtosis about 2.3 for sheets 2.4 σ apart, 3 for one noisy sheet), and the two
// groups lie over one another along the surface. A wave that one model fits badly is flat
// too, but its groups lie side by side. Read on large supports only: the sampling spread of
// the kurtosis is √(24 / n) for Gaussian noise, and a single noisy sheet split in two must
// not read as a wall.
constexpr size_t kFlatMinSamples = 384;
constexpr double kFlatKurtosis = 2.45;
constexpr double kFlatOverlap = 0.6;
// Within a few σ, each sheet's noise keeps the two-sheet error near the single fit's.
constexpr double kFlatImprovement = 0.85;
// Without the noise estimate's cloud-wide evidence (CloseSheets::local), a support must
// show close sheets on its own. ε is then the noise floor, 1.75 σ̂, about the 90 % quantile
// of one noisy sheet's distances (the fit error): a single fit through a wall a few σ thick
// misses it, and the two sheets' error (distances to the nearer sheet, so under about half
// the gap) stays well inside it, under kLocalTwoError × ε. A coarse cell's shape misfit that
// reads flat either passes ε already or splits into groups farther apart than that. Such
// walls show in supports of kLocalMinSamples points or more, flatter than the cloud-wide
// bar (kLocalKurtosis; the kurtosis of one noisy sheet spreads by √(24 / n), 0.31 at 256
// points, and smaller supports on a tube's curved, noisy side read flat by chance), and at
// least kLocalRadius × ε wide: in a support only a couple of noise floors across, detail of
// the noise's scale (gear teeth at 1 % noise) reads as two sheets too.
// Only flat supports (a height field fitted them): around a thin tube the single fit is a
// general quadric closed around it, which two sheets in one frame would only worsen.
constexpr double kLocalTwoError = 0.7;
constexpr size_t kLocalMinSamples = 256;
constexpr double kLocalKurtosis = 2.35;
constexpr double kLocalRadius = 3.0;
// Points of one sheet must lie this share of the gap inside the other sheet's positive side,
// or the sheets cross within the support.
constexpr double kClearance = 0.25;

struct Groups {
    double threshold = 0.0, gap = 0.0, spread = 0.0;
    size_t smaller = 0;
};

// The best two-group split of the values (sorted here), each group holding at least
// `min_group` of them.
Groups otsu(std::vector<double> &r, size_t min_group) {
    std::sort(r.begin(), r.end());
    const TwoGroups t = split_two_groups(r, min_group);
    Groups g;
    if (t.low == 0) return g;
    g.threshold = t.threshold;
    g.gap = t.high_mean - t.low_mean;
    g.spread = std::sqrt(t.squared_deviations / double(r.size()));
    g.smaller = std::min(t.low, r.size() - t.low);
    return g;
}

double kurtosis(const std::vector<double> &r) {
    double mean = 0.0;
    for (double x : r) mean += x;
    mean /= double(r.size());
    double m2 = 0.0, m4 = 0.0;
    for (double x : r) {
        const double d2 = (x - mean) * (x - mean);
        m2 += d2, m4 += d2 * d2;
    }
    return m2 > 0.0 ? double(r.size()) * m4 / (m2 * m2) : 0.0;
}

// How much the two groups lie over one another along the surface: the points are binned on
// a 4 × 4 grid of the support's tangent plane, and the share of the smaller group that
// finds as many points of the other group in its bins (1: fully interleaved, 0: apart).
double overlap(const PointList &pts, const std::vector<int> &label) {
    const Pca frame = compute_pca(pts);
    const Eigen::Vector3d t1 = frame.axes.col(2), t2 = frame.axes.col(1);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (const auto &p : pts) {
        const double c[2] = {p.dot(t1), p.dot(t2)};
        for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], c[d]), hi[d] = std::max(hi[d], c[d]);
    }
    constexpr int kBins = 4;
    size_t count[kBins * kBins][2] = {};
    size_t total[2] = {0, 0};
    for (size_t i = 0; i < pts.size(); ++i) {
        const double c[2] = {pts[i].dot(t1), pts[i].dot(t2)};
        int b[2];
        for (int d = 0; d < 2; ++d)
            b[d] = std::min(kBins - 1, int(double(kBins) * (c[d] - lo[d]) / std::max(1e-300, hi[d] - lo[d])));
        ++count[b[0] * kBins + b[1]][label[i]];
        ++total[label[i]];
    }
    size_t shared = 0;
    for (auto &c : count) shared += std::min(c[0], c[1]);
    const size_t smaller = std::min(total[0], total[1]);
    return smaller > 0 ? double(shared) / double(smaller) : 0.0;
}

double signed_distance(const Quadric &q, const Eigen::Vector3d &p) {
    const double gn = q.gradient(p).norm();
    return gn > 1e-12 ? q.value(p) / gn : 0.0;
}

// Fits each sheet in the frame of the larger group (offsetting the larger sheet for a group
// too small for its own quadratic), then re-assigns points to the nearer sheet.
bool fit_sheets(const PointList &pts, std::vector<int> &label, double radius, Quadric part[2]) {
    PointList group[2];
    for (int round = 0; round < 3; ++round) {
        group[0].clear(), group[1].clear();
        for (size_t i = 0; i < pts.size(); ++i) group[label[i]].push_back(pts[i]);
        const int big = group[0].size() >= group[1].size() ? 0 : 1, small = 1 - big;
        if (group[small].empty()) return false;
        const Pca frame = compute_pca(group[big]);
        part[big] = fit_bivariate(group[big], frame, radius);
        if (group[small].size() >= kOwnFitPoints) {
            part[small] = fit_bivariate(group[small], frame, radius);
        } else {
            std::vector<double> offset;
            for (const auto &p : group[small]) offset.push_back(part[big].value(p));
            part[small] = part[big];
            part[small].c -= median_in_place(offset);
        }
        if (round == 2) break;
        for (size_t i = 0; i < pts.size(); ++i)
            label[i] = std::abs(signed_distance(part[1], pts[i])) < std::abs(signed_distance(part[0], pts[i]));
    }
    // Each part positive towards the other sheet; every point of that sheet well inside.
    double gap = 0.0;
    for (int c = 0; c < 2; ++c) {
        const PointList &other = group[1 - c];
        double sum = 0.0;
        for (const auto &p : other) sum += signed_distance(part[c], p);
        if (sum < 0.0) part[c] *= -1.0;
        gap += std::abs(sum) / double(other.size());
    }
    gap *= 0.5;
    for (int c = 0; c < 2; ++c)
        for (const auto &p : group[1 - c])
            if (signed_distance(part[c], p) < kClearance * gap) return false;
    return true;
}

// The sheets end inside the support when at least kEndPoints, and kEndShare of the sampled
// points, lie deeper than kEndDepth of the gap from both sheets. Only where the sampling
// resolves the gap (kEndResolved sample spacings or more): sheets closer than that are fitted
// through points that straddle them, and those read as a rim face everywhere.
constexpr double kEndDepth = 0.25;
constexpr size_t kEndPoints = 4;
constexpr double kEndShare = 0.01;
constexpr double kEndResolved = 0.5;

// The sample spacing of two sheets that cross a support ball of radius R with n points
// (two discs of area π R² between them).
double two_sheet_spacing(size_t n, double radius) { return radius * std::sqrt(2.0 * M_PI / double(std::max<size_t>(1, n))); }

bool sheets_end(const PointList &pts, const PiecewiseShape &shape, double gap) {
    size_t deep = 0;
    for (const auto &p : pts)
        deep += std::min(signed_distance(shape.part[0], p), signed_distance(shape.part[1], p)) > kEndDepth * gap;
    return deep >= std::max(kEndPoints, size_t(kEndShare * double(pts.size())));
}

}  // namespace

SheetSplit fit_two_sheets(const PointList &support, const LocalShape &single, double single_error, double radius,
                          CloseSheets close, double epsilon, CellFit &out) {
    SheetSplit split;
    static const std::vector<PiecewiseShape> no_pieces;
    PointList pts;
    const double step = std::max(1.0, double(support.size()) / double(kMaxSamples));
    for (double k = 0; size_t(k) < support.size(); k += step) pts.push_back(support[size_t(k)]);
    const size_t min_group = std::max<size_t>(4, pts.size() / 20);
    if (pts.size() < 2 * min_group) return split;

    std::vector<double> r(pts.size());
    Eigen::Vector3d g;
    for (size_t i = 0; i < pts.size(); ++i) {
        const double v = single.value(pts[i], no_pieces, &g), gn = g.norm();
        r[i] = gn > 1e-12 ? v / gn : 0.0;
    }
    std::vector<double> sorted = r;
    const Groups groups = otsu(sorted, min_group);
    if (!(groups.gap > 1e-9 * radius)) return split;
    std::vector<int> label(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) label[i] = r[i] > groups.threshold;
    const bool separated = groups.gap >= kSeparation * groups.spread;
    const bool local_only = close == CloseSheets::local;
    const bool may_be_flat =
        close == CloseSheets::cloud
            ? pts.size() >= kFlatMinSamples
            : local_only && single.model == Model::bivariate && pts.size() >= kLocalMinSamples &&
                  single_error > epsilon && radius >= kLocalRadius * epsilon;
    const bool flat = may_be_flat && !separated && kurtosis(r) < (local_only ? kLocalKurtosis : kFlatKurtosis) &&
                      overlap(pts, label) > kFlatOverlap;
    if (!separated && !flat) return split;
    split.found = separated;
    split.gap = groups.gap;

    PiecewiseShape shape;
    if (!fit_sheets(pts, label, radius, shape.part)) return split;
    shape.count = 2;
    const std::vector<PiecewiseShape> table{shape};
    LocalShape local;
    local.model = Model::two_sheets;
    local.piece = 0;
    local.q = shape.part[0];  // a smooth stand-in, never used while piece ≥ 0
    const double error = taubin_error(local, table, support);
    if (!(error < (separated ? kImprovement : kFlatImprovement) * single_error)) return split;
    if (!separated && local_only && !(error < kLocalTwoError * epsilon)) return split;  // a misfit's groups
    out.shape = local;
    out.piece = shape;
    out.error = error;
    split.ends = groups.gap >= kEndResolved * two_sheet_spacing(support.size(), radius) && sheets_end(pts, shape, groups.gap);
    return split;
}

}  // namespace gmpu
