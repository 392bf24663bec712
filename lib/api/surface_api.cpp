// The C ABI of gmpu_surface: a state machine over the pipeline's stages
// (points → fitted → oriented), each verb checking that the stage before it is done.
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "api/guard.hpp"
#include "api/handles.hpp"
#include "api/input.hpp"
#include "api/param_table.hpp"
#include "api/statistics.hpp"
#include "api/surface_parts.hpp"
#include "core/parallel.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "core/release_memory.hpp"
#include "fit/build_octree.hpp"
#include "fit/noise_estimate.hpp"
#include "geometry/clusters.hpp"
#include "geometry/outliers.hpp"
#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/surface_field.hpp"
#include "implicit/winding_field.hpp"
#include "mesh/confidence.hpp"
#include "mesh/polygonizer.hpp"
#include "orient/orient.hpp"
#include "orient/orient_memory.hpp"

using gmpu::Error;
using gmpu::api::guarded;
using gmpu::api::require_arg;

struct gmpu_surface {
    enum class Stage { empty, points, fitted, oriented };
    Stage stage = Stage::empty;
    gmpu::Params params;
    gmpu::PointSet points;             // the input points less the outliers
    size_t input_count = 0;            // points given to set_points, outliers included
    std::vector<uint32_t> outliers;        // input indices set aside, increasing
    std::vector<uint32_t> outlier_nearest; // per outlier: the nearest kept point
    std::vector<float> input_normals;  // unit, 3 per point; empty when none were given
    gmpu::Octree tree;
    gmpu::PointMeasures measures;      // oriented normals, areas, trust radii per point
    gmpu::WindingField winding;        // built from the measures; signs far regions
    // Set when the points are spatially separated clusters: then each is a surface of its
    // own, and points, tree, measures and winding above stay empty.
    std::unique_ptr<gmpu::api::SurfaceParts> parts;
    gmpu_progress_fn progress_fn = nullptr;
    void *progress_user = nullptr;
    std::string last_error;
    gmpu::OrientStats orient_stats;
    double seconds[4] = {0, 0, 0, 0};  // by gmpu_stage
    int last_resolution = 0;
    double noise = 0.0, epsilon = 0.0;  // of the last fit, normalised units
    // The stage running on this surface (0 when none). Its progress callback may call back
    // into gmpu; a call on this same surface would free or rebuild what the stage is using,
    // so every such call is refused with BUSY, and destroy is deferred to the stage's end.
    int running_stage = 0;
    bool destroy_when_idle = false;

    void discard_fit() {
        if (stage > Stage::points) stage = Stage::points;
        tree = gmpu::Octree();
        measures = gmpu::PointMeasures();
        winding = gmpu::WindingField();
        orient_stats = {};
    }
    void require_idle(const char *verb) const {
        static const char *const names[] = {"", "gmpu_surface_fit", "gmpu_surface_orient", "gmpu_surface_polygonize"};
        if (running_stage != 0)
            throw Error(GMPU_ERROR_BUSY, std::string(verb) + " was called on a surface whose " +
                                             names[running_stage] +
                                             " is running (from its progress callback); call it after the stage returns");
    }
    void require(Stage needed, const char *verb, const char *missing) const {
        if (stage < needed)
            throw Error(GMPU_ERROR_WRONG_ORDER, std::string(verb) + " needs " + missing + " first");
    }
};

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A long stage (fit, orient, polygonize) behind the exception firewall. Whether it succeeds
// or fails, its temporaries are freed by the time it returns: hand them back to the OS. A
// successful stage did so itself before its final report (finish_stage); a failed one does
// here, except a cancelled one, which the caller wants back at once (the next stage or
// destroy hands the memory back).
template <class Body>
gmpu_status run_stage(gmpu_surface *s, gmpu_stage stage, const char *verb, Body &&body) noexcept {
    if (s && s->running_stage != 0)  // re-entered from the running stage's callback
        return guarded(nullptr, [&] { s->require_idle(verb); });
    if (s) s->running_stage = int(stage);
    gmpu_status status = guarded(s ? &s->last_error : nullptr, std::forward<Body>(body));
    if (s) {
        s->running_stage = 0;
        // The callback destroyed the surface: the stage was cancelled at that report (or had
        // just completed, and its mesh is the caller's); the surface goes now.
        if (s->destroy_when_idle) delete s;
    }
    if (status != GMPU_OK && status != GMPU_ERROR_CANCELLED) gmpu::release_free_memory();
    return status;
}

// Progress that also stops the stage once its surface is to be destroyed.
int progress_or_stop(void *surface, gmpu_stage stage, double fraction) {
    auto *s = static_cast<gmpu_surface *>(surface);
    if (s->destroy_when_idle) return 1;
    const int answer = s->progress_fn ? s->progress_fn(s->progress_user, stage, fraction) : 0;
    return s->destroy_when_idle ? 1 : answer;
}

// The end of a successful stage, before it commits its result. The temporaries are freed by
// now; handing their memory back to the OS can take tens of milliseconds of CPU, so it runs
// on a helper thread while this one keeps reporting (the callback's cadence is the calling
// thread's promise). Then the final report (fraction 1), after which nothing slow follows; a
// cancel on it counts.
void finish_stage(gmpu::Progress &progress) {
    std::atomic<bool> trimmed{false};
    try {
        std::thread trimmer([&] {
            gmpu::release_free_memory();
            trimmed = true;
        });
        while (!trimmed) {
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
            progress.report(0.0);  // repeats the last fraction
        }
        trimmer.join();
    } catch (const std::system_error &) {  // no thread to spare: trim here
        gmpu::release_free_memory();
    }
    progress.report(1.0, true);
    progress.throw_if_cancelled();
}

// The clusters' surfaces take every parameter of their owner's.
void push_params(const gmpu::Params &p, gmpu::api::SurfaceParts &parts) {
    for (int key = 1; key <= gmpu_param_count(); ++key)
        parts.set_param(gmpu_param(key), gmpu::api::get_param(p, gmpu_param(key)));
}

template <class T>
gmpu_status set_points(gmpu_surface *s, const T *xyz, size_t count, size_t stride) {
    return guarded(s ? &s->last_error : nullptr, [&] {
        require_arg(s, "surface");
        s->require_idle("gmpu_surface_set_points");
        gmpu::api::check_array(xyz, count, stride, 3 * sizeof(T), "xyz");
        const size_t min_points = size_t(s->params.min_points);
        gmpu::OutlierScan scan = gmpu::find_outliers(xyz, count, stride);
        const gmpu::Clusters groups = gmpu::find_clusters(xyz, count, stride, scan.outliers, min_points);
        if (groups.count > 1) {
            auto parts = std::make_unique<gmpu::api::SurfaceParts>(groups);
            push_params(s->params, *parts);
            parts->set_points(xyz, count, stride);
            s->discard_fit();
            s->points = gmpu::PointSet();
            s->input_count = count;
            s->outliers.clear();
            s->outlier_nearest.clear();
            s->input_normals.clear();
            s->parts = std::move(parts);
            s->stage = gmpu_surface::Stage::points;
            return;
        }
        gmpu::api::InputPoints in =
            gmpu::api::input_points(xyz, count, stride, min_points, std::move(scan), s->params.remove_outliers);
        s->discard_fit();
        s->parts.reset();
        s->points = std::move(in.points);
        s->input_count = count;
        s->outliers = std::move(in.outliers);
        s->outlier_nearest = std::move(in.nearest);
        s->input_normals.clear();
        s->stage = gmpu_surface::Stage::points;
    });
}

template <class T>
gmpu_status set_normals(gmpu_surface *s, const T *nxyz, size_t count, size_t stride) {
    return guarded(s ? &s->last_error : nullptr, [&] {
        require_arg(s, "surface");
        s->require_idle("gmpu_surface_set_normals");
        s->require(gmpu_surface::Stage::points, "gmpu_surface_set_normals", "gmpu_surface_set_points");
        gmpu::api::check_array(nxyz, count, stride, 3 * sizeof(T), "nxyz");
        if (count != s->input_count)
            throw Error(GMPU_ERROR_INVALID_INPUT, std::to_string(count) + " normals given for " +
                                                      std::to_string(s->input_count) + " points");
        if (s->parts) {
            s->parts->set_normals(nxyz, count, stride);
            if (s->stage > gmpu_surface::Stage::fitted) s->stage = gmpu_surface::Stage::fitted;
            return;
        }
        std::vector<float> unit = gmpu::api::unit_normals(nxyz, count, stride, s->outliers);
        s->input_normals.swap(unit);
        if (s->stage > gmpu_surface::Stage::fitted) s->stage = gmpu_surface::Stage::fitted;
    });
}

}  // namespace

extern "C" {

GMPU_API gmpu_status gmpu_surface_create(gmpu_surface **out) {
    return guarded(nullptr, [&] {
        require_arg(out, "out");
        *out = nullptr;
        *out = new gmpu_surface();
    });
}

GMPU_API void gmpu_surface_destroy(gmpu_surface *s) {
    if (!s) return;
    if (s->running_stage != 0) {  // from the stage's own callback: run_stage deletes it
        s->destroy_when_idle = true;
        return;
    }
    delete s;
    gmpu::release_free_memory();
}

GMPU_API const char *gmpu_surface_last_error(const gmpu_surface *s) { return s ? s->last_error.c_str() : ""; }

GMPU_API gmpu_status gmpu_surface_set_param(gmpu_surface *s, gmpu_param key, double value) {
    return guarded(s ? &s->last_error : nullptr, [&] {
        require_arg(s, "surface");
        s->require_idle("gmpu_surface_set_param");
        gmpu::api::check_param_key(key);
        gmpu::Params p = s->params;
        gmpu::api::set_param(p, key, value);
        if (gmpu::api::param_refits(key) && gmpu::api::get_param(p, key) != gmpu::api::get_param(s->params, key))
            s->discard_fit();
        s->params = p;
    });
}

GMPU_API gmpu_status gmpu_surface_get_param(const gmpu_surface *s, gmpu_param key, double *value) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        require_arg(value, "value");
        s->require_idle("gmpu_surface_get_param");
        gmpu::api::check_param_key(key);
        *value = gmpu::api::get_param(s->params, key);
    });
}

GMPU_API gmpu_status gmpu_surface_get_stat(const gmpu_surface *s, gmpu_stat key, double *value) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        require_arg(value, "value");
        s->require_idle("gmpu_surface_get_stat");
        gmpu::api::check_stat_key(key);
        if (s->parts && key != GMPU_STAT_POINTS && key != GMPU_STAT_FIT_SECONDS && key != GMPU_STAT_ORIENT_SECONDS &&
            key != GMPU_STAT_POLYGONIZE_SECONDS) {
            *value = s->parts->stat(key);
            return;
        }
        const gmpu::api::StatSources from{s->input_count,   s->points,  s->stage >= gmpu_surface::Stage::fitted,
                                          s->tree,          s->orient_stats,
                                          s->seconds,       s->last_resolution,
                                          s->noise,         s->epsilon};
        *value = gmpu::api::statistic(key, from);
    });
}

GMPU_API gmpu_status gmpu_surface_set_progress(gmpu_surface *s, gmpu_progress_fn fn, void *user) {
    return guarded(s ? &s->last_error : nullptr, [&] {
        require_arg(s, "surface");
        s->require_idle("gmpu_surface_set_progress");
        s->progress_fn = fn;
        s->progress_user = user;
    });
}

GMPU_API gmpu_status gmpu_surface_set_points_f64(gmpu_surface *s, const double *xyz, size_t count, size_t stride) {
    return set_points(s, xyz, count, stride);
}
GMPU_API gmpu_status gmpu_surface_set_points_f32(gmpu_surface *s, const float *xyz, size_t count, size_t stride) {
    return set_points(s, xyz, count, stride);
}
GMPU_API gmpu_status gmpu_surface_set_normals_f64(gmpu_surface *s, const double *n, size_t count, size_t stride) {
    return set_normals(s, n, count, stride);
}
GMPU_API gmpu_status gmpu_surface_set_normals_f32(gmpu_surface *s, const float *n, size_t count, size_t stride) {
    return set_normals(s, n, count, stride);
}

GMPU_API size_t gmpu_surface_point_count(const gmpu_surface *s) { return s ? s->input_count : 0; }

GMPU_API gmpu_status gmpu_surface_fit(gmpu_surface *s) {
    return run_stage(s, GMPU_STAGE_FIT, "gmpu_surface_fit", [&] {
        require_arg(s, "surface");
        s->require(gmpu_surface::Stage::points, "gmpu_surface_fit", "gmpu_surface_set_points");
        auto t0 = Clock::now();
        gmpu::Progress progress(s->progress_fn ? progress_or_stop : nullptr, s, GMPU_STAGE_FIT);
        progress.report(0.0, true);
        if (s->parts) {
            // Each cluster's fit replaces its own as it goes: until all are done, the
            // clusters do not share one fit, so a failed or cancelled fit leaves none.
            s->discard_fit();
            push_params(s->params, *s->parts);
            s->parts->fit(progress_or_stop, s);
            progress.report(1.0, true);
            progress.throw_if_cancelled();
            s->stage = gmpu_surface::Stage::fitted;
            s->seconds[GMPU_STAGE_FIT] = since(t0);
            return;
        }
        const double noise = gmpu::estimate_noise(s->points, progress);
        const double epsilon = gmpu::effective_epsilon(s->points, s->params, noise);
        gmpu::Octree tree = gmpu::build_octree(s->points, s->params, epsilon, progress);
        finish_stage(progress);
        s->discard_fit();
        s->tree = std::move(tree);
        s->noise = noise;
        s->epsilon = epsilon;
        s->stage = gmpu_surface::Stage::fitted;
        s->seconds[GMPU_STAGE_FIT] = since(t0);
    });
}

GMPU_API gmpu_status gmpu_surface_orient(gmpu_surface *s) {
    return run_stage(s, GMPU_STAGE_ORIENT, "gmpu_surface_orient", [&] {
        require_arg(s, "surface");
        s->require(gmpu_surface::Stage::fitted, "gmpu_surface_orient", "gmpu_surface_fit");
        auto t0 = Clock::now();
        gmpu::Progress progress(s->progress_fn ? progress_or_stop : nullptr, s, GMPU_STAGE_ORIENT);
        progress.report(0.0, true);
        // Orient only writes the cells' signs and resets them first, so a cancelled or failed
        // orient leaves a fit that the next orient can use as it is.
        s->stage = gmpu_surface::Stage::fitted;
        if (s->parts) {
            push_params(s->params, *s->parts);
            s->parts->orient(progress_or_stop, s);
            progress.report(1.0, true);
            progress.throw_if_cancelled();
            s->stage = gmpu_surface::Stage::oriented;
            s->seconds[GMPU_STAGE_ORIENT] = since(t0);
            return;
        }
        s->winding = gmpu::WindingField();
        gmpu::check_orient_memory(s->tree, s->points, s->params.max_memory);
        gmpu::Octree &tree = s->tree;
        gmpu::OrientStats stats = gmpu::orient_octree(
            tree, s->points, s->input_normals.empty() ? nullptr : s->input_normals.data(), s->params, progress);
        gmpu::MpuFunction f(tree, 0);
        const unsigned threads = gmpu::resolve_threads(s->params.threads);
        gmpu::PointMeasures measures;
        measures.normals = gmpu::point_normals(f, s->points, threads, progress,
                                               0.9 * double(s->points.size()) / 0.05,
                                               double(s->points.size()) / 0.05);
        gmpu::measure_points(tree, s->points, threads, progress, measures);
        s->measures = std::move(measures);
        s->winding = gmpu::WindingField(tree, s->points, s->measures.normals, s->measures.area, &progress);
        finish_stage(progress);
        s->orient_stats = stats;
        s->stage = gmpu_surface::Stage::oriented;
        s->seconds[GMPU_STAGE_ORIENT] = since(t0);
    });
}

GMPU_API gmpu_status gmpu_surface_evaluate(const gmpu_surface *s, const double *xyz, size_t count, double *values,
                                           double *gradients) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        if (count > 0) require_arg(xyz, "xyz");
        if (!values && !gradients) throw Error(GMPU_ERROR_INVALID_ARGUMENT, "values and gradients are both NULL");
        s->require_idle("gmpu_surface_evaluate");
        if (count > std::numeric_limits<size_t>::max() / (3 * sizeof(double)))
            throw Error(GMPU_ERROR_INVALID_ARGUMENT, "count " + std::to_string(count) +
                                                         " is too large: 3 × count doubles do not fit in memory");
        s->require(gmpu_surface::Stage::oriented, "gmpu_surface_evaluate", "gmpu_surface_orient");
        for (size_t i = 0; i < 3 * count; ++i)
            if (!std::isfinite(xyz[i]))
                throw Error(GMPU_ERROR_INVALID_INPUT, "query point " + std::to_string(i / 3) + " is NaN or infinite");
        if (s->parts) return s->parts->evaluate(xyz, count, values, gradients);
        const gmpu::MpuFunction mpu(s->tree, s->params.level);
        const gmpu::SurfaceField f(mpu, s->points, s->measures, s->winding);
        const gmpu::Normalisation &norm = s->points.normalisation();
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
    });
}

GMPU_API gmpu_status gmpu_surface_copy_normals(const gmpu_surface *s, double *out, size_t count) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        require_arg(out, "out");
        s->require_idle("gmpu_surface_copy_normals");
        s->require(gmpu_surface::Stage::oriented, "gmpu_surface_copy_normals", "gmpu_surface_orient");
        if (count != s->input_count)
            throw Error(GMPU_ERROR_INVALID_ARGUMENT, "count " + std::to_string(count) + " differs from the " +
                                                         std::to_string(s->input_count) + " points");
        if (s->parts) return s->parts->copy_normals(out, count);
        // An outlier takes the normal of the kept point nearest to it.
        size_t next_outlier = 0, kept = 0;
        for (size_t i = 0; i < count; ++i) {
            size_t from;
            if (next_outlier < s->outliers.size() && s->outliers[next_outlier] == i)
                from = s->outlier_nearest[next_outlier++];
            else
                from = kept++;
            for (int d = 0; d < 3; ++d) out[3 * i + d] = double(s->measures.normals[3 * from + d]);
        }
    });
}

GMPU_API gmpu_status gmpu_surface_polygonize(gmpu_surface *s, gmpu_mesh **out) {
    return run_stage(s, GMPU_STAGE_POLYGONIZE, "gmpu_surface_polygonize", [&] {
        require_arg(s, "surface");
        require_arg(out, "out");
        *out = nullptr;
        s->require(gmpu_surface::Stage::oriented, "gmpu_surface_polygonize", "gmpu_surface_orient");
        auto t0 = Clock::now();
        gmpu::Progress progress(s->progress_fn ? progress_or_stop : nullptr, s, GMPU_STAGE_POLYGONIZE);
        progress.report(0.0, true);
        if (s->parts) {
            push_params(s->params, *s->parts);
            auto mesh = std::make_unique<gmpu_mesh>();
            mesh->mesh = s->parts->polygonize(progress_or_stop, s);
            if (double(mesh->mesh.triangle_count()) > s->params.max_triangles)
                throw Error(GMPU_ERROR_LIMIT_EXCEEDED, "the clusters' meshes have " +
                                                           std::to_string(mesh->mesh.triangle_count()) +
                                                           " triangles together, over GMPU_PARAM_MAX_TRIANGLES");
            progress.report(1.0, true);
            progress.throw_if_cancelled();
            s->last_resolution = int(s->parts->stat(GMPU_STAT_RESOLUTION));
            s->seconds[GMPU_STAGE_POLYGONIZE] = since(t0);
            *out = mesh.release();
            return;
        }
        int resolution = s->params.resolution > 0 ? s->params.resolution : gmpu::default_resolution(s->tree);
        const gmpu::MpuFunction mpu(s->tree, s->params.level);
        auto mesh = std::make_unique<gmpu_mesh>();
        mesh->mesh = gmpu::polygonize(mpu, s->winding, s->points, s->measures, resolution, s->params, progress);
        if (mesh->mesh.triangle_count() == 0)
            throw Error(GMPU_ERROR_DEGENERATE_INPUT,
                        "polygonize found no closed surface at resolution " + std::to_string(resolution) +
                            " (no piece of the zero set is near enough input points): the points may be "
                            "too few or too sparse for a solid, or the grid too coarse for them");
        gmpu::compute_confidence(mesh->mesh, s->points, s->measures, s->params.threads, progress);
        finish_stage(progress);
        s->last_resolution = resolution;
        s->seconds[GMPU_STAGE_POLYGONIZE] = since(t0);
        *out = mesh.release();
    });
}

}  // extern "C"
