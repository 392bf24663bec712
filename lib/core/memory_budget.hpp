// The memory budget (GMPU_PARAM_MAX_MEMORY): its default, and the check a stage makes
// against an estimate of its peak before (and while) it allocates, so that a request the
// machine cannot hold fails with LIMIT_EXCEEDED instead of being killed by the system.
#pragma once

namespace gmpu {

// Half the physical memory (the other half is the caller's and the system's); 4 GiB when
// the system does not say.
double default_memory_budget();

// Throws LIMIT_EXCEEDED naming `what`, the estimate and the budget when estimate > budget.
void check_memory(double estimate_bytes, double budget_bytes, const char *what);

}  // namespace gmpu
