// The default mesh's size: the grid is set by the thinnest wall and the smallest leaves,
// so on thin-walled or porous parts (and a little on dense smooth ones) marching cubes makes
// several triangles per input point where the data carries less detail. An error-bounded
// decimation brings the count down towards a budget per point without moving the surface
// by more than a share of the fit's tolerance, keeping the topology (simplify.hpp).
#pragma once

#include <cstddef>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// Triangles a default mesh may have per input point.
constexpr double kTrianglesPerPoint = 2.0;

// Decimates `mesh` (polygonize's output, normals −∇f) when it has more than
// kTrianglesPerPoint × `points` triangles: towards a little under that count, stopping
// where the next collapse would move the surface by more than `max_error` (a fraction of
// the bounding-box diagonal). Watertight, edge-manifold, components and genus kept; the
// remaining vertices keep their positions and normals. Large meshes are decimated chunk by
// chunk on `workers` (simplify.hpp).
void cap_mesh_size(Mesh &mesh, size_t points, double max_error, Workers &workers, Progress &progress);

}  // namespace gmpu
