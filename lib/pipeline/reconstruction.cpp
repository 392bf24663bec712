#include "pipeline/reconstruction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "core/error.hpp"
#include "fit/build_octree.hpp"
#include "fit/noise_estimate.hpp"
#include "implicit/mpu_function.hpp"
#include "mesh/confidence.hpp"
#include "mesh/grid_budget.hpp"
#include "mesh/polygonizer.hpp"
#include "orient/orient.hpp"
#include "pipeline/blend_strays.hpp"
#include "pipeline/free_sheet.hpp"
#include "pipeline/inside_out_parts.hpp"
#include "pipeline/smooth_normals.hpp"
#include "pipeline/smooth_surface.hpp"

namespace gmpu {

namespace {

// Where the free-sheet test looks, in noise σ off each point: far enough to be off the noisy
// sheet, near enough to stay within a thin part.
constexpr double kFreeSheetOffset = 2.0;
// Parts turned inside out as a whole are looked for below this many points: on denser clouds
// the wrong normals left are patches on thin parts and in narrow gaps, not whole parts, and
// the look would cost two winding numbers a point. Each round turns the parts found, then
// looks again with the turned normals.
constexpr size_t kInsideOutPartsBelowPoints = 20000;
constexpr int kInsideOutRounds = 2;

// The end of a successful stage, before it commits its result: the final report (fraction
// 1), after which nothing slow follows; a cancel on it counts.
void finish(Progress &progress) {
    progress.report(1.0, true);
    progress.throw_if_cancelled();
}

// The blend's mesh at `resolution`, with its confidence, for the stray test; `seconds`
// gets the time it took.
Mesh blend_mesh(const SurfaceField &blend, int resolution, const Params &params, double noise, Workers &workers,
                Progress &progress, double &seconds) {
    const auto start = std::chrono::steady_clock::now();
    Progress march_progress = progress.slice(0.0, 0.95), confidence_progress = progress.slice(0.95, 1.0);
    Mesh mesh = polygonize(blend, resolution, params, workers, march_progress, noise);
    compute_confidence(mesh, blend.points(), blend.measures(), workers, confidence_progress);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return mesh;
}

}  // namespace

Workers &Reconstruction::workers(unsigned threads) {
    const unsigned wanted = resolve_threads(threads);
    if (!workers_ || workers_->requested() != wanted) {
        workers_.reset();  // its threads end before the new pool's start
        workers_ = std::make_unique<Workers>(wanted);
    }
    return *workers_;
}

void Reconstruction::discard_fit() {
    tree = Octree();
    signs.clear();
    measures = PointMeasures();
    winding = WindingField();
    smooth.reset();
    guide = Guide();
    smooth_kind = SurfaceKind::blend;
    strays_tested = strays_found = false;
    tested_mesh = Mesh();
    orient_stats = {};
    blend_grid = smooth_grid = shell_grid = 0;
    thin_walls = false;
    shell.reset();
}

void Reconstruction::fit(const Params &params, Progress &progress) {
    Workers &pool = workers(params.threads);
    progress.report(0.0, true);
    const NoiseEstimate estimate = estimate_noise_model(points, progress);
    const double new_noise = estimate.sigma;
    const double new_epsilon = effective_epsilon(points, params, new_noise);
    Progress tree_progress = progress.slice(0.0, 0.95), shell_progress = progress.slice(0.95, 1.0);
    Octree new_tree = build_octree(points, params, new_epsilon, pool, tree_progress, estimate.close_sheets);
    std::shared_ptr<const ShellField> new_shell = thin_shell_reading(points, new_noise, pool, shell_progress);
    finish(progress);
    discard_fit();
    tree = std::move(new_tree);
    shell = std::move(new_shell);
    noise = new_noise;
    epsilon = new_epsilon;
    thin_walls = std::isfinite(thin_wall_gap(tree));
}

void Reconstruction::orient(const Params &params, Progress &progress) {
    Workers &pool = workers(params.threads);
    progress.report(0.0, true);
    // Whether the automatic surface depends on the blend's strays: the blend is then tested.
    const bool thin_shell = shell != nullptr;
    const bool test_strays = strays_decide(params, points, noise, thin_walls, thin_shell);
    const bool may_smooth =
        test_strays || needs_smooth_field(surface_kind(params, points, noise, thin_walls, thin_shell, false));
    // The steps' shares of the stage's progress.
    const double signs_end = test_strays ? 0.4 : may_smooth ? 0.8 : 0.9, winding_end = signs_end + (may_smooth ? 0.05 : 0.1),
                 strays_end = test_strays ? 0.85 : winding_end;
    Progress signs_progress = progress.slice(0.0, signs_end), measures_progress = progress.slice(signs_end, signs_end + 0.05),
             winding_progress = progress.slice(signs_end + 0.05, winding_end),
             strays_progress = progress.slice(winding_end, strays_end), smooth_progress = progress.slice(strays_end, 1.0);
    // The fit is never changed, so a cancelled or failed orient leaves one the next orient
    // can use as it is.
    winding = WindingField();
    smooth.reset();
    guide = Guide();
    Orientation orientation = orient_octree(tree, points, input_normals.empty() ? nullptr : input_normals.data(),
                                            pool, signs_progress);
    const MpuFunction mpu(tree, orientation.signs, 0);
    // Noise-limited fits: the noise estimate is a sizeable share of the ε the tree was fitted to.
    const bool noisy_fits = noise >= 0.25 * epsilon;
    // The point measures of the blend as signed now, and the winding field of its normals.
    auto measure = [&](Progress &measure_progress, Progress &wind_progress) {
        measures = measure_points(mpu, points, pool, measure_progress, noisy_fits);
        winding = WindingField(tree, points, measures.blend_normals, measures.area, &wind_progress);
    };
    measure(measures_progress, winding_progress);
    // A sparse solid's parts turned inside out as a whole (inside_out_parts.hpp). Not a thin
    // shell's: beside its wall the winding number is 0 whichever way a sheet faces.
    // Then the parts facing away from open space that the winding number does not see as
    // facing out (an inner part, whose centres read about 0).
    if (input_normals.empty() && !thin_shell && points.size() < kInsideOutPartsBelowPoints) {
        Progress part_progress = winding_progress.slice(1.0, 1.0);
        auto remeasure = [&] {
            sign_inner_cells(tree, points, orientation.signs, part_progress);
            measure(part_progress, part_progress);
            orientation.stats.flipped_leaves = flipped_leaves(tree, orientation.signs);
        };
        for (int round = 0; round < kInsideOutRounds; ++round) {
            if (turn_inside_out_parts(tree, points, measures, winding, orientation.signs, pool, part_progress) == 0)
                break;
            remeasure();
        }
        if (turn_parts_facing_in(tree, points, measures, winding, orientation.signs, pool, part_progress) > 0)
            remeasure();
    }
    // The test's mesh is the one polygonize would make of the blend: at its grid and level.
    const int resolution = params.resolution > 0 ? params.resolution : blend_resolution();
    double seconds = 0.0;
    Mesh mesh;
    if (test_strays) {
        try {
            mesh = blend_mesh(SurfaceField(MpuFunction(tree, orientation.signs, params.level), points, measures,
                                           winding),
                              resolution, params, noise, pool, strays_progress, seconds);
        } catch (const Error &e) {
            // A mesh over the triangle or memory limits is polygonize's failure to report, as
            // without the test; the blend stays the surface.
            if (e.status() != GMPU_ERROR_LIMIT_EXCEEDED) throw;
        }
    }
    const bool strays = test_strays && blend_strays(stray_share(mesh));
    if (strays) mesh = Mesh();
    const SurfaceKind kind = surface_kind(params, points, noise, thin_walls, thin_shell, strays);
    // A thin shell's points face away from its wall's middle, each to its own side: no
    // orientation of the merged sheet gives them that.
    if (kind == SurfaceKind::shell) {
        parallel_for(0, points.size(), pool, winding_progress, [&](size_t i) {
            const Eigen::Vector3d n = shell->outward_normal(points, i);
            for (int d = 0; d < 3; ++d) measures.normals[3 * i + d] = measures.blend_normals[3 * i + d] = float(n[d]);
        });
        restore_full_trust(measures);
        winding = WindingField(tree, points, measures.blend_normals, measures.area, &winding_progress);
    }
    const bool wants_smooth = needs_smooth_field(kind);
    // Noise-limited fits of a thin wall may make one free sheet of it, or of a thin part of
    // a solid (free_sheet.hpp); the smooth field, not the blend, can make a slab of that.
    // Only where the smooth field also gives the point normals: where it only guides a
    // dense cloud's blend, the normals are the blend's, and a turned one would face a side
    // the blend's surface does not have.
    if (wants_smooth && noisy_fits && normals_follow_smooth_field(kind, points)) {
        const double offset = kFreeSheetOffset * noise;
        size_t turned = 0;
        if (is_free_sheet(winding, points, measures.blend_normals, offset, winding_progress)) {
            split_sheet_faces(mpu, points, measures, pool, winding_progress);
            turned = points.size();
        } else {
            turned = split_local_sheet_faces(winding, mpu, points, measures, offset, pool, winding_progress);
        }
        if (turned > 0) winding = WindingField(tree, points, measures.blend_normals, measures.area, &winding_progress);
    }
    std::shared_ptr<const SmoothField> new_smooth =
        wants_smooth
            ? solve_smooth_surface(params, kind, tree, points, measures, noise, thin_walls, pool, smooth_progress)
            : nullptr;
    // Where the surface is the smooth field, the point normals follow it (beside thin walls
    // only where the nearest normals agree: pipeline/smooth_normals.hpp).
    if (new_smooth && normals_follow_smooth_field(kind, points)) {
        Progress read_progress = smooth_progress.slice(1.0, 1.0);
        const FollowField follow = thin_walls ? FollowField::where_neighbours_agree : FollowField::every_point;
        measures.normals = field_point_normals(*new_smooth, points, measures, read_progress, follow);
    }
    blend_grid = blend_resolution();
    smooth_grid = smooth_resolution(tree, measures);
    shell_grid = shell ? shell_resolution(*shell, blend_grid) : 0;
    finish(progress);
    smooth = std::move(new_smooth);
    smooth_kind = kind;
    guide = kind == SurfaceKind::guided_blend ? guide_for(points, measures, thin_walls) : Guide();
    strays_tested = test_strays;
    strays_found = strays;
    tested_mesh = std::move(mesh);
    tested_resolution = resolution;
    tested_params = params;
    tested_seconds = seconds;
    signs = std::move(orientation.signs);
    orient_stats = orientation.stats;
}

Mesh Reconstruction::take_tested_mesh(const Params &params, int resolution, double &seconds) {
    if (tested_mesh.triangles.empty() || resolution != tested_resolution || !(params == tested_params) ||
        !field_matches(params))
        return Mesh();
    seconds = tested_seconds;
    return std::exchange(tested_mesh, Mesh());
}

Mesh Reconstruction::polygonize(const Params &params, int resolution, Progress &progress, double *made_at_orient) {
    Workers &pool = workers(params.threads);
    progress.report(0.0, true);
    // The caller checks the mesh and makes the final report.
    double seconds = 0.0;
    Mesh kept = take_tested_mesh(params, resolution, seconds);
    if (made_at_orient) *made_at_orient = kept.triangles.empty() ? 0.0 : seconds;
    if (!kept.triangles.empty()) return kept;
    if (field_matches(params)) return gmpu::polygonize(field(params.level), resolution, params, pool, progress, noise);
    // The surface parameter changed since orient: test the blend, solve or drop the smooth
    // field first.
    // To or from the thin shell's wall the point normals change: orient again.
    if ((surface_for(params) == SurfaceKind::shell) != (smooth_kind == SurfaceKind::shell)) {
        Progress orient_progress = progress.slice(0.0, 0.3), rest = progress.slice(0.3, 1.0);
        orient(params, orient_progress);
        return polygonize(params, resolution, rest, made_at_orient);
    }
    const bool test_strays = !strays_tested && strays_decide(params, points, noise, thin_walls, shell != nullptr);
    const double strays_end = test_strays ? 0.7 : 0.0, solve_end = test_strays ? 0.8 : 0.3;
    Progress strays_progress = progress.slice(0.0, strays_end), solve_progress = progress.slice(strays_end, solve_end),
             march_progress = progress.slice(solve_end, 1.0);
    if (test_strays) {
        const SurfaceField blend(MpuFunction(tree, signs, params.level), points, measures, winding);
        Mesh mesh = blend_mesh(blend, resolution, params, noise, pool, strays_progress, seconds);
        strays_tested = true;
        strays_found = blend_strays(stray_share(mesh));
        if (!strays_found) {
            smooth.reset(), smooth_kind = SurfaceKind::blend, guide = Guide();
            return mesh;
        }
    }
    const SurfaceKind kind = surface_for(params);
    if (!needs_smooth_field(kind)) smooth.reset();
    else if (!smooth || smooth_coarsening(kind, points) != smooth_coarsening(smooth_kind, points))
        smooth = solve_smooth_surface(params, kind, tree, points, measures, noise, thin_walls, pool, solve_progress);
    smooth_kind = kind;
    guide = kind == SurfaceKind::guided_blend ? guide_for(points, measures, thin_walls) : Guide();
    return gmpu::polygonize(field(params.level), resolution, params, pool, march_progress, noise);
}

int Reconstruction::default_resolution(const Params &params) const {
    // The guided blend's detail is the blend's: its grid too.
    const SurfaceKind kind = surface_for(params);
    const bool smooth_grid_wanted = kind == SurfaceKind::smooth;
    if (kind == SurfaceKind::shell) return shell_grid > 0 ? shell_grid : shell_resolution(*shell, blend_resolution());
    if (blend_grid > 0) return smooth_grid_wanted ? smooth_grid : blend_grid;
    return smooth_grid_wanted ? smooth_resolution(tree, measures) : blend_resolution();
}

int Reconstruction::blend_resolution() const {
    return resolution_within_budget(gmpu::default_resolution(tree, measures), measures, noise, median_leaf_size(tree),
                                    thin_wall_gap(tree));
}

bool Reconstruction::field_matches(const Params &params) const {
    if (!strays_tested && strays_decide(params, points, noise, thin_walls, shell != nullptr)) return false;
    return surface_for(params) == (smooth || smooth_kind == SurfaceKind::shell ? smooth_kind : SurfaceKind::blend);
}

void Reconstruction::evaluate(const Params &params, const double *xyz, size_t count, double *values,
                              double *gradients) const {
    // The trust the polygonizer gives the grid at the mesh's resolution, so the surface f
    // answers is the one the mesh shows.
    const int resolution = params.resolution > 0 ? params.resolution : default_resolution(params);
    const SurfaceField f = field(params.level).bounded(grid_min_trust(resolution), INFINITY);
    const Normalisation &norm = points.normalisation();
    Eigen::Vector3d g;
    for (size_t i = 0; i < count; ++i) {
        Eigen::Vector3d q = norm.to_unit(Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
        // A finite query can normalise to inf (1e300 against a cloud at 1e-30), and f and
        // ∇f would be inf and NaN. Beyond 1e15 box lengths f is the far value anyway.
        q = q.cwiseMax(-1e15).cwiseMin(1e15);
        double v = f.value(q, gradients ? &g : nullptr);
        if (values) values[i] = v / norm.scale;
        if (gradients)
            for (int d = 0; d < 3; ++d) gradients[3 * i + d] = g[d];
    }
}

}  // namespace gmpu
