// Outliers of a raw point cloud: points far from every other point compared with the
// cloud's own spacing (a scanner's stray returns, a wrong coordinate in a file). They would
// otherwise set the bounding box, and with it the scale of everything later (ε, the octree,
// the grid): two stray points at 100 times the object's size leave the object smaller than
// one grid cube. Found on the caller's doubles, before any normalisation, so that neither
// huge nor tiny offsets lose the cloud's precision.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace gmpu {

class Workers;

struct OutlierScan {
    std::vector<uint32_t> outliers;  // input indices, increasing; empty for most clouds
    double spacing = 0.0;            // typical distance to the k-th nearest neighbour
    double extent = 0.0;             // longest side of the kept points' bounding box
};

// kNeighbours-th nearest neighbour distances: the spacing is their median over a sample;
// a point is an outlier when its kNeighbours-th neighbour is farther than kFar × spacing.
constexpr size_t kOutlierNeighbours = 4;
constexpr double kOutlierFar = 20.0;

// `xyz`: count points of type T (double or float), `stride` bytes apart. Finds nothing (and
// leaves the errors to PointSet) when a coordinate is not finite or beyond ±1e300.
// With only_if_box_is_wide, the neighbour scan (a kd-tree over every point) runs only when
// the bounding box is over twice as wide as the bulk of the points (their 1 %–99 % range on
// some axis): outliers that do not widen the box so do not set the scale either, and most
// clouds are spared the scan's cost. With workers, a large scan's kd-tree and neighbour test
// run on their threads (the same answer).
template <class T>
OutlierScan find_outliers(const T *xyz, size_t count, size_t stride, bool only_if_box_is_wide = true,
                          Workers *workers = nullptr);

}  // namespace gmpu
