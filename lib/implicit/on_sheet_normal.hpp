// A point's normal from the local fits whose surface passes by the point.
//
// The MPU blend at an input point averages every leaf whose support covers it. Where a part
// is thin, or two parts nearly touch, and the samples are noisy, some of those leaves fit the
// other sheet (or a sheet between the two) and lie a wall thickness away from the point; their
// gradients there describe the other side and can outweigh the leaves that fit the point's
// own sheet, turning the normal over. Here a leaf speaks only if its zero set passes within
// a tolerance of the point, weighted more the closer it passes.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "implicit/mpu_function.hpp"

namespace gmpu {

// Writes the inward gradient direction (like ∇f, not normalised) at the input point p from
// the leaves of `near` (gathered for a box holding p) that pass within their tolerance of p;
// false when none does (the caller keeps the full blend).
bool on_sheet_gradient(const MpuFunction &mpu, const std::vector<uint32_t> &near, const Eigen::Vector3d &p,
                       Eigen::Vector3d &gradient);

}  // namespace gmpu
