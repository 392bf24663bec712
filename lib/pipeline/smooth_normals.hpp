// Output point normals from the smooth field (not in the paper): where the surface is the
// smooth field (at noise), the point normals (gmpu_surface_point_normals, --normals-out)
// follow it rather than the blend that oriented them, so the normals and the mesh agree.
// Beside thin walls only where the point's nearest normals mostly agree: there they point
// apart and the smooth field merges the two sheets, so the blend's normal is kept. A point
// whose own normal alone (or with one neighbour) is flipped still counts as agreeing, so the
// field, which the many right normals around it shape, turns it over. Elsewhere every point
// follows the field: a patch where belief propagation left about half the normals wrong
// reads as disagreeing too, and there the field, shaped by the right normals around the
// patch, is the better answer.
#pragma once

#include <vector>

#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/smooth_field.hpp"

namespace gmpu {

// Which points take the field's normal (where it is defined): every one, or only those
// whose nearest normals agree (beside thin walls; for the smooth field's second solve).
enum class FollowField { where_neighbours_agree, every_point };

// Each point's unit outward normal (3 per point): −∇f/|∇f| of `field` where it is defined
// and `follow` lets the point take it, else its normal in `measures`.
std::vector<float> field_point_normals(const SmoothField &field, const PointSet &points, const PointMeasures &measures,
                                       Progress &progress,
                                       FollowField follow = FollowField::where_neighbours_agree);

}  // namespace gmpu
