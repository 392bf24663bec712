// Spatially separated clusters of a point cloud: groups of points whose bounding boxes are
// farther apart than their own sizes (two scans of objects far apart, a part beside a
// calibration target at a million times its size). One octree, one ε and one grid over all
// of them would be set by the gap, not by any object: each cluster is reconstructed at its
// own scale instead (api/surface_parts.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gmpu {

struct Clusters {
    size_t count = 1;                            // 1: the cloud is one cluster (labels empty)
    std::vector<uint32_t> labels;                // per input point, in [0, count)
    std::vector<std::array<double, 6>> boxes;    // per cluster: lo xyz, hi xyz of its points
};

// A cluster needs this many points (and at least min_points) and a box that is not flat to
// stand on its own; a smaller or flat group is a stray: its points go to the nearest cluster,
// like outliers, without widening its box.
constexpr size_t kMinClusterPoints = 64;
// Two groups stay apart when the gap between their boxes exceeds this times the larger box's
// longest side; nearer groups (one object sampled with holes, nested shells) are one cluster.
constexpr double kClusterGap = 1.0;

// `xyz`: count points of type T, `stride` bytes apart; `outliers` (increasing input indices)
// take no part in finding the clusters and are labelled with the nearest one. Linear in
// count: occupied cells of a coarse grid (a few points per cell on a surface) joined with
// their 26 neighbours, then groups merged until every two are apart.
template <class T>
Clusters find_clusters(const T *xyz, size_t count, size_t stride, const std::vector<uint32_t> &outliers,
                       size_t min_points);

}  // namespace gmpu
