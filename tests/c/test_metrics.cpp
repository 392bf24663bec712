// The ground-truth metrics (tests/support) measured against answers known in closed form:
// if these are wrong, every benchmark number is wrong.
#include <array>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "aabb_tree.hpp"
#include "analytic_shapes.hpp"
#include "mesh_checks.hpp"
#include "metrics.hpp"
#include "primitive_meshes.hpp"
#include "sampling.hpp"
#include "triangle_distance.hpp"
#include "random_vectors.hpp"

// cmocka last: its macros (fail, ...) clash with names in the C++ headers. Its header
// has no extern "C" of its own.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using gmpu_test::draw_vector;

using namespace gmpu::testing;

namespace {

#define assert_near(a, b, tol) assert_true(std::abs((a) - (b)) <= (tol))

constexpr double kPi = 3.14159265358979323846;

// Unit square in the xy plane, normal +z, as two triangles.
TriangleMesh unit_square() {
    TriangleMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

// Closed tetrahedra over shared vertices: each quadruple gives four triangles, each
// wound so that its normal points away from the quadruple's fourth vertex.
TriangleMesh tetrahedra(std::vector<Vec3> vertices, const std::vector<std::array<uint32_t, 4>> &cells) {
    TriangleMesh m;
    m.vertices = std::move(vertices);
    for (const auto &q : cells)
        for (int skip = 0; skip < 4; ++skip) {
            Triangle t{};
            for (int k = 0, n = 0; k < 4; ++k)
                if (k != skip) t[n++] = q[k];
            m.triangles.push_back(t);
            if (triangle_cross(m, m.triangles.size() - 1).dot(m.vertices[q[skip]] - m.vertices[t[0]]) > 0)
                std::swap(m.triangles.back()[1], m.triangles.back()[2]);
        }
    return m;
}

// ---- point to triangle ----

void closest_point_in_every_voronoi_region(void **) {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    struct Case { Vec3 p, expected; };
    const Case cases[] = {
        {{0.25, 0.25, 2}, {0.25, 0.25, 0}},  // face
        {{-1, -1, 0.5}, a},                  // vertex a
        {{2, -1, 0}, b},                     // vertex b
        {{-1, 3, 0}, c},                     // vertex c
        {{0.5, -2, 1}, {0.5, 0, 0}},         // edge ab
        {{-2, 0.5, 0}, {0, 0.5, 0}},         // edge ac
        {{1, 0.6, 1}, {0.7, 0.3, 0}},        // edge bc
    };
    for (const Case &k : cases) {
        assert_true((closest_point_on_triangle(k.p, a, b, c) - k.expected).norm() < 1e-15);
        assert_near(point_triangle_distance(k.p, a, b, c), (k.p - k.expected).norm(), 1e-15);
    }
    // A triangle collapsed onto a segment still answers with the segment's nearest point.
    const Vec3 q = closest_point_on_triangle({1.5, 1, 0}, a, b, Vec3(2, 0, 0));
    assert_true((q - Vec3(1.5, 0, 0)).norm() < 1e-15);
}

void closest_point_never_beaten_by_dense_sampling(void **) {
    // The exact distance is a lower bound of the distance to any point of the triangle,
    // and a fine barycentric grid comes within its spacing of it.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    constexpr int kGrid = 60;
    for (int trial = 0; trial < 200; ++trial) {
        const Vec3 a = draw_vector(u, rng), b = draw_vector(u, rng), c = draw_vector(u, rng);
        const Vec3 p = 2 * draw_vector(u, rng);
        const double exact = point_triangle_distance(p, a, b, c);
        double sampled = std::numeric_limits<double>::infinity();
        for (int i = 0; i <= kGrid; ++i)
            for (int j = 0; i + j <= kGrid; ++j) {
                const double s = double(i) / kGrid, t = double(j) / kGrid;
                sampled = std::min(sampled, (a + s * (b - a) + t * (c - a) - p).norm());
            }
        const double spacing = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()}) / kGrid;
        assert_true(exact <= sampled + 1e-12);
        assert_true(sampled - exact <= spacing);
    }
}

// ---- AABB tree ----

void tree_matches_brute_force(void **) {
    TriangleMesh mesh = merged(icosphere(3), torus_mesh(1.5, 0.4, 40, 16, Vec3(0.5, 0, 0)));
    std::mt19937_64 rng(3);
    std::normal_distribution<double> jitter(0, 0.02);
    for (Vec3 &v : mesh.vertices) v += draw_vector(jitter, rng);
    const AabbTree tree(mesh);
    assert_int_equal(tree.size(), mesh.triangles.size());

    std::uniform_real_distribution<double> u(-3, 3);
    std::vector<Vec3> queries;
    for (int i = 0; i < 3000; ++i) queries.push_back(draw_vector(u, rng));
    const std::vector<AabbTree::Nearest> hits = tree.nearest_all(queries, 2);
    for (size_t i = 0; i < queries.size(); ++i) {
        double brute = std::numeric_limits<double>::infinity();
        for (const Triangle &t : mesh.triangles)
            brute = std::min(brute, point_triangle_distance(queries[i], mesh.vertices[t[0]],
                                                            mesh.vertices[t[1]], mesh.vertices[t[2]]));
        assert_true(hits[i].distance == brute);  // same formula, so bit for bit
        const Triangle &t = mesh.triangles[hits[i].triangle];
        assert_true(point_triangle_distance(queries[i], mesh.vertices[t[0]], mesh.vertices[t[1]],
                                            mesh.vertices[t[2]]) == brute);
        assert_near((hits[i].point - queries[i]).norm(), brute, 1e-15);
    }
}

void tree_skips_zero_area_and_handles_empty(void **) {
    TriangleMesh mesh = unit_square();
    mesh.vertices.emplace_back(2, 0, 0);
    mesh.triangles.push_back({0, 1, 4});  // collinear: no area, no normal
    const AabbTree tree(mesh);
    assert_int_equal(tree.size(), 2);
    const AabbTree::Nearest hit = tree.nearest({1.5, 0, 0});
    assert_true(hit.triangle < 2);
    assert_near(hit.distance, 0.5, 1e-15);

    const AabbTree none(TriangleMesh{});
    assert_true(none.empty());
    assert_true(std::isinf(none.nearest(Vec3::Zero()).distance));
}

void tree_answers_100k_queries_on_100k_triangles_fast(void **) {
    const TriangleMesh mesh = torus_mesh(1, 0.3, 400, 125);  // 100,000 triangles
    assert_int_equal(mesh.triangles.size(), 100000);
    std::vector<Vec3> queries = Torus(Vec3::Zero(), 1, 0.3).sample(100000, 5).positions;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    // Mostly near the surface, as the metrics query; every 20th anywhere in the box (a
    // point far from a curved surface has many near-equidistant triangles: the slow case).
    for (size_t i = 0; i < queries.size(); i += 20) queries[i] = draw_vector(u, rng);
    const auto start = std::chrono::steady_clock::now();
    const AabbTree tree(mesh);
    const std::vector<AabbTree::Nearest> hits = tree.nearest_all(queries, 1);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    print_message("build + 100k queries on 100k triangles, one thread: %.3f s\n", seconds);
    assert_int_equal(hits.size(), queries.size());
    // A brute-force search takes minutes; even under sanitizers this stays far below.
    if (!getenv("GMPU_TEST_NO_TIMING")) assert_true(seconds < 2.0);
}

// ---- distances against closed-form answers ----

void icosphere_is_within_its_sagitta_of_the_sphere(void **) {
    // Every face of an icosphere lies on a plane at height h_t < 1; the polytope is
    // convex, so the sphere point along a face's normal is exactly 1 − h_t from the mesh,
    // and no sphere point is farther than max(1 − h_t).
    const TriangleMesh mesh = icosphere(4);
    const AabbTree tree(mesh);
    double sagitta = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Vec3 n = triangle_normal(mesh, t);
        const double gap = 1 - n.dot(mesh.vertices[mesh.triangles[t][0]]);
        sagitta = std::max(sagitta, gap);
        assert_near(tree.nearest(n).distance, gap, 1e-14);
    }
    assert_true(sagitta > 1e-3 && sagitta < 2e-3);  // 5120 faces of a unit sphere

    const Sphere sphere(Vec3::Zero(), 1);
    double farthest = 0;
    for (const Vec3 &p : sphere.sample(20000, 2).positions) {
        const double d = tree.nearest(p).distance;
        assert_true(d <= sagitta + 1e-14);
        farthest = std::max(farthest, d);
    }
    assert_true(farthest > 0.8 * sagitta);
    // The other way: points on the mesh sit inside the sphere by at most the sagitta.
    for (const Vec3 &p : sample_mesh(mesh, 20000, 3).positions) {
        const double sd = sphere.signed_distance(p);
        assert_true(sd <= 1e-15 && sd >= -sagitta - 1e-15);
    }
}

void icosphere_against_the_analytic_sphere(void **) {
    // Both ways within the sagitta, wound outward; reversed, every sample faces inward.
    const TriangleMesh mesh = icosphere(4, 2.0, Vec3(1, 0, 0));
    const Sphere sphere(Vec3(1, 0, 0), 2.0);
    const double sagitta = 2.0 * 1.6e-3;  // < 1.6e-3 for the unit sphere (test above)
    const ShapeDeviation d = compare_to_shape(mesh, sphere);
    assert_true(d.max_distance <= sagitta && d.max_gap <= sagitta);
    assert_true(d.mean_distance > 0.1 * sagitta && d.mean_gap > 0.1 * sagitta);
    assert_true(d.normal_agreement > 0.999 && d.inward_share == 0);
    const ShapeDeviation f = compare_to_shape(flipped(mesh), sphere);
    assert_true(f.normal_agreement < -0.999 && f.inward_share == 1);
    // A hole shows as a gap even though every mesh point is on the sphere.
    TriangleMesh holed = mesh;
    holed.triangles.resize(holed.triangles.size() / 2);
    assert_true(compare_to_shape(holed, sphere).max_gap > 0.5);
    assert_true(std::isinf(compare_to_shape(TriangleMesh{}, sphere).max_gap));
}

void mesh_against_itself_scores_perfectly(void **) {
    const TriangleMesh mesh = torus_mesh(1, 0.3, 48, 20);
    const SurfaceComparison r = compare_surfaces(mesh, mesh, {20000, 1, {0.005, 0.01}, 0});
    assert_true(r.chamfer_l1 < 1e-15 && r.hausdorff < 1e-15);
    assert_near(r.diagonal, std::sqrt(2 * 2.6 * 2.6 + 0.6 * 0.6), 1e-12);
    assert_int_equal(r.fscores.size(), 2);
    for (const FScore &f : r.fscores) assert_true(f.precision == 1 && f.recall == 1 && f.fscore == 1);
    assert_near(r.normal_consistency, 1, 1e-12);
}

void translated_copy_measures_the_translation(void **) {
    // A square lifted along its normal: every point is exactly `lift` from the other.
    const TriangleMesh gt = unit_square();
    const double lift = 0.0075 * std::sqrt(2.0);  // 0.75 % of the diagonal √2
    const TriangleMesh out = translated(gt, Vec3(0, 0, lift));
    const SurfaceComparison r = compare_surfaces(out, gt, {20000, 4, {0.005, 0.01}, 0});
    assert_near(r.diagonal, std::sqrt(2.0), 1e-15);
    assert_near(r.accuracy, 0.0075, 1e-12);
    assert_near(r.completeness, 0.0075, 1e-12);
    assert_near(r.chamfer_l1, 0.0075, 1e-12);
    assert_near(r.hausdorff, 0.0075, 1e-12);
    // Between the two thresholds: nothing is within 0.5 %, everything within 1 %.
    assert_true(r.fscore_at(0.005)->fscore == 0);
    assert_true(r.fscore_at(0.01)->precision == 1 && r.fscore_at(0.01)->recall == 1);
    assert_true(r.fscore_at(0.02) == nullptr);
    assert_near(r.normal_consistency, 1, 1e-12);
}

void tilted_square_has_known_distance_distribution(void **) {
    // The square tilted about the x axis: a point at slope position y is y·sin α above
    // the flat one (and the flat one's point at y is y·sin α from the tilted plane), so
    // distances are uniform on [0, sin α]. With sin α = 2τ·diag for τ = 1 %, half the
    // samples lie within 1 % and a quarter within 0.5 %; the mean is sin α / 2.
    const TriangleMesh gt = unit_square();
    const double diag = std::sqrt(2.0), sin_a = 0.02 * diag, cos_a = std::sqrt(1 - sin_a * sin_a);
    TriangleMesh out = gt;
    for (Vec3 &v : out.vertices) v = Vec3(v.x(), v.y() * cos_a, v.y() * sin_a);
    const SurfaceComparison r = compare_surfaces(out, gt, {100000, 2, {0.005, 0.01}, 0});
    assert_near(r.accuracy, sin_a / 2 / diag, 0.01 * r.accuracy);
    assert_near(r.completeness, sin_a / 2 / diag, 0.01 * r.completeness);
    assert_near(r.hausdorff, sin_a / diag, 1e-3 * r.hausdorff);
    assert_near(r.fscore_at(0.01)->precision, 0.5, 0.01);
    assert_near(r.fscore_at(0.01)->recall, 0.5, 0.01);
    assert_near(r.fscore_at(0.005)->fscore, 0.25, 0.01);
}

void partial_output_is_accurate_but_incomplete(void **) {
    // Output = the left half of the ground-truth square: every output point is on the
    // ground truth (accuracy 0, precision 1), but the right half is x − 0.5 away from it.
    const TriangleMesh gt = unit_square();
    TriangleMesh half = gt;
    for (Vec3 &v : half.vertices) v.x() *= 0.5;
    const double diag = std::sqrt(2.0);
    const SurfaceComparison r = compare_surfaces(half, gt, {100000, 3, {0.005, 0.01}, 0});
    assert_true(r.accuracy < 1e-15);
    assert_near(r.completeness, 0.125 / diag, 0.01 * 0.125 / diag);  // ½ · mean of U[0, ½]
    assert_near(r.chamfer_l1, 0.0625 / diag, 0.01 * 0.0625 / diag);
    assert_near(r.hausdorff, 0.5 / diag, 1e-3);
    for (const FScore &f : r.fscores) {
        assert_true(f.precision == 1);
        assert_near(f.recall, 0.5 + f.tau * diag, 0.01);
        assert_near(f.fscore, 2 * f.recall / (1 + f.recall), 1e-12);
    }
}

void inside_out_mesh_is_caught(void **) {
    const TriangleMesh mesh = icosphere(3);
    const TriangleMesh inside_out = flipped(mesh);
    const MeshCheck good = check_mesh(mesh), bad = check_mesh(inside_out);
    assert_true(good.signed_volume > 0 && bad.signed_volume < 0);
    assert_near(bad.signed_volume, -good.signed_volume, 1e-12);
    assert_true(bad.watertight);  // reversed everywhere is still consistent
    const SurfaceComparison r = compare_surfaces(inside_out, mesh, {20000, 1, {0.01}, 0});
    assert_true(r.chamfer_l1 < 1e-15);
    assert_near(r.normal_consistency, -1, 1e-6);
    // Half of it flipped: consistency drops to about 0 while distances stay 0.
    TriangleMesh half = mesh;
    for (size_t t = 0; t < half.triangles.size(); ++t)
        if (triangle_normal(half, t).z() > 0) std::swap(half.triangles[t][1], half.triangles[t][2]);
    const SurfaceComparison h = compare_surfaces(half, mesh, {20000, 1, {0.01}, 0});
    assert_true(std::abs(h.normal_consistency) < 0.05);
}

void empty_output_scores_nothing(void **) {
    const SurfaceComparison r = compare_surfaces(TriangleMesh{}, icosphere(1));
    assert_true(std::isinf(r.chamfer_l1) && std::isnan(r.normal_consistency));
    for (const FScore &f : r.fscores) assert_true(f.fscore == 0);
    bool threw = false;
    try {
        compare_surfaces(icosphere(1), TriangleMesh{});
    } catch (const std::invalid_argument &) {
        threw = true;
    }
    assert_true(threw);
}

// ---- mesh checks ----

void closed_meshes_pass_with_their_genus(void **) {
    const MeshCheck s = check_mesh(icosphere(2));
    assert_true(s.watertight && s.edge_manifold && s.consistently_wound);
    assert_int_equal(s.boundary_edges + s.nonmanifold_edges + s.misoriented_edges, 0);
    assert_int_equal(s.nonmanifold_vertices + s.degenerate_triangles + s.duplicate_triangles, 0);
    assert_int_equal(s.components, 1);
    assert_int_equal(s.euler_characteristic, 2);
    assert_int_equal(s.component_reports[0].genus, 0);
    // Inscribed in the unit sphere: a little less than its volume.
    assert_true(s.signed_volume < 4.0 / 3 * kPi && s.signed_volume > 0.95 * 4.0 / 3 * kPi);

    const MeshCheck t = check_mesh(torus_mesh(1, 0.3, 64, 24));
    assert_true(t.watertight);
    assert_int_equal(t.euler_characteristic, 0);
    assert_int_equal(t.component_reports[0].genus, 1);
    const double torus_volume = Torus(Vec3::Zero(), 1, 0.3).volume();  // 24-gon tube: ~1.3 % less
    assert_true(t.signed_volume < torus_volume && t.signed_volume > 0.98 * torus_volume);

    const MeshCheck b = check_mesh(box_mesh(Vec3(1, 2, 3), Vec3(0.5, 1, 2)));
    assert_true(b.watertight);
    assert_near(b.signed_volume, 8.0, 1e-12);
    assert_near(b.area, 2 * (1 * 2 + 2 * 4 + 1 * 4), 1e-12);
}

void missing_triangle_breaks_watertightness(void **) {
    TriangleMesh mesh = icosphere(2);
    mesh.triangles.erase(mesh.triangles.begin() + 17);
    const MeshCheck r = check_mesh(mesh);
    assert_false(r.watertight);
    assert_false(r.edge_manifold);
    assert_true(r.consistently_wound);
    assert_int_equal(r.boundary_edges, 3);
    assert_int_equal(r.component_reports[0].genus, -1);
    assert_false(r.component_reports[0].closed_manifold);
}

void one_flipped_triangle_breaks_consistency(void **) {
    TriangleMesh mesh = icosphere(2);
    std::swap(mesh.triangles[5][1], mesh.triangles[5][2]);
    const MeshCheck r = check_mesh(mesh);
    assert_true(r.edge_manifold);
    assert_false(r.consistently_wound);
    assert_false(r.watertight);
    assert_int_equal(r.misoriented_edges, 3);
}

void disjoint_meshes_are_two_components(void **) {
    const TriangleMesh two = merged(icosphere(2), translated(torus_mesh(1, 0.3, 32, 12), Vec3(5, 0, 0)));
    const MeshCheck r = check_mesh(two);
    assert_true(r.watertight);
    assert_int_equal(r.components, 2);
    assert_int_equal(r.euler_characteristic, 2);  // sphere 2 + torus 0
    assert_int_equal(r.component_reports[0].genus, 1);  // the torus is larger
    assert_int_equal(r.component_reports[1].genus, 0);
}

void bowties_are_detected(void **) {
    // Two closed tetrahedra sharing the edge 0–3: four triangles on that edge.
    const std::vector<Vec3> corners = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                       {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    const TriangleMesh joined = tetrahedra(corners, {{0, 1, 2, 3}, {0, 4, 5, 3}});
    const MeshCheck e = check_mesh(joined);
    assert_int_equal(e.nonmanifold_edges, 1);
    assert_false(e.edge_manifold);
    assert_false(e.watertight);
    assert_int_equal(e.components, 1);

    // Two closed tetrahedra sharing one vertex: every edge is fine, the vertex is not.
    const TriangleMesh vertex_bowtie = tetrahedra(corners, {{0, 1, 2, 3}, {0, 4, 5, 6}});
    assert_true(check_mesh(tetrahedra(corners, {{0, 1, 2, 3}})).signed_volume > 0);
    const MeshCheck v = check_mesh(vertex_bowtie);
    assert_true(v.edge_manifold);
    assert_int_equal(v.nonmanifold_vertices, 1);
    assert_int_equal(v.components, 1);
    assert_false(v.component_reports[0].closed_manifold);

    // An open fin: three triangles on one edge.
    TriangleMesh fin;
    fin.vertices = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {-1, -1, 0}};
    fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
    assert_int_equal(check_mesh(fin).nonmanifold_edges, 1);
}

void degenerate_and_duplicate_triangles_are_counted(void **) {
    TriangleMesh mesh = icosphere(1);
    mesh.triangles.push_back(mesh.triangles[3]);                     // duplicate
    mesh.triangles.push_back({mesh.triangles[4][0], mesh.triangles[4][2], mesh.triangles[4][1]});
    mesh.triangles.push_back({1, 1, 2});                             // repeated index
    mesh.vertices.push_back(mesh.vertices[0]);                       // coincident copy
    mesh.triangles.push_back({0, static_cast<uint32_t>(mesh.vertices.size() - 1), 1});  // zero area
    const MeshCheck r = check_mesh(mesh);
    assert_int_equal(r.duplicate_triangles, 2);
    assert_int_equal(r.degenerate_triangles, 2);
    assert_false(r.watertight);
}

// ---- orientation accuracy ----

void orientation_accuracy_counts_outward_normals(void **) {
    const OrientedPoints s = Sphere(Vec3::Zero(), 1).sample(1000, 9);
    assert_near(orientation_accuracy(s.normals, s.normals).accuracy, 1.0, 0);
    std::vector<Vec3> normals = s.normals;
    for (size_t i = 0; i < normals.size(); i += 4) normals[i] = -normals[i];
    OrientationScore r = orientation_accuracy(normals, s.normals);
    assert_int_equal(r.correct, 750);
    assert_near(r.accuracy, 0.75, 1e-15);
    // A wrongly flipped whole cloud is wrong, not "consistent": no global flip.
    for (Vec3 &n : normals) n = -n;
    assert_near(orientation_accuracy(normals, s.normals).accuracy, 0.25, 1e-15);
    normals = s.normals;
    normals[0] = Vec3::Zero();
    normals[1] = Vec3::Constant(std::nan(""));
    assert_int_equal(orientation_accuracy(normals, s.normals).correct, 998);
    bool threw = false;
    try {
        orientation_accuracy(std::vector<Vec3>(3), s.normals);
    } catch (const std::invalid_argument &) {
        threw = true;
    }
    assert_true(threw);
}

// ---- sampling ----

void sampling_is_area_uniform_and_reproducible(void **) {
    const TriangleMesh box = box_mesh(Vec3::Zero(), Vec3(2, 1, 1));
    const MeshSamples a = sample_mesh(box, 100000, 11), b = sample_mesh(box, 100000, 11);
    const MeshSamples c = sample_mesh(box, 100000, 12);
    assert_true(a.positions == b.positions && a.normals == b.normals);
    assert_false(a.positions == c.positions);
    const AabbTree tree(box);
    size_t on_x_faces = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        assert_true(tree.nearest(a.positions[i]).distance < 1e-12);
        assert_true(a.normals[i] == triangle_normal(box, a.triangles[i]));
        on_x_faces += std::abs(a.normals[i].x()) == 1;
    }
    // x faces: 2 × (2·1)(2·1) = 8 of the total area 40.
    assert_near(double(on_x_faces) / 1e5, 0.2, 0.006);  // ~5 standard deviations
}

void sampling_is_uniform_inside_a_triangle(void **) {
    // The corner triangle x + y < ½ of the right triangle holds a quarter of its area.
    TriangleMesh tri;
    tri.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tri.triangles = {{0, 1, 2}};
    size_t corner = 0;
    for (const Vec3 &p : sample_mesh(tri, 40000, 5).positions) corner += p.x() + p.y() < 0.5;
    assert_near(double(corner) / 4e4, 0.25, 0.011);  // ~5 standard deviations
}

void nonuniform_density_grows_tenfold(void **) {
    // A long thin box along x: the density at the far end is 10× that at the near end,
    // so the last tenth of x holds 10^0.9 ≈ 7.9× the points of the first tenth.
    const TriangleMesh bar = box_mesh(Vec3::Zero(), Vec3(10, 0.01, 0.01));
    SamplingOptions o;
    o.nonuniform = true;
    const MeshSamples s = sample_mesh(bar, 100000, 2, o);
    size_t first = 0, last = 0;
    for (const Vec3 &p : s.positions) {
        first += p.x() < -8;
        last += p.x() > 8;
    }
    const double ratio = double(last) / double(first);
    assert_true(ratio > 7.2 && ratio < 8.7);
}

void noise_has_the_asked_sigma(void **) {
    SamplingOptions o;
    o.noise = 0.01;
    const MeshSamples s = sample_mesh(unit_square(), 50000, 3, o);
    double sum2 = 0;
    for (const Vec3 &p : s.positions) sum2 += p.z() * p.z();
    const double sigma = std::sqrt(sum2 / 50000);
    assert_near(sigma, 0.01 * std::sqrt(2.0), 0.03 * 0.01 * std::sqrt(2.0));
    for (const Vec3 &n : s.normals) assert_true(n == Vec3::UnitZ());  // clean normals
}

// ---- analytic shapes ----

void analytic_shapes_are_self_consistent(void **) {
    const Sphere sphere(Vec3(1, 2, 3), 0.7);
    const Torus torus(Vec3(0, 0, 1), 1, 0.25);
    const NestedSpheres shell(Vec3::Zero(), 0.5, 1);
    const Plate plate(Vec3(0.1, 0, 0), Vec3(1, 0.6, 0.02));
    const AnalyticShape *shapes[] = {&sphere, &torus, &shell, &plate};
    constexpr double h = 1e-6, step = 1e-3;
    for (const AnalyticShape *shape : shapes) {
        const OrientedPoints s = shape->sample(4000, 1);
        assert_int_equal(s.size(), 4000);
        for (size_t i = 0; i < s.size(); ++i) {
            const Vec3 &p = s.positions[i], &n = s.normals[i];
            assert_true(std::abs(shape->signed_distance(p)) < 1e-12);
            assert_true(shape->bounds().exteriorDistance(p) < 1e-12);
            assert_near(n.norm(), 1, 1e-12);
            assert_true(shape->normal(p).dot(n) > 1 - 1e-9);
            // A small step along n leaves the solid, the other way enters it.
            assert_near(shape->signed_distance(p + step * n), step, 1e-9);
            // (inside, a nearer face may be closer than the step: at a plate's rim)
            const double inside = shape->signed_distance(p - step * n);
            assert_true(inside < 0 && inside >= -step - 1e-9);
            // The normal is the gradient of the signed distance just outside.
            const Vec3 q = p + 0.5 * step * n;
            Vec3 grad;
            for (int k = 0; k < 3; ++k)
                grad[k] = (shape->signed_distance(q + h * Vec3::Unit(k)) -
                           shape->signed_distance(q - h * Vec3::Unit(k))) / (2 * h);
            assert_true(grad.dot(shape->normal(q)) > 1 - 1e-6);
        }
    }
    assert_true(shell.signed_distance(Vec3::Zero()) > 0);         // the cavity is outside
    assert_true(shell.signed_distance(Vec3(0.75, 0, 0)) < 0);     // the shell is solid
    assert_true(shell.normal(Vec3(0.55, 0, 0)).x() < 0);          // inner wall faces in
    assert_true(torus.signed_distance(Vec3(0, 0, 1)) > 0);        // the hole is outside
    assert_near(plate.signed_distance(Vec3(0.1, 0, 0)), -0.02, 1e-15);
    assert_near(plate.signed_distance(Vec3(2.1, 0, 0)), 1, 1e-15);
}

void analytic_sampling_is_area_uniform(void **) {
    // On a torus the outer half (cos θ > 0) has (πR + 2r) / 2πR of the area, not half.
    const double R = 1, r = 0.3;
    const Torus torus(Vec3::Zero(), R, r);
    const OrientedPoints t = torus.sample(50000, 4);
    size_t outer = 0;
    for (const Vec3 &p : t.positions) outer += std::hypot(p.x(), p.y()) > R;
    assert_near(double(outer) / 5e4, (kPi * R + 2 * r) / (2 * kPi * R), 0.01);
    // On a shell the inner sphere gets r² / (R² + r²) of the points.
    const OrientedPoints s = NestedSpheres(Vec3::Zero(), 0.5, 1).sample(50000, 4);
    size_t inner = 0;
    for (const Vec3 &p : s.positions) inner += p.norm() < 0.75;
    assert_near(double(inner) / 5e4, 0.25 / 1.25, 0.01);
    // Areas agree with fine meshes of the same solids.
    assert_near(surface_area(torus_mesh(R, r, 400, 120)), torus.area(), 1e-3 * torus.area());
    assert_near(surface_area(icosphere(5)), Sphere(Vec3::Zero(), 1).area(), 2e-3 * 4 * kPi);
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(closest_point_in_every_voronoi_region),
        cmocka_unit_test(closest_point_never_beaten_by_dense_sampling),
        cmocka_unit_test(tree_matches_brute_force),
        cmocka_unit_test(tree_skips_zero_area_and_handles_empty),
        cmocka_unit_test(tree_answers_100k_queries_on_100k_triangles_fast),
        cmocka_unit_test(icosphere_is_within_its_sagitta_of_the_sphere),
        cmocka_unit_test(icosphere_against_the_analytic_sphere),
        cmocka_unit_test(mesh_against_itself_scores_perfectly),
        cmocka_unit_test(translated_copy_measures_the_translation),
        cmocka_unit_test(tilted_square_has_known_distance_distribution),
        cmocka_unit_test(partial_output_is_accurate_but_incomplete),
        cmocka_unit_test(inside_out_mesh_is_caught),
        cmocka_unit_test(empty_output_scores_nothing),
        cmocka_unit_test(closed_meshes_pass_with_their_genus),
        cmocka_unit_test(missing_triangle_breaks_watertightness),
        cmocka_unit_test(one_flipped_triangle_breaks_consistency),
        cmocka_unit_test(disjoint_meshes_are_two_components),
        cmocka_unit_test(bowties_are_detected),
        cmocka_unit_test(degenerate_and_duplicate_triangles_are_counted),
        cmocka_unit_test(orientation_accuracy_counts_outward_normals),
        cmocka_unit_test(sampling_is_area_uniform_and_reproducible),
        cmocka_unit_test(sampling_is_uniform_inside_a_triangle),
        cmocka_unit_test(nonuniform_density_grows_tenfold),
        cmocka_unit_test(noise_has_the_asked_sigma),
        cmocka_unit_test(analytic_shapes_are_self_consistent),
        cmocka_unit_test(analytic_sampling_is_area_uniform),
    };
    return cmocka_run_group_tests_name("metrics", tests, nullptr, nullptr);
}
