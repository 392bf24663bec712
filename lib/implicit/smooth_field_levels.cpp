// SmoothField's levels (smooth_field.hpp): the local zero level and the thin parts' bias,
// applied to a solved f.
#include "implicit/smooth_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <vector>

namespace gmpu {

namespace {
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
}  // namespace

void SmoothField::follow_local_level(const PointSet &points, const SampleRows &samples, double sigma,
                                     Eigen::VectorXd &x, Workers &workers, Progress &progress) {
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
        if (samples.scale[i] == 0.0) continue;
        cell_of_sample[i] = uint32_t(cell_of(points.point(i)));
        ++start[cell_of_sample[i] + 1];
    }
    for (size_t c = 0; c < cell_count; ++c) start[c + 1] += start[c];
    std::vector<double> values(start[cell_count]);
    std::vector<uint32_t> filled(start.begin(), start.end() - 1);
    for (size_t i = 0; i < n; ++i) {
        if (cell_of_sample[i] != UINT32_MAX)
            values[filled[cell_of_sample[i]]++] = samples.value(i, x);
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

}  // namespace gmpu
