// The parameters of the C ABI, read from core/param_table.def: validation, get and set by
// key, and what gmpu_param_info reports.
#pragma once

#include "core/params.hpp"
#include "gmpu/gmpu.h"

namespace gmpu::api {

// Throws INVALID_ARGUMENT unless key is 1..gmpu_param_count() (any int may come from C).
void check_param_key(const gmpu_param &key);

// Whether changing key's value discards a previous fit.
bool param_refits(gmpu_param key);

double get_param(const Params &params, gmpu_param key);

// Throws INVALID_ARGUMENT naming the range when value is not one the key accepts.
void set_param(Params &params, gmpu_param key, double value);

}  // namespace gmpu::api
