#include "fit/cell_fit.hpp"

#include <algorithm>

#include "fit/piecewise_fit.hpp"
#include "fit/two_sheet_fit.hpp"

namespace gmpu {

namespace {
// Large supports (coarse cells) are fitted on an even subsample: the fit of a coarse cell
// only has to be roughly right, and its error is still measured on every point.
constexpr size_t kMaxFitPoints = 2048;
// Sharp features are looked for only in small supports (finest cells): in large ones two
// clusters of normals mostly mean curvature, not an edge.
constexpr size_t kMaxSharpSupport = 64;
// A thin part (a leg, a finger, an ear, a blade) two or three sample spacings across: the
// smallest supports (N_min points) hold both of its sides, and on noise-free data ε is about
// one spacing, so a height field through the middle of the part can pass or stay a leaf
// while it gives both sides one normal. Such supports are far from flat (surface variation
// above kThinPartVariation, where a patch of a smooth surface reads under 0.02); a general
// quadric can close around the part, and is taken when its error is under
// kThinPartImprovement × the height field's. Only where the fit is not noise-limited and its
// error is at least kThinPartError × ε; elsewhere the paper's choice stands.
constexpr double kThinPartVariation = 0.05;
constexpr double kThinPartImprovement = 0.25;
constexpr double kThinPartError = 0.25;
// Around a thin part, the quadric's gradients on the support point both ways across it;
// at a crease or a corner (a far-from-flat support of one side) nearly all point one way,
// and a general quadric there only adds zero sets. This share of the support must have
// its gradient on the other side of the support's tangent plane from the rest.
constexpr double kThinPartOpposed = 0.2;
// Thin parts a few spacings across are decided in small supports; a large one that misses
// ε is split anyway, and refitting it would only cost time.
constexpr size_t kThinPartMaxSupport = 128;

// Share of the points whose gradient of `q` points against the majority's, along `normal`.
double opposed_share(const Quadric &q, const PointList &points, const Eigen::Vector3d &normal) {
    size_t up = 0;
    for (const auto &p : points) up += q.gradient(p).dot(normal) > 0.0;
    return double(std::min(up, points.size() - up)) / double(std::max<size_t>(1, points.size()));
}

const PointList &fit_sample(const PointList &support, PointList &buffer) {
    if (support.size() <= kMaxFitPoints) return support;
    buffer.clear();
    double step = double(support.size()) / double(kMaxFitPoints);
    for (size_t k = 0; k < kMaxFitPoints; ++k) buffer.push_back(support[size_t(double(k) * step)]);
    return buffer;
}
}  // namespace

CellFit fit_cell(const PointList &support, double radius, double epsilon, double requested, const Params &params,
                 CloseSheets close_sheets) {
    thread_local PointList sample_buffer;
    const PointList &sample = fit_sample(support, sample_buffer);
    static const std::vector<PiecewiseShape> no_pieces;

    CellFit fit;
    Pca pca = compute_pca(sample);
    fit.variation = pca.variation;
    if (pca.variation > kVariationThreshold) {
        fit.shape.model = Model::quadric;
        fit.shape.q = fit_general_quadric(sample, radius);
    } else {
        fit.shape.model = Model::bivariate;
        fit.shape.q = fit_bivariate(sample, pca, radius);
    }
    fit.error = taubin_error(fit.shape, no_pieces, support);

    if (fit.error > std::min(epsilon, requested)) {
        CellFit two;
        two.variation = fit.variation;
        const SheetSplit split = fit_two_sheets(support, fit.shape, fit.error, radius, close_sheets, epsilon, two);
        if (two.shape.model == Model::two_sheets) {
            two.sheets_end = split.ends && epsilon <= requested;
            return two;
        }
        fit.unresolved_sheets = split.found;
    }
    if (epsilon <= requested && support.size() <= kThinPartMaxSupport && fit.shape.model == Model::bivariate &&
        pca.variation > kThinPartVariation && fit.error > kThinPartError * epsilon) {
        LocalShape general;
        general.model = Model::quadric;
        general.q = fit_general_quadric(sample, radius);
        const double e = taubin_error(general, no_pieces, support);
        if (e < kThinPartImprovement * fit.error &&
            opposed_share(general.q, sample, pca.axes.col(0)) >= kThinPartOpposed) {
            fit.shape = general;
            // A cell that missed ε still splits as before, so the octree and the grid the
            // polygonizer sizes from its leaves do not coarsen (a part two spacings across
            // needs the fine grid); where it cannot split, the leaf keeps the quadric.
            if (fit.error <= epsilon) fit.error = e;
        }
    }

    if (fit.error > epsilon && params.sharp_features && support.size() <= kMaxSharpSupport) {
        CellFit sharp;
        if (fit_piecewise(support, radius, epsilon, sharp) && sharp.error < fit.error) {
            sharp.variation = fit.variation;
            return sharp;
        }
    }
    return fit;
}

}  // namespace gmpu
