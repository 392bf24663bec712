#include "mesh/point_buckets.hpp"

#include <algorithm>
#include <cmath>

#include "core/cancellable_sort.hpp"
#include "core/resize_reporting.hpp"

namespace gmpu {

PointBuckets::PointBuckets(const BlockGrid &g, const std::vector<int64_t> &band, const SurfaceField &f,
                           Progress &progress, double fraction) {
    const PointSet &points = f.points();
    // 1. Representatives: sort by voxel, keep the first (lowest index) of each.
    const double voxel = 0.5 * g.h;
    std::vector<std::pair<uint64_t, uint32_t>> keyed;
    assign_reporting(keyed, points.size(), progress);
    // Every loop over the points or the blocks runs on the calling thread: poll every few
    // thousand items (a million points take tens of milliseconds per loop).
    constexpr size_t kPollEvery = 4096;
    for (uint32_t i = 0; i < points.size(); ++i) {
        if (i % kPollEvery == 0) progress.poll(fraction);
        const Eigen::Vector3d v = (points.point(i) - g.origin) / voxel;
        keyed[i] = {uint64_t(std::max(0.0, v[0])) | uint64_t(std::max(0.0, v[1])) << 21 |
                        uint64_t(std::max(0.0, v[2])) << 42,
                    i};
    }
    cancellable_sort(keyed, progress, fraction);
    std::vector<uint32_t> rep, count;
    for (size_t k = 0; k < keyed.size(); ++k) {
        if (k % kPollEvery == 0) progress.poll(fraction);
        if (k > 0 && keyed[k].first == keyed[k - 1].first) {
            ++count.back();
        } else {
            rep.push_back(keyed[k].second);
            count.push_back(1);
        }
    }
    keyed.clear();
    keyed.shrink_to_fit();

    // 2. Bucket each representative into the band blocks its trust ball's box overlaps
    //    (closed boxes, widened a hair, as BlockGrid marks the band).
    std::vector<int32_t> band_index(g.block_count(), -1);
    for (size_t b = 0; b < band.size(); ++b) band_index[size_t(band[b])] = int32_t(b);
    const double block = BlockGrid::B * g.h;
    auto for_blocks = [&](uint32_t p, auto &&visit) {
        const double r = f.trust_radius(p);
        const Eigen::Vector3d q = points.point(p) - g.origin;
        int64_t lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            lo[d] = std::clamp<int64_t>(int64_t(std::floor((q[d] - r) / block - 1e-9)), 0, g.blocks[d] - 1);
            hi[d] = std::clamp<int64_t>(int64_t(std::floor((q[d] + r) / block + 1e-9)), 0, g.blocks[d] - 1);
        }
        for (int64_t z = lo[2]; z <= hi[2]; ++z)
            for (int64_t y = lo[1]; y <= hi[1]; ++y)
                for (int64_t x = lo[0]; x <= hi[0]; ++x) {
                    const int32_t b = band_index[size_t(g.block_id(x, y, z))];
                    if (b >= 0) visit(size_t(b));
                }
    };
    progress.poll(fraction);
    offsets.assign(band.size() + 1, 0);
    for (size_t k = 0; k < rep.size(); ++k) {
        if (k % kPollEvery == 0) progress.poll(fraction);
        for_blocks(rep[k], [&](size_t b) { ++offsets[b + 1]; });
    }
    for (size_t b = 0; b < band.size(); ++b) offsets[b + 1] += offsets[b];
    point.resize(offsets.back());
    weight.resize(offsets.back());
    progress.poll(fraction);
    std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (size_t k = 0; k < rep.size(); ++k) {
        if (k % kPollEvery == 0) progress.poll(fraction);
        for_blocks(rep[k], [&](size_t b) {
            point[fill[b]] = rep[k];
            weight[fill[b]++] = count[k];
        });
    }
}

}  // namespace gmpu
