// Working arrays that a stage allocates, fills once and drops (the smooth field's splats and
// bands, solved level after level) are fresh memory each time: every first touch of a 4 KB
// page is a fault into the kernel, and on a virtual machine those faults take a visible share
// of the solve. This allocator puts arrays of 2 MB and more on 2 MB boundaries, whole huge
// pages, advised as such (huge_pages.hpp), so a first touch faults in 2 MB at once. Smaller
// arrays go to the standard allocator. Where the kernel declines the advice nothing changes.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include "core/huge_pages.hpp"

namespace gmpu {

inline constexpr size_t kHugePageBytes = size_t(2) << 20;

template <class T>
struct HugePageAllocator {
    using value_type = T;

    HugePageAllocator() noexcept = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U> &) noexcept {}

    T *allocate(size_t n) {
        if (n > std::numeric_limits<size_t>::max() / sizeof(T) - kHugePageBytes) throw std::bad_array_new_length();
        if (n * sizeof(T) < kHugePageBytes) return std::allocator<T>().allocate(n);
        const size_t bytes = (n * sizeof(T) + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
        void *memory = std::aligned_alloc(kHugePageBytes, bytes);
        if (!memory) throw std::bad_alloc();
        advise_huge_pages(memory, bytes);
        return static_cast<T *>(memory);
    }

    void deallocate(T *memory, size_t n) noexcept {
        if (n * sizeof(T) < kHugePageBytes) std::allocator<T>().deallocate(memory, n);
        else std::free(memory);
    }

    template <class U>
    bool operator==(const HugePageAllocator<U> &) const noexcept {
        return true;
    }
    template <class U>
    bool operator!=(const HugePageAllocator<U> &) const noexcept {
        return false;
    }
};

template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace gmpu
