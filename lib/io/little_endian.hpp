// Binary output in little-endian byte order whatever the host's (STL and glTF are
// little-endian by definition).
#pragma once

#include <cstddef>
#include <cstring>
#include <utility>

namespace gmpu::io::detail {

// Stores v at p in little-endian order; returns the byte after it.
template <class T>
char *put_le(char *p, T v) {
    std::memcpy(p, &v, sizeof v);
    if constexpr (__BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__)
        for (size_t i = 0; i < sizeof v / 2; ++i) std::swap(p[i], p[sizeof v - 1 - i]);
    return p + sizeof v;
}

}  // namespace gmpu::io::detail
