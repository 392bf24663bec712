// Thin shells sampled too sparsely for their two sheets (implicit/shell_field.hpp): walls
// under a sample spacing thick. A hollow sphere must come out as its two nested shells with
// each point's normal to its own side (merged, it was one sheet with half the normals
// wrong), a hollow box too, its wall whole round every edge and corner, a plate must end at
// its rim (the patches reach past it), and a solid must not be read as a shell at all.
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "fit/noise_estimate.hpp"
#include "geometry/point_set.hpp"
#include "implicit/shell_field.hpp"
#include "mesh_checks.hpp"
#include "metrics.hpp"
#include "primitive_meshes.hpp"
#include "reconstruct.hpp"
#include "sampling.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu::testing;

namespace {

// 1,000 points: at this density the walls below are under a sample spacing thick.
constexpr size_t kSparse = 1000;

// A sphere of radius 0.5 with a wall 0.02 thick (1.2 % of the diagonal, a third of the
// spacing of 1,000 points), as two closed surfaces, the inner one wound inward.
TriangleMesh hollow_sphere() {
    TriangleMesh inner = icosphere(4, 0.48);
    for (Triangle &t : inner.triangles) std::swap(t[1], t[2]);
    return merged(icosphere(4, 0.5), inner);
}

// 1 × 0.8 × 0.6 with a wall 0.03 thick (under half the spacing of 2,000 points), or `wall`,
// as two closed boxes, the inner one wound inward.
TriangleMesh hollow_box(double wall = 0.03) {
    const Vec3 half(0.5, 0.4, 0.3);
    TriangleMesh inner = box_mesh(Vec3::Zero(), half - Vec3::Constant(wall));
    for (Triangle &t : inner.triangles) std::swap(t[1], t[2]);
    return merged(box_mesh(Vec3::Zero(), half), inner);
}

// Share of the points whose oriented normal agrees with the true one.
double oriented_share(const std::vector<Vec3> &normals, const std::vector<Vec3> &truth) {
    size_t agree = 0;
    for (size_t i = 0; i < truth.size(); ++i) agree += normals[i].dot(truth[i]) > 0.0;
    return double(agree) / double(truth.size());
}

// A reconstruction of `count` points sampled on `truth`, checked against it: the mesh's
// components and genus, the share of point normals facing the true side, and F at 0.5 % of
// the diagonal (skipped without `score`).
struct ShellRun {
    MeshCheck check;
    double oriented = 0.0, fscore = 0.0;
};

ShellRun reconstructed(const TriangleMesh &truth, size_t count, uint64_t seed, bool score = true) {
    const MeshSamples samples = sample_mesh(truth, count, seed);
    Reconstruction r = reconstruct(samples.positions);
    assert_int_equal(r.status, GMPU_OK);
    ShellRun run;
    run.check = check_mesh(r.mesh);
    run.oriented = oriented_share(r.normals, samples.normals);
    if (score) run.fscore = compare_surfaces(r.mesh, truth, {30000, 1, {0.005, 0.01}, 0}).fscores[0].fscore;
    return run;
}

gmpu::ShellField shell_reading(const std::vector<Vec3> &points) {
    std::vector<double> xyz;
    for (const Vec3 &p : points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
    const gmpu::PointSet set = gmpu::PointSet::from_array(xyz.data(), points.size(), 3 * sizeof(double), 1);
    gmpu::Workers workers(1);
    gmpu::Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    return gmpu::ShellField(set, workers, progress);
}

void sparse_hollow_sphere_keeps_both_shells(void **) {
    const ShellRun run = reconstructed(hollow_sphere(), kSparse, 11);
    print_message("hollow sphere: %zu components, oriented %.4f, F at 0.5 %% %.4f\n", run.check.components,
                  run.oriented, run.fscore);
    assert_true(run.check.watertight);
    // One merged sheet: a single component with half the normals facing the wrong way.
    assert_int_equal(run.check.components, 2);
    assert_true(run.oriented > 0.97);
    assert_true(run.fscore > 0.97);
}

void sparse_hollow_box_keeps_its_wall_round_edges_and_corners(void **) {
    // At the box's edges and corners no neighbourhood reads two sheets, and the faces'
    // patches meet there.
    const ShellRun run = reconstructed(hollow_box(), 2 * kSparse, 31);
    const MeshCheck &check = run.check;
    print_message("hollow box: %zu components, genus %d and %d, oriented %.4f, F at 0.5 %% %.4f\n",
                  check.components, check.component_reports.empty() ? -1 : check.component_reports[0].genus,
                  check.component_reports.size() < 2 ? -1 : check.component_reports[1].genus, run.oriented,
                  run.fscore);
    assert_true(check.watertight);
    // Each failure pierces the wall at the edges, joining the outer face to the inner one:
    // the misfit patches left out of the blend where the faces' patches reach (slots along
    // the edges: one component of genus 12); patches blended with the first one's side
    // instead of an orientation passed along the wall (the turn is a toss-up across an edge:
    // one component of genus 1); the nearest misfit patch taken alone off the wall (one
    // component).
    assert_int_equal(check.components, 2);
    assert_int_equal(check.component_reports[0].genus, 0);
    assert_int_equal(check.component_reports[1].genus, 0);
    assert_true(run.oriented > 0.98);
    // The misfits blended at full weight round the edges off (F at 0.5 % 0.04 lower).
    assert_true(run.fscore > 0.88);
}

void box_of_a_thousand_points_is_read_as_its_walls(void **) {
    // Half as many points: the wall is a quarter of a spacing thick and the faces' middles are
    // the only neighbourhoods clear of a fold, a quarter of them.
    const ShellRun run = reconstructed(hollow_box(), kSparse, 31);
    print_message("hollow box, 1,000 points: %zu components, oriented %.4f, F at 0.5 %% %.4f\n",
                  run.check.components, run.oriented, run.fscore);
    assert_true(run.check.watertight);
    // Not read as a shell (the share of two-sheet neighbourhoods held to the thicker walls'
    // bar, or the noise estimate taking the folds for noise), the blend or the smooth
    // surface merges the two boxes into one with about half the normals inside out.
    assert_int_equal(run.check.components, 2);
    assert_true(run.oriented > 0.85);
    assert_true(run.fscore > 0.75);
}

void points_near_a_fold_face_their_own_side(void **) {
    // Half the wall, 0.015: near the box's edges the blended middle surface bends, and points
    // on one sheet fall on the other's side of it; the two-sheet patches reaching them still
    // read their sheet.
    const ShellRun run = reconstructed(hollow_box(0.015), kSparse, 37, false);
    print_message("hollow box, wall 0.015, 1,000 points: %zu components, oriented %.4f\n", run.check.components,
                  run.oriented);
    assert_true(run.oriented > 0.93);
}

void sparse_folded_wall_is_not_noise(void **) {
    // Around most centres of the 1,000-point box the ball of neighbours holds both sheets,
    // its centre's own short of a fit: read in a larger ball, not skipped, or only the folds
    // and corners are read, and their shape taken for noise.
    const std::vector<Vec3> points = sample_mesh(hollow_box(), kSparse, 31).positions;
    std::vector<double> xyz;
    for (const Vec3 &p : points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
    const gmpu::PointSet set = gmpu::PointSet::from_array(xyz.data(), points.size(), 3 * sizeof(double), 1);
    gmpu::Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    const double noise = gmpu::estimate_noise(set, progress) / (set.world_diagonal() * set.normalisation().scale);
    print_message("hollow box, 1,000 points: estimated noise %.5f %% of the diagonal\n", 100.0 * noise);
    assert_true(noise <= 0.0005);
}

void sparse_plate_ends_at_its_rim(void **) {
    // 0.8 × 0.8 × 0.015.
    const TriangleMesh plate = box_mesh(Vec3::Zero(), Vec3(0.4, 0.4, 0.0075));
    const MeshSamples samples = sample_mesh(plate, kSparse, 13);
    Reconstruction r = reconstruct(samples.positions);
    assert_int_equal(r.status, GMPU_OK);
    const MeshCheck check = check_mesh(r.mesh);
    const SurfaceComparison c = compare_surfaces(r.mesh, plate, {30000, 1, {0.005, 0.01}, 0});
    const Vec3 size = bounding_box(r.mesh).sizes();
    print_message("plate: F at 0.5 %% %.4f, precision at 1 %% %.4f, %.3f x %.3f x %.3f, oriented %.4f\n",
                  c.fscores[0].fscore, c.fscores[1].precision, size.x(), size.y(), size.z(),
                  oriented_share(r.normals, samples.normals));
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    // Without the rim test the wall runs on about two spacings past the rim all round
    // (0.1 of the plate's width here), a quarter of the mesh's area.
    assert_true(c.fscores[1].precision > 0.97);
    assert_true(size.x() < 0.86 && size.y() < 0.86);
    assert_true(oriented_share(r.normals, samples.normals) > 0.97);
}

TriangleMesh polygonized(gmpu_surface *surface) {
    gmpu_mesh *mesh = nullptr;
    assert_int_equal(gmpu_surface_polygonize(surface, &mesh), GMPU_OK);
    TriangleMesh out = mesh_from_arrays(gmpu_mesh_vertices(mesh), gmpu_mesh_vertex_count(mesh),
                                        gmpu_mesh_triangles(mesh), gmpu_mesh_triangle_count(mesh));
    gmpu_mesh_destroy(mesh);
    return out;
}

std::vector<double> copied_normals(gmpu_surface *surface, size_t count) {
    std::vector<double> n(3 * count);
    assert_int_equal(gmpu_surface_copy_normals(surface, n.data(), count), GMPU_OK);
    return n;
}

void surface_parameter_changed_after_orient_to_and_from_the_shell(void **) {
    // The shell's point normals are not the blend's: polygonize orients again when the
    // surface parameter moves to or from the shell, and hands out what a fresh run makes.
    // A coarse grid: what is checked is which surface and normals come out, not the mesh.
    const std::vector<Vec3> points = sample_mesh(hollow_sphere(), kSparse, 23).positions;
    Reconstruction automatic = reconstruct(points, {{GMPU_PARAM_RESOLUTION, 32}}),
                   blend = reconstruct(points, {{GMPU_PARAM_SURFACE, 0}, {GMPU_PARAM_RESOLUTION, 32}});
    assert_int_equal(automatic.status, GMPU_OK);
    assert_int_equal(blend.status, GMPU_OK);
    // The shell's normals: not the blend's.
    assert_false(copied_normals(automatic.surface, points.size()) == copied_normals(blend.surface, points.size()));
    assert_int_equal(gmpu_surface_set_param(automatic.surface, GMPU_PARAM_SURFACE, 0), GMPU_OK);
    const TriangleMesh switched = polygonized(automatic.surface);
    assert_true(switched.vertices == blend.mesh.vertices && switched.triangles == blend.mesh.triangles);
    assert_true(copied_normals(automatic.surface, points.size()) == copied_normals(blend.surface, points.size()));
    assert_int_equal(gmpu_surface_set_param(automatic.surface, GMPU_PARAM_SURFACE, 2), GMPU_OK);
    const TriangleMesh back = polygonized(automatic.surface);
    assert_true(back.vertices == automatic.mesh.vertices && back.triangles == automatic.mesh.triangles);
}

void a_blocks_gathered_patches_give_each_corner_its_own_value(void **) {
    // The polygonizer gathers the patches once for a block of corners and each corner scans
    // that list: every corner must get exactly what a query of its own gets (the blocks that
    // share a corner then agree, and the mesh is the field's), a patch missed or summed in
    // another order would show.
    std::vector<double> xyz;
    for (const Vec3 &p : sample_mesh(hollow_sphere(), kSparse, 19).positions) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
    const gmpu::PointSet set = gmpu::PointSet::from_array(xyz.data(), xyz.size() / 3, 3 * sizeof(double), 1);
    gmpu::Workers workers(1);
    gmpu::Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    const gmpu::ShellField shell(set, workers, progress);
    // 9³ corners 0.01 apart (normalised units: the wall is 0.02 thick), astride the wall.
    const Eigen::Vector3d centre = set.point(0), first = centre - Eigen::Vector3d::Constant(0.04);
    std::vector<uint32_t> patches;
    shell.gather(set, centre, std::sqrt(3.0) * 0.04, patches);
    size_t defined = 0, inside = 0;
    for (int k = 0; k <= 8; ++k)
        for (int j = 0; j <= 8; ++j)
            for (int i = 0; i <= 8; ++i) {
                const Eigen::Vector3d x = first + 0.01 * Eigen::Vector3d(i, j, k);
                double own = 0.0, among = 0.0;
                const bool has_own = shell.value(set, x, own, nullptr);
                assert_int_equal(has_own, shell.value_among(set, patches, x, among));
                if (!has_own) continue;
                assert_true(own == among);
                ++defined, inside += own > 0.0;
            }
    print_message("block: %zu of 729 corners defined, %zu inside the wall\n", defined, inside);
    assert_true(defined > 400 && inside > 0);
}

void solids_and_resolved_walls_are_not_shells(void **) {
    // A solid torus sampled as sparsely: its neighbourhoods show one sheet.
    const gmpu::ShellField torus = shell_reading(sample_mesh(torus_mesh(0.4, 0.15, 64, 32), kSparse, 17).positions);
    print_message("torus: two-sheet share %.3f\n", torus.two_sheet_share());
    assert_false(torus.whole_shell());
    // The hollow sphere at 1,000 points is one; at 20 times the density its wall is over a
    // spacing thick, and the octree's two-sheet fits keep it.
    const gmpu::ShellField sparse = shell_reading(sample_mesh(hollow_sphere(), kSparse, 19).positions);
    const gmpu::ShellField dense = shell_reading(sample_mesh(hollow_sphere(), 20 * kSparse, 19).positions);
    print_message("hollow sphere: share %.3f, gap / spacing %.3f sparse, %.3f dense\n", sparse.two_sheet_share(),
                  sparse.median_gap() / sparse.median_spacing(), dense.median_gap() / dense.median_spacing());
    assert_true(sparse.whole_shell());
    assert_false(dense.whole_shell());
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sparse_hollow_sphere_keeps_both_shells),
        cmocka_unit_test(sparse_hollow_box_keeps_its_wall_round_edges_and_corners),
        cmocka_unit_test(box_of_a_thousand_points_is_read_as_its_walls),
        cmocka_unit_test(points_near_a_fold_face_their_own_side),
        cmocka_unit_test(sparse_folded_wall_is_not_noise),
        cmocka_unit_test(sparse_plate_ends_at_its_rim),
        cmocka_unit_test(surface_parameter_changed_after_orient_to_and_from_the_shell),
        cmocka_unit_test(a_blocks_gathered_patches_give_each_corner_its_own_value),
        cmocka_unit_test(solids_and_resolved_walls_are_not_shells),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
