// The adaptive octree of MPU: cells with a centre, a spherical support and a local shape
// function. Built by fit (lib/fit/build_octree.cpp) and never changed after; orient's result
// is a sign per cell kept beside it (CellSigns); the implicit function and the polygonizer
// read both. The root is the cube of 1.2 × the longest side of the
// normalised bounding box (which is 1), centred at the origin.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "model/local_shape.hpp"

namespace gmpu {

constexpr double kRootSize = 1.2;
constexpr int kMaxDepth = 16;  // integer cell coordinates fit in 16 bits

struct Cell {
    Eigen::Vector3d centre;
    double size = 0.0;     // edge length
    double radius = 0.0;   // support radius R (after growing to hold N_min points)
    // Radius around the centre that holds the support ball of this cell and of every cell
    // below it: a grown child's ball can reach beyond its parent's, so searches prune on this.
    double subtree_radius = 0.0;
    uint16_t coord[3] = {0, 0, 0};  // integer position among the cells of its depth
    uint8_t depth = 0;
    uint8_t child_mask = 0;          // which of the 8 octants have a child
    int32_t first_child = -1;        // children are stored contiguously, in octant order
    int32_t parent = -1;
    uint32_t point_begin = 0, point_end = 0;  // points inside the cube: Octree::order range
    uint32_t support_count = 0;       // points used by the fit
    uint32_t initial_count = 0;       // points in the ungrown ball (capped at N_min)
    float error = 0.0f;               // Taubin distance error of the fit (normalised units)
    float variation = 0.0f;           // PCA surface variation σ of the support
    bool unresolved_sheets = false;   // fit saw two sheets it could not model: split anyway
    // Its two-sheet fit meets ε but the sheets end inside the support (a plate's rim): split
    // anyway, a bounded number of times (build_octree.cpp), counted down the tree by
    // rim_splits_above.
    bool split_at_rim = false;
    uint8_t rim_splits_above = 0;
    // Factor on the cell's partition-of-unity weight: 1, except for a leaf whose fit misses
    // ε but which could not be split because no child would be near the data (see
    // build_octree.cpp): its coarse fit is unreliable wherever a finer leaf has a say.
    float blend_factor = 1.0f;
    LocalShape shape;

    bool is_leaf() const { return child_mask == 0; }
    // The leaf as the grid's size sees it: the rim's extra refinement below a cell that was
    // split at its rim does not make the whole grid finer.
    bool is_sizing_leaf() const {
        return rim_splits_above == 0 && (is_leaf() || split_at_rim) && point_end > point_begin;
    }
};

// Orientation labels ℓ_i, one per cell: +1 keeps the fitted sign of the cell's shape, −1
// flips it. Empty: every cell as fitted.
using CellSigns = std::vector<int8_t>;

// ℓ_i Q_i(x), the cell's oriented local function at x (gradient written if asked).
inline double oriented_value(const Cell &c, int8_t sign, const Eigen::Vector3d &x,
                             const std::vector<PiecewiseShape> &pieces, Eigen::Vector3d *gradient) {
    const double v = c.shape.value(x - c.centre, pieces, gradient);
    if (sign < 0) {
        if (gradient) *gradient = -*gradient;
        return -v;
    }
    return v;
}

struct Octree {
    std::vector<Cell> cells;             // cells[0] is the root; parents before children
    std::vector<PiecewiseShape> pieces;  // piecewise shapes referenced by cells
    std::vector<uint32_t> order;         // point indices, grouped by cell (Cell::point_begin)

    bool empty() const { return cells.empty(); }
    // Index of the child in `octant` (bit 0: +x, bit 1: +y, bit 2: +z), or -1.
    int32_t child(const Cell &c, int octant) const {
        if (!(c.child_mask & (1u << octant))) return -1;
        return c.first_child + __builtin_popcount(c.child_mask & ((1u << octant) - 1u));
    }
};

}  // namespace gmpu
