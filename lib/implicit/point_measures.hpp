// What orient measures at every input point, in one place: the oriented normal, the
// surface area the point stands for and its trust radius (how far from it the MPU blend is
// believed, surface_field.hpp). The winding field and the surface field read them.
#pragma once

#include <vector>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"

namespace gmpu {

struct PointMeasures {
    std::vector<float> normals;       // unit outward, 3 per point
    std::vector<float> area;          // surface area each point stands for
    std::vector<float> trust_radius;  // normalised units
    double widest_trust = 0.0;        // max of trust_radius
};

// Every measure of every point, for the oriented MPU blend.
PointMeasures measure_points(const MpuFunction &mpu, const PointSet &points, Workers &workers, Progress &progress);

// Unit outward normal at every input point: −∇f/|∇f|, or the oriented fit of the point's
// leaf where ∇f vanishes. 3 floats per point.
std::vector<float> point_normals(const MpuFunction &mpu, const PointSet &points, Workers &workers,
                                 Progress &progress);

}  // namespace gmpu
