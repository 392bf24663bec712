// std::sort that keeps a progress callback alive. One sort of a million elements takes
// ~100 ms, past the callback's 50 ms cadence (and so past a cancel): this sorts slices of
// 32k elements, then merges them pass by pass, polling progress before each step.
#pragma once

#include <algorithm>
#include <vector>

#include "core/progress.hpp"

namespace gmpu {

// Sorts v ascending; throws CANCELLED between steps. `fraction`: the stage's bar position.
template <class T>
void cancellable_sort(std::vector<T> &v, Progress &progress, double fraction) {
    constexpr size_t kSlice = size_t(1) << 15;
    const auto at = [&](size_t i) { return v.begin() + long(std::min(v.size(), i)); };
    for (size_t lo = 0; lo < v.size(); lo += kSlice) {
        progress.poll(fraction);
        std::sort(at(lo), at(lo + kSlice));
    }
    for (size_t width = kSlice; width < v.size(); width *= 2)
        for (size_t lo = 0; lo + width < v.size(); lo += 2 * width) {
            progress.poll(fraction);
            std::inplace_merge(at(lo), at(lo + width), at(lo + 2 * width));
        }
    progress.poll(fraction);
}

}  // namespace gmpu
