// gmpu_surface_get_stat's answers, computed from what the stages left on a surface.
#pragma once

#include <cstddef>

#include "model/octree.hpp"
#include "geometry/point_set.hpp"
#include "gmpu/gmpu.h"
#include "orient/orient.hpp"

namespace gmpu::api {

// What a surface holds that statistics are read from.
struct StatSources {
    size_t input_count;          // points given to set_points, outliers included
    const PointSet &points;      // the kept points
    bool fitted;                 // a fit has completed (noise and epsilon are its)
    const Octree &tree;
    const OrientStats &orient;
    const double *seconds;       // by gmpu_stage
    int last_resolution;
    double noise, epsilon;       // of the last fit, normalised units
};

// Throws INVALID_ARGUMENT unless key is a gmpu_stat enumerator (any int may come from C).
void check_stat_key(const gmpu_stat &key);

double statistic(gmpu_stat key, const StatSources &from);

}  // namespace gmpu::api
