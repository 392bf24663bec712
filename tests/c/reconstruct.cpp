#include "reconstruct.hpp"

#include <cstdlib>

namespace gmpu::testing {

namespace {
std::vector<double> flatten(const std::vector<Vec3> &v) {
    std::vector<double> out;
    out.reserve(3 * v.size());
    for (const auto &p : v) out.insert(out.end(), {p[0], p[1], p[2]});
    return out;
}
}  // namespace

Reconstruction reconstruct(const std::vector<Vec3> &points, const std::vector<std::pair<gmpu_param, double>> &params,
                           const std::vector<Vec3> *input_normals) {
    Reconstruction r;
    auto fail = [&](gmpu_status s) {
        r.status = s;
        r.error = gmpu_last_error();
        return s != GMPU_OK;
    };
    if (fail(gmpu_surface_create(&r.surface))) return r;
    for (const auto &[key, value] : params)
        if (fail(gmpu_surface_set_param(r.surface, key, value))) return r;
    const std::vector<double> xyz = flatten(points);
    if (fail(gmpu_surface_set_points_f64(r.surface, xyz.data(), points.size(), 0))) return r;
    if (input_normals) {
        const std::vector<double> n = flatten(*input_normals);
        if (fail(gmpu_surface_set_normals_f64(r.surface, n.data(), input_normals->size(), 0))) return r;
    }
    if (fail(gmpu_surface_fit(r.surface)) || fail(gmpu_surface_orient(r.surface))) return r;
    std::vector<double> normals(xyz.size());
    if (fail(gmpu_surface_copy_normals(r.surface, normals.data(), points.size()))) return r;
    for (size_t i = 0; i < points.size(); ++i) r.normals.emplace_back(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    gmpu_mesh *mesh = nullptr;
    if (fail(gmpu_surface_polygonize(r.surface, &mesh))) return r;
    r.mesh = mesh_from_arrays(gmpu_mesh_vertices(mesh), gmpu_mesh_vertex_count(mesh), gmpu_mesh_triangles(mesh),
                              gmpu_mesh_triangle_count(mesh));
    const double *n = gmpu_mesh_normals(mesh);
    for (size_t i = 0; n && i < gmpu_mesh_vertex_count(mesh); ++i) r.mesh_normals.emplace_back(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
    gmpu_mesh_destroy(mesh);
    return r;
}

std::vector<double> Reconstruction::evaluate(const std::vector<Vec3> &at, std::vector<Vec3> *gradients) const {
    const std::vector<double> xyz = flatten(at);
    std::vector<double> f(at.size()), g(3 * at.size());
    if (gmpu_surface_evaluate(surface, xyz.data(), at.size(), f.data(), g.data()) != GMPU_OK) return {};
    if (gradients) {
        gradients->clear();
        for (size_t i = 0; i < at.size(); ++i) gradients->emplace_back(g[3 * i], g[3 * i + 1], g[3 * i + 2]);
    }
    return f;
}

double Reconstruction::stat(gmpu_stat key) const {
    double v = -1;
    gmpu_surface_get_stat(surface, key, &v);
    return v;
}

std::string test_data(const std::string &relative) {
    const char *env = std::getenv("GMPU_TEST_DATA");
    std::string root = env ? env : std::string(std::getenv("GMPU_SOURCE_ROOT") ? std::getenv("GMPU_SOURCE_ROOT") : ".") + "/tests/data";
    return root + "/" + relative;
}

}  // namespace gmpu::testing
