// Binary STL: an 80-byte header, the triangle count (uint32), then per triangle its unit
// normal and three corners as float32 and a zero attribute word. STL has no shared vertices
// and no vertex normals: each triangle carries the normal of its own plane (zero for a
// degenerate one, as readers expect).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/little_endian.hpp"

namespace gmpu::io::detail {

void write_stl(AtomicFile &out, const MeshView &mesh) {
    if (mesh.triangle_count > UINT32_MAX)
        fail(GMPU_ERROR_INVALID_INPUT, out.path(), "more than 2^32 - 1 triangles for STL");
    char header[80] = {};
    // Not "solid ...": readers take a binary file that starts so for an ASCII one.
    const char title[] = "binary STL written by gmpu";
    std::memcpy(header, title, sizeof title - 1);
    out.write(header, sizeof header);
    char count[4];
    put_le(count, static_cast<uint32_t>(mesh.triangle_count));
    out.write(count, sizeof count);

    char record[50];
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        const double *c[3];
        for (size_t k = 0; k < 3; ++k) c[k] = mesh.vertices + 3 * size_t{mesh.triangles[3 * t + k]};
        const double u[3] = {c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]};
        const double v[3] = {c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (double &x : n) x = length > 0 ? x / length : 0.0;
        char *p = record;
        for (double x : n) p = put_le(p, static_cast<float>(x));
        for (const double *corner : c)
            for (size_t k = 0; k < 3; ++k) p = put_le(p, static_cast<float>(corner[k]));
        p = put_le(p, uint16_t{0});
        out.write(record, static_cast<size_t>(p - record));
    }
}

}  // namespace gmpu::io::detail
