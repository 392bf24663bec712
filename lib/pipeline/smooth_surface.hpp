// Which implicit a reconstruction hands out (GMPU_PARAM_SURFACE): the MPU blend (0), the
// smooth field solved from the oriented points (1), or automatically the smooth field where
// the estimated noise says the blend would follow it (2, the default).
#pragma once

#include <memory>

#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/smooth_field.hpp"
#include "model/octree.hpp"

namespace gmpu {

// Whether `params` asks for the smooth field, given the fit's estimated noise (normalised
// units).
bool wants_smooth_surface(const Params &params, const PointSet &points, double noise);

// The grid (cubes along the longest side) the smooth field is solved on, and polygonize's
// default when it is used: the octree's default, refined to the points' spacing.
int smooth_resolution(const Octree &tree, const PointMeasures &measures);

// The smooth field of an oriented reconstruction, on the grid of smooth_resolution: solved
// from the blend's normals, then again from its own normals at the points, on `workers`.
// Reports `progress` to 1.
std::shared_ptr<const SmoothField> solve_smooth_surface(const Params &params, const Octree &tree,
                                                        const PointSet &points, const PointMeasures &measures,
                                                        double noise, Workers &workers, Progress &progress);

}  // namespace gmpu
