// Every tunable of the pipeline, with the defaults the C ABI documents (gmpu.h).
#pragma once

#include "core/memory_budget.hpp"

namespace gmpu {

struct Params {
    double error = 0.002;          // ε, fraction of the bounding-box diagonal
    double noise_scale = 1.75;     // ε is at least this many estimated noise deviations
    int max_depth = 10;            // deepest octree level
    int min_points = 15;           // N_min: fewest points in a support ball
    double support_scale = 0.75;   // α: R = α × cell diagonal
    bool sharp_features = false;   // piecewise quadrics at edges and corners (experimental)
    int resolution = 0;            // polygonize grid, 0 = from the octree
    int level = 0;                 // level-of-detail cap, 0 = all levels
    unsigned threads = 0;          // 0 = every core
    double max_cells = 2e7;        // fit fails beyond this many cells
    double max_triangles = 1e8;    // polygonize fails beyond this many triangles
    double max_memory = default_memory_budget();  // bytes a stage may estimate to need
    bool remove_outliers = true;   // set_points leaves the outliers out of the fit
};

}  // namespace gmpu
