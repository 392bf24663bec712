// Which implicit a reconstruction hands out (GMPU_PARAM_SURFACE): the MPU blend (0), the
// smooth field solved from the oriented points (1), the blend guided by the smooth field
// (3, implicit/guided_blend.hpp), or automatically (2, the default): the smooth field where
// the estimated noise says the blend would follow it, the guided blend on small clouds and
// on larger ones without thin walls (up to a few hundred thousand points) where the blend
// strays from the data (pipeline/blend_strays.hpp), else the blend; and, before those, the
// thin shell's wall (implicit/shell_field.hpp) on a small noise-free cloud that reads as one
// throughout.
#pragma once

#include <memory>

#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/guided_blend.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/shell_field.hpp"
#include "implicit/smooth_field.hpp"
#include "model/octree.hpp"

namespace gmpu {

enum class SurfaceKind { blend, smooth, guided_blend, shell };

// What `params` asks for, given the fit's estimated noise (normalised units), the points,
// whether the fit found thin walls (two sheets in one support: on a dense cloud the
// automatic choice leaves them to the blend, whose strays are not tested), and whether
// the blend strays from the data (pipeline/blend_strays.hpp; false when not tested), and
// whether the fit read the whole cloud as a thin shell (shell_field.hpp: thin_shell_reading).
SurfaceKind surface_kind(const Params &params, const PointSet &points, double noise, bool thin_walls,
                         bool thin_shell, bool blend_strays);

// Whether the answer of surface_kind depends on `blend_strays` (and the cloud is small enough
// for the test, smooth_surface.cpp): only then is the blend tested.
bool strays_decide(const Params &params, const PointSet &points, double noise, bool thin_walls, bool thin_shell);

// Whether that surface needs the smooth field solved.
inline bool needs_smooth_field(SurfaceKind kind) { return kind != SurfaceKind::blend && kind != SurfaceKind::shell; }

// The thin-shell reading of a fit's points (shell_field.hpp) where the automatic surface may
// use it: noise-free clouds small enough that a wall can be a sample spacing thick; null
// where the cloud is not one shell throughout.
std::shared_ptr<const ShellField> thin_shell_reading(const PointSet &points, double noise, Workers &workers,
                                                     Progress &progress);

// The shell's grid: polygonize's default, or the shell's own where that is finer
// (ShellField::grid).
int shell_resolution(const ShellField &shell, int default_grid);

// How far the guided blend may depart from the smooth field (normalised units): a fraction
// of the points' median spacing on small clouds, a spacing on dense ones (whose smooth
// field is solved on a coarser grid, solve_smooth_surface); where the fit found
// `thin_walls`, widened where the smooth field is flat (Guide).
Guide guide_for(const PointSet &points, const PointMeasures &measures, bool thin_walls);

// The grid (cubes along the longest side) the smooth field is solved on, and polygonize's
// default when it is used: the octree's default, refined to the points' spacing.
int smooth_resolution(const Octree &tree, const PointMeasures &measures);

// Whether the oriented point normals are the smooth field's (smooth_normals.hpp) for the
// surface `kind`: for the smooth surface, and for the guided blend on small clouds, where
// the field's normals are better oriented than the blend's; on dense clouds the blend's are
// (the coarser guiding field blurs them where parts nearly touch).
bool normals_follow_smooth_field(SurfaceKind kind, const PointSet &points);

// How many times coarser than smooth_resolution the smooth field of the surface `kind` is
// solved (1 or kDenseGuideCoarsening, smooth_surface.cpp).
int smooth_coarsening(SurfaceKind kind, const PointSet &points);

// The smooth field of an oriented reconstruction for the surface `kind`, on the grid of
// smooth_resolution (half as fine where it guides the blend of a dense cloud: there it only
// has to catch strays of several spacings): solved from the blend's normals, then again from
// its own normals at the points at high noise, on `workers`. Its zero set lies at the
// samples' median value, or at their mean where the fit found `thin_walls` (ZeroLevel).
// Reports `progress` to 1.
std::shared_ptr<const SmoothField> solve_smooth_surface(const Params &params, SurfaceKind kind, const Octree &tree,
                                                        const PointSet &points, const PointMeasures &measures,
                                                        double noise, bool thin_walls, Workers &workers,
                                                        Progress &progress);

}  // namespace gmpu
