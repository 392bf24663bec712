#include "pipeline/smooth_normals.hpp"

#include <algorithm>
#include <cmath>

#include "implicit/smooth_field.hpp"

namespace gmpu {

namespace {
constexpr double kSparseSpacing = 0.025;
constexpr size_t kSpacingNeighbour = 6, kSpacingProbes = 256;
// The grid step, in median sample spacings (√ of the median area a point stands for): a
// finer grid gave the same normals at several times the cost.
constexpr double kStepInSpacings = 0.7;
// A point's own normal and its nearest neighbours' (kAgreeNeighbours in all) agree when
// their mean is at least this long; two sheets of a thin wall give a far shorter one.
constexpr size_t kAgreeNeighbours = 9;
constexpr double kAgreeing = 0.8;

double normalised_diagonal(const PointSet &points) {
    return points.world_diagonal() * points.normalisation().scale;
}

Eigen::Vector3d normal_of(const std::vector<float> &normals, size_t i) {
    return Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
}
}  // namespace

bool sparse_cloud(const PointSet &points) {
    const size_t n = points.size();
    const double diagonal = normalised_diagonal(points);
    if (n <= kSpacingNeighbour || !(diagonal > 0.0)) return false;
    const size_t probes = std::min(n, kSpacingProbes);
    std::vector<double> reach;
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    for (size_t k = 0; k < probes; ++k) {
        points.nearest(points.point(k * n / probes), kSpacingNeighbour + 1, idx, d2);
        if (d2.size() == kSpacingNeighbour + 1) reach.push_back(std::sqrt(double(d2.back())));
    }
    if (reach.empty()) return false;
    std::nth_element(reach.begin(), reach.begin() + long(reach.size() / 2), reach.end());
    return reach[reach.size() / 2] >= kSparseSpacing * diagonal;
}

std::vector<float> smooth_point_normals(const Params &params, const PointSet &points, const PointMeasures &measures,
                                        double noise, Progress &progress) {
    if (points.size() == 0 || measures.area.empty()) {
        progress.report(1.0);
        return measures.normals;
    }
    std::vector<float> area(measures.area);
    std::nth_element(area.begin(), area.begin() + long(area.size() / 2), area.end());
    const double spacing = std::sqrt(double(area[area.size() / 2]));
    const double diagonal = normalised_diagonal(points);
    const double step = kStepInSpacings * (spacing > 0.0 ? spacing : diagonal / 64.0);
    Progress solve = progress.slice(0.0, 0.9), read = progress.slice(0.9, 1.0);
    const SmoothField field(points, measures, step, 2.0 * step, diagonal > 0.0 ? noise / diagonal : 0.0,
                            params.max_memory, solve);
    std::vector<float> normals = field_point_normals(field, points, measures, read);
    return normals;
}

std::vector<float> field_point_normals(const SmoothField &field, const PointSet &points, const PointMeasures &measures,
                                       Progress &progress) {
    std::vector<float> normals(measures.normals);
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    for (size_t i = 0; i < points.size(); ++i) {
        if (i % 1024 == 0) progress.poll(double(i) / double(points.size()));
        double f;
        Eigen::Vector3d g;
        if (!field.value(points.point(i), f, &g) || !(g.norm() > 0.0)) continue;
        points.nearest(points.point(i), kAgreeNeighbours, idx, d2);
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (uint32_t j : idx) mean += normal_of(measures.normals, j);
        if (mean.norm() < kAgreeing * double(idx.size())) continue;
        const Eigen::Vector3d n = -g.normalized();
        for (int d = 0; d < 3; ++d) normals[3 * i + size_t(d)] = float(n[d]);
    }
    progress.report(1.0);
    return normals;
}

}  // namespace gmpu
