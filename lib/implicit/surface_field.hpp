// The implicit that gmpu hands out: the MPU blend where it is trustworthy, and a
// sign from the winding number elsewhere.
//
// Local quadrics are only valid near the points they were fitted to; extended into empty
// space they cross zero in spurious sheets (a known MPU pitfall). So a query x is
// "trusted" when it lies within the trust radius of some input point (a few local
// spacings, never less than two polygonizer cubes); there f is the MPU blend. Farther out
// f = ±d(x), the distance to the nearest point, signed by which side of the nearby points'
// oriented normals x lies on (Hoppe's test, voted over the 8 nearest points), unless the
// winding number is clearly 0 or 1 there (it sees every point, and the
// nearest ones can all face away from x beyond a concave part): continuous
// enough at the border (the blend is about a signed distance too) and never zero, so no
// surface can appear away from the data.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/winding_field.hpp"

namespace gmpu {

class SurfaceField {
public:
    // `min_trust` widens every trust radius to at least that (the polygonizer passes two
    // cube sizes, so every cube the surface crosses has its corners trusted). `reach`
    // bounds the neighbour searches of untrusted queries (infinite for general use; the
    // polygonizer knows every query it makes has a point within its band's reach, and
    // bounded searches are much cheaper far from the data).
    // `winding` (built from the same measures) signs the far field where it is decisive
    // (see far_value); an empty one leaves it to the side test.
    SurfaceField(const MpuFunction &mpu, const PointSet &points, const PointMeasures &measures,
                 const WindingField &winding, double min_trust = 0.0, double reach = INFINITY)
        : mpu_(mpu), points_(points), measures_(measures), winding_(winding), min_trust_(min_trust), reach_(reach) {}

    // f and optionally ∇f at x (normalised frame).
    double value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const;

    // value() for x inside the box `leaves` was gathered for (MpuFunction::gather).
    double value_among(const std::vector<uint32_t> &leaves, const Eigen::Vector3d &x,
                       Eigen::Vector3d *gradient) const;

    // Whether x lies within some point's trust radius (widened to min_trust).
    bool trusted(const Eigen::Vector3d &x) const;
    // The far field: ±(distance to the nearest point), signed by the nearby points' normals.
    double far_value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const;
    // Trust radius of point i, widened to min_trust.
    double trust_radius(uint32_t i) const { return std::max(double(measures_.trust_radius[i]), min_trust_); }
    double widest_trust() const { return std::max(measures_.widest_trust, min_trust_); }

    const MpuFunction &mpu() const { return mpu_; }
    const PointSet &points() const { return points_; }

private:
    const MpuFunction &mpu_;
    const PointSet &points_;
    const PointMeasures &measures_;
    const WindingField &winding_;
    double min_trust_, reach_;
};

}  // namespace gmpu
