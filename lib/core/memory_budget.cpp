#include "core/memory_budget.hpp"

#include <cstdio>
#include <string>
#include <unistd.h>

#include "core/error.hpp"

namespace gmpu {

double default_memory_budget() {
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return 4.0 * (1ull << 30);
    return 0.5 * double(pages) * double(page);
}

void check_memory(double estimate, double budget, const char *what) {
    if (estimate <= budget) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  "%s needs about %.3g bytes, over GMPU_PARAM_MAX_MEMORY = %.3g bytes; raise the budget "
                  "or ask for less detail",
                  what, estimate, budget);
    throw Error(GMPU_ERROR_LIMIT_EXCEEDED, text);
}

}  // namespace gmpu
