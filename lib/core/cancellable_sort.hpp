// std::sort that keeps a progress callback alive. One sort of a million elements takes
// ~100 ms, past the callback's 50 ms cadence (and so past a cancel): this sorts slices of
// 32k elements, then merges them pass by pass into a second buffer, polling progress every
// 32k elements written, so that not even the last pass (which merges the whole array, and
// faults in the buffer's pages as it goes) runs long without a report.
#pragma once

#include <algorithm>
#include <vector>

#include "core/progress.hpp"

namespace gmpu {

// Sorts v ascending; throws CANCELLED between steps. `fraction`: the stage's bar position.
// The merges are stable, as std::inplace_merge's are.
template <class T>
void cancellable_sort(std::vector<T> &v, Progress &progress, double fraction) {
    constexpr size_t kSlice = size_t(1) << 15;
    const size_t n = v.size();
    for (size_t lo = 0; lo < n; lo += kSlice) {
        progress.poll(fraction);
        std::sort(v.begin() + long(lo), v.begin() + long(std::min(n, lo + kSlice)));
    }
    std::vector<T> spare;
    if (n > kSlice) spare.reserve(n);
    std::vector<T> *from = &v, *to = &spare;
    for (size_t width = kSlice; width < n; width *= 2) {
        to->clear();
        for (size_t lo = 0; lo < n; lo += 2 * width) {
            size_t i = lo, j = std::min(n, lo + width);
            const size_t mid = j, hi = std::min(n, lo + 2 * width);
            while (i < mid || j < hi) {
                progress.poll(fraction);
                for (size_t left = kSlice; left > 0 && (i < mid || j < hi); --left) {
                    const bool take_right = i == mid || (j < hi && (*from)[j] < (*from)[i]);
                    to->push_back(take_right ? (*from)[j++] : (*from)[i++]);
                }
            }
        }
        std::swap(from, to);
    }
    if (from != &v) v.swap(*from);
    progress.poll(fraction);
}

}  // namespace gmpu
