// Shared body of the reader fuzz targets: parse the input as points and as a mesh, run the
// value checks, and trap if a successful parse broke an invariant the rest of gmpu relies
// on. gmpu::Error is the expected way to reject input; anything else (a crash, a sanitizer
// report, another exception, an oversized allocation) is a finding.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/error.hpp"
#include "io/formats.hpp"

namespace gmpu::fuzz {

inline void check_invariants(const io::detail::Parsed &p, bool mesh) {
    const size_t n = p.positions.size() / 3;
    if (p.positions.size() % 3 != 0) __builtin_trap();
    if (!p.normals.empty() && p.normals.size() != p.positions.size()) __builtin_trap();
    if (!mesh && !p.triangles.empty()) __builtin_trap();
    if (p.triangles.size() % 3 != 0) __builtin_trap();
    for (uint32_t t : p.triangles)
        if (t >= n) __builtin_trap();
}

template <class Parse>
void run(Parse &&parse, const uint8_t *data, size_t size) {
    const char *text = reinterpret_cast<const char *>(data);
    for (io::detail::Want want : {io::detail::Want::points, io::detail::Want::mesh}) {
        try {
            io::detail::Parsed p = parse(text, size, want);
            check_invariants(p, want == io::detail::Want::mesh);
            if (want == io::detail::Want::points)
                io::detail::check_points(p, "fuzz");
            else
                io::detail::check_mesh(p, "fuzz");
        } catch (const Error &) {
            // Rejected with a status and a message: fine.
        }
    }
}

}  // namespace gmpu::fuzz
