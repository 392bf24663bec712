// A random vector from three draws of one distribution, in a fixed order.
// `Vector3d(d(rng), d(rng), d(rng))` leaves the order of the three calls to the compiler (gcc
// draws z first, clang x first), so one seed gave each compiler's build another cloud: the
// sanitizer build (clang) tested other samples than the release build (gcc), and a bound
// that held for one could fail on the other. The order here is gcc's, which the tests'
// bounds and quoted figures were measured with.
#pragma once

#include <Eigen/Core>

namespace gmpu_test {

template <class Distribution, class Rng>
Eigen::Vector3d draw_vector(Distribution &distribution, Rng &rng) {
    const double z = distribution(rng);
    const double y = distribution(rng);
    const double x = distribution(rng);
    return Eigen::Vector3d(x, y, z);
}

}  // namespace gmpu_test
