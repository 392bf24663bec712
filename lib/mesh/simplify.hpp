// Decimation: fewer triangles for the same surface, by meshoptimizer's quadric-error edge
// collapses, with the topology (manifold, closed, components, genus) checked after every
// round since the collapses themselves do not guarantee it.
#pragma once

#include <cstddef>

#include "mesh/mesh.hpp"

namespace gmpu {

// Welds vertices at identical positions, then collapses edges until at most
// `target_triangles` remain (0: no count target) or the next collapse would move the
// surface by more than `target_error` × the bounding-box diagonal. A round whose result
// changes the topology is retried with a smaller reduction, and simplification stops at
// the last mesh that kept it. Vertices are a subset of the input's (positions exact, the
// confidence carried); normals are recomputed from the triangles, or with `keep_normals`
// carried from the input when it has them (polygonize's normals are −∇f, exact at each
// vertex). `achieved_error` (may be null) receives the accumulated error bound, as a
// fraction of the diagonal. A mesh without triangles gives an empty mesh.
Mesh simplify_mesh(const Mesh &mesh, size_t target_triangles, double target_error, double *achieved_error,
                   bool keep_normals = false);

// Unit area-weighted vertex normals of the triangles (a vertex no triangle uses keeps
// `fallback`'s normal when given, else +z).
void recompute_normals(Mesh &mesh, const Mesh *fallback = nullptr);

}  // namespace gmpu
