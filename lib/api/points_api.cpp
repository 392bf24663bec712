// C ABI of point sets: read from a file or built from caller arrays, queried, written.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "api/guard.hpp"
#include "api/handles.hpp"
#include "core/progress.hpp"
#include "gmpu/gmpu.h"
#include "io/io.hpp"

namespace {

using gmpu::Error;

// Copies count × 3 doubles, rejecting non-finite values with their index.
void copy_finite(std::vector<double> &dst, const double *src, size_t count, const char *what) {
    dst.assign(src, src + 3 * count);
    for (size_t i = 0; i < dst.size(); ++i)
        if (!std::isfinite(dst[i]))
            throw Error(GMPU_ERROR_INVALID_INPUT,
                        std::string(what) + " of point " + std::to_string(i / 3) + " is not finite");
}

}  // namespace

extern "C" {

GMPU_API gmpu_status gmpu_points_read_with(const char *path, double max_memory, gmpu_progress_fn fn, void *user,
                                           gmpu_points **out) {
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        gmpu::api::require_arg(path, "path");
        if (!(max_memory == 0.0 || (max_memory >= 1e6 && max_memory <= 1e15)))
            throw Error(GMPU_ERROR_INVALID_ARGUMENT,
                        "max_memory = " + std::to_string(max_memory) + " is out of range: expected 0 or 1e6..1e15");
        gmpu::Progress progress(fn, user, GMPU_STAGE_READ);
        progress.report(0.0, true);
        gmpu::io::ReadOptions options;
        options.max_memory = max_memory;
        options.progress = &progress;
        auto points = std::make_unique<gmpu_points>();
        points->cloud = gmpu::io::read_points(path, options);
        progress.report(1.0, true);
        progress.throw_if_cancelled();
        *out = points.release();
    });
}

GMPU_API gmpu_status gmpu_points_read(const char *path, gmpu_points **out) {
    return gmpu_points_read_with(path, 0.0, nullptr, nullptr, out);
}

GMPU_API gmpu_status gmpu_points_create_with(const double *xyz, const double *normals, const uint8_t *colors,
                                             size_t count, gmpu_points **out) {
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        if (count > size_t(PTRDIFF_MAX) / (3 * sizeof(double)))
            throw Error(GMPU_ERROR_INVALID_ARGUMENT, "count is too large");
        if (count == 0) throw Error(GMPU_ERROR_INVALID_INPUT, "no points");
        gmpu::api::require_arg(xyz, "xyz");
        auto points = std::make_unique<gmpu_points>();
        copy_finite(points->cloud.positions, xyz, count, "coordinate");
        if (normals) copy_finite(points->cloud.normals, normals, count, "normal");
        if (colors) points->cloud.colors.assign(colors, colors + 3 * count);
        *out = points.release();
    });
}

GMPU_API gmpu_status gmpu_points_create(const double *xyz, const double *normals, size_t count,
                                        gmpu_points **out) {
    return gmpu_points_create_with(xyz, normals, nullptr, count, out);
}

GMPU_API void gmpu_points_destroy(gmpu_points *points) {
    gmpu::api::guarded(nullptr, [&] { delete points; });
}

GMPU_API size_t gmpu_points_count(const gmpu_points *points) {
    size_t n = 0;
    gmpu::api::guarded(nullptr, [&] { n = points ? points->cloud.size() : 0; });
    return n;
}

GMPU_API const double *gmpu_points_positions(const gmpu_points *points) {
    const double *p = nullptr;
    gmpu::api::guarded(nullptr, [&] { p = points ? points->cloud.positions.data() : nullptr; });
    return p;
}

GMPU_API const double *gmpu_points_normals(const gmpu_points *points) {
    const double *p = nullptr;
    gmpu::api::guarded(nullptr, [&] {
        p = points && !points->cloud.normals.empty() ? points->cloud.normals.data() : nullptr;
    });
    return p;
}

GMPU_API const uint8_t *gmpu_points_colors(const gmpu_points *points) {
    const uint8_t *p = nullptr;
    gmpu::api::guarded(nullptr, [&] {
        p = points && !points->cloud.colors.empty() ? points->cloud.colors.data() : nullptr;
    });
    return p;
}

GMPU_API gmpu_status gmpu_points_write(const gmpu_points *points, const char *path) {
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(points, "points");
        gmpu::api::require_arg(path, "path");
        const gmpu::io::PointCloud &c = points->cloud;
        gmpu::io::write_points(path, c.positions.data(), c.normals.empty() ? nullptr : c.normals.data(), c.size());
    });
}

}  // extern "C"
