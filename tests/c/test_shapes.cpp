// The whole pipeline through the C ABI on solids known in closed form: exact distances,
// orientation against the true outward normals, topology, and the sign of f off the
// surface. Each shape exercises a part of the paper: a sphere (general quadric cells), a
// torus (a handle), nested spheres (a shell inside a shell: the inner normals must point
// into the cavity), a thin plate (two close sheets BP must not merge), islands.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "aabb_tree.hpp"
#include "analytic_shapes.hpp"
#include "files.hpp"
#include "mesh_checks.hpp"
#include "metrics.hpp"
#include "reconstruct.hpp"
#include "sampling.hpp"
#include "triangle_mesh.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Expectation {
    size_t components;
    int genus;               // of every component
    double min_orientation;  // share of points with outward normals
    double max_mean_distance;  // mesh → true surface, fraction of the bbox diagonal
    double max_gap;            // true surface → mesh, worst case, fraction of the diagonal
    double max_distance = 1.0; // mesh → true surface, worst case, fraction of the diagonal
};

double diagonal(const AnalyticShape &s) { return s.bounds().diagonal().norm(); }

// Reconstructs `count` samples of the shape and checks the mesh and the normals.
Reconstruction check_shape(const AnalyticShape &shape, size_t count, const Expectation &e,
                           const std::vector<std::pair<gmpu_param, double>> &params = {}) {
    OrientedPoints pts = shape.sample(count, 7);
    Reconstruction r = reconstruct(pts.positions, params);
    if (r.status != GMPU_OK) fprintf(stderr, "reconstruction failed: %s\n", r.error.c_str());
    assert_int_equal(r.status, GMPU_OK);

    MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.nonmanifold_vertices, 0);
    assert_int_equal(check.components, e.components);
    for (const auto &c : check.component_reports) assert_int_equal(c.genus, e.genus);

    OrientationScore o = orientation_accuracy(r.normals, pts.normals);
    ShapeDeviation d = compare_to_shape(r.mesh, shape, 20000, 3);
    const double diag = diagonal(shape);
    fprintf(stderr, "  orientation %.4f%%, mean distance %.5f%%, max distance %.4f%%, max gap %.4f%% of the diagonal, %zu triangles\n",
            100 * o.accuracy, 100 * d.mean_distance / diag, 100 * d.max_distance / diag, 100 * d.max_gap / diag,
            r.mesh.triangles.size());
    assert_true(o.accuracy >= e.min_orientation);
    assert_true(d.mean_distance <= e.max_mean_distance * diag);
    assert_true(d.max_gap <= e.max_gap * diag);
    assert_true(d.max_distance <= e.max_distance * diag);
    assert_true(d.normal_agreement > 0.98);
    assert_true(d.inward_share < 0.005);
    // Outward winding: the enclosed volume is positive and close to the solid's.
    assert_true(check.signed_volume > 0.97 * shape.volume() && check.signed_volume < 1.03 * shape.volume());
    return r;
}

// f is positive inside, negative outside, at points clearly off the surface.
void check_signs(const Reconstruction &r, const AnalyticShape &shape, const std::vector<Vec3> &probes) {
    std::vector<double> f = r.evaluate(probes);
    assert_int_equal(f.size(), probes.size());
    for (size_t i = 0; i < probes.size(); ++i) {
        const bool inside = shape.signed_distance(probes[i]) < 0;
        if (inside != (f[i] > 0)) fprintf(stderr, "  wrong sign at probe %zu: f = %g\n", i, f[i]);
        assert_true(inside == (f[i] > 0));
    }
}

void sphere(void **) {
    Sphere shape({0.2, -0.1, 0.3}, 1.0);
    Reconstruction r = check_shape(shape, 20000, {1, 0, 0.999, 0.0005, 0.01});
    check_signs(r, shape, {{0.2, -0.1, 0.3}, {0.9, -0.1, 0.3}, {1.5, -0.1, 0.3}, {5, 5, 5}, {-40, 3, 1}, {0.2, -0.1, -0.65}});
    // Near the surface f is about the signed distance, in the caller's units, and ∇f points
    // inward with about unit length.
    std::vector<Vec3> grads;
    std::vector<double> f = r.evaluate({{1.23, -0.1, 0.3}, {1.17, -0.1, 0.3}}, &grads);
    assert_true(std::abs(f[0] - (-0.03)) < 0.01 && std::abs(f[1] - 0.03) < 0.01);
    for (const Vec3 &g : grads) {
        assert_true(g.normalized().dot(Vec3(-1, 0, 0)) > 0.99);
        assert_true(g.norm() > 0.8 && g.norm() < 1.25);
    }
    // Far from the data too (the far field, and beyond the kd-tree's float range), ∇f
    // points towards the solid, where f grows.
    const Vec3 centre(0.2, -0.1, 0.3);
    std::vector<Vec3> far = {{3, -0.1, 0.3}, {0.2, -4, 0.3}, {1e25, 2e25, -1e25}};
    f = r.evaluate(far, &grads);
    for (size_t i = 0; i < far.size(); ++i) {
        assert_true(f[i] < 0 && std::isfinite(f[i]));
        assert_true(grads[i].normalized().dot((centre - far[i]).normalized()) > 0.9);
    }
}

void torus(void **) {
    Torus shape({0, 0, 0}, 1.0, 0.3);
    Reconstruction r = check_shape(shape, 30000, {1, 1, 0.999, 0.0005, 0.01});
    check_signs(r, shape, {{0, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 0, 0.5}, {1.5, 0, 0}, {0.71, 0.71, 0.1}});
}

void nested_spheres(void **) {
    NestedSpheres shape({0, 0, 0}, 0.6, 1.0);
    Reconstruction r = check_shape(shape, 30000, {2, 0, 0.999, 0.0005, 0.01});
    // The solid is the shell: the cavity and the outside are both negative.
    check_signs(r, shape, {{0, 0, 0}, {0.8, 0, 0}, {0, -0.8, 0}, {0, 0, 0.3}, {1.3, 0, 0}, {0.45, 0.45, 0.45}});
}

void thin_plate(void **) {
    // 2 × 2 × 0.08: its two faces are a few sample spacings apart.
    Plate shape({0, 0, 0}, {1.0, 1.0, 0.04});
    Reconstruction r = check_shape(shape, 40000, {1, 0, 0.995, 0.001, 0.01});
    check_signs(r, shape, {{0, 0, 0}, {0.5, -0.5, 0.01}, {0, 0, 0.1}, {0, 0, -0.1}, {0.9, 0.9, 0}});
}

void hollow_sphere(void **) {
    // A wall 1.2 % of the diagonal thick, under two sample spacings: every support holds
    // both sheets, and one quadric per cell would make a single sheet in the middle of the
    // wall (orientation ~50 %, one component). Two sheets fitted per cell keep both.
    const double outer = 1.0, wall = 0.012 * 2 * std::sqrt(3.0) * outer;
    NestedSpheres shape({0, 0, 0}, outer - wall, outer);
    Reconstruction r = check_shape(shape, 20000, {2, 0, 0.995, 0.001, 0.01});
    check_signs(r, shape, {{0, 0, 0}, {0.979, 0, 0}, {0, -0.979, 0}, {0, 0, 1.02}, {0, 0, 0.93}});
}

void sparse_thin_plate(void **) {
    // 1,000 points on a plate 1.2 % of the diagonal thick (about a tenth of the sample
    // spacing): each sheet is the other's nearest data, which reads as noise; two sheets
    // must still be seen through the raised noise floor.
    Plate shape({0, 0, 0}, {1.0, 1.0, 0.012 * std::sqrt(8.0) / 2});
    OrientedPoints pts = shape.sample(1000, 5);
    Reconstruction r = reconstruct(pts.positions);
    assert_int_equal(r.status, GMPU_OK);
    MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    const double accuracy = orientation_accuracy(r.normals, pts.normals).accuracy;
    fprintf(stderr, "  orientation %.2f%%\n", 100 * accuracy);
    assert_true(accuracy >= 0.97);
    check_signs(r, shape, {{0, 0, 0}, {0.5, -0.5, 0}, {0, 0, 0.05}, {0, 0, -0.05}});
}

void pipe_ends_at_its_rims(void **) {
    // A tube whose wall is 1.2 % of the diagonal thick (the corpus's pipe), densely sampled:
    // its cells hold two sheets, and where a cell's support reaches past the tube's end its
    // fits run on beyond the rim and meet there: a fin around each end, up to 3.6 % of the
    // diagonal high, unless those cells are split down towards the rim.
    const TriangleMesh truth = load_mesh(test_data("corpus/meshes/pipe.off"));
    const MeshSamples cloud = sample_mesh(truth, 35000, 7);
    const Reconstruction r = reconstruct(cloud.positions);
    assert_int_equal(r.status, GMPU_OK);
    const MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    assert_int_equal(check.component_reports[0].genus, 1);
    ComparisonOptions opt;
    opt.samples = 30000;
    const SurfaceComparison cmp = compare_surfaces(r.mesh, truth, opt);
    const FScore &f = *cmp.fscore_at(0.005);
    fprintf(stderr, "  precision@0.5%% %.4f, recall %.4f, Hausdorff %.3f%% of the diagonal\n", f.precision, f.recall,
            100 * cmp.hausdorff / cmp.diagonal);
    assert_true(f.precision >= 0.995 && f.recall >= 0.995);
    assert_true(cmp.hausdorff <= 0.015 * cmp.diagonal);
    // The grid is sized by the leaves as they were before that split (Cell::is_sizing_leaf):
    // counting the rim's small leaves made the median leaf a rim leaf and the grid 106
    // cubes across instead of 79, for no gain away from the rims.
    const double resolution = r.stat(GMPU_STAT_RESOLUTION);
    fprintf(stderr, "  grid resolution %.0f\n", resolution);
    assert_true(resolution <= 90);
}

void thin_torus(void **) {
    // A tube two sample spacings across (3,000 points, tube radius 0.6 % of the diagonal):
    // the smallest supports hold both sides of it and, with ε about one spacing, a height
    // field through the middle of the tube passes; the blend then gives both sides one
    // normal (orientation about 50 %, genus over 20). A general quadric closes around the
    // tube where the height field misfits it (cell_fit.cpp).
    Torus shape({0, 0, 0}, 1.0, 0.012);
    OrientedPoints pts = shape.sample(3000, 2);
    Reconstruction r = reconstruct(pts.positions);
    assert_int_equal(r.status, GMPU_OK);
    MeshCheck check = check_mesh(r.mesh);
    const double accuracy = orientation_accuracy(r.normals, pts.normals).accuracy;
    fprintf(stderr, "  orientation %.2f%%, %zu components, genus %d\n", 100 * accuracy, check.components,
            check.components ? check.component_reports[0].genus : -1);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    assert_int_equal(check.component_reports[0].genus, 1);
    assert_true(accuracy >= 0.99);
}

void cube(void **) {
    // Sharp edges and corners. Beside a corner, coarse cells with no point in their cube
    // fit the two or three faces with one quadric that misses ε by far; at full weight they
    // pulled the blend into pockets inside the solid (mean distance 0.039 % here, 0.010 %
    // with them down-weighted; build_octree.cpp).
    Plate shape({0.1, 0, -0.2}, {0.5, 0.5, 0.5});
    Reconstruction r = check_shape(shape, 30000, {1, 0, 0.999, 0.0002, 0.01, 0.006});
    check_signs(r, shape, {{0.1, 0, -0.2}, {0.55, 0.45, 0.25}, {0.7, 0.6, 0.4}, {-0.45, 0, -0.2}});
}

void islands(void **) {
    // Three separate spheres of different sizes: each piece outward on its own.
    Sphere a({0, 0, 0}, 1.0), b({3, 0, 0}, 0.5), c({0, 2.5, 0.5}, 0.3);
    OrientedPoints pa = a.sample(12000, 1), pb = b.sample(4000, 2), pc = c.sample(2000, 3);
    std::vector<Vec3> pts = pa.positions, normals = pa.normals;
    for (const OrientedPoints *p : {&pb, &pc}) {
        pts.insert(pts.end(), p->positions.begin(), p->positions.end());
        normals.insert(normals.end(), p->normals.begin(), p->normals.end());
    }
    Reconstruction r = reconstruct(pts);
    assert_int_equal(r.status, GMPU_OK);
    MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 3);
    for (const auto &comp : check.component_reports) assert_true(comp.signed_volume > 0);
    assert_true(orientation_accuracy(r.normals, normals).accuracy >= 0.999);
    std::vector<double> f = r.evaluate({{0, 0, 0}, {3, 0, 0}, {0, 2.5, 0.5}, {1.7, 0, 0}, {0, 1.6, 0.3}});
    assert_true(f[0] > 0 && f[1] > 0 && f[2] > 0 && f[3] < 0 && f[4] < 0);
}

// A tight cluster of 40 points off a sphere, 0.07 across: at the default grid (about 1.5
// cubes across) it encloses a corner or two and would be a closed piece the grid cannot
// resolve, which is dropped; on a grid 2× finer (about 3 cubes) it is a piece of its own.
void grid_scale_pieces_are_dropped(void **) {
    Sphere big({0, 0, 0}, 1.0), cluster({1.2, 0, 0}, 0.035);
    std::vector<Vec3> pts = big.sample(20000, 1).positions;
    const std::vector<Vec3> small = cluster.sample(40, 2).positions;
    pts.insert(pts.end(), small.begin(), small.end());
    Reconstruction coarse = reconstruct(pts);
    assert_int_equal(coarse.status, GMPU_OK);
    MeshCheck check = check_mesh(coarse.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    const double resolution = coarse.stat(GMPU_STAT_RESOLUTION);
    Reconstruction fine = reconstruct(pts, {{GMPU_PARAM_RESOLUTION, 2 * resolution}});
    assert_int_equal(fine.status, GMPU_OK);
    check = check_mesh(fine.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 2);
}

void scale_invariance(void **) {
    // The same sphere at 1e-6 and 1e6 scale (and far from the origin) gives the same mesh
    // up to the scale: everything works in a normalised frame.
    Sphere unit({0, 0, 0}, 1.0);
    OrientedPoints pts = unit.sample(8000, 5);
    size_t triangles = 0;
    for (double scale : {1e-6, 1.0, 1e6}) {
        std::vector<Vec3> p;
        for (const Vec3 &x : pts.positions) p.push_back(scale * x + Vec3(3 * scale, 0, 0));
        Reconstruction r = reconstruct(p);
        assert_int_equal(r.status, GMPU_OK);
        if (triangles == 0) triangles = r.mesh.triangles.size();
        assert_int_equal(r.mesh.triangles.size(), triangles);
        double mean_radius = 0;
        for (const Vec3 &v : r.mesh.vertices) mean_radius += (v - Vec3(3 * scale, 0, 0)).norm() / scale;
        mean_radius /= double(r.mesh.vertices.size());
        assert_true(std::abs(mean_radius - 1.0) < 0.002);
    }
}

void input_normals_decide_the_sign(void **) {
    // With normals given, BP is skipped and the normals are obeyed, even when they say the
    // sphere is a cavity (normals pointing in): then f is negative at the centre.
    Sphere shape({0, 0, 0}, 1.0);
    OrientedPoints pts = shape.sample(10000, 9);
    Reconstruction out = reconstruct(pts.positions, {}, &pts.normals);
    assert_int_equal(out.status, GMPU_OK);
    assert_true(orientation_accuracy(out.normals, pts.normals).accuracy >= 0.999);
    assert_true(out.evaluate({{0, 0, 0}})[0] > 0);

    std::vector<Vec3> inward;
    for (const Vec3 &n : pts.normals) inward.push_back(-n);
    Reconstruction in = reconstruct(pts.positions, {}, &inward);
    assert_int_equal(in.status, GMPU_OK);
    assert_true(orientation_accuracy(in.normals, inward).accuracy >= 0.999);
    assert_true(in.evaluate({{0, 0, 0}})[0] < 0);
}

void level_of_detail(void **) {
    // Capping the octree level blends coarser cells: a cruder but still closed surface, and
    // the full-detail one is closer to the truth.
    Torus shape({0, 0, 0}, 1.0, 0.3);
    OrientedPoints pts = shape.sample(30000, 4);
    Reconstruction fine = reconstruct(pts.positions, {{GMPU_PARAM_RESOLUTION, 96}});
    Reconstruction coarse = reconstruct(pts.positions, {{GMPU_PARAM_RESOLUTION, 96}, {GMPU_PARAM_LEVEL, 3}});
    assert_int_equal(fine.status, GMPU_OK);
    assert_int_equal(coarse.status, GMPU_OK);
    assert_true(check_mesh(coarse.mesh).watertight);
    ShapeDeviation df = compare_to_shape(fine.mesh, shape), dc = compare_to_shape(coarse.mesh, shape);
    fprintf(stderr, "  level 3 mean distance %.5f, full %.5f\n", dc.mean_distance, df.mean_distance);
    assert_true(dc.mean_distance > 2 * df.mean_distance);
    // evaluate honours the cap too.
    std::vector<double> a = fine.evaluate({{1.25, 0.1, 0.05}}), b = coarse.evaluate({{1.25, 0.1, 0.05}});
    assert_true(a[0] != b[0]);
}

// An exact sphere is one quadric: the root cell fits it and neither subdivision nor belief
// propagation runs (the sphere test above). With a little noise, no noise floor and a tiny
// ε, every cell misses ε and the octree goes down to MAX_DEPTH: hundreds of bivariate
// leaves whose fitted signs are arbitrary (the PCA normal's direction), which orient must
// make agree.
void sphere_that_subdivides(void **) {
    Sphere shape({0.2, -0.1, 0.3}, 1.0);
    OrientedPoints pts = shape.sample(20000, 13);
    add_gaussian_noise(pts.positions, 0.0005, 14);
    Reconstruction r = reconstruct(pts.positions,
                                   {{GMPU_PARAM_NOISE_SCALE, 0}, {GMPU_PARAM_ERROR, 1e-5}, {GMPU_PARAM_MAX_DEPTH, 4}});
    assert_int_equal(r.status, GMPU_OK);
    const double depth = r.stat(GMPU_STAT_DEPTH), leaves = r.stat(GMPU_STAT_LEAVES),
                 flipped = r.stat(GMPU_STAT_FLIPPED_CELLS);
    const double orientation = orientation_accuracy(r.normals, pts.normals).accuracy;
    fprintf(stderr, "  depth %.0f, %.0f leaves, %.0f flipped by orient, orientation %.4f%%\n", depth, leaves, flipped,
            100 * orientation);
    assert_true(depth == 4);
    assert_true(leaves > 200);
    assert_true(flipped > 0.2 * leaves && flipped < 0.8 * leaves);  // orient had work to do
    assert_true(r.stat(GMPU_STAT_COMPONENTS) == 1);
    assert_true(orientation >= 0.999);
    MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    assert_int_equal(check.component_reports[0].genus, 0);
    assert_true(check.signed_volume > 0);
}

// GMPU_PARAM_LEVEL on one fitted, oriented surface: the mesh at every level is closed and
// has the shape's topology, and all levels together are closer to the truth than the
// coarsest. Level 1's eight cells alone cannot hold a torus (their blend has genus 4), but
// a capped cell whose fit misses its points by much is replaced by its children, so the
// torus stays a torus at every level. A sphere is one at every level.
void level_of_detail_keeps_topology(void **) {
    const Torus torus({0, 0, 0}, 1.0, 0.3);
    const Sphere sphere({0, 0, 0}, 1.0);
    struct Case {
        const AnalyticShape *shape;
        int genus;
        int first_level;  // the coarsest level whose mesh has the shape's topology
    } cases[] = {{&torus, 1, 1}, {&sphere, 0, 1}};
    for (const Case &c : cases) {
        OrientedPoints pts = c.shape->sample(20000, 21);
        add_gaussian_noise(pts.positions, 0.0005, 22);  // a sphere must subdivide too (above)
        Reconstruction r = reconstruct(pts.positions, {{GMPU_PARAM_RESOLUTION, 64}, {GMPU_PARAM_NOISE_SCALE, 0},
                                                       {GMPU_PARAM_ERROR, 1e-5}, {GMPU_PARAM_MAX_DEPTH, 5}});
        assert_int_equal(r.status, GMPU_OK);
        const int depth = int(r.stat(GMPU_STAT_DEPTH));
        assert_int_equal(depth, 5);
        double coarsest = 0.0;
        for (int level = 1; level <= depth + 1; ++level) {
            const int cap = level > depth ? 0 : level;  // 0: every level
            assert_int_equal(gmpu_surface_set_param(r.surface, GMPU_PARAM_LEVEL, cap), GMPU_OK);
            gmpu_mesh *m = nullptr;
            assert_int_equal(gmpu_surface_polygonize(r.surface, &m), GMPU_OK);
            TriangleMesh mesh = mesh_from_arrays(gmpu_mesh_vertices(m), gmpu_mesh_vertex_count(m),
                                                 gmpu_mesh_triangles(m), gmpu_mesh_triangle_count(m));
            gmpu_mesh_destroy(m);
            MeshCheck check = check_mesh(mesh);
            ShapeDeviation d = compare_to_shape(mesh, *c.shape, 5000, 3);
            fprintf(stderr, "  genus-%d shape, level %d: %zu components, genus %d, watertight %d, mean distance %.5f\n",
                    c.genus, cap, check.components, check.components ? check.component_reports[0].genus : -1,
                    int(check.watertight), d.mean_distance);
            assert_true(check.watertight);  // at every level, even below first_level
            if (level == 1) coarsest = d.mean_distance;
            if (cap == 0) assert_true(d.mean_distance < 0.5 * coarsest);
            if (level < c.first_level) continue;
            assert_int_equal(check.components, 1);
            assert_int_equal(check.component_reports[0].genus, c.genus);
        }
    }
}

// How far a cube's true edges and corners are from the reconstruction: mean distance to the
// mesh, and mean |f| (about the distance to the implicit's zero set, which the polygonizer
// then rounds at the scale of its grid).
struct FeatureDistances {
    double edge_mesh = 0, corner_mesh = 0, edge_f = 0, corner_f = 0;
};
FeatureDistances feature_distances(const Reconstruction &r, const Vec3 &centre, double half) {
    std::vector<Vec3> edge, corner;
    for (int axis = 0; axis < 3; ++axis)
        for (int s = 0; s < 4; ++s)
            for (int k = 1; k < 20; ++k) {  // along each of the 12 edges, corners excluded
                Vec3 p = centre;
                p[(axis + 1) % 3] += (s & 1 ? half : -half);
                p[(axis + 2) % 3] += (s & 2 ? half : -half);
                p[axis] += half * (-1.0 + 2.0 * k / 20.0);
                edge.push_back(p);
            }
    for (int c = 0; c < 8; ++c) corner.push_back(centre + half * Vec3(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1));
    const AabbTree tree(r.mesh);
    FeatureDistances out;
    auto mean = [&](const std::vector<Vec3> &at, double &mesh, double &f) {
        const std::vector<double> values = r.evaluate(at);
        for (size_t i = 0; i < at.size(); ++i) {
            mesh += tree.nearest(at[i]).distance / double(at.size());
            f += std::abs(values[i]) / double(at.size());
        }
    };
    mean(edge, out.edge_mesh, out.edge_f);
    mean(corner, out.corner_mesh, out.corner_f);
    return out;
}

void sharp_features_reach_the_edges(void **) {
    const Vec3 centre(0.1, 0, -0.2);
    const double half = 0.5;
    Plate cube(centre, {half, half, half});
    OrientedPoints pts = cube.sample(30000, 8);
    FeatureDistances d[2];
    for (int sharp = 0; sharp < 2; ++sharp) {
        // The same grid for both: the automatic one follows the leaves, which differ.
        Reconstruction r = reconstruct(pts.positions, {{GMPU_PARAM_SHARP_FEATURES, double(sharp)}, {GMPU_PARAM_RESOLUTION, 128}});
        assert_int_equal(r.status, GMPU_OK);
        MeshCheck check = check_mesh(r.mesh);
        assert_true(check.watertight);
        assert_int_equal(check.components, 1);
        assert_int_equal(check.component_reports[0].genus, 0);
        if (sharp) assert_true(r.stat(GMPU_STAT_PIECEWISE_CELLS) > 0);
        else assert_true(r.stat(GMPU_STAT_PIECEWISE_CELLS) == 0);
        d[sharp] = feature_distances(r, centre, half);
        fprintf(stderr, "  sharp features %d: %.0f piecewise leaves; true edges: mesh %.5f, |f| %.5f; corners: mesh %.5f, "
                        "|f| %.5f (grid cube %.4f)\n",
                sharp, r.stat(GMPU_STAT_PIECEWISE_CELLS), d[sharp].edge_mesh, d[sharp].edge_f, d[sharp].corner_mesh,
                d[sharp].corner_f, 2 * half / 128);
    }
    // Measured: about a quarter closer along the edges, both in f and in the mesh.
    assert_true(d[1].edge_f < 0.9 * d[0].edge_f && d[1].corner_f < d[0].corner_f);
    assert_true(d[1].edge_mesh < 0.9 * d[0].edge_mesh && d[1].corner_mesh < d[0].corner_mesh);
}

void deterministic(void **) {
    Torus shape({0, 0, 0}, 1.0, 0.35);
    OrientedPoints pts = shape.sample(15000, 11);
    Reconstruction a = reconstruct(pts.positions), b = reconstruct(pts.positions, {{GMPU_PARAM_THREADS, 1}});
    assert_int_equal(a.mesh.vertices.size(), b.mesh.vertices.size());
    assert_int_equal(a.mesh.triangles.size(), b.mesh.triangles.size());
    for (size_t i = 0; i < a.mesh.vertices.size(); ++i) assert_true(a.mesh.vertices[i] == b.mesh.vertices[i]);
    assert_memory_equal(a.mesh.triangles.data(), b.mesh.triangles.data(), a.mesh.triangles.size() * sizeof(Triangle));
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sphere),
        cmocka_unit_test(torus),
        cmocka_unit_test(nested_spheres),
        cmocka_unit_test(thin_plate),
        cmocka_unit_test(hollow_sphere),
        cmocka_unit_test(sparse_thin_plate),
        cmocka_unit_test(pipe_ends_at_its_rims),
        cmocka_unit_test(thin_torus),
        cmocka_unit_test(cube),
        cmocka_unit_test(islands),
        cmocka_unit_test(grid_scale_pieces_are_dropped),
        cmocka_unit_test(scale_invariance),
        cmocka_unit_test(input_normals_decide_the_sign),
        cmocka_unit_test(level_of_detail),
        cmocka_unit_test(sphere_that_subdivides),
        cmocka_unit_test(level_of_detail_keeps_topology),
        cmocka_unit_test(sharp_features_reach_the_edges),
        cmocka_unit_test(deterministic),
    };
    // GMPU_TEST_FILTER=sphere* runs only the matching tests (cmocka's wildcards).
    if (const char *only = getenv("GMPU_TEST_FILTER")) cmocka_set_test_filter(only);
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
