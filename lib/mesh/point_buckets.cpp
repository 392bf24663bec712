#include "mesh/point_buckets.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/resize_reporting.hpp"

namespace gmpu {

namespace {

// Every loop over the points or the blocks runs on the calling thread: poll every few
// thousand items (a million points take tens of milliseconds per loop).
constexpr size_t kPollEvery = 4096;

// Voxel coordinates fit 16 bits: a grid has at most a few thousand voxels a side, and a
// point past the last (or before the first) merely shares the edge voxel.
constexpr double kEdge = 65535.0;

// The voxel of side `voxel` holding point i, counted from `origin`.
std::array<uint32_t, 3> voxel_of(const PointSet &points, uint32_t i, const Eigen::Vector3d &origin, double voxel) {
    const Eigen::Vector3d v = (points.point(i) - origin) / voxel;
    return {uint32_t(std::clamp(v[0], 0.0, kEdge)), uint32_t(std::clamp(v[1], 0.0, kEdge)),
            uint32_t(std::clamp(v[2], 0.0, kEdge))};
}

}  // namespace

// A stable counting pass splits the indices into z-slabs (4 bytes a point, the points read in
// index order); each slab then sorts its (y, x, index) keys in a buffer of its own size. A
// comparison sort of (key, index) pairs over the whole cloud would hold 16 bytes a point
// twice over (the pairs and the merge buffer).
void voxel_representatives(const PointSet &points, const Eigen::Vector3d &origin, double voxel, Progress &progress,
                           double fraction, std::vector<uint32_t> &rep, std::vector<uint32_t> &count) {
    rep.clear();
    count.clear();
    const size_t n = points.size();
    // start[z + 1]: the points in slab z, then (summed) where slab z + 1 begins.
    std::vector<size_t> start(1, 0);
    for (uint32_t i = 0; i < n; ++i) {
        if (i % kPollEvery == 0) progress.poll(fraction);
        const size_t z = voxel_of(points, i, origin, voxel)[2];
        if (start.size() < z + 2) start.resize(z + 2, 0);
        ++start[z + 1];
    }
    for (size_t z = 1; z < start.size(); ++z) start[z] += start[z - 1];
    std::vector<uint32_t> by_slab;
    assign_reporting(by_slab, n, progress);
    {
        std::vector<size_t> fill(start.begin(), start.end() - 1);
        for (uint32_t i = 0; i < n; ++i) {
            if (i % kPollEvery == 0) progress.poll(fraction);
            by_slab[fill[voxel_of(points, i, origin, voxel)[2]]++] = i;
        }
    }
    // Within a slab, a key is y (16 bits) x (16 bits) index (32 bits).
    std::vector<uint64_t> keys;
    for (size_t z = 0; z + 1 < start.size(); ++z) {
        keys.clear();
        for (size_t k = start[z]; k < start[z + 1]; ++k) {
            if (k % kPollEvery == 0) progress.poll(fraction);
            const std::array<uint32_t, 3> v = voxel_of(points, by_slab[k], origin, voxel);
            keys.push_back(uint64_t(v[1]) << 48 | uint64_t(v[0]) << 32 | by_slab[k]);
        }
        std::sort(keys.begin(), keys.end());
        for (size_t k = 0; k < keys.size(); ++k) {
            if (k > 0 && keys[k] >> 32 == keys[k - 1] >> 32) {
                ++count.back();
            } else {
                rep.push_back(uint32_t(keys[k]));
                count.push_back(1);
            }
        }
    }
}

PointBuckets::PointBuckets(const BlockGrid &g, const std::vector<int64_t> &band, const SurfaceField &f,
                           Progress &progress, double fraction) {
    const PointSet &points = f.points();
    // 1. Representatives: the points in voxel order, the first (lowest index) of each voxel
    //    kept with the number of points in it.
    std::vector<uint32_t> rep, count;
    voxel_representatives(points, g.origin, 0.5 * g.h, progress, fraction, rep, count);

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
