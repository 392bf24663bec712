// SmoothField's screening term (smooth_field.hpp): how hard each sample pulls the zero set
// through it, and its rows in the matrix.
#include "implicit/smooth_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <vector>

#include "core/block_sums.hpp"
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
}  // namespace

double SmoothField::SampleRows::value(size_t i, const Eigen::VectorXd &x) const {
    double at = 0.0;
    for (size_t k = 0; k < 8; ++k) at += weight[8 * i + k] * x[node[8 * i + k]];
    return at;
}

SmoothField::SampleRows SmoothField::sample_rows(const PointSet &points, const PointMeasures &measures, double noise,
                                                 int32_t unknowns, Eigen::VectorXd &diagonal, Workers &workers,
                                                 Progress &progress) const {
    const size_t n = points.size();
    const double box_diagonal = points.world_diagonal() * points.normalisation().scale;  // normalised
    const double knee_noise = std::max(kNoiseKnee, kKneeSteps * fine_step_ / box_diagonal);
    const double knee = noise > 0.0 ? knee_noise / noise : INFINITY;
    const double pull = kMaxScreening * sparseness_.factor;
    const double alpha = std::clamp(pull * std::pow(knee, kNoisePower), kMinScreening, pull) / h_;
    // Every sample weighs the same (the mean area): a point's area comes from its
    // neighbours' distances, and with noise the points pushed outward of a convex part are
    // farther apart than those pushed inward, so area weights would pull the surface out.
    double mean_area = 0.0;
    for (size_t i = 0; i < n; ++i) mean_area += double(measures.area[i]) / double(n);
    SampleRows rows;
    rows.node.assign(8 * n, -1);
    rows.weight.assign(8 * n, 0.0);
    rows.scale.assign(n, 0.0);
    Progress corners_progress = progress.slice(0.3, 0.4);
    block_for(n, workers, corners_progress, [&](size_t lo, size_t hi) {
        for (size_t i = lo; i < hi; ++i) {
            const Corners corner = corners((points.point(i) - origin_) / h_);
            std::copy(corner.node, corner.node + 8, rows.node.begin() + long(8 * i));
            std::copy(corner.weight, corner.weight + 8, rows.weight.begin() + long(8 * i));
            // Always complete (the band covers a cell diagonal around every point); a sample
            // that were not would simply not pull.
            rows.scale[i] = corner.complete ? alpha * mean_area : 0.0;
        }
    });
    // The diagonal sums in the samples' order, whatever the thread count.
    for (size_t i = 0; i < n; ++i) {
        if (rows.scale[i] == 0.0) continue;
        for (int k = 0; k < 8; ++k)
            diagonal[rows.node[8 * i + size_t(k)]] +=
                rows.scale[i] * rows.weight[8 * i + size_t(k)] * rows.weight[8 * i + size_t(k)];
    }
    // The samples' part read per unknown: the (sample, corner) pairs that land on it, in
    // sample order, so that each unknown's row sums alone (in parallel, in a fixed order).
    rows.row_start.assign(size_t(unknowns) + 1, 0);
    for (size_t i = 0; i < n; ++i) {
        if (i % 4096 == 0) progress.poll(0.4);
        if (rows.scale[i] != 0.0)
            for (int k = 0; k < 8; ++k) ++rows.row_start[size_t(rows.node[8 * i + size_t(k)]) + 1];
    }
    for (size_t u = 0; u < size_t(unknowns); ++u) rows.row_start[u + 1] += rows.row_start[u];
    rows.row_pairs.resize(rows.row_start.back());
    {
        std::vector<uint32_t> fill(rows.row_start.begin(), rows.row_start.end() - 1);
        for (size_t i = 0; i < n; ++i) {
            if (i % 4096 == 0) progress.poll(0.4);
            if (rows.scale[i] != 0.0)
                for (int k = 0; k < 8; ++k)
                    rows.row_pairs[fill[size_t(rows.node[8 * i + size_t(k)])]++] = uint32_t(8 * i + size_t(k));
        }
    }
    return rows;
}

}  // namespace gmpu
