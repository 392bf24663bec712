#include "core/parallel.hpp"

#include <algorithm>
#include <chrono>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace gmpu {

unsigned resolve_threads(unsigned requested) {
    if (requested > 0) return requested;
    unsigned hw = std::thread::hardware_concurrency();
    return hw > 0 ? hw : 1;
}

void parallel_for(size_t begin, size_t end, unsigned threads, Progress &progress,
                  const std::function<void(size_t)> &body, double done_before, double total,
                  size_t chunk) {
    if (begin >= end) return;
    chunk = std::max<size_t>(1, chunk);
    std::atomic<size_t> next{begin};
    std::atomic<size_t> finished{0};
    std::atomic<unsigned> active{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;

    auto work = [&](bool is_caller) {
        for (;;) {
            if (progress.cancelled()) return;
            size_t start = next.fetch_add(chunk);
            if (start >= end) return;
            size_t stop = std::min(end, start + chunk);
            try {
                for (size_t i = start; i < stop; ++i) body(i);
            } catch (...) {
                std::lock_guard<std::mutex> lock(failure_mutex);
                if (!failure) failure = std::current_exception();
                progress.cancel();  // stop the others; the first failure wins
                return;
            }
            size_t done = finished.fetch_add(stop - start) + (stop - start);
            // A loop without a share of the bar (total 0) still reports, repeating the last
            // fraction, so that the callback keeps its 50 ms cadence and can cancel the loop.
            if (is_caller) progress.report(total > 0 ? (done_before + double(done)) / total : 0.0);
        }
    };

    unsigned n = std::max(1u, std::min<unsigned>(threads, unsigned((end - begin + chunk - 1) / chunk)));
    std::vector<std::thread> pool;
    pool.reserve(n - 1);
    for (unsigned t = 1; t < n; ++t) {
        active.fetch_add(1);
        try {
            pool.emplace_back([&] {
                work(false);
                active.fetch_sub(1);
            });
        } catch (...) {
            // The system refused a thread (a pids or process limit, no memory for a stack):
            // the threads already running and the caller share the work instead. Letting the
            // exception out here would destroy joinable threads, which terminates.
            active.fetch_sub(1);
            break;
        }
    }
    work(true);
    // The caller keeps reporting (and so keeps cancellation responsive) while the last
    // chunks finish on the other threads.
    while (active.load() > 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        progress.report(total > 0 ? (done_before + double(finished.load())) / total : 0.0);
    }
    for (auto &t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
}

}  // namespace gmpu
