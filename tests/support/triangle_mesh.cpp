#include "triangle_mesh.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace gmpu::testing {

TriangleMesh mesh_from_arrays(const double *vertices, size_t vertex_count,
                              const uint32_t *triangles, size_t triangle_count) {
    TriangleMesh mesh;
    mesh.vertices.reserve(vertex_count);
    for (size_t i = 0; i < vertex_count; ++i)
        mesh.vertices.emplace_back(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
    mesh.triangles.reserve(triangle_count);
    for (size_t t = 0; t < triangle_count; ++t) {
        Triangle tri{triangles[3 * t], triangles[3 * t + 1], triangles[3 * t + 2]};
        for (uint32_t v : tri)
            if (v >= vertex_count)
                throw std::invalid_argument("triangle " + std::to_string(t) +
                                            " indexes vertex " + std::to_string(v) + " of " +
                                            std::to_string(vertex_count));
        mesh.triangles.push_back(tri);
    }
    return mesh;
}

Eigen::AlignedBox3d bounding_box(const TriangleMesh &mesh) {
    Eigen::AlignedBox3d box;  // starts empty
    for (const Vec3 &v : mesh.vertices) box.extend(v);
    return box;
}

double bbox_diagonal(const TriangleMesh &mesh) {
    const Eigen::AlignedBox3d box = bounding_box(mesh);
    return box.isEmpty() ? 0.0 : box.diagonal().norm();
}

Vec3 triangle_cross(const TriangleMesh &mesh, size_t triangle) {
    const Triangle &t = mesh.triangles[triangle];
    const Vec3 &a = mesh.vertices[t[0]];
    return (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
}

double triangle_area(const TriangleMesh &mesh, size_t triangle) {
    return 0.5 * triangle_cross(mesh, triangle).norm();
}

Vec3 triangle_normal(const TriangleMesh &mesh, size_t triangle) {
    const Vec3 n = triangle_cross(mesh, triangle);
    const double length = n.norm();
    return length > 0 ? Vec3(n / length) : Vec3::Zero();
}

double surface_area(const TriangleMesh &mesh) {
    double area = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) area += triangle_area(mesh, t);
    return area;
}

TriangleMesh flipped(TriangleMesh mesh) {
    for (Triangle &t : mesh.triangles) std::swap(t[1], t[2]);
    return mesh;
}

TriangleMesh translated(TriangleMesh mesh, const Vec3 &offset) {
    for (Vec3 &v : mesh.vertices) v += offset;
    return mesh;
}

TriangleMesh merged(const TriangleMesh &a, const TriangleMesh &b) {
    TriangleMesh mesh = a;
    const auto base = static_cast<uint32_t>(a.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const Triangle &t : b.triangles)
        mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    return mesh;
}

}  // namespace gmpu::testing
