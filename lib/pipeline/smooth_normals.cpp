#include "pipeline/smooth_normals.hpp"

#include "implicit/smooth_field.hpp"

namespace gmpu {

namespace {
// A point's own normal and its nearest neighbours' (kAgreeNeighbours in all) agree when
// their mean is at least this long; two sheets of a thin wall give a far shorter one
// (about 0). A point whose own normal is flipped among eight right ones gives 7/9, so the
// bar must sit below that for the field to correct it: here one more of the nine may
// dissent (5/9).
constexpr size_t kAgreeNeighbours = 9;
constexpr double kAgreeing = 0.5;

Eigen::Vector3d normal_of(const std::vector<float> &normals, size_t i) {
    return Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
}
}  // namespace

std::vector<float> field_point_normals(const SmoothField &field, const PointSet &points, const PointMeasures &measures,
                                       Progress &progress, FollowField follow) {
    std::vector<float> normals(measures.normals);
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    for (size_t i = 0; i < points.size(); ++i) {
        if (i % 1024 == 0) progress.poll(double(i) / double(points.size()));
        double f;
        Eigen::Vector3d g;
        if (!field.value(points.point(i), f, &g) || !(g.norm() > 0.0)) continue;
        if (follow == FollowField::where_neighbours_agree) {
            points.nearest(points.point(i), kAgreeNeighbours, idx, d2);
            Eigen::Vector3d mean = Eigen::Vector3d::Zero();
            for (uint32_t j : idx) mean += normal_of(measures.normals, j);
            if (mean.norm() < kAgreeing * double(idx.size())) continue;
        }
        const Eigen::Vector3d n = -g.normalized();
        for (int d = 0; d < 3; ++d) normals[3 * i + size_t(d)] = float(n[d]);
    }
    progress.report(1.0);
    return normals;
}

}  // namespace gmpu
