// gmpu_param_count / gmpu_param_info / gmpu_param_key and the per-key get, set and
// validation behind gmpu_surface_set_param and get_param: every one is a loop over, or an
// index into, the rows of core/param_table.def.
#include "api/param_table.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <string>

#include "api/guard.hpp"
#include "core/error.hpp"
#include "model/octree.hpp"

namespace gmpu::api {
namespace {

enum Bounds { CLOSED, OPEN };
enum Refit { KEEPS_FIT, REFITS };

struct Row {
    int key;
    const char *name, *enumerator;
    gmpu_value_type type;
    double min, max;
    Bounds bounds;
    Refit refit;
    const char *doc;
    double (*get)(const Params &);
    void (*set)(Params &, double);
};

#define GMPU_PARAM(KEY, field, ctype, TYPE, default_value, lo, hi, BOUNDS, REFIT, doc)                        \
    {GMPU_PARAM_##KEY, #field, "GMPU_PARAM_" #KEY, GMPU_TYPE_##TYPE, lo, hi, BOUNDS, REFIT, doc,              \
     [](const Params &p) { return double(p.field); }, [](Params &p, double v) { p.field = static_cast<ctype>(v); }},
const Row kRows[] = {
#include "core/param_table.def"
};
#undef GMPU_PARAM

// The table's order is the keys' order, 1, 2, 3...: a key indexes its row, and a binding
// enumerates the keys as 1..count.
constexpr int kKeys[] = {
#define GMPU_PARAM(KEY, ...) GMPU_PARAM_##KEY,
#include "core/param_table.def"
#undef GMPU_PARAM
};
constexpr bool keys_are_one_to_count() {
    for (size_t i = 0; i < std::size(kKeys); ++i)
        if (kKeys[i] != int(i) + 1) return false;
    return true;
}
static_assert(keys_are_one_to_count(), "core/param_table.def: rows must be in key order 1, 2, 3... with no gap");

constexpr int kCount = int(std::size(kKeys));

// The depth parameters' ranges end at the octree's deepest level.
constexpr double kMaxima[] = {
#define GMPU_PARAM(KEY, field, ctype, TYPE, default_value, lo, hi, ...) hi,
#include "core/param_table.def"
#undef GMPU_PARAM
};
static_assert(kMaxima[GMPU_PARAM_MAX_DEPTH - 1] == kMaxDepth && kMaxima[GMPU_PARAM_LEVEL - 1] == kMaxDepth,
              "core/param_table.def: max_depth and level must end at kMaxDepth");

const Row &row(gmpu_param key) { return kRows[int(key) - 1]; }

// Shortest exact-enough text for a parameter value ("16", "0.002", "1e+09").
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// Rules beyond a range, each a parameter's own.
void check_rules(const Row &r, double value) {
    if (r.key == GMPU_PARAM_RESOLUTION && value > 0 && value < 8)
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "GMPU_PARAM_RESOLUTION must be 0 (automatic) or 8..4096");
}

}  // namespace

void check_param_key(const gmpu_param &key) {
    const int v = enum_int(key);
    if (v < 1 || v > kCount) throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key " + std::to_string(v));
}

bool param_refits(gmpu_param key) { return row(key).refit == REFITS; }

double get_param(const Params &params, gmpu_param key) { return row(key).get(params); }

void set_param(Params &params, gmpu_param key, double value) {
    const Row &r = row(key);
    const bool open = r.bounds == OPEN, integer = r.type == GMPU_TYPE_INT;
    const bool inside = open ? value > r.min && value < r.max : value >= r.min && value <= r.max;
    if (!std::isfinite(value) || !inside || (integer && value != std::floor(value)))
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, std::string(r.enumerator) + " = " + number(value) +
                                                     " is out of range: expected " +
                                                     (integer ? "an integer " : "a number ") + (open ? "in (" : "in [") +
                                                     number(r.min) + ", " + number(r.max) + (open ? ")" : "]"));
    check_rules(r, value);
    r.set(params, value);
}

}  // namespace gmpu::api

extern "C" {

GMPU_API int gmpu_param_count(void) { return gmpu::api::kCount; }

GMPU_API gmpu_status gmpu_param_info(gmpu_param key, gmpu_param_info_t *info) {
    using namespace gmpu::api;
    return guarded(nullptr, [&] {
        check_param_key(key);
        require_arg(info, "info");
        const Row &r = row(key);
        *info = {r.name, r.type, r.get(gmpu::Params{}), r.min, r.max, r.bounds == OPEN, r.bounds == OPEN,
                 r.refit == REFITS, r.doc};
    });
}

GMPU_API int gmpu_param_key(const char *name) {
    using namespace gmpu::api;
    if (!name) return 0;
    for (const Row &r : kRows)
        if (std::strcmp(name, r.name) == 0 || std::strcmp(name, r.enumerator) == 0) return r.key;
    return 0;
}

}  // extern "C"
