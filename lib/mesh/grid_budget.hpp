// The default grid against the mesh's triangle budget. The octree's leaves and the walls'
// gaps ask for a grid fine enough to keep every local fit and every sheet; on dense, clean
// data that grid makes several triangles per point, which the size cap then decimates
// (size_cap.hpp) at a cost comparable to the march itself. Where the points are dense
// enough that a uniform grid at the budget still resolves the shape, the grid is made that
// coarse from the start instead: the march does a fraction of the work and the cap has
// nothing left to do.
#pragma once

#include "implicit/point_measures.hpp"

namespace gmpu {

// `resolution` (cubes along the longest side), coarsened so that marching cubes makes about
// kTrianglesPerPoint triangles per point (size_cap.hpp), from the surface area the points
// stand for. Unchanged when it already makes fewer, when the budget is under
// kUniformBudget triangles (few points: the decimation's adaptive triangles keep more of the
// shape than a coarse uniform grid), when the noise estimate `noise` (normalised units) is
// not small against the sample spacing (the points' areas then measure the noise too), and
// never coarser than the median leaf `leaf` (each local fit keeps a cube) nor than
// kCubesPerWallGap of `wall_gap`, the gap of a thin wall's two sheets (INFINITY: none).
int resolution_within_budget(int resolution, const PointMeasures &measures, double noise, double leaf,
                             double wall_gap);

}  // namespace gmpu
