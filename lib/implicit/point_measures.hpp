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
    // −∇f/|∇f| of the blend itself, 3 per point: what extends the blend beyond the points
    // (the winding field) must agree with it; `normals` may differ where a thin wall
    // misleads the blend (on_sheet_normal.hpp).
    std::vector<float> blend_normals;
    std::vector<float> area;          // surface area each point stands for
    std::vector<float> trust_radius;  // normalised units
    double widest_trust = 0.0;        // max of trust_radius
};

// Every measure of every point, for the oriented MPU blend. noisy_fits: the fit's ε is set
// by the sampling noise (its leaves are coarse and may hold both sheets of a thin part), so
// the normals come from the sheets through the points (on_sheet_normal.hpp); on clean
// clouds the fits follow every sheet and the blend's normals are kept.
PointMeasures measure_points(const MpuFunction &mpu, const PointSet &points, Workers &workers, Progress &progress,
                             bool noisy_fits = false);

// Every point's trust at its full reach, from its area: undoes the shrinking of sparse
// clouds' trust (which keeps the blend from extrapolating) for a surface that does not
// extrapolate, so the trusted shell around the points has no holes.
void restore_full_trust(PointMeasures &measures);

// Unit outward normal at every input point: −∇f/|∇f|, or the oriented fit of the point's
// leaf where ∇f vanishes; with from_sheets, from the leaves whose sheet passes by the point
// where there are any (on_sheet_normal.hpp). 3 floats per point. `blend_normals`, if given,
// receives −∇f/|∇f| (same fallback).
std::vector<float> point_normals(const MpuFunction &mpu, const PointSet &points, Workers &workers,
                                 Progress &progress, bool from_sheets = false,
                                 std::vector<float> *blend_normals = nullptr);

}  // namespace gmpu
