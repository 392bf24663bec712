#include "pipeline/blend_strays.hpp"

#include <algorithm>

namespace gmpu {

namespace {
// Surface this many local sample spacings from every point is not the data's: random
// gaps between samples leave it under 3 from the points, a lump past a sparse foot or tail
// lies 10-30 out.
constexpr double kStrayConfidence = 5.0;
// The blend strays when at least this share of its mesh's area lies that far out: a single
// fin past a claw or a fingertip is about this much of an animal's mesh or more, while the
// odd triangles on the sparse rims of a part that keeps to its data stay well under it.
constexpr double kStrayShare = 0.0005;
}  // namespace

double stray_share(const Mesh &mesh) {
    if (mesh.confidence.size() != mesh.vertex_count()) return 0.0;
    double area = 0.0, far = 0.0;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        const uint32_t *v = &mesh.triangles[3 * t];
        const double piece = 0.5 * triangle_cross(mesh.vertices, mesh.triangles, t).norm();
        area += piece;
        if (std::max({mesh.confidence[v[0]], mesh.confidence[v[1]], mesh.confidence[v[2]]}) > kStrayConfidence)
            far += piece;
    }
    return area > 0.0 ? far / area : 0.0;
}

bool blend_strays(double share) { return share >= kStrayShare; }

}  // namespace gmpu
