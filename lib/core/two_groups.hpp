// The best split of a sorted list of values into a low and a high group (1-D two-means,
// which is Otsu's threshold): the split whose two groups have the smallest summed squared
// deviations from their means. Used to tell two sheets from one in a support's residuals.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace gmpu {

struct TwoGroups {
    size_t low = 0;  // values in the low group; 0 when no split leaves min_side on each side
    double threshold = 0.0, low_mean = 0.0, high_mean = 0.0;
    double squared_deviations = 0.0;  // both groups' sums of squared deviations, added
};

// `sorted` ascending; each group holds at least `min_side` values.
inline TwoGroups split_two_groups(const std::vector<double> &sorted, size_t min_side) {
    const size_t n = sorted.size();
    std::vector<double> sum(n + 1, 0.0), sq(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i) {
        sum[i + 1] = sum[i] + sorted[i];
        sq[i + 1] = sq[i] + sorted[i] * sorted[i];
    }
    TwoGroups best;
    best.squared_deviations = INFINITY;
    for (size_t k = std::max<size_t>(min_side, 1); k + min_side <= n && k < n; ++k) {
        const double n0 = double(k), n1 = double(n - k);
        const double m0 = sum[k] / n0, m1 = (sum[n] - sum[k]) / n1;
        const double ss = std::max(0.0, sq[k] - n0 * m0 * m0) + std::max(0.0, sq[n] - sq[k] - n1 * m1 * m1);
        if (ss < best.squared_deviations) best = {k, 0.5 * (sorted[k - 1] + sorted[k]), m0, m1, ss};
    }
    if (best.low == 0) best.squared_deviations = 0.0;
    return best;
}

}  // namespace gmpu
