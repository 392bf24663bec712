// The triangle mesh that polygonize produces and the C ABI hands out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace gmpu {

struct Mesh {
    std::vector<double> vertices;     // 3 per vertex
    std::vector<double> normals;      // 3 per vertex (unit, outward), or empty
    // Per vertex: distance to the nearest input point in units of that point's sample
    // spacing (polygonize fills it; empty for meshes built from caller arrays).
    std::vector<double> confidence;
    std::vector<uint8_t> colors;      // red green blue per vertex (0..255), or empty
    std::vector<uint32_t> triangles;  // 3 per triangle, counter-clockwise seen from outside
    size_t vertex_count() const { return vertices.size() / 3; }
    size_t triangle_count() const { return triangles.size() / 3; }
};

// Triangle t's (b − a) × (c − a), its corners taken from `vertices` (3 per vertex): along its
// normal as wound, twice its area long.
inline Eigen::Vector3d triangle_cross(const std::vector<double> &vertices, const std::vector<uint32_t> &triangles,
                                      size_t t) {
    auto at = [&](uint32_t v) { return Eigen::Vector3d(vertices[3 * v], vertices[3 * v + 1], vertices[3 * v + 2]); };
    const Eigen::Vector3d a = at(triangles[3 * t]);
    return (at(triangles[3 * t + 1]) - a).cross(at(triangles[3 * t + 2]) - a);
}

}  // namespace gmpu
