// How open the space in front of a point is: the share of rays from just in front of it,
// in a cone about a direction, that leave the cloud's box without passing near any point.
// Seen from outside, a solid's surface faces open space: rays along its outward normal mostly
// escape, rays along the inward one meet the far side. Rays are marched through a grid that
// marks the space within a blocking radius of some point (a sampled surface is a wall to
// them, its random gaps closed by that radius), so a ray costs a few hundred cell steps.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "geometry/point_set.hpp"

namespace gmpu {

class OpenSky {
public:
    // `block`: the blocking radius (normalised units). The grid's cells are half of it, and
    // never more than kMaxCells along a side (coarser cells block a little more).
    OpenSky(const PointSet &points, double block);

    // The share, of the fixed ray directions within 60° of `direction` (unit), of rays from
    // `from` that escape.
    double escaping(const Eigen::Vector3d &from, const Eigen::Vector3d &direction) const;

    static constexpr int kMaxCells = 256;
    static constexpr int kDirections = 64;

private:
    bool blocked(int64_t i, int64_t j, int64_t k) const {
        const size_t c = size_t(i + n_[0] * (j + n_[1] * k));
        return (bits_[c >> 6] >> (c & 63)) & 1;
    }
    bool escapes(const Eigen::Vector3d &from, const Eigen::Vector3d &d) const;

    Eigen::Vector3d origin_;
    double cell_ = 0.0;
    int64_t n_[3] = {0, 0, 0};
    std::vector<uint64_t> bits_;
    std::vector<Eigen::Vector3d> directions_;
};

}  // namespace gmpu
