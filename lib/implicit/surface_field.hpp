// The implicit that gmpu hands out: the MPU blend where it is trustworthy, and a
// sign from the winding number elsewhere.
//
// Local quadrics are only valid near the points they were fitted to; extended into empty
// space they cross zero in spurious sheets (a known MPU pitfall). So a query x is
// "trusted" when it lies within the trust radius of its nearest input point (a few local
// spacings, never less than two polygonizer cubes); there f is the MPU blend. Farther out
// f = ±d(x), the distance to the nearest point, signed by which side of the nearby points'
// oriented normals x lies on (Hoppe's test, voted over the 8 nearest points; reliable once
// x is a few spacings away): continuous
// enough at the border (the blend is about a signed distance too) and never zero, so no
// surface can appear away from the data.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"

namespace gmpu {

// Per-point quantities computed at orient time.
struct PointMeasures {
    std::vector<float> normals;       // unit outward, 3 per point
    std::vector<float> area;          // surface area each point stands for
    std::vector<float> trust_radius;  // normalised units
};

class SurfaceField {
public:
    SurfaceField(const MpuFunction &mpu, const PointSet &points, const PointMeasures &measures)
        : mpu_(mpu), points_(points), measures_(measures) {}

    // f and optionally ∇f at x (normalised frame). `min_trust` widens every trust radius
    // to at least that (the polygonizer passes two cube sizes).
    double value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient, double min_trust = 0.0) const;

    // Distance to the nearest point and whether x is trusted; `nearest` receives its index.
    bool trusted(const Eigen::Vector3d &x, double min_trust, double &distance, uint32_t &nearest) const;

    // The far-field value at an untrusted x: ±distance, signed by the nearest normals.
    double far_value(const Eigen::Vector3d &x, double distance, uint32_t nearest, Eigen::Vector3d *gradient) const;

    const MpuFunction &mpu() const { return mpu_; }

private:
    const MpuFunction &mpu_;
    const PointSet &points_;
    const PointMeasures &measures_;
};

// Normals are given; area and trust radius come from the k nearest neighbours.
void measure_points(const PointSet &points, unsigned threads, class Progress &progress, PointMeasures &out);

}  // namespace gmpu
