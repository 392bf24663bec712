// The MPU implicit f(x) = Σ w_i(x) Q_i(x) / Σ w_i(x) (paper eq. 1), blended over the leaf
// cells whose support ball holds x, with Ohtake's quadratic B-spline weight
// w_i(x) = b(1.5 |x − c_i| / R_i), and its analytic gradient. Read-only: safe to share
// between threads.
//
// Where no leaf covers x (far from the data) the deepest cell that does cover it stands in
// (its coarser fit is the best estimate there); beyond the root's ball, the root's fit.
// (Far from the data the field the library hands out is signed otherwise anyway, see
// surface_field.hpp.)
// A level cap L (paper Fig. 7) treats the cells of level L as leaves.
#pragma once

#include <Eigen/Core>

#include "geometry/octree.hpp"

namespace gmpu {

class MpuFunction {
public:
    MpuFunction(const Octree &tree, int level_cap) : tree_(tree), cap_(level_cap > 0 ? level_cap : 255) {}

    // f and (optionally) ∇f at x, in the normalised frame.
    double value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const;

    const Octree &tree() const { return tree_; }

private:
    struct Sum;
    void visit(uint32_t index, const Eigen::Vector3d &x, Sum &sum, bool want_gradient) const;
    void add(const Cell &c, const Eigen::Vector3d &x, Sum &sum, bool want_gradient) const;
    const Octree &tree_;
    int cap_;
};

}  // namespace gmpu
