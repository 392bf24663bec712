#include "orient/orient_memory.hpp"

#include <string>

#include "core/memory_budget.hpp"

namespace gmpu {

namespace {

// Resident from the fit, per point: the normalised floats, the kd-trees and the octree's order.
constexpr double kResidentBytesPerPoint = 48;
// Orient's own, per point: the output and the blend's normals, area and trust radius, and
// the searches that make them.
constexpr double kOrientBytesPerPoint = 44;
// Per leaf: its graph node and about thirty directed edges (neighbour and agreement), its
// component, label and place in the front's queue and heap, and its outward moment.
constexpr double kOrientBytesPerLeaf = 30 * 5 + 64 + 64;
// Per cell: its winding-number moment.
constexpr double kOrientBytesPerCell = 64;

}  // namespace

double orient_memory(const Octree &tree, const PointSet &points) {
    double leaves = 0;
    for (const Cell &c : tree.cells) leaves += c.is_leaf();
    return double(points.size()) * (kResidentBytesPerPoint + kOrientBytesPerPoint) +
           double(tree.cells.capacity()) * double(sizeof(Cell)) + leaves * kOrientBytesPerLeaf +
           double(tree.cells.size()) * kOrientBytesPerCell;
}

void check_orient_memory(const Octree &tree, const PointSet &points, double budget) {
    const double estimate = orient_memory(tree, points);
    if (estimate <= budget) return;
    const std::string what = "orient (" + std::to_string(points.size()) + " points, " +
                             std::to_string(tree.cells.size()) + " cells)";
    check_memory(estimate, budget, what.c_str());
}

}  // namespace gmpu
