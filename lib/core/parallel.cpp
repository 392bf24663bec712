#include "core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>

#include <pthread.h>
#include <signal.h>

namespace gmpu {

unsigned resolve_threads(unsigned requested) {
    if (requested > 0) return requested;
    unsigned hw = std::thread::hardware_concurrency();
    return hw > 0 ? hw : 1;
}

Workers::Workers(unsigned threads) : requested_(resolve_threads(threads)) {
    helpers_.reserve(requested_ - 1);
    // The pool outlives the stages, so its threads sit idle inside the host's process. They
    // take none of its signals (a new thread inherits this mask): a SIGINT or SIGTERM goes to
    // a host thread, whose handler can then clean up while no other thread writes on.
    sigset_t all, host_mask;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &host_mask);
    for (unsigned t = 1; t < requested_; ++t) {
        try {
            helpers_.emplace_back([this] { helper_loop(); });
        } catch (...) {
            // The system refused a thread (a pids or process limit, no memory for a stack):
            // the threads already running and the caller share the work instead.
            break;
        }
    }
    pthread_sigmask(SIG_SETMASK, &host_mask, nullptr);
}

Workers::~Workers() {
    {
        std::lock_guard<std::mutex> lock(m_);
        stop_ = true;
    }
    wake_.notify_all();
    for (auto &t : helpers_) t.join();
}

void Workers::helper_loop() {
    unsigned long seen = 0;
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
        wake_.wait(lock, [&] { return stop_ || (job_ && generation_ != seen); });
        if (stop_) return;
        seen = generation_;
        const std::function<void()> *job = job_;
        ++running_;
        lock.unlock();
        (*job)();
        lock.lock();
        if (--running_ == 0) idle_.notify_all();
    }
}

void parallel_for(size_t begin, size_t end, Workers &workers, Progress &progress,
                  const std::function<void(size_t)> &body, size_t chunk) {
    if (begin >= end) return;
    chunk = std::max<size_t>(1, chunk);
    const double count = double(end - begin);
    std::atomic<size_t> next{begin};
    std::atomic<size_t> finished{0};
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
            if (is_caller) progress.report(double(done) / count);
        }
    };

    std::unique_lock<std::mutex> busy(workers.busy_, std::try_to_lock);
    const bool shared = busy.owns_lock() && !workers.helpers_.empty() && end - begin > chunk;
    const std::function<void()> helper_work = [&] { work(false); };
    if (shared) {
        {
            std::lock_guard<std::mutex> lock(workers.m_);
            workers.job_ = &helper_work;
            ++workers.generation_;
        }
        workers.wake_.notify_all();
    }
    work(true);
    if (shared) {
        // No helper may start the job from here on; then the caller keeps reporting (and so
        // keeps cancellation responsive) while the helpers inside it finish their chunks.
        std::unique_lock<std::mutex> lock(workers.m_);
        workers.job_ = nullptr;
        while (workers.running_ > 0) {
            workers.idle_.wait_for(lock, std::chrono::milliseconds(5));
            lock.unlock();
            progress.report(double(finished.load()) / count);
            lock.lock();
        }
    }
    if (failure) std::rethrow_exception(failure);
}

}  // namespace gmpu
