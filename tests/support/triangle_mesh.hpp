// The two data types every test helper shares: an indexed triangle mesh and a set of
// points with normals. Plain structs of Eigen vectors, so tests can build them by hand.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gmpu::testing {

using Vec3 = Eigen::Vector3d;
using Triangle = std::array<uint32_t, 3>;

// Triangles are counter-clockwise seen from outside (outward normal = (b−a)×(c−a)).
struct TriangleMesh {
    std::vector<Vec3> vertices;
    std::vector<Triangle> triangles;
};

// Positions with one normal each (normals may be empty: a cloud without normals).
struct OrientedPoints {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;
    size_t size() const { return positions.size(); }
};

// Copies flat arrays (3 doubles per vertex, 3 indices per triangle), e.g. a gmpu_mesh's.
TriangleMesh mesh_from_arrays(const double *vertices, size_t vertex_count,
                              const uint32_t *triangles, size_t triangle_count);

// Box of all vertices, and its diagonal: the unit of every relative distance.
Eigen::AlignedBox3d bounding_box(const TriangleMesh &mesh);
double bbox_diagonal(const TriangleMesh &mesh);

// (b−a)×(c−a): twice the area times the outward unit normal.
Vec3 triangle_cross(const TriangleMesh &mesh, size_t triangle);
double triangle_area(const TriangleMesh &mesh, size_t triangle);
// Unit outward normal; the zero vector when the triangle has no area.
Vec3 triangle_normal(const TriangleMesh &mesh, size_t triangle);
double surface_area(const TriangleMesh &mesh);

// Copies with reversed winding (inside-out), moved by offset, or two meshes side by side.
TriangleMesh flipped(TriangleMesh mesh);
TriangleMesh translated(TriangleMesh mesh, const Vec3 &offset);
TriangleMesh merged(const TriangleMesh &a, const TriangleMesh &b);

}  // namespace gmpu::testing
