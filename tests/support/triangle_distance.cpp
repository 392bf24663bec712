#include "triangle_distance.hpp"

#include <algorithm>

namespace gmpu::testing {

Vec3 closest_point_on_segment(const Vec3 &p, const Vec3 &a, const Vec3 &b) {
    const Vec3 ab = b - a;
    const double length2 = ab.squaredNorm();
    if (!(length2 > 0)) return a;
    const double t = std::clamp((p - a).dot(ab) / length2, 0.0, 1.0);
    return a + t * ab;
}

Vec3 closest_point_on_triangle(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;  // vertex region a

    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;  // vertex region b

    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;  // edge ab

    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;  // vertex region c

    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;  // edge ac

    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)  // edge bc
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);

    // Face region. va + vb + vc is |ab × ac|² in exact arithmetic; it is not positive
    // only for a degenerate triangle, whose closest point lies on one of its edges.
    const double denom = va + vb + vc;
    if (!(denom > 0)) {
        const Vec3 candidates[3] = {closest_point_on_segment(p, a, b),
                                    closest_point_on_segment(p, b, c),
                                    closest_point_on_segment(p, c, a)};
        const Vec3 *best = &candidates[0];
        for (const Vec3 &q : candidates)
            if ((q - p).squaredNorm() < (*best - p).squaredNorm()) best = &q;
        return *best;
    }
    return a + ab * (vb / denom) + ac * (vc / denom);
}

double point_triangle_distance(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    return (closest_point_on_triangle(p, a, b, c) - p).norm();
}

}  // namespace gmpu::testing
