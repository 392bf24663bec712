// Progress reporting and cancellation for one long call (fit, orient, polygonize).
// Workers only read `cancelled()`; the calling thread alone invokes the user's callback,
// at most every kReportInterval, so a slow callback never throttles the workers.
//
// The promise of gmpu.h: a callback at least every kMaxWorkBetweenReports of the calling
// thread's CPU time, and a return within kMaxCancelLatency of a cancel. Every loop the
// calling thread runs therefore polls: per item (poll) when it knows its fraction, or with
// tick() deep inside work shared with the workers (a fit, a block), which reports only
// when it runs on the calling thread.
#pragma once

#include <atomic>
#include <chrono>
#include <thread>

#include "core/error.hpp"
#include "gmpu/gmpu.h"

namespace gmpu {

// The cadence gmpu.h documents (tests/c/test_docs_match.cpp checks the header's figures).
constexpr auto kReportInterval = std::chrono::milliseconds(10);        // at most this often
constexpr auto kMaxWorkBetweenReports = std::chrono::milliseconds(50);  // at least this often
constexpr auto kMaxCancelLatency = std::chrono::milliseconds(100);

class Progress {
public:
    Progress(gmpu_progress_fn fn, void *user, gmpu_stage stage) : own_{fn, user, stage, std::this_thread::get_id()} {}
    // A slice is a view of the same progress (one callback, one cancel flag) whose fractions
    // 0..1 land on [lo, hi] of this one's: a stage hands each of its steps a slice, and a
    // step reports 0..1 without knowing where it sits in the stage. Slices must not outlive
    // the progress they were cut from.
    Progress(const Progress &) = delete;
    Progress &operator=(const Progress &) = delete;
    Progress slice(double lo, double hi) const { return Progress(*shared_, at(lo), at(hi)); }

    // Calling thread only. Reports `fraction` if enough time has passed since the last report
    // (always when force is set) and records a cancellation request.
    void report(double fraction, bool force = false) { report_overall(at(fraction), force); }

    bool cancelled() const { return shared_->cancelled.load(std::memory_order_relaxed); }
    void cancel() { shared_->cancelled.store(true, std::memory_order_relaxed); }

    // Throws CANCELLED if the callback asked to stop.
    void throw_if_cancelled() const;

    // report() then throw_if_cancelled(), for serial loops on the calling thread: called once
    // per item it keeps the callback's cadence (report throttles itself; a clock read is
    // noise next to an item's work) and stops the loop within one item of a cancel.
    void poll(double fraction) {
        report(fraction);
        throw_if_cancelled();
    }

    // From any thread, inside work too long to go without a report (one cell's fit, one
    // block): on the calling thread it reports the last fraction again (throttled); on
    // every thread it throws CANCELLED once cancelled, which parallel_for carries back.
    void tick() {
        if (std::this_thread::get_id() == shared_->caller) report_overall(shared_->last_fraction, false);
        throw_if_cancelled();
    }

    gmpu_stage stage() const { return shared_->stage; }

private:
    struct Shared {
        gmpu_progress_fn fn;
        void *user;
        gmpu_stage stage;
        std::thread::id caller;
        double last_fraction = 0.0;
        std::atomic<bool> cancelled{false};
        std::chrono::steady_clock::time_point last_report{};
    };
    Progress(Shared &shared, double lo, double hi) : shared_(&shared), lo_(lo), hi_(hi) {}
    double at(double fraction) const { return lo_ + fraction * (hi_ - lo_); }
    void report_overall(double fraction, bool force);

    Shared own_{};
    Shared *shared_ = &own_;
    double lo_ = 0.0, hi_ = 1.0;  // this slice of the stage's bar
};

}  // namespace gmpu
