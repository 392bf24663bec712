#include "implicit/surface_field.hpp"

#include <cmath>


namespace gmpu {

namespace {
constexpr size_t kSideVotes = 8;
// The winding number overrules the side test when it is within this of 0 or 1. Telling
// 0 from 1 needs less accuracy than the far regions' sign (block_grid.cpp): cells count as
// one dipole from 1.2 radii on instead of 2: the check then costs the 1M-point polygonize
// 0.15–0.25 s instead of 0.45 s, and no mesh we measured changed by more than noise.
constexpr double kDecisiveWinding = 0.25;
constexpr double kWindingFarRatio = 1.2;
constexpr double kFarAway = 1e6;  // normalised units: the data spans 1
}  // namespace

bool SurfaceField::trusted(const Eigen::Vector3d &x) const {
    thread_local std::vector<uint32_t> idx;
    idx.clear();
    // A little wider than needed: the kd-tree compares float distances.
    points_.within(x, widest_trust() * (1.0 + 1e-5) + 1e-7, idx);
    for (uint32_t i : idx)
        if ((x - points_.point(i)).norm() <= trust_radius(i)) return true;
    return false;
}

double SurfaceField::far_value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
    // Very far away (where the kd-tree's float distances would overflow), the data is a
    // point at the origin of the normalised frame: outside, at distance |x|.
    if (x.norm() > kFarAway) {
        if (gradient) *gradient = -x.normalized();
        return -x.norm();
    }
    // The sign: the winding number of all the oriented points where it is clearly 0 or 1;
    // else Hoppe's side test, voted over the k nearest points (weighted by closeness) so
    // that one poorly estimated normal (at the tip of a thin part, say) cannot flip a
    // region. The side test alone only sees the nearest points: far beyond a concave part
    // (above a back between two humps, say) their normals can all face away from x.
    double sign = 0.0;
    if (!winding_.empty()) {
        const double w = winding_.winding(x, kWindingFarRatio);
        if (w > 1.0 - kDecisiveWinding) sign = 1.0;
        else if (w < kDecisiveWinding) sign = -1.0;
    }
    thread_local std::vector<uint32_t> idx;
    thread_local std::vector<float> d2;
    points_.nearest(x, sign != 0.0 ? 1 : kSideVotes, idx, d2, reach_);
    if (idx.empty()) {
        if (gradient) gradient->setZero();
        return -reach_;  // beyond the reach of every point: outside
    }
    if (sign == 0.0) {
        double vote = 0.0;
        for (size_t k = 0; k < idx.size(); ++k) {
            const uint32_t i = idx[k];
            Eigen::Vector3d n(measures_.normals[3 * i], measures_.normals[3 * i + 1], measures_.normals[3 * i + 2]);
            double side = (x - points_.point(i)).dot(n);
            vote += (side < 0.0 ? 1.0 : -1.0) / (std::sqrt(double(d2[k])) + 1e-12);
        }
        sign = vote > 0.0 ? 1.0 : -1.0;  // behind the outward normals: inside
    }
    const double distance = std::sqrt(double(d2[0]));
    if (gradient) {
        Eigen::Vector3d away = x - points_.point(idx[0]);
        // f = sign · distance grows away from the point inside and falls outside.
        *gradient = distance > 0.0 ? Eigen::Vector3d(sign * away / distance) : Eigen::Vector3d::Zero();
    }
    return sign * distance;
}

double SurfaceField::value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
    return trusted(x) ? mpu_.value(x, gradient) : far_value(x, gradient);
}

double SurfaceField::value_among(const std::vector<uint32_t> &leaves, const Eigen::Vector3d &x,
                                 Eigen::Vector3d *gradient) const {
    return trusted(x) ? mpu_.value_among(leaves, x, gradient) : far_value(x, gradient);
}

}  // namespace gmpu
