// A free-standing sheet: a cloud whose oriented points bound no solid. When the two faces of
// a thin wall lie closer together than the noise, the fit sees one noisy sheet through the
// middle, and orientation makes it consistent: every normal points the same way across the
// wall. Closed up, that sheet becomes a dome over one side, nothing like the wall. A closed
// surface has the winding number ≈ 1 just behind its points and ≈ 0 just in front (a jump of
// 1 about a centre of ½); a free sheet jumps by 1 about a centre of 0 (−½ in front, +½ behind).
// Turning each point's normal away from the sheet's middle (to the side of the fit its point
// lies on) then makes the two faces of a thin slab, which the smooth field closes around the
// sheet's rim.
#pragma once

#include <vector>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/winding_field.hpp"

namespace gmpu {

// Whether the points with these outward normals (3 floats each) form one free sheet: on a
// sample of them, the median winding-number centre is under an eighth of the median jump,
// between points `offset` behind and in front of each (offset: a few noise σ, so that both
// lie off the noisy sheet). Polls `progress`.
bool is_free_sheet(const WindingField &winding, const PointSet &points, const std::vector<float> &normals,
                   double offset, Progress &progress);

// Turns the normals (both of `measures`' sets) of the points on the inside of `mpu` to face
// away from the sheet's middle.
void split_sheet_faces(const MpuFunction &mpu, const PointSet &points, PointMeasures &measures, Workers &workers,
                       Progress &progress);

// The same where only a part of the cloud is a free sheet: a thin part (a blade, a fin, a
// spine) whose faces the noise merged, standing off a solid. The test is read at a sample of
// the points, `offset` behind and in front of each, and every point goes with the majority
// of the samples among its nearest neighbours; the points of free parts on the inside of
// `mpu` have their normals turned. Returns how many were turned (the winding field must then
// be made again).
size_t split_local_sheet_faces(const WindingField &winding, const MpuFunction &mpu, const PointSet &points,
                               PointMeasures &measures, double offset, Workers &workers, Progress &progress);

}  // namespace gmpu
