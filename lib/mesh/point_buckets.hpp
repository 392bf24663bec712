// The input points as the polygonizer needs them: thinned to one representative per voxel
// of half a cube (the lowest index in the voxel, with the number of points it stands for —
// dense clouds have tens of points per cube, and their union of trust balls, at least two
// cubes wide, hardly changes), and bucketed by the band blocks each representative's trust
// ball reaches. One global pass, so every block sees the same representatives and neighbouring
// blocks agree on every shared corner.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/surface_field.hpp"
#include "mesh/block_grid.hpp"

namespace gmpu {

// One representative per occupied voxel (cubes of side `voxel` from `origin`, 65,536 a side:
// a point outside counts in the nearest edge voxel): the lowest point index in it and the
// number of points it holds, in voxel order (z, then y, then x). Polls `progress` at
// `fraction`.
void voxel_representatives(const PointSet &points, const Eigen::Vector3d &origin, double voxel, Progress &progress,
                           double fraction, std::vector<uint32_t> &rep, std::vector<uint32_t> &count);

struct PointBuckets {
    std::vector<uint32_t> offsets;  // per band block (index into `band`), CSR into the two below
    std::vector<uint32_t> point;    // representative point index
    std::vector<uint32_t> weight;   // points it stands for

    // `band`: the band's block ids, in the order polygonize processes them.
    // Reports (at `fraction`) and checks for cancellation between its passes.
    PointBuckets(const BlockGrid &g, const std::vector<int64_t> &band, const SurfaceField &f, Progress &progress,
                 double fraction);

    size_t begin(size_t band_index) const { return offsets[band_index]; }
    size_t end(size_t band_index) const { return offsets[band_index + 1]; }
};

}  // namespace gmpu
