// File formats: point clouds in, meshes and oriented points out. Every reader treats its
// input as hostile (bounded allocations, every count checked against the bytes present);
// every writer goes through AtomicFile so a failure never leaves a partial file.
// Failures throw gmpu::Error with GMPU_ERROR_IO / PARSE / UNSUPPORTED / INVALID_INPUT and
// a message that names the file and the problem.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace gmpu {
class Progress;
}

namespace gmpu::io {

// How a file is read: the memory budget (bytes; 0 is the library's default, half the
// physical memory) and where progress goes (null: nowhere; a cancel there stops the read).
struct ReadOptions {
    double max_memory = 0.0;
    Progress *progress = nullptr;
};

struct PointCloud {
    std::vector<double> positions;  // 3 per point
    std::vector<double> normals;    // 3 per point, or empty when the file has none
    std::vector<uint8_t> colors;    // red green blue per point (0..255), or empty
    size_t size() const { return positions.size() / 3; }
};

struct MeshData {
    std::vector<double> vertices;     // 3 per vertex
    std::vector<uint32_t> triangles;  // 3 per triangle (polygons are fan-triangulated)
};

// Borrowed arrays to write; normals may be null.
struct MeshView {
    const double *vertices = nullptr;
    size_t vertex_count = 0;
    const uint32_t *triangles = nullptr;
    size_t triangle_count = 0;
    const double *normals = nullptr;
    const double *confidence = nullptr;  // per vertex; written by .ply only (float property)
    const uint8_t *colors = nullptr;     // red green blue per vertex: .ply (uchar), .glb (COLOR_0)
};

// .ply (ascii, binary_little_endian, binary_big_endian), .xyz/.txt (3 or 6 columns),
// .off, .obj (vertices only). Format chosen by extension, case-insensitive.
//
// Which failure is which (every message starts with the path):
//   IO            the file is missing, unreadable, a directory or not a regular file (a FIFO,
//                 a device: refused before reading), with the system's reason;
//   UNSUPPORTED   the extension, a PLY format/version/property type, 4OFF/nOFF, binary OFF;
//   PARSE         bad syntax, a token that is not entirely a number ("1.0abc") or is beyond
//                 the double range ("1e999"), a header count the file does not hold
//                 ("expected N vertices, file ends after M"), a face index out of range;
//   INVALID_INPUT no points, or a NaN / infinite coordinate or normal (binary, or "nan" /
//                 "inf" in text), naming the vertex index;
//   LIMIT_EXCEEDED what the points would take in memory (from the PLY header's vertex count
//                 and the file's size, or a text file's line count) is over the budget:
//                 found before the body is read or parsed;
//   CANCELLED     the progress callback asked to stop.
// Per format: lib/io/ply_reader.cpp, xyz_format.cpp, off_format.cpp, obj_format.cpp.
PointCloud read_points(const std::string &path, const ReadOptions &options = {});

// Vertices and faces of .off, .obj or .ply meshes (used by tests and the benchmark).
MeshData read_mesh(const std::string &path);

// .ply (binary little-endian, with per-vertex normals when given), .obj, .off, .stl
// (binary, face normals), .glb (glTF 2.0 binary, float32, vertex normals when given).
void write_mesh(const std::string &path, const MeshView &mesh);

// .ply (binary little-endian; nx ny nz when normals is non-null) or .xyz (ascii).
void write_points(const std::string &path, const double *xyz, const double *normals,
                  size_t count);

}  // namespace gmpu::io
