#include "implicit/mpu_function.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {
// Quadratic B-spline b(t) on |t| < 1.5 and its derivative (t ≥ 0).
inline double bspline(double t) { return t <= 0.5 ? 0.75 - t * t : 0.5 * (1.5 - t) * (1.5 - t); }
inline double bspline_derivative(double t) { return t <= 0.5 ? -2.0 * t : -(1.5 - t); }
}  // namespace

uint32_t MpuFunction::collect(const Eigen::Vector3d &x, std::vector<uint32_t> &out) const {
    uint32_t deepest = 0;
    uint32_t stack[8 * (kMaxDepth + 2)];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const uint32_t i = stack[--top];
        const Cell &c = tree_.cells[i];
        // A subtree may hold covering leaves even where its root's own ball does not reach
        // (grown supports), so the walk prunes on the subtree's radius.
        if ((x - c.centre).squaredNorm() >= c.subtree_radius * c.subtree_radius) continue;
        const bool own = covers(c, x);
        if (own && c.depth >= tree_.cells[deepest].depth) deepest = i;
        if (is_leaf(c)) {
            if (own) out.push_back(i);
            continue;
        }
        for (int o = 0; o < 8; ++o) {
            int32_t k = tree_.child(c, o);
            if (k >= 0) stack[top++] = uint32_t(k);
        }
    }
    return deepest;
}

double MpuFunction::blend(const std::vector<uint32_t> &leaves, const Eigen::Vector3d &x,
                          Eigen::Vector3d *gradient, uint32_t fallback) const {
    double sw = 0.0, swq = 0.0;
    Eigen::Vector3d dw_sum = Eigen::Vector3d::Zero(), dwq_sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d g;
    for (uint32_t i : leaves) {
        const Cell &c = tree_.cells[i];
        const Eigen::Vector3d y = x - c.centre;
        const double d2 = y.squaredNorm();
        if (d2 >= c.radius * c.radius) continue;
        const double d = std::sqrt(d2);
        const double t = 1.5 * d / c.radius;
        const double w = c.blend_factor * bspline(t);
        const double q = cell_value(i, x, gradient ? &g : nullptr);
        sw += w;
        swq += w * q;
        if (gradient) {
            Eigen::Vector3d dw = d > 0.0 ? Eigen::Vector3d(c.blend_factor * bspline_derivative(t) * 1.5 / (c.radius * d) * y)
                                         : Eigen::Vector3d::Zero();
            dw_sum += dw;
            dwq_sum += dw * q + w * g;
        }
    }
    if (!(sw > 0.0)) return cell_value(fallback, x, gradient);
    const double f = swq / sw;
    if (gradient) *gradient = (dwq_sum - f * dw_sum) / sw;
    return f;
}

double MpuFunction::value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
    thread_local std::vector<uint32_t> leaves;
    leaves.clear();
    // No leaf reaches x: the deepest cell that does stands in (beyond the root's ball,
    // the root itself).
    const uint32_t fallback = collect(x, leaves);
    std::sort(leaves.begin(), leaves.end());
    return blend(leaves, x, gradient, fallback);
}

void MpuFunction::gather(const Eigen::AlignedBox3d &box, std::vector<uint32_t> &leaves) const {
    leaves.clear();
    thread_local std::vector<uint32_t> stack;
    stack.assign(1, 0);
    while (!stack.empty()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        const Cell &c = tree_.cells[i];
        const double d2 = box.squaredExteriorDistance(c.centre);
        if (d2 >= c.subtree_radius * c.subtree_radius) continue;
        if (is_leaf(c)) {
            if (d2 < c.radius * c.radius) leaves.push_back(i);
            continue;
        }
        for (int o = 0; o < 8; ++o) {
            int32_t k = tree_.child(c, o);
            if (k >= 0) stack.push_back(uint32_t(k));
        }
    }
    std::sort(leaves.begin(), leaves.end());
}

void MpuFunction::gather_among(const std::vector<uint32_t> &candidates, const Eigen::AlignedBox3d &box,
                               std::vector<uint32_t> &leaves) const {
    leaves.clear();
    for (uint32_t i : candidates) {
        const Cell &c = tree_.cells[i];
        if (box.squaredExteriorDistance(c.centre) < c.radius * c.radius) leaves.push_back(i);
    }
}

double MpuFunction::value_among(const std::vector<uint32_t> &leaves, const Eigen::Vector3d &x,
                                Eigen::Vector3d *gradient) const {
    // blend() skips the leaves that do not cover x, so the covering ones are summed in the
    // same order as value() sums them; only the fallback needs the walk.
    for (uint32_t i : leaves)
        if (covers(tree_.cells[i], x)) return blend(leaves, x, gradient, 0);
    return value(x, gradient);
}

}  // namespace gmpu
