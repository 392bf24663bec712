#include "implicit/mpu_function.hpp"

#include <cmath>

namespace gmpu {

namespace {
// Quadratic B-spline b(t) on |t| < 1.5 and its derivative (t ≥ 0).
inline double bspline(double t) { return t <= 0.5 ? 0.75 - t * t : 0.5 * (1.5 - t) * (1.5 - t); }
inline double bspline_derivative(double t) { return t <= 0.5 ? -2.0 * t : -(1.5 - t); }
}  // namespace

struct MpuFunction::Sum {
    double w = 0.0, wq = 0.0;
    Eigen::Vector3d dw = Eigen::Vector3d::Zero();   // Σ ∇w
    Eigen::Vector3d dwq = Eigen::Vector3d::Zero();  // Σ ∇(w q)
    uint32_t fallback = 0;                          // deepest inner cell covering x
    int fallback_depth = 0;
};

void MpuFunction::add(const Cell &c, const Eigen::Vector3d &x, Sum &sum, bool want_gradient) const {
    const Eigen::Vector3d y = x - c.centre;
    const double d = y.norm();
    const double t = 1.5 * d / c.radius;
    const double w = bspline(t);
    Eigen::Vector3d g;
    const double q = c.value(x, tree_.pieces, want_gradient ? &g : nullptr);
    sum.w += w;
    sum.wq += w * q;
    if (want_gradient) {
        Eigen::Vector3d dw = d > 0.0 ? Eigen::Vector3d(bspline_derivative(t) * 1.5 / (c.radius * d) * y)
                                     : Eigen::Vector3d::Zero();
        sum.dw += dw;
        sum.dwq += dw * q + w * g;
    }
}

void MpuFunction::visit(uint32_t index, const Eigen::Vector3d &x, Sum &sum, bool want_gradient) const {
    const Cell &c = tree_.cells[index];
    if ((x - c.centre).squaredNorm() >= c.radius * c.radius) return;
    if (c.is_leaf() || c.depth >= cap_) {
        add(c, x, sum, want_gradient);
        return;
    }
    if (c.depth >= sum.fallback_depth) sum.fallback = index, sum.fallback_depth = c.depth;
    for (int o = 0; o < 8; ++o) {
        int32_t k = tree_.child(c, o);
        if (k >= 0) visit(uint32_t(k), x, sum, want_gradient);
    }
}

double MpuFunction::value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
    Sum sum;
    visit(0, x, sum, gradient != nullptr);
    if (!(sum.w > 0.0)) {
        // No leaf reaches x: the deepest cell that does stands in (beyond the root's ball,
        // the root itself).
        return tree_.cells[sum.fallback].value(x, tree_.pieces, gradient);
    }
    const double f = sum.wq / sum.w;
    if (gradient) *gradient = (sum.dwq - f * sum.dw) / sum.w;
    return f;
}

}  // namespace gmpu
