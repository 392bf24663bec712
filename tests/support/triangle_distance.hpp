// Exact point-to-triangle distance: the closest point is found in closed form, so a
// perfect surface measures 0 (sampling the other surface instead has a floor of about
// the sample spacing).
#pragma once

#include "triangle_mesh.hpp"

namespace gmpu::testing {

// Closest point to p on the solid triangle abc (Ericson, Real-Time Collision Detection,
// §5.1.5: classify p into a vertex, edge or face Voronoi region). A degenerate triangle
// (a segment or a point) is handled as the union of its edges.
Vec3 closest_point_on_triangle(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c);

// Closest point to p on the segment ab (a when a == b).
Vec3 closest_point_on_segment(const Vec3 &p, const Vec3 &a, const Vec3 &b);

double point_triangle_distance(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c);

}  // namespace gmpu::testing
