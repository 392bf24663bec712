// Output point normals from the smooth field (not in the paper): on sparse clouds, and
// wherever the smooth surface is used.
//
// At about a thousand points each MPU leaf fits a dozen or so points, and across sharp
// teeth, flanges and thin limbs neighbouring fits disagree: the blend's gradient at a point
// can lie on the wrong side of the true normal. A least-squares field solved once over the
// whole cloud from the oriented normals (smooth_field.hpp) averages each normal with its
// neighbourhood's, and its gradient at a point is more often on the right side. The surface
// stays the blend; only the point normals (gmpu_surface_point_normals, --normals-out)
// change, and only where the point's nearest normals agree: at a thin wall they point
// apart and the smooth field merges the two sheets, so the blend's normal is kept there.
#pragma once

#include <vector>

#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/smooth_field.hpp"

namespace gmpu {

// Whether the cloud is sparse enough for smooth_point_normals: the median distance to a
// point's 6th nearest neighbour is at least 2.5 % of the bounding-box diagonal (sampled on
// 256 points).
bool sparse_cloud(const PointSet &points);

// Each point's unit outward normal (3 per point): −∇f/|∇f| of the smooth field solved from
// `measures` where the field is defined and the point's nearest normals agree, else its
// normal in `measures`. `noise`: the fit's estimate (normalised units). Checks the solve's
// memory estimate against params.max_memory; reports `progress` to 1.
std::vector<float> smooth_point_normals(const Params &params, const PointSet &points, const PointMeasures &measures,
                                        double noise, Progress &progress);

// The same normals from a field already solved (the smooth surface's, at noise): where the
// surface is the smooth field, the point normals follow it.
std::vector<float> field_point_normals(const SmoothField &field, const PointSet &points, const PointMeasures &measures,
                                       Progress &progress);

}  // namespace gmpu
