#include "implicit/surface_field.hpp"

#include <cmath>

#include "core/parallel.hpp"

namespace gmpu {

namespace {
constexpr size_t kNeighbours = 8;
// Trust extends this many k-th-neighbour distances from a point: enough to bridge the
// gaps between samples so the trusted shell around the surface has no holes.
constexpr double kTrustSpacings = 1.5;
constexpr size_t kSideVotes = 8;
}  // namespace

bool SurfaceField::trusted(const Eigen::Vector3d &x, double min_trust, double &distance, uint32_t &nearest) const {
    thread_local std::vector<uint32_t> idx;
    thread_local std::vector<float> d2;
    points_.nearest(x, 1, idx, d2);
    nearest = idx[0];
    distance = std::sqrt(double(d2[0]));
    return distance <= std::max(double(measures_.trust_radius[nearest]), min_trust);
}

double SurfaceField::far_value(const Eigen::Vector3d &x, double distance, uint32_t nearest,
                               Eigen::Vector3d *gradient) const {
    // Hoppe's side test, voted over the k nearest points (weighted by closeness) so that
    // one poorly estimated normal — at the tip of a thin part, say — cannot flip a region.
    thread_local std::vector<uint32_t> idx;
    thread_local std::vector<float> d2;
    points_.nearest(x, kSideVotes, idx, d2);
    double vote = 0.0;
    for (size_t k = 0; k < idx.size(); ++k) {
        const uint32_t i = idx[k];
        Eigen::Vector3d n(measures_.normals[3 * i], measures_.normals[3 * i + 1], measures_.normals[3 * i + 2]);
        double side = (x - points_.point(i)).dot(n);
        vote += (side < 0.0 ? 1.0 : -1.0) / (std::sqrt(double(d2[k])) + 1e-12);
    }
    const double sign = vote > 0.0 ? 1.0 : -1.0;  // behind the outward normals: inside
    if (gradient) {
        Eigen::Vector3d away = x - points_.point(nearest);
        *gradient = distance > 0.0 ? Eigen::Vector3d(-sign * away / distance) : Eigen::Vector3d::Zero();
    }
    return sign * distance;
}

double SurfaceField::value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient, double min_trust) const {
    double distance;
    uint32_t nearest;
    if (trusted(x, min_trust, distance, nearest)) return mpu_.value(x, gradient);
    return far_value(x, distance, nearest, gradient);
}

void measure_points(const PointSet &points, unsigned threads, Progress &progress, PointMeasures &out) {
    const size_t n = points.size();
    out.area.assign(n, 0.0f);
    out.trust_radius.assign(n, 0.0f);
    parallel_for(0, n, threads, progress, [&](size_t i) {
        thread_local std::vector<uint32_t> idx;
        thread_local std::vector<float> d2;
        points.nearest(points.point(i), kNeighbours + 1, idx, d2);  // includes the point itself
        double rk = std::sqrt(double(d2.back()));
        out.area[i] = float(M_PI * rk * rk / double(kNeighbours));
        out.trust_radius[i] = float(kTrustSpacings * rk);
    }, 0.0, 0.0, 512);
    progress.throw_if_cancelled();
}

}  // namespace gmpu
