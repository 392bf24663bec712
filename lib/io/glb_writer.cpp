// glTF 2.0 binary (.glb): one scene, one node, one triangle mesh. The 12-byte header, a JSON
// chunk describing the mesh, and a BIN chunk holding float32 positions, float32 unit normals
// (when the mesh has them), float32 linear colours COLOR_0 (when it has them) and uint32 indices, each 4-byte aligned as the format requires.
// Positions get the min/max the specification demands, taken from the float32 values
// actually stored. A mesh without triangles is written as a valid file with an empty scene.
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/little_endian.hpp"

namespace gmpu::io::detail {

namespace {

// The shortest text that reads back as the same float; locale-independent, unlike printf.
std::string number(float x) {
    std::array<char, 32> text;
    const auto end = std::to_chars(text.data(), text.data() + text.size(), x).ptr;
    return std::string(text.data(), end);
}

std::string vec3(const float v[3]) {
    return "[" + number(v[0]) + "," + number(v[1]) + "," + number(v[2]) + "]";
}

// A unit normal as float32: glTF readers (and its validator) require unit length.
void unit(const double *n, float out[3]) {
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (size_t k = 0; k < 3; ++k) out[k] = length > 0 ? static_cast<float>(n[k] / length) : (k == 2 ? 1.0f : 0.0f);
}

// glTF colours are linear; PLY colours (as every 8-bit image) are sRGB-encoded.
float linear_of_srgb(uint8_t c) {
    const double x = c / 255.0;
    return static_cast<float>(x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4));
}

std::string json_of(const MeshView &mesh, const float lo[3], const float hi[3], size_t positions_bytes,
                    size_t normals_bytes, size_t colors_bytes, size_t indices_bytes) {
    const std::string n = std::to_string(mesh.vertex_count);
    std::string accessors = "{\"bufferView\":0,\"componentType\":5126,\"count\":" + n +
                            ",\"type\":\"VEC3\",\"min\":" + vec3(lo) + ",\"max\":" + vec3(hi) + "}";
    std::string views = "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":" + std::to_string(positions_bytes) +
                        ",\"target\":34962}";
    std::string attributes = "\"POSITION\":0";
    size_t offset = positions_bytes;
    size_t next = 1;
    if (mesh.normals) {
        accessors += ",{\"bufferView\":1,\"componentType\":5126,\"count\":" + n + ",\"type\":\"VEC3\"}";
        views += ",{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
                 ",\"byteLength\":" + std::to_string(normals_bytes) + ",\"target\":34962}";
        attributes += ",\"NORMAL\":1";
        offset += normals_bytes;
        ++next;
    }
    if (mesh.colors) {
        const std::string view = std::to_string(next);
        accessors += ",{\"bufferView\":" + view + ",\"componentType\":5126,\"count\":" + n + ",\"type\":\"VEC3\"}";
        views += ",{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
                 ",\"byteLength\":" + std::to_string(colors_bytes) + ",\"target\":34962}";
        attributes += ",\"COLOR_0\":" + view;
        offset += colors_bytes;
        ++next;
    }
    const std::string index = std::to_string(next);
    accessors += ",{\"bufferView\":" + index + ",\"componentType\":5125,\"count\":" +
                 std::to_string(3 * mesh.triangle_count) + ",\"type\":\"SCALAR\"}";
    views += ",{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
             ",\"byteLength\":" + std::to_string(indices_bytes) + ",\"target\":34963}";
    return "{\"asset\":{\"version\":\"2.0\",\"generator\":\"gmpu\"},\"scene\":0,"
           "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{" + attributes + "},\"indices\":" + index +
           ",\"mode\":4}]}],\"accessors\":[" + accessors + "],\"bufferViews\":[" + views +
           "],\"buffers\":[{\"byteLength\":" + std::to_string(offset + indices_bytes) + "}]}";
}

void write_u32(AtomicFile &out, uint32_t v) {
    char bytes[4];
    put_le(bytes, v);
    out.write(bytes, sizeof bytes);
}

}  // namespace

void write_glb(AtomicFile &out, const MeshView &mesh) {
    const bool empty = mesh.triangle_count == 0;
    const size_t positions_bytes = empty ? 0 : 12 * mesh.vertex_count;
    const size_t normals_bytes = empty || !mesh.normals ? 0 : 12 * mesh.vertex_count;
    const size_t indices_bytes = empty ? 0 : 12 * mesh.triangle_count;
    const size_t colors_bytes = empty || !mesh.colors ? 0 : 12 * mesh.vertex_count;
    const size_t bin_bytes = positions_bytes + normals_bytes + colors_bytes + indices_bytes;
    // The file's length is a uint32; the JSON is far below the margin left for it.
    if (mesh.vertex_count > UINT32_MAX / 36 || mesh.triangle_count > UINT32_MAX / 24 ||
        bin_bytes > UINT32_MAX - (size_t{1} << 20))
        fail(GMPU_ERROR_INVALID_INPUT, out.path(), "mesh too large for a .glb file (4 GiB at most)");

    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < (empty ? 0 : mesh.vertex_count); ++i)
        for (size_t k = 0; k < 3; ++k) {
            const float x = static_cast<float>(mesh.vertices[3 * i + k]);
            lo[k] = i == 0 || x < lo[k] ? x : lo[k];
            hi[k] = i == 0 || x > hi[k] ? x : hi[k];
        }
    std::string json = empty ? std::string("{\"asset\":{\"version\":\"2.0\",\"generator\":\"gmpu\"},"
                                           "\"scene\":0,\"scenes\":[{\"nodes\":[]}]}")
                             : json_of(mesh, lo, hi, positions_bytes, normals_bytes, colors_bytes, indices_bytes);
    json.append((4 - json.size() % 4) % 4, ' ');  // chunks are 4-byte aligned; JSON pads with spaces

    const size_t total = 12 + 8 + json.size() + (empty ? 0 : 8 + bin_bytes);
    out.write("glTF", 4);
    write_u32(out, 2);
    write_u32(out, static_cast<uint32_t>(total));
    write_u32(out, static_cast<uint32_t>(json.size()));
    out.write("JSON", 4);
    out.write(json);
    if (empty) return;
    write_u32(out, static_cast<uint32_t>(bin_bytes));
    out.write("BIN\0", 4);

    char record[12];
    for (size_t i = 0; i < mesh.vertex_count; ++i) {
        char *p = record;
        for (size_t k = 0; k < 3; ++k) p = put_le(p, static_cast<float>(mesh.vertices[3 * i + k]));
        out.write(record, sizeof record);
    }
    if (mesh.normals)
        for (size_t i = 0; i < mesh.vertex_count; ++i) {
            float n[3];
            unit(mesh.normals + 3 * i, n);
            char *p = record;
            for (float x : n) p = put_le(p, x);
            out.write(record, sizeof record);
        }
    if (mesh.colors)
        for (size_t i = 0; i < mesh.vertex_count; ++i) {
            char *p = record;
            for (size_t k = 0; k < 3; ++k) p = put_le(p, linear_of_srgb(mesh.colors[3 * i + k]));
            out.write(record, sizeof record);
        }
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        char *p = record;
        for (size_t k = 0; k < 3; ++k) p = put_le(p, mesh.triangles[3 * t + k]);
        out.write(record, sizeof record);
    }
}

}  // namespace gmpu::io::detail
