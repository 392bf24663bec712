#include "implicit/on_sheet_normal.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {

// A leaf passes by p when p is within this many sample spacings of its zero set, or within
// this many of its fit errors (noise widens the band the samples lie in). A wall thinner
// than that is not told apart; the blend decides there as before.
constexpr double kSpacings = 1.0;
constexpr double kErrors = 3.0;

// Sample spacing in a leaf's support: its ball meets the surface in about a disk.
double support_spacing(const Cell &c) {
    return std::sqrt(M_PI * c.radius * c.radius / double(std::max<uint32_t>(1, c.support_count)));
}

}  // namespace

bool on_sheet_gradient(const MpuFunction &mpu, const std::vector<uint32_t> &near, const Eigen::Vector3d &p,
                       Eigen::Vector3d &gradient) {
    const Octree &tree = mpu.tree();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), g;
    double weight = 0.0;
    for (uint32_t i : near) {
        const Cell &c = tree.cells[i];
        const double r2 = c.radius * c.radius;
        const double d2 = (p - c.centre).squaredNorm();
        if (d2 >= r2) continue;
        const double f = mpu.cell_value(i, p, &g);
        const double gn = g.norm();
        if (!(gn > 1e-12) || !std::isfinite(f)) continue;
        const double tolerance = std::max(kSpacings * support_spacing(c), kErrors * double(c.error));
        const double s = 1.0 - d2 / r2;
        const double off_sheet = std::abs(f) / gn / tolerance;  // distance to the leaf's sheet, in tolerances
        if (off_sheet >= 1.0) continue;
        // A smooth fall-off with the distance from the centre (like the blend's) and with the
        // distance from the leaf's sheet.
        const double w = c.blend_factor * s * s * (1.0 - off_sheet * off_sheet);
        sum += w * g / gn;
        weight += w;
    }
    if (!(weight > 0.0) || !(sum.norm() > 1e-12)) return false;
    gradient = sum;
    return true;
}

}  // namespace gmpu
