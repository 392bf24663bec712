#include "geometry/open_sky.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {
// Rays in a cone of this half-angle's cosine about the direction asked.
constexpr double kConeCosine = 0.5;
}  // namespace

OpenSky::OpenSky(const PointSet &points, double block) {
    // Directions spread evenly over the sphere (a Fibonacci lattice): the same for every point.
    for (int i = 0; i < kDirections; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / kDirections, r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double a = M_PI * (1.0 + std::sqrt(5.0)) * (i + 0.5);
        directions_.emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
    if (points.empty() || !(block > 0.0)) return;
    const Eigen::Vector3d lo = points.box_min() - Eigen::Vector3d::Constant(2.0 * block);
    const Eigen::Vector3d extent = points.box_max() - points.box_min() + Eigen::Vector3d::Constant(4.0 * block);
    cell_ = std::max(0.5 * block, extent.maxCoeff() / kMaxCells);
    origin_ = lo;
    size_t cells = 1;
    for (int d = 0; d < 3; ++d) cells *= size_t(n_[d] = std::max<int64_t>(1, int64_t(std::ceil(extent[d] / cell_))));
    bits_.assign((cells + 63) / 64, 0);
    // A cell is blocked when its centre lies within `block` of a point.
    const int64_t reach = int64_t(std::ceil(block / cell_));
    for (size_t p = 0; p < points.size(); ++p) {
        const Eigen::Vector3d q = (points.point(p) - origin_) / cell_;
        const int64_t ci = int64_t(q.x()), cj = int64_t(q.y()), ck = int64_t(q.z());
        for (int64_t k = std::max<int64_t>(0, ck - reach); k <= std::min(n_[2] - 1, ck + reach); ++k)
            for (int64_t j = std::max<int64_t>(0, cj - reach); j <= std::min(n_[1] - 1, cj + reach); ++j)
                for (int64_t i = std::max<int64_t>(0, ci - reach); i <= std::min(n_[0] - 1, ci + reach); ++i) {
                    const Eigen::Vector3d centre = Eigen::Vector3d(double(i) + 0.5, double(j) + 0.5, double(k) + 0.5);
                    if ((centre - q).squaredNorm() * cell_ * cell_ > block * block) continue;
                    const size_t c = size_t(i + n_[0] * (j + n_[1] * k));
                    bits_[c >> 6] |= uint64_t(1) << (c & 63);
                }
    }
}

bool OpenSky::escapes(const Eigen::Vector3d &from, const Eigen::Vector3d &d) const {
    // Amanatides–Woo traversal of the grid's cells along the ray.
    const Eigen::Vector3d q = (from - origin_) / cell_;
    int64_t c[3];
    double next[3], delta[3];
    int step[3];
    for (int a = 0; a < 3; ++a) {
        c[a] = int64_t(std::floor(q[a]));
        if (c[a] < 0 || c[a] >= n_[a]) return true;
        step[a] = d[a] > 0 ? 1 : -1;
        delta[a] = d[a] != 0.0 ? std::fabs(1.0 / d[a]) : INFINITY;
        const double edge = d[a] > 0 ? double(c[a] + 1) - q[a] : q[a] - double(c[a]);
        next[a] = d[a] != 0.0 ? edge * delta[a] : INFINITY;
    }
    for (;;) {
        if (blocked(c[0], c[1], c[2])) return false;
        const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= n_[a]) return true;
        next[a] += delta[a];
    }
}

double OpenSky::escaping(const Eigen::Vector3d &from, const Eigen::Vector3d &direction) const {
    if (bits_.empty()) return 1.0;
    size_t rays = 0, escaped = 0;
    for (const Eigen::Vector3d &d : directions_) {
        if (!(d.dot(direction) > kConeCosine)) continue;
        ++rays;
        escaped += escapes(from, d);
    }
    return rays ? double(escaped) / double(rays) : 1.0;
}

}  // namespace gmpu
