// Estimate of the sampling noise: the median, over a sample of points, of the RMS residual
// of a bivariate quadratic fitted to each point's neighbourhood. A quadratic absorbs the
// surface's curvature, so on clean data the residual is near zero and on noisy data it is
// about the noise's standard deviation. Subdividing until the Taubin error is below the
// noise level only fits the noise (MPU's known weakness on noisy scans), so fit uses it as a
// floor for ε.
#pragma once

#include "core/progress.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

// σ̂ in the normalised frame. Runs on the calling thread; polls progress per sample.
double estimate_noise(const PointSet &points, Progress &progress);

}  // namespace gmpu
