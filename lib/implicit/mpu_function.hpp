// The MPU implicit f(x) = Σ w_i(x) Q_i(x) / Σ w_i(x) (paper eq. 1), blended over the leaf
// cells whose support ball holds x, with Ohtake's quadratic B-spline weight
// w_i(x) = b(1.5 |x − c_i| / R_i), and its analytic gradient. Read-only: safe to share
// between threads.
//
// The sum always runs over the covering leaves in increasing cell index, whichever way they
// were found (a walk down the octree, or a list gathered once for a whole region), so
// every path gives bit-identical values — the polygonizer relies on that for neighbouring
// blocks to agree on shared corners.
//
// Where no leaf covers x (far from the data) the deepest cell that does cover it stands in
// (its coarser fit is the best estimate there); beyond the root's ball, the root's fit.
// (Far from the data the field the library hands out is signed otherwise anyway, see
// surface_field.hpp.) A level cap L (paper Fig. 7) treats the cells of level L as leaves,
// except those whose own fit misses their points by more than kCoarseFitTolerance of the
// cell's size: such a fit does not have the shape of the data (it bridges two sheets,
// say), and blending it in changes the topology (extra handles and pieces); below it the
// deeper cells stand in, down to where the fit is good enough or to the leaves.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/octree.hpp"

namespace gmpu {

// The largest Taubin error, as a fraction of the cell's edge, at which a cell of the level
// cap stands for its subtree: the shared clouds keep the components and genus of the full
// surface at every cap from 5 to 7 with it (tests/c/test_meshes.cpp); 0.1 does not.
constexpr double kCoarseFitTolerance = 0.07;

class MpuFunction {
public:
    // `signs`: orient's labels (empty: every cell as fitted). Both are kept by reference.
    MpuFunction(const Octree &tree, const CellSigns &signs, int level_cap)
        : tree_(tree), signs_(signs), cap_(level_cap > 0 ? level_cap : 255) {}

    // f and (optionally) ∇f at x, in the normalised frame.
    double value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const;

    // The leaves (at the level cap) whose support meets `box`, in increasing index.
    void gather(const Eigen::AlignedBox3d &box, std::vector<uint32_t> &leaves) const;
    // The same for a box inside the one `candidates` was gathered for: a filter of that
    // list, without walking the octree again.
    void gather_among(const std::vector<uint32_t> &candidates, const Eigen::AlignedBox3d &box,
                      std::vector<uint32_t> &leaves) const;

    // value() for an x inside the box `leaves` was gathered for: same result, faster.
    double value_among(const std::vector<uint32_t> &leaves, const Eigen::Vector3d &x,
                       Eigen::Vector3d *gradient) const;

    const Octree &tree() const { return tree_; }
    int8_t sign(uint32_t cell) const { return signs_.empty() ? int8_t(1) : signs_[cell]; }
    // ℓ_i Q_i(x) of one cell.
    double cell_value(uint32_t cell, const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
        return oriented_value(tree_.cells[cell], sign(cell), x, tree_.pieces, gradient);
    }

private:
    bool is_leaf(const Cell &c) const {
        return c.is_leaf() || (c.depth >= cap_ && c.error <= kCoarseFitTolerance * c.size);
    }
    bool covers(const Cell &c, const Eigen::Vector3d &x) const {
        return (x - c.centre).squaredNorm() < c.radius * c.radius;
    }
    // Covering leaves of x in `out` (unsorted); returns the deepest covering cell.
    uint32_t collect(const Eigen::Vector3d &x, std::vector<uint32_t> &out) const;
    double blend(const std::vector<uint32_t> &sorted_leaves, const Eigen::Vector3d &x,
                 Eigen::Vector3d *gradient, uint32_t fallback) const;
    const Octree &tree_;
    const CellSigns &signs_;
    int cap_;
};

}  // namespace gmpu
