#include "pipeline/free_sheet.hpp"

#include <algorithm>
#include <cmath>

#include "core/median.hpp"

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

// The local test reads one point's centre and jump, which the noise spreads more than the
// whole cloud's medians: on a noisy fin standing off a block (σ 1 %, 1.0 σ thick) the fin's
// samples' centre-to-jump ratio spread from −0.53 to 0.75 (5th to 95th percentile), while
// the block's 5th percentile was 0.39. A point's vote is its sample neighbours' majority, a
// few samples among kLocalVoters neighbours.
constexpr double kLocalFreeRatio = 0.25;
constexpr size_t kLocalStride = 8;
constexpr size_t kLocalVoters = 64;
// A single sample reading free among few is the noise's (closed surfaces have a few such):
// a free part is read free by several.
constexpr int kLocalMinFree = 2;
// Nearer a point than its spacing, the winding number is its nearest points' discs more
// than the surface (a sparse, clean, thin torus read −0.46 just in front of its points, 1.18
// behind: a free sheet's reading), so a sample is read only where the offset is at least
// this many of its spacings.
constexpr double kMinOffsetPerSpacing = 1.0;

// The winding number `offset` behind and in front of point p (outward normal n): its centre
// and its jump, and whether they are a free sheet's at the given centre-to-jump ratio.
struct SheetReading {
    double centre = 0.0, jump = 0.0;
    SheetReading(const WindingField &winding, const Eigen::Vector3d &p, const Eigen::Vector3d &n, double offset) {
        const double behind = winding.winding(p - offset * n), in_front = winding.winding(p + offset * n);
        centre = 0.5 * (behind + in_front);
        jump = behind - in_front;
    }
    SheetReading(double centre_, double jump_) : centre(centre_), jump(jump_) {}
    bool free(double ratio) const { return jump > kMinJump && std::fabs(centre) < ratio * jump; }
};

void turn_normal(PointMeasures &measures, size_t i) {
    for (size_t d = 0; d < 3; ++d) {
        measures.normals[3 * i + d] = -measures.normals[3 * i + d];
        measures.blend_normals[3 * i + d] = -measures.blend_normals[3 * i + d];
    }
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
        const SheetReading reading(winding, points.point(i), normal_of(normals, uint32_t(i)), offset);
        centre.push_back(reading.centre);
        jump.push_back(reading.jump);
    }
    return SheetReading(median_in_place(centre), median_in_place(jump)).free(kFreeRatio);
}

void split_sheet_faces(const MpuFunction &mpu, const PointSet &points, PointMeasures &measures, Workers &workers,
                       Progress &progress) {
    parallel_for(0, points.size(), workers, progress, [&](size_t i) {
        // f is positive inside: the point lies behind the sheet's middle.
        if (mpu.value(points.point(i), nullptr) > 0.0) turn_normal(measures, i);
    });
}

size_t split_local_sheet_faces(const WindingField &winding, const MpuFunction &mpu, const PointSet &points,
                               PointMeasures &measures, double offset, Workers &workers, Progress &progress) {
    const size_t n = points.size();
    if (winding.empty() || n == 0) return 0;
    // Per point: −1 not a sample, else whether the sample reads free.
    std::vector<int8_t> sample(n, -1);
    parallel_for(0, (n + kLocalStride - 1) / kLocalStride, workers, progress, [&](size_t s) {
        const size_t i = s * kLocalStride;
        if (offset < kMinOffsetPerSpacing * std::sqrt(double(measures.area[i]))) return;
        sample[i] = SheetReading(winding, points.point(i), normal_of(measures.blend_normals, uint32_t(i)), offset)
                        .free(kLocalFreeRatio);
    });
    // Only points near a sample that reads free can have a majority of such samples among
    // their neighbours (most clouds have none or a few): those within twice the voters of one.
    std::vector<uint32_t> free_samples;
    for (size_t i = 0; i < n; i += kLocalStride)
        if (sample[i] > 0) free_samples.push_back(uint32_t(i));
    if (free_samples.size() < size_t(kLocalMinFree)) return 0;
    std::vector<uint8_t> candidate(n, 0);
    std::vector<uint32_t> near;
    std::vector<float> d2;
    for (uint32_t s : free_samples) {
        progress.tick();
        points.nearest(points.point(s), 2 * kLocalVoters, near, d2);
        for (uint32_t j : near) candidate[j] = 1;
    }
    std::vector<uint8_t> turn(n, 0);
    parallel_for(0, n, workers, progress, [&](size_t i) {
        if (!candidate[i]) return;
        thread_local std::vector<uint32_t> voters;
        thread_local std::vector<float> voter_d2;
        points.nearest(points.point(i), kLocalVoters, voters, voter_d2);
        int free_votes = 0, samples = 0;
        for (uint32_t j : voters)
            if (sample[j] >= 0) ++samples, free_votes += sample[j];
        turn[i] = free_votes >= kLocalMinFree && 2 * free_votes > samples && mpu.value(points.point(i), nullptr) > 0.0;
    });
    size_t turned = 0;
    for (size_t i = 0; i < n; ++i)
        if (turn[i]) turn_normal(measures, i), ++turned;
    return turned;
}

}  // namespace gmpu
