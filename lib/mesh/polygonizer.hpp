// Polygonize stage: the zero set of f as a closed, edge-manifold, consistently wound mesh.
// Marching cubes (marching_cubes.hpp) over the band of a sparse block grid (block_grid.hpp):
// corners near the data take the implicit's value, corners touching the far regions take
// their region's sign, so every surface closes inside the band and zero sets of far-away
// quadrics never become surface. Blocks are independent (run in parallel) and agree on
// shared corners because every corner's value is a function of its position alone.
#pragma once

#include "core/parallel.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/surface_field.hpp"
#include "implicit/winding_field.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// Grid resolution (cubes along the longest side) that follows the data: cubes about twice
// the mean sample spacing (from the points' areas, so dense data gets a finer grid), never
// coarser than the octree's leaves (every local fit keeps a cube across) nor than the gap of
// a thin wall's two sheets.
int default_resolution(const Octree &tree, const PointMeasures &measures);

// The median size of the leaves that hold points, INFINITY where none does.
double median_leaf_size(const Octree &tree);

// The gap between the two sheets of the thinnest walls that hold a real share of the points
// (leaves fitted with two sheets), INFINITY where there are none.
double thin_wall_gap(const Octree &tree);

// The grid widens every point's trust radius to at least this at `resolution` (two cubes,
// so every cube the surface crosses has its corners trusted); `evaluate` widens it the same.
inline double grid_min_trust(int resolution) { return 2.0 / resolution; }

// `noise`: the fit's noise estimate σ̂ (normalised units). On clean, dense data (σ̂ well
// under a cube, samples closer than a cube) vertices are put on f = 0 and onto sharp edges;
// under noise or between sparse samples f's zero set is a rougher guess and the linear
// interpolant between grid corners, which smooths it, is the better mesh.
// Throws CANCELLED or LIMIT_EXCEEDED (params.max_triangles).
Mesh polygonize(const SurfaceField &field, int resolution, const Params &params, Workers &workers,
                Progress &progress, double noise = 0.0);

}  // namespace gmpu
