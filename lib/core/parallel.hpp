// parallel_for over an index range on a persistent pool of worker threads (Workers), with
// the calling thread taking part: it alone reports progress, so user callbacks stay on the
// caller's thread. Work is handed out in small chunks from an atomic counter; every worker
// stops at its next chunk once the progress is cancelled. Exceptions thrown by the body are
// re-thrown on the calling thread.
//
// A surface creates its Workers once and every stage's loops reuse them (starting threads
// per loop cost one creation per octree level). When the system refuses to create a
// thread, the pool keeps the threads it has (at least the caller works); when a loop finds
// the pool already busy (a second caller), it runs on its calling thread alone.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "core/progress.hpp"

namespace gmpu {

// Number of threads to use for `requested` (0 = hardware concurrency), at least 1.
unsigned resolve_threads(unsigned requested);

class Workers {
public:
    // `threads` counts the caller: threads − 1 helpers are started (fewer if refused).
    explicit Workers(unsigned threads);
    ~Workers();
    Workers(const Workers &) = delete;
    Workers &operator=(const Workers &) = delete;

    // Threads a loop runs on, the caller included.
    unsigned threads() const { return unsigned(helpers_.size()) + 1; }
    // The thread count this pool was asked for (resolve_threads of it), for reuse checks.
    unsigned requested() const { return requested_; }

private:
    friend void parallel_for(size_t, size_t, Workers &, Progress &, const std::function<void(size_t)> &, size_t);
    void helper_loop();

    const unsigned requested_;
    std::vector<std::thread> helpers_;
    std::mutex busy_;  // held by the loop running on the pool
    std::mutex m_;
    std::condition_variable wake_, idle_;
    const std::function<void()> *job_ = nullptr;  // the running loop's work, or null
    unsigned long generation_ = 0;                // bumped for every job
    unsigned running_ = 0;                        // helpers inside the current job
    bool stop_ = false;
};

// Calls body(i) for every i in [begin, end) on the workers' threads, reporting the share of
// indices done as progress 0..1 (hand it a slice of the stage's progress).
void parallel_for(size_t begin, size_t end, Workers &workers, Progress &progress,
                  const std::function<void(size_t)> &body, size_t chunk = 16);

}  // namespace gmpu
