#include "fit/noise_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fit/fits.hpp"

namespace gmpu {

namespace {
constexpr size_t kSamples = 1024;
constexpr size_t kNeighbours = 24;
}  // namespace

double estimate_noise(const PointSet &points) {
    const size_t n = points.size();
    const size_t step = std::max<size_t>(1, n / kSamples);
    std::vector<double> rms;
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    PointList local;
    for (size_t i = 0; i < n; i += step) {
        const Eigen::Vector3d centre = points.point(i);
        points.nearest(centre, kNeighbours, idx, d2);
        if (idx.size() < 10) continue;
        local.clear();
        for (uint32_t j : idx) local.push_back(points.point(j) - centre);
        const double radius = std::sqrt(double(d2.back()));
        if (!(radius > 0.0)) continue;
        Pca pca = compute_pca(local);
        Quadric q = fit_bivariate(local, pca, radius);
        double sum = 0.0;
        for (const auto &p : local) sum += q.value(p) * q.value(p) / std::max(1e-24, q.gradient(p).squaredNorm());
        // Unbiased for the 6 fitted coefficients.
        rms.push_back(std::sqrt(sum / double(local.size() - 6)));
    }
    if (rms.empty()) return 0.0;
    std::nth_element(rms.begin(), rms.begin() + long(rms.size() / 2), rms.end());
    return rms[rms.size() / 2];
}

}  // namespace gmpu
