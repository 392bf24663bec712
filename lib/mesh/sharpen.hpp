// Sharp edges and corners put back on the polygonizer's mesh. Marching cubes places
// vertices on grid edges, so a crease between two faces comes out cut by a chamfer about a
// cube wide even where f itself has the crease. Each vertex whose neighbours' normals (∇f at
// the vertices) spread past a feature angle moves to the point that best fits the tangent
// planes of its 1-ring: a quadric error minimised as in dual contouring, with the small
// eigenvalues dropped so the vertex moves only along the directions the planes pin down
// (across a crease onto its line; at a corner onto the corner). The connectivity is not
// touched (the mesh stays closed and edge-manifold); a move is undone when it would take
// the vertex farther than `reach` or turn one of its triangles over or flatten it.
#pragma once

#include "core/progress.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// Moves feature vertices of `mesh` (normals required, unit, outward) in place and gives the
// moved ones the area-weighted normal of their triangles. Returns how many moved.
size_t sharpen_features(Mesh &mesh, double reach, Progress &progress);

}  // namespace gmpu
