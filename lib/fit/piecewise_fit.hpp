// Piecewise quadrics at sharp features (Ohtake's edge and corner models, detected without
// input normals): the support is split into two or three near-planar clusters by k-means
// on unoriented local normals, each cluster gets a bivariate quadratic, and the shape is
// the min of the parts, each signed positive towards the other clusters.
#pragma once

#include "fit/cell_fit.hpp"

namespace gmpu {

// Returns true and fills `out` when the support is an edge or a corner whose piecewise fit
// meets epsilon.
bool fit_piecewise(const PointList &support, double radius, double epsilon, CellFit &out);

}  // namespace gmpu
