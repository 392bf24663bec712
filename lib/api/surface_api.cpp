// The C ABI of gmpu_surface: a state machine over the pipeline's stages
// (points → fitted → oriented), each verb checking that the stage before it is done.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "api/guard.hpp"
#include "api/handles.hpp"
#include "api/input.hpp"
#include "api/param_table.hpp"
#include "api/statistics.hpp"
#include "api/surface_parts.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/clusters.hpp"
#include "geometry/outliers.hpp"
#include "geometry/point_set.hpp"
#include "mesh/confidence.hpp"
#include "mesh/polygonizer.hpp"
#include "orient/orient_memory.hpp"
#include "pipeline/reconstruction.hpp"

using gmpu::Error;
using gmpu::api::guarded;
using gmpu::api::require_arg;

// The handle is the reconstruction (lib/pipeline) plus what the ABI keeps around it: the
// parameters, the stage reached, the progress callback, the last error and the timings.
struct gmpu_surface : gmpu::Reconstruction {
    enum class Stage { empty, points, fitted, oriented };
    Stage stage = Stage::empty;
    gmpu::Params params;
    // Set when the points are spatially separated clusters: then each is a surface of its
    // own, and the reconstruction's points, tree, measures and winding stay empty.
    std::unique_ptr<gmpu::api::SurfaceParts> parts;
    gmpu_progress_fn progress_fn = nullptr;
    void *progress_user = nullptr;
    std::string last_error;
    double seconds[4] = {0, 0, 0, 0};  // by gmpu_stage
    int last_resolution = 0;
    // The stage running on this surface (0 when none). Its progress callback may call back
    // into gmpu; a call on this same surface would free or rebuild what the stage is using,
    // so every such call is refused with BUSY, and destroy is deferred to the stage's end.
    int running_stage = 0;
    bool destroy_when_idle = false;

    void discard_fit() {
        if (stage > Stage::points) stage = Stage::points;
        gmpu::Reconstruction::discard_fit();
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

// A long stage (fit, orient, polygonize) behind the exception firewall.
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
    return status;
}

// Progress that also stops the stage once its surface is to be destroyed.
int progress_or_stop(void *surface, gmpu_stage stage, double fraction) {
    auto *s = static_cast<gmpu_surface *>(surface);
    if (s->destroy_when_idle) return 1;
    const int answer = s->progress_fn ? s->progress_fn(s->progress_user, stage, fraction) : 0;
    return s->destroy_when_idle ? 1 : answer;
}

// The clusters' surfaces take every parameter of their owner's.
void push_params(const gmpu::Params &p, gmpu::api::SurfaceParts &parts) {
    for (int key = 1; key <= gmpu_param_count(); ++key)
        parts.set_param(gmpu_param(key), gmpu::api::get_param(p, gmpu_param(key)));
}

// The kept point whose normal input point i takes, `before` being the number of outliers
// before i: kept points are numbered without them, and an outlier takes the normal of the
// kept point nearest to it.
size_t normal_source(const gmpu_surface &s, size_t i, size_t before) {
    return before < s.outliers.size() && s.outliers[before] == i ? s.outlier_nearest[before] : i - before;
}

template <class T>
gmpu_status set_points(gmpu_surface *s, const T *xyz, size_t count, size_t stride) {
    return guarded(s ? &s->last_error : nullptr, [&] {
        require_arg(s, "surface");
        s->require_idle("gmpu_surface_set_points");
        gmpu::api::check_array(xyz, count, stride, 3 * sizeof(T), "xyz");
        const size_t min_points = size_t(s->params.min_points);
        gmpu::Workers &workers = s->workers(unsigned(s->params.threads));
        gmpu::OutlierScan scan = gmpu::find_outliers(xyz, count, stride, true, &workers);
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
            gmpu::api::input_points(xyz, count, stride, min_points, std::move(scan), s->params.remove_outliers,
                                    &workers);
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
        if (s->parts) {
            // Each cluster's fit replaces its own as it goes: until all are done, the
            // clusters do not share one fit, so a failed or cancelled fit leaves none.
            progress.report(0.0, true);
            s->discard_fit();
            push_params(s->params, *s->parts);
            s->parts->fit(progress_or_stop, s);
            progress.report(1.0, true);
            progress.throw_if_cancelled();
            s->stage = gmpu_surface::Stage::fitted;
            s->seconds[GMPU_STAGE_FIT] = since(t0);
            return;
        }
        s->fit(s->params, progress);
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
        s->stage = gmpu_surface::Stage::fitted;  // until this orient completes
        if (s->parts) {
            progress.report(0.0, true);
            push_params(s->params, *s->parts);
            s->parts->orient(progress_or_stop, s);
            progress.report(1.0, true);
            progress.throw_if_cancelled();
            s->stage = gmpu_surface::Stage::oriented;
            s->seconds[GMPU_STAGE_ORIENT] = since(t0);
            return;
        }
        gmpu::check_orient_memory(s->tree, s->points, s->params.max_memory);
        s->orient(s->params, progress);
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
        // Evaluate may run on several threads at once, so it cannot solve or drop the smooth
        // field itself; answering from the other surface would be silently wrong.
        if (!s->field_matches(s->params))
            throw Error(GMPU_ERROR_WRONG_ORDER,
                        "gmpu_surface_evaluate: GMPU_PARAM_SURFACE changed since the surface was made; call "
                        "gmpu_surface_polygonize or gmpu_surface_orient first");
        s->evaluate(s->params, xyz, count, values, gradients);
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
        size_t before = 0;  // outliers before point i
        for (size_t i = 0; i < count; ++i) {
            while (before < s->outliers.size() && s->outliers[before] < i) ++before;
            const size_t from = normal_source(*s, i, before);
            for (int d = 0; d < 3; ++d) out[3 * i + d] = double(s->measures.normals[3 * from + d]);
        }
    });
}

GMPU_API gmpu_status gmpu_surface_copy_normals_at(const gmpu_surface *s, const int64_t *indices, size_t count,
                                                  double *out) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        if (count > 0) {
            require_arg(indices, "indices");
            require_arg(out, "out");
        }
        s->require_idle("gmpu_surface_copy_normals_at");
        s->require(gmpu_surface::Stage::oriented, "gmpu_surface_copy_normals_at", "gmpu_surface_orient");
        for (size_t j = 0; j < count; ++j)
            if (indices[j] < 0 || uint64_t(indices[j]) >= s->input_count)
                throw Error(GMPU_ERROR_INVALID_ARGUMENT, "indices[" + std::to_string(j) + "] = " +
                                                             std::to_string(indices[j]) + " is not a point: there are " +
                                                             std::to_string(s->input_count) + " points");
        if (s->parts) return s->parts->copy_normals_at(indices, count, out);
        for (size_t j = 0; j < count; ++j) {
            const auto i = uint32_t(indices[j]);
            const auto before = std::lower_bound(s->outliers.begin(), s->outliers.end(), i);
            const size_t from = normal_source(*s, i, size_t(before - s->outliers.begin()));
            for (int d = 0; d < 3; ++d) out[3 * j + d] = double(s->measures.normals[3 * from + d]);
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
        int resolution = s->params.resolution > 0 ? s->params.resolution : s->default_resolution(s->params);
        // The steps' shares of the stage's progress.
        gmpu::Progress mesh_progress = progress.slice(0.0, 0.95), confidence_progress = progress.slice(0.95, 1.0);
        auto mesh = std::make_unique<gmpu_mesh>();
        double made_at_orient = 0.0;  // the mesh orient made for its stray test, handed out here
        mesh->mesh = s->polygonize(s->params, resolution, mesh_progress, &made_at_orient);
        if (mesh->mesh.triangle_count() == 0)
            throw Error(GMPU_ERROR_DEGENERATE_INPUT,
                        "polygonize found no closed surface at resolution " + std::to_string(resolution) +
                            " (no piece of the zero set is near enough input points): the points may be "
                            "too few or too sparse for a solid, or the grid too coarse for them");
        if (mesh->mesh.confidence.size() != mesh->mesh.vertex_count())
            gmpu::compute_confidence(mesh->mesh, s->points, s->measures, s->workers(s->params.threads),
                                    confidence_progress);
        progress.report(1.0, true);  // the final report; a cancel on it counts
        progress.throw_if_cancelled();
        s->last_resolution = resolution;
        // Its time counts as polygonize's, where the mesh is wanted, not orient's.
        s->seconds[GMPU_STAGE_POLYGONIZE] = since(t0) + made_at_orient;
        s->seconds[GMPU_STAGE_ORIENT] = std::max(0.0, s->seconds[GMPU_STAGE_ORIENT] - made_at_orient);
        *out = mesh.release();
    });
}

}  // extern "C"
