// Output point normals from the smooth field (not in the paper): where the surface is the
// smooth field (at noise), the point normals (gmpu_surface_point_normals, --normals-out)
// follow it rather than the blend that oriented them, so the normals and the mesh agree.
// Only where the point's nearest normals mostly agree: at a thin wall they point apart and
// the smooth field merges the two sheets, so the blend's normal is kept there. A point whose
// own normal alone (or with one neighbour) is flipped still counts as agreeing, so the
// field, which the many right normals around it shape, turns it over.
#pragma once

#include <vector>

#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/smooth_field.hpp"

namespace gmpu {

// Each point's unit outward normal (3 per point): −∇f/|∇f| of `field` where it is defined
// and the point's nearest normals agree, else its normal in `measures`.
std::vector<float> field_point_normals(const SmoothField &field, const PointSet &points, const PointMeasures &measures,
                                       Progress &progress);

}  // namespace gmpu
