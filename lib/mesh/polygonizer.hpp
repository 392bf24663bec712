// Polygonize stage: the zero set of f as a closed, edge-manifold, consistently wound mesh.
//
// A grid of cube size h covers the data; it is split into blocks of 8³ cubes, and only
// blocks near the data (holding a point, plus enough blocks around to hold every trusted
// corner, see surface_field.hpp) are evaluated — the band. The rest of the grid falls into
// connected regions of far blocks; each is entirely inside or outside (the outer one always
// outside, enclosed ones by the winding number), and every grid corner touching a far
// block takes that region's sign. The band's border therefore has one sign per region, so
// marching tetrahedra inside the band closes every surface, and zero sets of far-away
// quadrics can never become surface.
#pragma once

#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/surface_field.hpp"
#include "implicit/winding_field.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// Grid resolution (cubes along the longest side) that keeps the detail of the octree.
int default_resolution(const Octree &tree, const PointSet &points);

// Throws CANCELLED or LIMIT_EXCEEDED (params.max_triangles).
Mesh polygonize(const SurfaceField &f, const WindingField &winding, const PointSet &points,
                const PointMeasures &measures, int resolution, const Params &params, Progress &progress);

}  // namespace gmpu
