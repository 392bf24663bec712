// Topology and orientation checks of a triangle mesh: is it closed, manifold, wound
// consistently and outward; how many pieces, of which genus.
#pragma once

#include "triangle_mesh.hpp"

#include <cstddef>
#include <vector>

namespace gmpu::testing {

struct ComponentReport {
    size_t vertices = 0, edges = 0, triangles = 0;
    long euler_characteristic = 0;  // V − E + F
    bool closed_manifold = false;   // watertight and no non-manifold vertex, on its own
    int genus = -1;                 // (2 − χ) / 2 when closed_manifold, else −1
    double signed_volume = 0;       // positive when wound outward
};

struct MeshCheck {
    size_t vertices = 0, triangles = 0;
    // Repeated vertex index or zero area. Triangles with a repeated index have no real
    // edges and are left out of every edge and component count below.
    size_t degenerate_triangles = 0;
    size_t duplicate_triangles = 0;   // same three vertices as an earlier one, any order
    size_t boundary_edges = 0;        // undirected edges used by one triangle
    size_t nonmanifold_edges = 0;     // ... by three or more
    size_t misoriented_edges = 0;     // undirected edges with a direction used twice
    size_t nonmanifold_vertices = 0;  // whose triangles form more than one fan (bowtie)
    bool edge_manifold = false;       // every undirected edge in exactly two triangles
    bool consistently_wound = false;  // no directed edge used twice
    bool watertight = false;          // edge_manifold && consistently_wound
    size_t components = 0;            // by shared vertices
    std::vector<ComponentReport> component_reports;  // largest (by triangles) first
    long euler_characteristic = 0;
    double signed_volume = 0;  // Σ a·(b×c)/6: positive when closed and wound outward
    double area = 0;
};

// O(n log n) in the triangle count.
MeshCheck check_mesh(const TriangleMesh &mesh);

}  // namespace gmpu::testing
