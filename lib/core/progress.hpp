// Progress reporting and cancellation for one long call (fit, orient, polygonize).
// Workers only read `cancelled()`; the calling thread alone invokes the user's callback,
// at most every few milliseconds, so a slow callback never throttles the workers.
#pragma once

#include <atomic>
#include <chrono>

#include "core/error.hpp"
#include "gmpu/gmpu.h"

namespace gmpu {

class Progress {
public:
    Progress(gmpu_progress_fn fn, void *user, gmpu_stage stage) : fn_(fn), user_(user), stage_(stage) {}

    // Calling thread only. Reports `fraction` if enough time has passed since the last report
    // (always when force is set) and records a cancellation request.
    void report(double fraction, bool force = false);

    bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
    void cancel() { cancelled_.store(true, std::memory_order_relaxed); }

    // Throws CANCELLED if the callback asked to stop.
    void throw_if_cancelled() const;

    // report() then throw_if_cancelled(), for serial loops on the calling thread: called once
    // per item it keeps the callback's cadence (report throttles itself; a clock read is
    // noise next to an item's work) and stops the loop within one item of a cancel.
    void poll(double fraction) {
        report(fraction);
        throw_if_cancelled();
    }

    gmpu_stage stage() const { return stage_; }

private:
    gmpu_progress_fn fn_;
    void *user_;
    gmpu_stage stage_;
    double last_fraction_ = 0.0;
    std::atomic<bool> cancelled_{false};
    std::chrono::steady_clock::time_point last_report_{};
};

}  // namespace gmpu
