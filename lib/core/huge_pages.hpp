// Large per-point arrays are written page by page as they fill, and each first touch of a
// 4 KB page is a fault into the kernel: at millions of points those faults are a visible share
// of the run, more so on a virtual machine. Asking for transparent huge pages on such an array
// makes it one fault per 2 MB. A hint only: where THP is off (or not Linux) nothing changes,
// and the memory is the same (the arrays are filled whole).
#pragma once

#include <cstddef>
#include <vector>

namespace gmpu {

// Advises huge pages for the 2 MB-aligned part of [data, data + bytes); does nothing for
// ranges too small to hold one.
void advise_huge_pages(const void *data, size_t bytes);

// The same for a vector's whole capacity: call it after reserving, before filling.
template <class T, class A>
void advise_huge_pages(const std::vector<T, A> &v) {
    advise_huge_pages(v.data(), v.capacity() * sizeof(T));
}

// The same for a dense Eigen vector or matrix (anything with data() and size()): call it
// after sizing it uninitialised, before filling.
template <class Dense>
auto advise_huge_pages(const Dense &m) -> decltype(m.data(), m.size(), void()) {
    advise_huge_pages(m.data(), size_t(m.size()) * sizeof(*m.data()));
}

}  // namespace gmpu
