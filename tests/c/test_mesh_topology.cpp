// The topology summary that simplification checks after every round (mesh/mesh_topology.hpp),
// on small meshes whose answers are known: a closed tetrahedron, a pinched vertex, a fin of
// three triangles on one edge, pillows of two triangles on the same three vertices (either
// winding), open and degenerate triangles, two components.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "mesh/mesh_topology.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu;

namespace {

Mesh mesh_of(size_t vertices, std::vector<uint32_t> triangles) {
    Mesh m;
    m.vertices.assign(3 * vertices, 0.0);
    m.triangles = std::move(triangles);
    return m;
}

// Outward-wound tetrahedron on vertices o, o+1, o+2, o+3.
std::vector<uint32_t> tetrahedron(uint32_t o) {
    return {o + 0, o + 2, o + 1, o + 0, o + 1, o + 3, o + 1, o + 2, o + 3, o + 0, o + 3, o + 2};
}

bool holds(const std::vector<uint32_t> &list, uint32_t v) { return std::find(list.begin(), list.end(), v) != list.end(); }

void closed_tetrahedron(void **) {
    std::vector<uint32_t> culprits;
    const MeshTopology t = mesh_topology(mesh_of(4, tetrahedron(0)), &culprits);
    assert_true(t.closed_manifold());
    assert_int_equal(t.components, 1);
    assert_int_equal(t.euler_characteristic, 2);
    assert_true(culprits.empty());
}

void two_tetrahedra(void **) {
    std::vector<uint32_t> tri = tetrahedron(0), other = tetrahedron(4);
    tri.insert(tri.end(), other.begin(), other.end());
    const MeshTopology t = mesh_topology(mesh_of(8, tri));
    assert_true(t.closed_manifold());
    assert_int_equal(t.components, 2);
    assert_int_equal(t.euler_characteristic, 4);
}

void pinched_vertex(void **) {
    // Two tetrahedra sharing vertex 3: every edge has two triangles, vertex 3 two fans.
    std::vector<uint32_t> tri = tetrahedron(0), other = tetrahedron(3);
    tri.insert(tri.end(), other.begin(), other.end());
    std::vector<uint32_t> culprits;
    const MeshTopology t = mesh_topology(mesh_of(7, tri), &culprits);
    assert_int_equal(t.nonmanifold_edges, 0);
    assert_int_equal(t.nonmanifold_vertices, 1);
    assert_true(holds(culprits, 3));
    assert_false(t.manifold());
}

void fin_on_an_edge(void **) {
    // A tetrahedron with one more triangle on its edge 0-1.
    std::vector<uint32_t> tri = tetrahedron(0);
    tri.insert(tri.end(), {0, 1, 4});
    std::vector<uint32_t> culprits;
    const MeshTopology t = mesh_topology(mesh_of(5, tri), &culprits);
    assert_int_equal(t.nonmanifold_edges, 1);
    assert_true(holds(culprits, 0) && holds(culprits, 1));
    assert_int_equal(t.boundary_edges, 2);
    // Wound the other way: 0→1 once, 1→0 twice.
    tri.resize(tri.size() - 3);
    tri.insert(tri.end(), {1, 0, 4});
    assert_int_equal(mesh_topology(mesh_of(5, tri)).nonmanifold_edges, 1);
}

void pillows(void **) {
    // Opposite windings: each edge once each way, manifold by the edges alone.
    MeshTopology t = mesh_topology(mesh_of(3, {0, 1, 2, 0, 2, 1}));
    assert_int_equal(t.nonmanifold_edges, 0);
    assert_int_equal(t.duplicate_triangles, 1);
    assert_false(t.manifold());
    // The same winding, rotated.
    t = mesh_topology(mesh_of(3, {0, 1, 2, 1, 2, 0}));
    assert_int_equal(t.duplicate_triangles, 1);
    // Three copies: two duplicates of the first.
    t = mesh_topology(mesh_of(3, {0, 1, 2, 2, 1, 0, 2, 0, 1}));
    assert_int_equal(t.duplicate_triangles, 2);
    // A tetrahedron has none, though its faces share edges.
    assert_int_equal(mesh_topology(mesh_of(4, tetrahedron(0))).duplicate_triangles, 0);
}

void open_and_degenerate(void **) {
    MeshTopology t = mesh_topology(mesh_of(4, {0, 1, 2, 0, 2, 3}));  // a quad
    assert_true(t.manifold());
    assert_int_equal(t.boundary_edges, 4);
    assert_int_equal(t.euler_characteristic, 1);
    t = mesh_topology(mesh_of(4, {0, 1, 2, 3, 3, 1}));
    assert_int_equal(t.degenerate_triangles, 1);
    assert_false(t.manifold());
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(closed_tetrahedron), cmocka_unit_test(two_tetrahedra), cmocka_unit_test(pinched_vertex),
        cmocka_unit_test(fin_on_an_edge),     cmocka_unit_test(pillows),        cmocka_unit_test(open_and_degenerate),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
