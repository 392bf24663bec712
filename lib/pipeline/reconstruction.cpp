#include "pipeline/reconstruction.hpp"

#include <algorithm>
#include <cmath>

#include "fit/build_octree.hpp"
#include "fit/noise_estimate.hpp"
#include "implicit/mpu_function.hpp"
#include "mesh/grid_budget.hpp"
#include "mesh/polygonizer.hpp"
#include "pipeline/free_sheet.hpp"
#include "pipeline/smooth_normals.hpp"
#include "pipeline/smooth_surface.hpp"

namespace gmpu {

namespace {

// Where the free-sheet test looks, in noise σ off each point: far enough to be off the noisy
// sheet, near enough to stay within a thin part.
constexpr double kFreeSheetOffset = 2.0;

// The end of a successful stage, before it commits its result: the final report (fraction
// 1), after which nothing slow follows; a cancel on it counts.
void finish(Progress &progress) {
    progress.report(1.0, true);
    progress.throw_if_cancelled();
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
    guide = INFINITY;
    orient_stats = {};
    blend_grid = smooth_grid = 0;
    thin_walls = false;
}

void Reconstruction::fit(const Params &params, Progress &progress) {
    Workers &pool = workers(params.threads);
    progress.report(0.0, true);
    const NoiseEstimate estimate = estimate_noise_model(points, progress);
    const double new_noise = estimate.sigma;
    const double new_epsilon = effective_epsilon(points, params, new_noise);
    Octree new_tree = build_octree(points, params, new_epsilon, pool, progress, estimate.close_sheets);
    finish(progress);
    discard_fit();
    tree = std::move(new_tree);
    noise = new_noise;
    epsilon = new_epsilon;
    thin_walls = std::isfinite(thin_wall_gap(tree));
}

void Reconstruction::orient(const Params &params, Progress &progress) {
    Workers &pool = workers(params.threads);
    progress.report(0.0, true);
    // The steps' shares of the stage's progress.
    const SurfaceKind kind = surface_kind(params, points, noise, thin_walls);
    const bool wants_smooth = needs_smooth_field(kind);
    const double signs_end = wants_smooth ? 0.8 : 0.9, winding_end = wants_smooth ? 0.85 : 1.0;
    Progress signs_progress = progress.slice(0.0, signs_end), measures_progress = progress.slice(signs_end, signs_end + 0.05),
             winding_progress = progress.slice(signs_end + 0.05, winding_end),
             smooth_progress = progress.slice(winding_end, 1.0);
    // The fit is never changed, so a cancelled or failed orient leaves one the next orient
    // can use as it is.
    winding = WindingField();
    smooth.reset();
    guide = INFINITY;
    Orientation orientation = orient_octree(tree, points, input_normals.empty() ? nullptr : input_normals.data(),
                                            pool, signs_progress);
    const MpuFunction mpu(tree, orientation.signs, 0);
    // Noise-limited fits: the noise estimate is a sizeable share of the ε the tree was fitted to.
    const bool noisy_fits = noise >= 0.25 * epsilon;
    measures = measure_points(mpu, points, pool, measures_progress, noisy_fits);
    winding = WindingField(tree, points, measures.blend_normals, measures.area, &winding_progress);
    // Noise-limited fits of a thin wall may make one free sheet of it (free_sheet.hpp); the
    // smooth field, not the blend, can make a slab of that.
    if (wants_smooth && noisy_fits &&
        is_free_sheet(winding, points, measures.blend_normals, kFreeSheetOffset * noise, winding_progress)) {
        split_sheet_faces(mpu, points, measures, pool, winding_progress);
        winding = WindingField(tree, points, measures.blend_normals, measures.area, &winding_progress);
    }
    std::shared_ptr<const SmoothField> new_smooth =
        wants_smooth ? solve_smooth_surface(params, tree, points, measures, noise, pool, smooth_progress) : nullptr;
    // Where the surface is the smooth field, the point normals follow it.
    if (new_smooth) {
        Progress read_progress = smooth_progress.slice(1.0, 1.0);
        measures.normals = field_point_normals(*new_smooth, points, measures, read_progress);
    }
    blend_grid = blend_resolution();
    smooth_grid = smooth_resolution(tree, measures);
    finish(progress);
    smooth = std::move(new_smooth);
    guide = kind == SurfaceKind::guided_blend ? guide_limit(measures) : INFINITY;
    signs = std::move(orientation.signs);
    orient_stats = orientation.stats;
}

Mesh Reconstruction::polygonize(const Params &params, int resolution, Progress &progress) {
    Workers &pool = workers(params.threads);
    progress.report(0.0, true);
    // The caller checks the mesh and makes the final report.
    if (field_matches(params)) return gmpu::polygonize(field(params.level), resolution, params, pool, progress, noise);
    // The surface parameter changed since orient: solve or drop the smooth field first.
    Progress solve_progress = progress.slice(0.0, 0.3), march_progress = progress.slice(0.3, 1.0);
    const SurfaceKind kind = surface_kind(params, points, noise, thin_walls);
    if (!needs_smooth_field(kind)) smooth.reset();
    else if (!smooth) smooth = solve_smooth_surface(params, tree, points, measures, noise, pool, solve_progress);
    guide = kind == SurfaceKind::guided_blend ? guide_limit(measures) : INFINITY;
    return gmpu::polygonize(field(params.level), resolution, params, pool, march_progress, noise);
}

int Reconstruction::default_resolution(const Params &params) const {
    // The guided blend's detail is the blend's: its grid too.
    const bool smooth_grid_wanted = surface_kind(params, points, noise, thin_walls) == SurfaceKind::smooth;
    if (blend_grid > 0) return smooth_grid_wanted ? smooth_grid : blend_grid;
    return smooth_grid_wanted ? smooth_resolution(tree, measures) : blend_resolution();
}

int Reconstruction::blend_resolution() const {
    return resolution_within_budget(gmpu::default_resolution(tree, measures), measures, noise, median_leaf_size(tree),
                                    thin_wall_gap(tree));
}

bool Reconstruction::field_matches(const Params &params) const {
    const SurfaceKind current = !smooth                 ? SurfaceKind::blend
                                : std::isfinite(guide) ? SurfaceKind::guided_blend
                                                       : SurfaceKind::smooth;
    return surface_kind(params, points, noise, thin_walls) == current;
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
