// Sizing a big array writes, and so faults in, every page of it at once: on a virtual machine
// that is tens of milliseconds for tens of megabytes, longer than the progress cadence
// allows. This sizes it a megabyte at a time, reporting between the slices.
#pragma once

#include <algorithm>
#include <vector>

#include "core/huge_pages.hpp"
#include "core/progress.hpp"

namespace gmpu {

// v becomes n copies of `value` (whatever it held before is dropped).
template <class T>
void assign_reporting(std::vector<T> &v, size_t n, Progress &progress, const T &value = T()) {
    constexpr size_t kSliceBytes = size_t(1) << 20;
    const size_t step = std::max<size_t>(1, kSliceBytes / sizeof(T));
    v.clear();
    v.reserve(n);
    advise_huge_pages(v);
    while (v.size() < n) {
        progress.tick();
        v.resize(std::min(n, v.size() + step), value);
    }
}

}  // namespace gmpu
