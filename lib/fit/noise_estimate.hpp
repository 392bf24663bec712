// Estimate of the sampling noise σ. Around sampled centres, a height quadratic is fitted in
// the tangent plane to the 12 and the 24 nearest neighbours (nearest along the plane, taken
// from a ball several σ tall, so that the noise's tails are not cut off). What the shape
// leaves (curvature, creases, detail too fine for the sampling) grows from the smaller
// neighbourhood to the larger one; noise does not, so the two are combined to cancel the
// first. A neighbourhood holding two sheets (a thin wall) is cut to the centre's sheet;
// sheets too close for that (a few σ) show as residuals flatter than Gaussian noise, and
// their offset is taken out of the estimate (and reported: the fit then looks for them);
// the residuals are read at a low quantile over the centres, with the correction that the
// quantile of a χ distribution implies: shape residual is where the detail is, noise is
// everywhere. Subdividing until the Taubin error is below the noise level only fits the
// noise (MPU's known weakness on noisy scans), so fit uses it as a floor for ε.
#pragma once

#include "core/progress.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

struct NoiseEstimate {
    double sigma = 0.0;          // σ̂ in the normalised frame
    bool close_sheets = false;   // residuals flatter than noise: sheets a few σ apart
};

// Runs on the calling thread; polls progress per centre.
NoiseEstimate estimate_noise_model(const PointSet &points, Progress &progress);
inline double estimate_noise(const PointSet &points, Progress &progress) {
    return estimate_noise_model(points, progress).sigma;
}

}  // namespace gmpu
