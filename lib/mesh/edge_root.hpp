// Where a grid edge crosses the zero set of f, found on f itself rather than on the linear
// interpolant of the two corner values. The vertex stays on its edge (strictly between the
// corners), so the polygonizer's mesh keeps its topology and its guarantees (closed,
// edge-manifold, every triangle inside its cube), while lying on the surface: a coarser
// grid then loses little accuracy.
#pragma once

#include <algorithm>
#include <cmath>

namespace gmpu {

// A parameter t in [0, 1] with f(t) ≈ 0, for corner values fa = f(0) and fb = f(1) of
// opposite signs (they may come from another field than `f`, e.g. a forced far sign: only
// their signs bracket the root). Regula falsi with the Illinois halving, which never lets
// one end stick; stops after `steps` evaluations or when |f| ≤ tolerance. A non-finite
// value ends the search at the last bracketed estimate.
template <class F>
double edge_root(double fa, double fb, F &&f, int steps, double tolerance) {
    double a = 0.0, b = 1.0;
    double t = std::clamp(fa / (fa - fb), 0.0, 1.0);
    int side = 0;  // which end was kept last time: -1 a, +1 b
    for (int s = 0; s < steps; ++s) {
        const double ft = f(t);
        if (!std::isfinite(ft) || std::abs(ft) <= tolerance) break;
        if ((ft > 0) == (fa > 0)) {
            a = t, fa = ft;
            if (side == -1) fb *= 0.5;
            side = -1;
        } else {
            b = t, fb = ft;
            if (side == 1) fa *= 0.5;
            side = 1;
        }
        t = std::clamp(a + (b - a) * fa / (fa - fb), a, b);
    }
    return t;
}

}  // namespace gmpu
