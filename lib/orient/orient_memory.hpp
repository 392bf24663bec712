// The memory model of the orient stage, for GMPU_PARAM_MAX_MEMORY. Orient sizes everything
// it allocates from the fit it is given (the leaf graph, the fronts, the winding moments,
// the per-point measures), so one check before it starts covers the stage.
#pragma once

#include "model/octree.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

// Upper estimate of the stage's peak in bytes: what the fit keeps resident (points, their
// kd-trees and order, the cells) plus what orient adds per point, leaf and cell.
double orient_memory(const Octree &tree, const PointSet &points);

// Throws LIMIT_EXCEEDED, naming the estimate and the budget, when orient_memory > budget.
void check_orient_memory(const Octree &tree, const PointSet &points, double budget);

}  // namespace gmpu
