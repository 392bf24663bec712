// How well the input supports each part of the mesh, and trimming what it does not.
// Polygonize closes every surface, inventing caps over the holes of an open scan; a
// vertex far from every input point, compared with the spacing of the points there, lies
// on such a cap.
#pragma once

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/surface_field.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// Per vertex: distance to the nearest input point divided by that point's sample spacing
// (the square root of the area it stands for), up to tripled where the vertex lies past the
// edge of the data (its nearest points, seen in its tangent plane, leave a gap wider than a
// half-turn around it: beyond a hole's rim). About 0.5 or less on sampled surface; several where the surface
// bridges a hole. Fills mesh.confidence.
void compute_confidence(Mesh &mesh, const PointSet &points, const PointMeasures &measures, Workers &workers,
                        Progress &progress);

// Cuts the mesh where its confidence, linear along each edge, passes `threshold`, keeping
// the supported side (triangles across the cut are clipped, not dropped, so the boundary
// follows the threshold however coarse the triangles); only regions over the threshold
// that rise to twice it somewhere are cut (caps over holes; a few vertices just over it
// inside the scanned surface stay, unperforated). Then it removes the pieces of fewer
// than 8 triangles left apart (slivers of a cap that passed within the threshold of the
// data; kept if they are half the mesh), and the vertices left unused: the caps over holes
// go, leaving boundaries where the data ends. The mesh must carry a confidence.
Mesh trim_unsupported(const Mesh &mesh, double threshold);

}  // namespace gmpu
