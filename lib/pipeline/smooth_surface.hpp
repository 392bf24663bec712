// Which implicit a reconstruction hands out (GMPU_PARAM_SURFACE): the MPU blend (0), the
// smooth field solved from the oriented points (1), the blend guided by the smooth field
// (3, implicit/guided_blend.hpp), or automatically (2, the default): the smooth field where
// the estimated noise says the blend would follow it, the guided blend on small clouds
// without thin walls, else the blend.
#pragma once

#include <memory>

#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/smooth_field.hpp"
#include "model/octree.hpp"

namespace gmpu {

enum class SurfaceKind { blend, smooth, guided_blend };

// What `params` asks for, given the fit's estimated noise (normalised units), the points,
// and whether the fit found thin walls (two sheets closer than the smooth field's grid can
// keep apart on a sparse cloud: the automatic choice leaves them to the blend).
SurfaceKind surface_kind(const Params &params, const PointSet &points, double noise, bool thin_walls);

// Whether that surface needs the smooth field solved.
inline bool needs_smooth_field(SurfaceKind kind) { return kind != SurfaceKind::blend; }

// How far the guided blend may depart from the smooth field (normalised units): a fraction
// of the points' median spacing.
double guide_limit(const PointMeasures &measures);

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
