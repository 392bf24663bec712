// Every tunable of the pipeline, with the defaults the C ABI documents (gmpu.h): one field
// per row of core/param_table.def.
#pragma once

#include "core/memory_budget.hpp"

namespace gmpu {

struct Params {
#define GMPU_PARAM(KEY, field, ctype, type, default_value, ...) ctype field = default_value;
#include "core/param_table.def"
#undef GMPU_PARAM
};

// Whether every parameter is the same.
inline bool operator==(const Params &a, const Params &b) {
#define GMPU_PARAM(KEY, field, ...) \
    if (!(a.field == b.field)) return false;
#include "core/param_table.def"
#undef GMPU_PARAM
    return true;
}

}  // namespace gmpu
