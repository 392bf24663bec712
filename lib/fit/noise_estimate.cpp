#include "fit/noise_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fit/fits.hpp"

namespace gmpu {

namespace {
constexpr size_t kSamples = 1024;
constexpr size_t kNeighbours = 24;
// When the noise is this large a share of the neighbourhood's radius, a 24-point quadratic
// absorbs much of it (sphere_scan: 0.63 % measured for about 1 % true); measure again on
// neighbourhoods four times larger, where it cannot.
constexpr double kHeavyNoise = 0.2;
constexpr size_t kWideNeighbours = 96;

double median(std::vector<double> &v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// Median residual of local quadratic fits over k-neighbourhoods, and their median radius.
void measure(const PointSet &points, size_t k, Progress &progress, double &noise, double &radius) {
    const size_t n = points.size();
    const size_t step = std::max<size_t>(1, n / kSamples);
    std::vector<double> rms, radii;
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    PointList local;
    for (size_t i = 0; i < n; i += step) {
        progress.tick();
        const Eigen::Vector3d centre = points.point(i);
        points.nearest(centre, k, idx, d2);
        if (idx.size() < 10) continue;
        local.clear();
        for (uint32_t j : idx) local.push_back(points.point(j) - centre);
        const double r = std::sqrt(double(d2.back()));
        if (!(r > 0.0)) continue;
        Pca pca = compute_pca(local);
        Quadric q = fit_bivariate(local, pca, r);
        double sum = 0.0;
        for (const auto &p : local) sum += q.value(p) * q.value(p) / std::max(1e-24, q.gradient(p).squaredNorm());
        // Unbiased for the 6 fitted coefficients.
        rms.push_back(std::sqrt(sum / double(local.size() - 6)));
        radii.push_back(r);
    }
    noise = median(rms);
    radius = median(radii);
}
}  // namespace

double estimate_noise(const PointSet &points, Progress &progress) {
    double noise, radius;
    measure(points, kNeighbours, progress, noise, radius);
    if (radius > 0.0 && noise > kHeavyNoise * radius && points.size() > 4 * kWideNeighbours) {
        double wide, wide_radius;
        measure(points, kWideNeighbours, progress, wide, wide_radius);
        noise = std::max(noise, wide);
    }
    return noise;
}

}  // namespace gmpu
