// The per-format readers and writers behind io.hpp. Readers parse an in-memory buffer
// (`name` is only used in messages), so the fuzz targets in tests/fuzz call them directly.
// The file readers (format_dispatch.cpp) give the line-based formats a LineReader over the
// file read in chunks, and PLY its bytes once its header has been checked.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/io.hpp"
#include "io/read_ticker.hpp"

namespace gmpu::io {

class AtomicFile;

namespace detail {

// What a reader found. Parsers check structure (counts, indices, truncation, syntax);
// check_points / check_mesh then check the values (finiteness, emptiness).
struct Parsed {
    std::vector<double> positions;   // 3 per vertex
    std::vector<double> normals;     // 3 per vertex, or empty
    std::vector<uint8_t> colors;     // red green blue per vertex (PLY only), or empty
    std::vector<uint32_t> triangles; // 3 per triangle; filled only for Want::mesh
};

enum class Want { points, mesh };  // mesh: faces are parsed (and checked) too

// `ticker` (may be null) hears how much of the buffer is parsed, every thousand records.
Parsed parse_ply_buffer(const char *data, size_t size, const std::string &name, Want want,
                        const ReadTicker *ticker = nullptr);
Parsed parse_xyz_buffer(const char *data, size_t size, const std::string &name);
Parsed parse_off_buffer(const char *data, size_t size, const std::string &name, Want want);
Parsed parse_obj_buffer(const char *data, size_t size, const std::string &name, Want want);

// The line-based formats from a LineReader (a buffer, or a file read in chunks);
// line_count (an upper bound on the vertices, 0 if unknown) sizes the arrays once.
class LineReader;
Parsed parse_xyz_lines(LineReader &lines, const std::string &name, uint64_t line_count);
Parsed parse_off_lines(LineReader &lines, const std::string &name, Want want);
Parsed parse_obj_lines(LineReader &lines, const std::string &name, Want want, uint64_t line_count);

// PLY: the header alone, checked (GMPU_ERROR_PARSE / UNSUPPORTED as parse_ply_buffer), so
// that a file that is not a PLY fails before its body is read. `data` must hold the whole
// header; true if it does (an "end_header" line was found), with *vertices (when given) the
// vertex count the header claims.
bool check_ply_header(const char *data, size_t size, const std::string &name, uint64_t *vertices = nullptr);

// INVALID_INPUT for a non-finite coordinate or normal (naming the vertex index) and for
// an empty result ("no points" / "no vertices").
void check_points(const Parsed &parsed, const std::string &name, const ReadTicker *ticker = nullptr);
void check_mesh(const Parsed &parsed, const std::string &name);

// Writers append the whole file to `out`; the caller commits it. `mesh.triangles` is
// written only by the mesh formats; write_ply writes a face element only when faces is
// true (point files have none).
void write_ply(AtomicFile &out, const MeshView &mesh, bool faces);
void write_obj(AtomicFile &out, const MeshView &mesh);
void write_off(AtomicFile &out, const MeshView &mesh);
void write_xyz(AtomicFile &out, const double *xyz, const double *normals, size_t count);
void write_stl(AtomicFile &out, const MeshView &mesh);  // binary; face normals from the triangles
void write_glb(AtomicFile &out, const MeshView &mesh);  // glTF 2.0 binary; vertex normals when given

// The polygon of `count` vertex indices (already range-checked) as a triangle fan.
inline void append_fan(std::vector<uint32_t> &triangles, const uint32_t *polygon, size_t count) {
    for (size_t k = 1; k + 1 < count; ++k) {
        triangles.push_back(polygon[0]);
        triangles.push_back(polygon[k]);
        triangles.push_back(polygon[k + 1]);
    }
}

}  // namespace detail
}  // namespace gmpu::io
