// C ABI of meshes: built from caller arrays (or by gmpu_surface_polygonize), queried,
// simplified, trimmed, written.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "api/guard.hpp"
#include "api/handles.hpp"
#include "gmpu/gmpu.h"
#include "io/io.hpp"
#include "mesh/colour_transfer.hpp"
#include "mesh/confidence.hpp"
#include "mesh/simplify.hpp"

extern "C" {

GMPU_API gmpu_status gmpu_mesh_create_with(const double *vertices, size_t vertex_count, const uint32_t *triangles,
                                           size_t triangle_count, const double *normals, const double *confidence,
                                           const uint8_t *colors, gmpu_mesh **out) {
    using gmpu::Error;
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        // Arrays of 3 × count elements must be addressable (a std::vector holds at most
        // PTRDIFF_MAX bytes), and 32-bit indices address at most 2^32 vertices.
        if (vertex_count > (size_t(1) << 32) || triangle_count > size_t(PTRDIFF_MAX) / (3 * sizeof(uint32_t)))
            throw Error(GMPU_ERROR_INVALID_ARGUMENT, "count is too large");
        if (vertex_count > 0) gmpu::api::require_arg(vertices, "vertices");
        if (triangle_count > 0) gmpu::api::require_arg(triangles, "triangles");
        auto mesh = std::make_unique<gmpu_mesh>();
        mesh->mesh.vertices.assign(vertices, vertices + 3 * vertex_count);
        for (size_t i = 0; i < mesh->mesh.vertices.size(); ++i)
            if (!std::isfinite(mesh->mesh.vertices[i]))
                throw Error(GMPU_ERROR_INVALID_INPUT,
                            "coordinate of vertex " + std::to_string(i / 3) + " is not finite");
        mesh->mesh.triangles.assign(triangles, triangles + 3 * triangle_count);
        for (size_t i = 0; i < mesh->mesh.triangles.size(); ++i)
            if (mesh->mesh.triangles[i] >= vertex_count)
                throw Error(GMPU_ERROR_INVALID_INPUT,
                            "triangle " + std::to_string(i / 3) + " uses vertex index " +
                                std::to_string(mesh->mesh.triangles[i]) + ", but vertex_count is " +
                                std::to_string(vertex_count));
        if (normals && vertex_count > 0) {
            std::vector<double> &n = mesh->mesh.normals;
            n.assign(normals, normals + 3 * vertex_count);
            for (size_t v = 0; v < vertex_count; ++v) {
                const double length = std::hypot(n[3 * v], n[3 * v + 1], n[3 * v + 2]);
                if (!(std::isfinite(length) && length > 0))
                    throw Error(GMPU_ERROR_INVALID_INPUT,
                                "normal of vertex " + std::to_string(v) + " is zero or not finite");
                // The accessor promises unit normals; unit ones are kept bit for bit, so a mesh
                // copied through arrays writes the same file as the original.
                if (std::fabs(length - 1.0) > 1e-12)
                    for (size_t k = 0; k < 3; ++k) n[3 * v + k] /= length;
            }
        }
        if (confidence && vertex_count > 0) {
            mesh->mesh.confidence.assign(confidence, confidence + vertex_count);
            for (size_t v = 0; v < vertex_count; ++v)
                if (!(confidence[v] >= 0 && confidence[v] <= INFINITY))  // polygonize gives +inf to the unsupported
                    throw Error(GMPU_ERROR_INVALID_INPUT,
                                "confidence of vertex " + std::to_string(v) + " is negative or NaN");
        }
        if (colors && vertex_count > 0) mesh->mesh.colors.assign(colors, colors + 3 * vertex_count);
        *out = mesh.release();
    });
}

GMPU_API gmpu_status gmpu_mesh_create(const double *vertices, size_t vertex_count, const uint32_t *triangles,
                                      size_t triangle_count, gmpu_mesh **out) {
    return gmpu_mesh_create_with(vertices, vertex_count, triangles, triangle_count, nullptr, nullptr, nullptr, out);
}

GMPU_API const uint8_t *gmpu_mesh_colors(const gmpu_mesh *mesh) {
    const uint8_t *p = nullptr;
    gmpu::api::guarded(nullptr, [&] {
        p = mesh && !mesh->mesh.colors.empty() ? mesh->mesh.colors.data() : nullptr;
    });
    return p;
}

GMPU_API gmpu_status gmpu_mesh_color_from_points(const gmpu_mesh *mesh, const gmpu_points *points, gmpu_mesh **out) {
    using gmpu::Error;
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        gmpu::api::require_arg(mesh, "mesh");
        gmpu::api::require_arg(points, "points");
        const gmpu::io::PointCloud &cloud = points->cloud;
        if (cloud.colors.empty() || cloud.colors.size() != 3 * cloud.size())
            throw Error(GMPU_ERROR_INVALID_ARGUMENT, "the points have no colours (a .ply file with uchar red green blue)");
        auto result = std::make_unique<gmpu_mesh>();
        result->mesh = mesh->mesh;
        gmpu::transfer_colours(result->mesh, cloud.positions.data(), cloud.colors.data(), cloud.size());
        *out = result.release();
    });
}

GMPU_API void gmpu_mesh_destroy(gmpu_mesh *mesh) {
    gmpu::api::guarded(nullptr, [&] { delete mesh; });
}

GMPU_API size_t gmpu_mesh_vertex_count(const gmpu_mesh *mesh) {
    size_t n = 0;
    gmpu::api::guarded(nullptr, [&] { n = mesh ? mesh->mesh.vertex_count() : 0; });
    return n;
}

GMPU_API size_t gmpu_mesh_triangle_count(const gmpu_mesh *mesh) {
    size_t n = 0;
    gmpu::api::guarded(nullptr, [&] { n = mesh ? mesh->mesh.triangle_count() : 0; });
    return n;
}

GMPU_API const double *gmpu_mesh_vertices(const gmpu_mesh *mesh) {
    const double *p = nullptr;
    gmpu::api::guarded(nullptr, [&] { p = mesh ? mesh->mesh.vertices.data() : nullptr; });
    return p;
}

GMPU_API const double *gmpu_mesh_normals(const gmpu_mesh *mesh) {
    const double *p = nullptr;
    gmpu::api::guarded(nullptr, [&] {
        p = mesh && !mesh->mesh.normals.empty() ? mesh->mesh.normals.data() : nullptr;
    });
    return p;
}

GMPU_API const uint32_t *gmpu_mesh_triangles(const gmpu_mesh *mesh) {
    const uint32_t *p = nullptr;
    gmpu::api::guarded(nullptr, [&] { p = mesh ? mesh->mesh.triangles.data() : nullptr; });
    return p;
}

GMPU_API const double *gmpu_mesh_confidence(const gmpu_mesh *mesh) {
    const double *p = nullptr;
    gmpu::api::guarded(nullptr, [&] {
        p = mesh && !mesh->mesh.confidence.empty() ? mesh->mesh.confidence.data() : nullptr;
    });
    return p;
}

GMPU_API gmpu_status gmpu_mesh_simplify(const gmpu_mesh *mesh, size_t target_triangles, double target_error,
                                        gmpu_mesh **out) {
    using gmpu::Error;
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        gmpu::api::require_arg(mesh, "mesh");
        if (!(target_error >= 0.0 && target_error <= 1.0))
            throw Error(GMPU_ERROR_INVALID_ARGUMENT,
                        "target_error must be in [0, 1] (a fraction of the bounding-box diagonal), not " +
                            std::to_string(target_error));
        auto result = std::make_unique<gmpu_mesh>();
        result->mesh = gmpu::simplify_mesh(mesh->mesh, target_triangles, target_error, nullptr);
        *out = result.release();
    });
}

GMPU_API gmpu_status gmpu_mesh_trim(const gmpu_mesh *mesh, double threshold, gmpu_mesh **out) {
    using gmpu::Error;
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        gmpu::api::require_arg(mesh, "mesh");
        if (!(threshold > 0.0 && std::isfinite(threshold)))
            throw Error(GMPU_ERROR_INVALID_ARGUMENT,
                        "threshold must be finite and positive (a distance in sample spacings), not " +
                            std::to_string(threshold));
        if (mesh->mesh.confidence.size() != mesh->mesh.vertex_count() || mesh->mesh.confidence.empty())
            throw Error(GMPU_ERROR_INVALID_ARGUMENT,
                        "the mesh has no confidence to trim by (only gmpu_surface_polygonize makes one)");
        auto result = std::make_unique<gmpu_mesh>();
        result->mesh = gmpu::trim_unsupported(mesh->mesh, threshold);
        *out = result.release();
    });
}

GMPU_API gmpu_status gmpu_mesh_write(const gmpu_mesh *mesh, const char *path) {
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(mesh, "mesh");
        gmpu::api::require_arg(path, "path");
        const gmpu::Mesh &m = mesh->mesh;
        gmpu::io::MeshView view;
        view.vertices = m.vertices.data();
        view.vertex_count = m.vertex_count();
        view.triangles = m.triangles.data();
        view.triangle_count = m.triangle_count();
        // A mesh's normals are per vertex; without a full set, write none.
        view.normals = m.normals.size() == m.vertices.size() && !m.normals.empty() ? m.normals.data() : nullptr;
        view.confidence = m.confidence.size() == m.vertex_count() && !m.confidence.empty() ? m.confidence.data() : nullptr;
        view.colors = m.colors.size() == m.vertices.size() && !m.colors.empty() ? m.colors.data() : nullptr;
        gmpu::io::write_mesh(path, view);
    });
}

}  // extern "C"
