// The C ABI of gmpu_surface: a state machine over the pipeline's stages
// (points → fitted → oriented), each verb checking that the stage before it is done.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "api/guard.hpp"
#include "api/handles.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/outliers.hpp"
#include "geometry/point_set.hpp"
#include "mesh/polygonizer.hpp"
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

struct ParamSpec {
    double lo, hi;
    bool integer;
    bool refits;  // changing it discards the fit
    const char *name;
};

// Unknown keys are rejected as ints, before the enum is loaded (see enum_int).
void check_key(const gmpu_param &key) {
    const int v = gmpu::api::enum_int(key);
    if (v < GMPU_PARAM_ERROR || v > GMPU_PARAM_MAX_MEMORY)  // the first and the last key
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key " + std::to_string(v));
}
void check_key(const gmpu_stat &key) {
    const int v = gmpu::api::enum_int(key);
    if (v < GMPU_STAT_POINTS || v > GMPU_STAT_OUTLIERS)  // the first and the last key
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown statistic key " + std::to_string(v));
}

ParamSpec spec(gmpu_param key) {
    switch (key) {
        case GMPU_PARAM_ERROR: return {0.0, 1.0, false, true, "GMPU_PARAM_ERROR"};
        case GMPU_PARAM_MAX_DEPTH: return {1, gmpu::kMaxDepth, true, true, "GMPU_PARAM_MAX_DEPTH"};
        case GMPU_PARAM_MIN_POINTS: return {6, 1000, true, true, "GMPU_PARAM_MIN_POINTS"};
        case GMPU_PARAM_SUPPORT_SCALE: return {0.5, 2.0, false, true, "GMPU_PARAM_SUPPORT_SCALE"};
        case GMPU_PARAM_SHARP_FEATURES: return {0, 1, true, true, "GMPU_PARAM_SHARP_FEATURES"};
        case GMPU_PARAM_RESOLUTION: return {0, 4096, true, false, "GMPU_PARAM_RESOLUTION"};
        case GMPU_PARAM_LEVEL: return {0, gmpu::kMaxDepth, true, false, "GMPU_PARAM_LEVEL"};
        case GMPU_PARAM_THREADS: return {0, 1024, true, false, "GMPU_PARAM_THREADS"};
        case GMPU_PARAM_MAX_CELLS: return {1, 1e9, true, true, "GMPU_PARAM_MAX_CELLS"};
        case GMPU_PARAM_MAX_TRIANGLES: return {1, 2e9, true, false, "GMPU_PARAM_MAX_TRIANGLES"};
        case GMPU_PARAM_NOISE_SCALE: return {0, 20, false, true, "GMPU_PARAM_NOISE_SCALE"};
        case GMPU_PARAM_MAX_MEMORY: return {1e6, 1e15, true, false, "GMPU_PARAM_MAX_MEMORY"};
    }
    throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key " + std::to_string(int(key)));
}

double *param_slot(gmpu::Params &p, gmpu_param key, double &scratch) {
    switch (key) {
        case GMPU_PARAM_ERROR: return &p.error;
        case GMPU_PARAM_SUPPORT_SCALE: return &p.support_scale;
        case GMPU_PARAM_MAX_CELLS: return &p.max_cells;
        case GMPU_PARAM_MAX_TRIANGLES: return &p.max_triangles;
        case GMPU_PARAM_NOISE_SCALE: return &p.noise_scale;
        case GMPU_PARAM_MAX_MEMORY: return &p.max_memory;
        default: return &scratch;  // integer-valued: converted by the caller
    }
}

double get_param(const gmpu::Params &p, gmpu_param key) {
    switch (key) {
        case GMPU_PARAM_ERROR: return p.error;
        case GMPU_PARAM_MAX_DEPTH: return p.max_depth;
        case GMPU_PARAM_MIN_POINTS: return p.min_points;
        case GMPU_PARAM_SUPPORT_SCALE: return p.support_scale;
        case GMPU_PARAM_SHARP_FEATURES: return p.sharp_features ? 1 : 0;
        case GMPU_PARAM_RESOLUTION: return p.resolution;
        case GMPU_PARAM_LEVEL: return p.level;
        case GMPU_PARAM_THREADS: return p.threads;
        case GMPU_PARAM_MAX_CELLS: return p.max_cells;
        case GMPU_PARAM_MAX_TRIANGLES: return p.max_triangles;
        case GMPU_PARAM_NOISE_SCALE: return p.noise_scale;
        case GMPU_PARAM_MAX_MEMORY: return p.max_memory;
    }
    throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key " + std::to_string(int(key)));
}

// Shortest exact-enough text for a parameter value ("16", "0.002", "1e+09").
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

void set_param(gmpu::Params &p, gmpu_param key, double value) {
    ParamSpec s = spec(key);
    bool open_low = key == GMPU_PARAM_ERROR;  // ε must be positive
    if (!std::isfinite(value) || value < s.lo || value > s.hi || (open_low && value <= s.lo) ||
        (key == GMPU_PARAM_ERROR && value >= s.hi) || (s.integer && value != std::floor(value)))
        throw Error(GMPU_ERROR_INVALID_ARGUMENT,
                    std::string(s.name) + " = " + number(value) + " is out of range: expected " +
                        (s.integer ? "an integer " : "a number ") + (open_low ? "in (" : "in [") +
                        number(s.lo) + ", " + number(s.hi) + (key == GMPU_PARAM_ERROR ? ")" : "]"));
    if (key == GMPU_PARAM_RESOLUTION && value > 0 && value < 8)
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "GMPU_PARAM_RESOLUTION must be 0 (automatic) or 8..4096");
    double scratch = 0;
    *param_slot(p, key, scratch) = value;
    switch (key) {
        case GMPU_PARAM_MAX_DEPTH: p.max_depth = int(value); break;
        case GMPU_PARAM_MIN_POINTS: p.min_points = int(value); break;
        case GMPU_PARAM_SHARP_FEATURES: p.sharp_features = value != 0; break;
        case GMPU_PARAM_RESOLUTION: p.resolution = int(value); break;
        case GMPU_PARAM_LEVEL: p.level = int(value); break;
        case GMPU_PARAM_THREADS: p.threads = unsigned(value); break;
        default: break;
    }
}

void check_array(const void *data, size_t count, size_t stride, size_t element, const char *what) {
    require_arg(data, what);
    if (stride != 0 && stride < element)
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, std::string(what) + " stride " + std::to_string(stride) +
                                                     " is smaller than one point (" + std::to_string(element) +
                                                     " bytes)");
    size_t s = stride ? stride : element;
    // The last point ends at (count - 1) × stride + element bytes: that must be addressable.
    if (count > 0 && (count - 1 > (std::numeric_limits<size_t>::max() - element) / s ||
                      count > std::numeric_limits<uint32_t>::max() / 4))
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, std::string(what) + ": too many points");
}

Error clusters(const gmpu::OutlierScan &scan) {
    return Error(GMPU_ERROR_INVALID_INPUT, "the points are spaced " + number(scan.spacing) +
                                               " apart over an extent of " + number(scan.extent) +
                                               ": clusters this far apart cannot share one surface's scale; "
                                               "reconstruct each cluster on its own surface");
}

// The points as given; when they look collinear or coplanar, says so unless they are
// far-apart clusters (which look so from afar).
template <class T>
gmpu::PointSet points_or_clusters(const T *xyz, size_t count, size_t stride, size_t min_points) {
    try {
        return gmpu::PointSet::from_array(xyz, count, stride, min_points);
    } catch (const Error &e) {
        if (e.status() != GMPU_ERROR_DEGENERATE_INPUT) throw;
        const gmpu::OutlierScan full = gmpu::find_outliers(xyz, count, stride, false);
        if (full.spacing > 0.0 && full.spacing < 1e-6 * full.extent) throw clusters(full);
        throw;
    }
}

// The points less the outliers: the scale comes from them, and only they join the fits.
// nearest[k]: the kept point nearest to outlier k (its normal stands in for the outlier's).
template <class T>
gmpu::PointSet kept_points(const T *xyz, size_t count, size_t stride, size_t min_points,
                           const std::vector<uint32_t> &outliers, std::vector<uint32_t> &nearest) {
    const size_t step = stride ? stride : 3 * sizeof(T);
    const auto *bytes = reinterpret_cast<const unsigned char *>(xyz);
    auto read = [&](size_t i, T v[3]) { std::memcpy(v, bytes + i * step, 3 * sizeof(T)); };
    std::vector<T> kept;
    kept.reserve(3 * (count - outliers.size()));
    size_t next = 0;
    for (size_t i = 0; i < count; ++i) {
        if (next < outliers.size() && outliers[next] == i) {
            ++next;
            continue;
        }
        T v[3];
        read(i, v);
        kept.insert(kept.end(), v, v + 3);
    }
    gmpu::PointSet points = gmpu::PointSet::from_array(kept.data(), kept.size() / 3, 0, min_points);
    points.set_outlier_count(outliers.size());
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    for (uint32_t o : outliers) {
        T v[3];
        read(o, v);
        const Eigen::Vector3d q = points.normalisation().to_unit({double(v[0]), double(v[1]), double(v[2])});
        points.nearest(q.cwiseMax(-1e15).cwiseMin(1e15), 1, idx, d2);
        nearest.push_back(idx.empty() ? 0 : idx[0]);
    }
    return points;
}

template <class T>
gmpu_status set_points(gmpu_surface *s, const T *xyz, size_t count, size_t stride) {
    return guarded(s ? &s->last_error : nullptr, [&] {
        require_arg(s, "surface");
        s->require_idle("gmpu_surface_set_points");
        check_array(xyz, count, stride, 3 * sizeof(T), "xyz");
        const size_t min_points = size_t(s->params.min_points);
        gmpu::OutlierScan scan = gmpu::find_outliers(xyz, count, stride);
        // The points' own spacing, not their bounding box, is the scale of the detail: one
        // octree in float coordinates resolves about a millionth of the extent.
        if (scan.spacing > 0.0 && scan.spacing < 1e-6 * scan.extent) throw clusters(scan);
        std::vector<uint32_t> nearest;
        gmpu::PointSet points = scan.outliers.empty() ? points_or_clusters(xyz, count, stride, min_points)
                                                      : kept_points(xyz, count, stride, min_points, scan.outliers, nearest);
        s->discard_fit();
        s->points = std::move(points);
        s->input_count = count;
        s->outliers = std::move(scan.outliers);
        s->outlier_nearest = std::move(nearest);
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
        check_array(nxyz, count, stride, 3 * sizeof(T), "nxyz");
        if (count != s->input_count)
            throw Error(GMPU_ERROR_INVALID_INPUT, std::to_string(count) + " normals given for " +
                                                      std::to_string(s->input_count) + " points");
        if (stride == 0) stride = 3 * sizeof(T);
        std::vector<float> unit;
        unit.reserve(3 * s->points.size());
        size_t next_outlier = 0;
        const auto *bytes = reinterpret_cast<const unsigned char *>(nxyz);
        for (size_t i = 0; i < count; ++i) {
            T v[3];
            std::memcpy(v, bytes + i * stride, sizeof v);
            Eigen::Vector3d n{double(v[0]), double(v[1]), double(v[2])};
            if (!n.allFinite())
                throw Error(GMPU_ERROR_INVALID_INPUT, "normal " + std::to_string(i) + " is NaN or infinite");
            // Only the direction matters: divide by the largest component first, so that
            // squaring neither underflows (1e-320) nor overflows (1e200).
            const double largest = n.cwiseAbs().maxCoeff();
            if (!(largest > 0.0))
                throw Error(GMPU_ERROR_INVALID_INPUT, "normal " + std::to_string(i) + " is zero");
            n /= largest;
            n /= n.norm();
            if (next_outlier < s->outliers.size() && s->outliers[next_outlier] == i) {
                ++next_outlier;  // validated like the others, but no fit is near it
                continue;
            }
            for (int d = 0; d < 3; ++d) unit.push_back(float(n[d]));
        }
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
        check_key(key);
        gmpu::Params p = s->params;
        set_param(p, key, value);
        if (spec(key).refits && get_param(p, key) != get_param(s->params, key)) s->discard_fit();
        s->params = p;
    });
}

GMPU_API gmpu_status gmpu_surface_get_param(const gmpu_surface *s, gmpu_param key, double *value) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        require_arg(value, "value");
        s->require_idle("gmpu_surface_get_param");
        check_key(key);
        *value = get_param(s->params, key);
    });
}

GMPU_API gmpu_status gmpu_surface_get_stat(const gmpu_surface *s, gmpu_stat key, double *value) {
    return guarded(nullptr, [&] {
        require_arg(s, "surface");
        require_arg(value, "value");
        s->require_idle("gmpu_surface_get_stat");
        check_key(key);
        const auto &cells = s->tree.cells;
        auto leaves_where = [&](auto pred) {
            double n = 0;
            for (const auto &c : cells) n += c.is_leaf() && pred(c);
            return n;
        };
        switch (key) {
            case GMPU_STAT_POINTS: *value = double(s->input_count); break;
            case GMPU_STAT_CELLS: *value = double(cells.size()); break;
            case GMPU_STAT_LEAVES: *value = leaves_where([](const gmpu::Cell &) { return true; }); break;
            case GMPU_STAT_DEPTH: {
                int d = 0;
                for (const auto &c : cells) d = std::max<int>(d, c.depth);
                *value = d;
                break;
            }
            case GMPU_STAT_QUADRIC_CELLS:
                *value = leaves_where([](const gmpu::Cell &c) { return c.shape.model == gmpu::Model::quadric; });
                break;
            case GMPU_STAT_BIVARIATE_CELLS:
                *value = leaves_where([](const gmpu::Cell &c) { return c.shape.model == gmpu::Model::bivariate; });
                break;
            case GMPU_STAT_PIECEWISE_CELLS:
                *value = leaves_where([](const gmpu::Cell &c) {
                    return c.shape.model == gmpu::Model::edge || c.shape.model == gmpu::Model::corner;
                });
                break;
            case GMPU_STAT_COMPONENTS: *value = s->orient_stats.components; break;
            case GMPU_STAT_FLIPPED_CELLS: *value = s->orient_stats.flipped_leaves; break;
            case GMPU_STAT_FIT_SECONDS: *value = s->seconds[GMPU_STAGE_FIT]; break;
            case GMPU_STAT_ORIENT_SECONDS: *value = s->seconds[GMPU_STAGE_ORIENT]; break;
            case GMPU_STAT_POLYGONIZE_SECONDS: *value = s->seconds[GMPU_STAGE_POLYGONIZE]; break;
            case GMPU_STAT_RESOLUTION: *value = s->last_resolution; break;
            case GMPU_STAT_OUTLIERS: *value = double(s->points.outlier_count()); break;
            case GMPU_STAT_BBOX_DIAGONAL: *value = s->points.empty() ? 0.0 : s->points.world_diagonal(); break;
            case GMPU_STAT_NOISE:
            case GMPU_STAT_EFFECTIVE_ERROR: {
                // Normalised units → fraction of the diagonal.
                double diag = s->points.empty() ? 0.0 : s->points.world_diagonal() * s->points.normalisation().scale;
                double v = key == GMPU_STAT_NOISE ? s->noise : s->epsilon;
                *value = diag > 0.0 && s->stage >= gmpu_surface::Stage::fitted ? v / diag : 0.0;
                break;
            }
            default: throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown statistic key " + std::to_string(int(key)));
        }
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
        int resolution = s->params.resolution > 0 ? s->params.resolution : gmpu::default_resolution(s->tree);
        auto mesh = std::make_unique<gmpu_mesh>();
        mesh->mesh = s->polygonize(s->params, resolution, progress);
        if (mesh->mesh.triangle_count() == 0)
            throw Error(GMPU_ERROR_DEGENERATE_INPUT,
                        "polygonize found no closed surface at resolution " + std::to_string(resolution) +
                            " (no piece of the zero set is near enough input points): the points may be "
                            "too few or too sparse for a solid, or the grid too coarse for them");
        progress.report(1.0, true);  // the final report; a cancel on it counts
        progress.throw_if_cancelled();
        s->last_resolution = resolution;
        s->seconds[GMPU_STAGE_POLYGONIZE] = since(t0);
        *out = mesh.release();
    });
}

}  // extern "C"
