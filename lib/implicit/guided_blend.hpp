// The MPU blend guided by the smooth field (GMPU_PARAM_SURFACE = 3, and the automatic choice
// on small noise-free clouds).
//
// On a few thousand points the blend's local fits have few points each: past the end of a
// thin part (a horn, a finger, a tail) a leaf's quadric goes on where its points stop, and
// a bridge or a small handle can join two parts that nearly touch. The smooth field, one
// least-squares problem over the whole cloud, ends thin parts where their points end and
// makes no such bridges, but it rounds what the blend resolves: sharp edges, walls thinner
// than its grid. Both are about signed distances near the surface, so each keeps what it
// does best when the blend is held to the smooth field: where the two agree to within a
// limit (a fraction of the sample spacing) the value is the blend's; where the blend departs
// farther, it is pulled back to that limit:
//     f = b − shrink(b − s, limit),   shrink(d, t) = sign(d) · max(|d| − t, 0).
// f is continuous, and its zero set is the blend's wherever the blend stays within the
// limit of the smooth surface. Away from the data the far field signs f as for the blend
// (surface_field.hpp): the smooth field's outer part is only there to bound its band.
//
// Where two sheets of a thin wall lie closer than the smooth field's grid can keep apart,
// their opposite normals cancel in the field it integrates: there it is flat, neither inside
// nor outside, while the blend keeps both sheets. A limit in f's units would pull the
// blend's inside of the wall to the smooth value and cut holes through it. So the limit can
// be measured in distance instead: divided by |∇s| (a signed distance has |∇s| ≈ 1), no
// less steep than `min_slope`, it widens where the smooth field is flat and lets the wall
// stand. On a sparse cloud without thin walls the field is flatter than that near every
// sparsely sampled tip, where its guide is wanted, so there the limit stays fixed.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace gmpu {

// How far the blend may depart from the smooth field: `limit` (normalised units; infinite:
// not guided), widened by 1/|∇s| where the smooth field's slope is under 1, down to
// `min_slope` (1: never widened).
struct Guide {
    double limit = INFINITY;
    double min_slope = 1.0;

    bool active() const { return std::isfinite(limit); }
    bool widens() const { return min_slope < 1.0; }
    double limit_at(const Eigen::Vector3d &smooth_gradient) const {
        return limit / std::clamp(smooth_gradient.norm(), min_slope, 1.0);
    }
};

// f from the blend's value b and the smooth field's s; with gradients (both given or both
// null), ∇f: the blend's where it is kept, the smooth field's where it is held.
inline double guided_value(double b, double s, double limit, const Eigen::Vector3d *blend_gradient,
                           const Eigen::Vector3d *smooth_gradient, Eigen::Vector3d *gradient) {
    const double departure = b - s;
    if (std::fabs(departure) <= limit) {
        if (gradient) *gradient = *blend_gradient;
        return b;
    }
    if (gradient) *gradient = *smooth_gradient;
    return s + std::copysign(limit, departure);
}

}  // namespace gmpu
