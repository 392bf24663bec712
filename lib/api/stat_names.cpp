// gmpu_stat_count and gmpu_stat_name: the statistics' names, so that bindings list them from
// the library instead of restating the enum (tests/python/test_cdef.py checks this table
// against the header's enumerators).
#include <iterator>

#include "gmpu/gmpu.h"

namespace {

// By key, from GMPU_STAT_POINTS = 1: the enumerator's suffix in lower case.
constexpr const char *kStatNames[] = {
    "points",        "cells",          "leaves",           "depth",         "quadric_cells",
    "bivariate_cells", "piecewise_cells", "components",     "flipped_cells", "fit_seconds",
    "orient_seconds", "polygonize_seconds", "resolution",   "bbox_diagonal", "noise",
    "effective_error", "outliers",
};

}  // namespace

extern "C" {

GMPU_API int gmpu_stat_count(void) { return int(std::size(kStatNames)); }

GMPU_API const char *gmpu_stat_name(gmpu_stat key) {
    const int k = int(key);
    return k >= 1 && k <= gmpu_stat_count() ? kStatNames[k - 1] : nullptr;
}

}  // extern "C"
