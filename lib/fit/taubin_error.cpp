#include <cmath>
#include <limits>

#include "fit/fits.hpp"

namespace gmpu {

double taubin_error(const LocalShape &shape, const std::vector<PiecewiseShape> &pieces,
                    const PointList &points) {
    double worst = 0.0;
    Eigen::Vector3d g;
    for (const auto &p : points) {
        double v = std::abs(shape.value(p, pieces, &g));
        double gn = g.norm();
        // A vanishing gradient on the data means the fit is not a surface there.
        double e = gn > 1e-12 ? v / gn : std::numeric_limits<double>::infinity();
        if (e > worst) worst = e;
    }
    return worst;
}

}  // namespace gmpu
