// The topological summary of a triangle mesh that an edit must leave unchanged: whether
// every edge and vertex is manifold, how many boundary edges, components and what Euler
// characteristic. Simplification checks it before and after, since an edge collapse can
// pinch a vertex, fold two faces onto each other or close a handle without any local sign.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"

namespace gmpu {

struct MeshTopology {
    size_t nonmanifold_edges = 0;     // in three or more triangles, or twice in one direction
    size_t nonmanifold_vertices = 0;  // whose triangles form more than one fan
    size_t boundary_edges = 0;        // in one triangle only
    size_t degenerate_triangles = 0;  // a vertex index repeated
    size_t duplicate_triangles = 0;   // the same three vertices as another, in any order
    size_t components = 0;            // by shared vertices, among vertices some triangle uses
    long euler_characteristic = 0;    // V - E + F over the used vertices

    // Two triangles on the same three vertices (a flattened pillow) pass every edge test
    // but enclose nothing: not a manifold surface either.
    bool manifold() const {
        return nonmanifold_edges == 0 && nonmanifold_vertices == 0 && degenerate_triangles == 0 &&
               duplicate_triangles == 0;
    }
    bool closed_manifold() const { return manifold() && boundary_edges == 0; }
    // Same surface type: a manifold stays manifold with the same boundary, components and
    // Euler characteristic (so the same genus per component).
    bool same_as(const MeshTopology &o) const {
        return manifold() == o.manifold() && (boundary_edges == 0) == (o.boundary_edges == 0) &&
               components == o.components && euler_characteristic == o.euler_characteristic;
    }
};

// O(n log n) in the triangle count. `culprits` (may be null) receives the ends of every
// non-manifold edge and every non-manifold vertex: where an edit went wrong.
MeshTopology mesh_topology(const Mesh &mesh, std::vector<uint32_t> *culprits = nullptr);

}  // namespace gmpu
