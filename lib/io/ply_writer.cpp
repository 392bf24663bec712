// PLY output: binary little-endian, double x y z (so a write → read round trip is exact),
// optional double nx ny nz, optional float confidence, optional uchar red green blue, and for meshes `element face` with `list uchar int
// vertex_indices` (the most widely read layout).
#include <cstring>
#include <string>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"

namespace gmpu::io::detail {

namespace {

constexpr bool host_is_little = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

template <class T>
char *put_le(char *p, T v) {
    std::memcpy(p, &v, sizeof v);
    if (!host_is_little)
        for (size_t i = 0; i < sizeof v / 2; ++i) std::swap(p[i], p[sizeof v - 1 - i]);
    return p + sizeof v;
}

}  // namespace

void write_ply(AtomicFile &out, const MeshView &mesh, bool faces) {
    std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment written by gmpu\nelement vertex " +
        std::to_string(mesh.vertex_count) +
        "\nproperty double x\nproperty double y\nproperty double z\n";
    if (mesh.normals) header += "property double nx\nproperty double ny\nproperty double nz\n";
    // Float: a confidence is a ratio of distances, read by viewers as a scalar colour map.
    if (mesh.confidence) header += "property float confidence\n";
    if (mesh.colors) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    if (faces)
        header += "element face " + std::to_string(mesh.triangle_count) +
                  "\nproperty list uchar int vertex_indices\n";
    header += "end_header\n";
    out.write(header);

    char record[64];
    for (size_t i = 0; i < mesh.vertex_count; ++i) {
        char *p = record;
        for (size_t k = 0; k < 3; ++k) p = put_le(p, mesh.vertices[3 * i + k]);
        if (mesh.normals)
            for (size_t k = 0; k < 3; ++k) p = put_le(p, mesh.normals[3 * i + k]);
        if (mesh.confidence) p = put_le(p, static_cast<float>(mesh.confidence[i]));
        if (mesh.colors)
            for (size_t k = 0; k < 3; ++k) *p++ = static_cast<char>(mesh.colors[3 * i + k]);
        out.write(record, static_cast<size_t>(p - record));
    }
    if (!faces) return;
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        char *p = record;
        *p++ = 3;
        // The caller checked vertex_count <= INT32_MAX, so every index fits an int.
        for (size_t k = 0; k < 3; ++k) p = put_le(p, static_cast<int32_t>(mesh.triangles[3 * t + k]));
        out.write(record, static_cast<size_t>(p - record));
    }
}

}  // namespace gmpu::io::detail
