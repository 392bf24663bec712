// Fit stage: the adaptive MPU octree over the points. Each cell's support ball (radius
// α × cell diagonal, grown until it holds N_min points) gets a local shape function; a cell
// is subdivided while its Taubin error exceeds ε, it is shallower than the maximum depth,
// and its ungrown ball still holds N_min points (below that scale children would only
// refit the same points). Only cells near the data are created (a point in the cube or
// within one cell size of its centre), so the tree follows the data and every leaf is
// non-empty.
#pragma once

#include "core/params.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "model/octree.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

// The ε the fit works to, in normalised units: the caller's, raised to noise_scale × the
// estimated noise (noise_estimate.hpp).
double effective_epsilon(const PointSet &points, const Params &params, double noise);

// Throws CANCELLED or LIMIT_EXCEEDED (GMPU_PARAM_MAX_CELLS). epsilon in normalised units.
// `close_sheets`: the noise estimate saw sheets only a few σ apart (two_sheet_fit.hpp).
Octree build_octree(const PointSet &points, const Params &params, double epsilon, Workers &workers,
                    Progress &progress, bool close_sheets = false);

}  // namespace gmpu
