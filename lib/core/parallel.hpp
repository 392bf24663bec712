// parallel_for over an index range with the calling thread taking part: it alone reports
// progress, so user callbacks stay on the caller's thread. Work is handed out in small
// chunks from an atomic counter; every worker stops at its next chunk once the progress
// is cancelled. Exceptions thrown by the body are re-thrown on the calling thread. When the
// system refuses to create a thread, the loop runs on the threads it has (at least the caller).
#pragma once

#include <cstddef>
#include <functional>

#include "core/progress.hpp"

namespace gmpu {

// Number of threads to use for `requested` (0 = hardware concurrency), at least 1.
unsigned resolve_threads(unsigned requested);

// Calls body(i) for every i in [begin, end) on `threads` threads. `done_before` and
// `total` map the loop onto the stage's progress fraction: (done_before + i) / total.
void parallel_for(size_t begin, size_t end, unsigned threads, Progress &progress,
                  const std::function<void(size_t)> &body, double done_before = 0.0,
                  double total = 0.0, size_t chunk = 16);

}  // namespace gmpu
