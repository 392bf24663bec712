// The triangle mesh that polygonize produces and the C ABI hands out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

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

}  // namespace gmpu
