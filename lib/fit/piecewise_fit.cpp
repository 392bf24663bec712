#include "fit/piecewise_fit.hpp"

namespace gmpu {

bool fit_piecewise(const PointList &, double, double, CellFit &) { return false; }

}  // namespace gmpu
