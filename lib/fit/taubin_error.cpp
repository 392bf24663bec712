#include <cmath>
#include <limits>
#include <algorithm>

#include "fit/fits.hpp"

namespace gmpu {

namespace {
// The paper takes the largest distance. On scans, a few noisy points always exceed any ε
// near the noise level and drive subdivision down to fitting the noise itself (cells of a
// dozen points whose fits flip at random), so we take a high quantile instead — while the
// largest distance may still not exceed kLargestSlack × ε, so a small feature that holds
// few of a cell's points still forces the cell to split.
constexpr double kQuantile = 0.9;
constexpr double kLargestSlack = 3.0;
}  // namespace

double taubin_error(const LocalShape &shape, const std::vector<PiecewiseShape> &pieces,
                    const PointList &points) {
    thread_local std::vector<double> e;
    e.resize(points.size());
    Eigen::Vector3d g;
    for (size_t i = 0; i < points.size(); ++i) {
        double v = std::abs(shape.value(points[i], pieces, &g));
        double gn = g.norm();
        // A vanishing gradient on the data means the fit is not a surface there.
        e[i] = gn > 1e-12 ? v / gn : std::numeric_limits<double>::infinity();
    }
    if (e.empty()) return 0.0;
    const double largest = *std::max_element(e.begin(), e.end());
    const size_t k = std::min(e.size() - 1, size_t(kQuantile * double(e.size())));
    std::nth_element(e.begin(), e.begin() + long(k), e.end());
    return std::max(e[k], largest / kLargestSlack);
}

}  // namespace gmpu
