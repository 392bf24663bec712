#include "pipeline/free_sheet.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {

// Enough samples for stable medians; the test costs two winding queries each.
constexpr size_t kSamples = 2000;
// A closed surface's centre-to-jump ratio is ½ (measured 0.44–0.65 on noisy clouds, the
// winding number's near field inflating both); a free sheet's is 0.
constexpr double kFreeRatio = 0.125;
// The jump must be there at all: offsets that cross a wall thinner than them land outside
// on both sides (centre and jump both near 0), which says nothing.
constexpr double kMinJump = 0.5;

double median(std::vector<double> &v) {
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

Eigen::Vector3d normal_of(const std::vector<float> &normals, uint32_t i) {
    return Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
}

}  // namespace

bool is_free_sheet(const WindingField &winding, const PointSet &points, const std::vector<float> &normals,
                   double offset, Progress &progress) {
    if (winding.empty() || points.size() == 0) return false;
    const size_t stride = std::max<size_t>(1, points.size() / kSamples);
    std::vector<double> centre, jump;
    for (size_t i = 0; i < points.size(); i += stride) {
        progress.tick();
        const Eigen::Vector3d p = points.point(i), n = normal_of(normals, uint32_t(i));
        const double behind = winding.winding(p - offset * n), in_front = winding.winding(p + offset * n);
        centre.push_back(0.5 * (behind + in_front));
        jump.push_back(behind - in_front);
    }
    const double c = median(centre), j = median(jump);
    return j > kMinJump && std::fabs(c) < kFreeRatio * j;
}

void split_sheet_faces(const MpuFunction &mpu, const PointSet &points, PointMeasures &measures, Workers &workers,
                       Progress &progress) {
    parallel_for(0, points.size(), workers, progress, [&](size_t i) {
        // f is positive inside: the point lies behind the sheet's middle.
        if (mpu.value(points.point(i), nullptr) <= 0.0) return;
        for (size_t d = 0; d < 3; ++d) {
            measures.normals[3 * i + d] = -measures.normals[3 * i + d];
            measures.blend_normals[3 * i + d] = -measures.blend_normals[3 * i + d];
        }
    });
}

}  // namespace gmpu
