// The public entry points of io.hpp: pick the format's row (kFormats) from the extension,
// open the file (a regular file, or an IO error), parse it, check the values; or validate,
// write through AtomicFile and commit. A new format is one row plus its reader and writer.
#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/memory_budget.hpp"

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/input_file.hpp"
#include "io/io.hpp"

namespace gmpu::io {

namespace detail {

namespace {

// What reading `points` points takes at most, on top of `held` bytes of the file in memory:
// positions and normals as doubles. Over the budget: LIMIT_EXCEEDED, before the arrays or
// the body exist.
constexpr double kBytesPerPoint = 6 * sizeof(double);
constexpr size_t kLineBufferBytes = size_t{1} << 20;  // a text reader's chunk
void check_read_memory(const std::string &path, uint64_t points, double held, double budget) {
    const double estimate = held + double(points) * kBytesPerPoint;
    if (estimate <= budget) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  "reading it needs about %.3g bytes (%llu points), over the memory budget of %.3g bytes "
                  "(GMPU_PARAM_MAX_MEMORY)",
                  estimate, static_cast<unsigned long long>(points), budget);
    fail(GMPU_ERROR_LIMIT_EXCEEDED, path, text);
}

// PLY: its header first, checked, and only then the body (read whole: binary bodies are
// parsed in place). A 2 GB file that is not a PLY fails on its first bytes; one whose
// header claims more points than the budget holds, before its body is read.
std::string read_ply_bytes(InputFile &file, const std::string &path, double budget) {
    std::string bytes;
    size_t want = size_t{64} << 10;
    for (;;) {
        const size_t had = bytes.size();
        bytes.resize(had + want);
        size_t got = had;
        while (got < bytes.size()) {
            const size_t n = file.read(&bytes[got], bytes.size() - got);
            if (n == 0) break;
            got += n;
        }
        const bool at_end = got < bytes.size();
        bytes.resize(got);
        uint64_t vertices = 0;
        if (check_ply_header(bytes.data(), bytes.size(), path, &vertices)) {
            // Counted up to what the file's bytes can hold (a vertex takes three at least):
            // a header that claims more is a truncated file, which the parse reports.
            check_read_memory(path, std::min<uint64_t>(vertices, file.size() / 3), double(file.size()), budget);
            break;
        }
        if (at_end) break;
        want = bytes.size();  // doubling: a long header is scanned a bounded number of times
    }
    file.read_rest(bytes);
    return bytes;
}

// Progress: the bytes read, then parsed, each pass a share of the whole (the values' check
// after it takes the last tenth).
Parsed read_ply(InputFile &file, const std::string &path, Want want, double budget, ReadTicker &ticker) {
    file.set_ticker(&ticker);
    ticker.pass(0.0, 0.45);
    const std::string bytes = read_ply_bytes(file, path, budget);
    file.set_ticker(nullptr);
    ticker.pass(0.45, 0.45);
    return parse_ply_buffer(bytes.data(), bytes.size(), path, want, &ticker);
}

// Text formats: read in chunks, the arrays sized once from a count of the lines, so a text
// file costs the memory of its numbers, not of its bytes as well. The count (an upper bound
// on the points) is checked against the budget before the parse.
uint64_t count_text_lines(InputFile &file, const std::string &path, double budget, ReadTicker &ticker) {
    file.set_ticker(&ticker);
    ticker.pass(0.0, 0.2);
    const uint64_t line_count = count_lines(file, path);
    check_read_memory(path, line_count, double(kLineBufferBytes), budget);
    ticker.pass(0.2, 0.7);
    return line_count;
}
Parsed read_xyz(InputFile &file, const std::string &path, Want, double budget, ReadTicker &ticker) {
    const uint64_t line_count = count_text_lines(file, path, budget, ticker);
    LineReader lines(file, path);
    return parse_xyz_lines(lines, path, line_count);
}
Parsed read_off(InputFile &file, const std::string &path, Want want, double budget, ReadTicker &ticker) {
    count_text_lines(file, path, budget, ticker);
    LineReader lines(file, path);
    return parse_off_lines(lines, path, want);
}
Parsed read_obj(InputFile &file, const std::string &path, Want want, double budget, ReadTicker &ticker) {
    const uint64_t line_count = count_text_lines(file, path, budget, ticker);
    LineReader lines(file, path);
    return parse_obj_lines(lines, path, want, line_count);
}

void write_ply_mesh(AtomicFile &out, const MeshView &mesh) { write_ply(out, mesh, true); }
void write_ply_points(AtomicFile &out, const double *xyz, const double *normals, size_t count) {
    MeshView view;
    view.vertices = xyz;
    view.vertex_count = count;
    view.normals = normals;
    write_ply(out, view, false);
}

// One row per format: its extensions and what reads and writes it (null: not supported).
struct FormatRow {
    const char *extension;       // lower case, without the dot
    const char *read_extension;  // another name accepted when reading points, or null
    Parsed (*read_points)(InputFile &, const std::string &, Want, double budget, ReadTicker &);
    Parsed (*read_mesh)(InputFile &, const std::string &, Want, double budget, ReadTicker &);
    void (*write_mesh)(AtomicFile &, const MeshView &);
    void (*write_points)(AtomicFile &, const double *, const double *, size_t);
};
constexpr FormatRow kFormats[] = {
    {"ply", nullptr, read_ply, read_ply, write_ply_mesh, write_ply_points},
    {"obj", nullptr, read_obj, read_obj, write_obj, nullptr},
    {"off", nullptr, read_off, read_off, write_off, nullptr},
    {"xyz", "txt", read_xyz, nullptr, nullptr, write_xyz},
    {"stl", nullptr, nullptr, nullptr, write_stl, nullptr},  // binary STL, written only
    {"glb", nullptr, nullptr, nullptr, write_glb, nullptr},  // glTF 2.0 binary, written only
};

// The roles a format can play, for lookup and for the error message.
enum class Role { read_points, read_mesh, write_mesh, write_points };

bool plays(const FormatRow &row, Role role) {
    switch (role) {
        case Role::read_points: return row.read_points != nullptr;
        case Role::read_mesh: return row.read_mesh != nullptr;
        case Role::write_mesh: return row.write_mesh != nullptr;
        case Role::write_points: return row.write_points != nullptr;
    }
    return false;
}

const char *purpose(Role role) {
    switch (role) {
        case Role::read_points: return "reading points";
        case Role::read_mesh: return "reading meshes";
        case Role::write_mesh: return "writing meshes";
        case Role::write_points: return "writing points";
    }
    return "";
}

// Lower-cased extension of the file name (without the dot), "" when it has none.
std::string extension(const std::string &path) {
    const size_t slash = path.find_last_of('/');
    const size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot + 1);
    for (char &c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

const FormatRow &format_of(const std::string &path, Role role) {
    const std::string ext = extension(path);
    std::string list;
    for (const FormatRow &row : kFormats) {
        if (!plays(row, role)) continue;
        const bool reads_alias = role == Role::read_points && row.read_extension;
        if (ext == row.extension || (reads_alias && ext == row.read_extension)) return row;
        list += std::string(list.empty() ? "." : ", .") + row.extension;
        if (reads_alias) list += std::string(", .") + row.read_extension;
    }
    fail(GMPU_ERROR_UNSUPPORTED, path,
         (ext.empty() ? std::string("no file extension") : "unsupported extension '." + ext + "'") + " for " +
             purpose(role) + " (expected " + list + ")");
}

void check_finite(const std::vector<double> &v, const std::string &name, const char *what,
                  const ReadTicker *ticker) {
    constexpr size_t kTickValues = size_t{1} << 16;
    for (size_t i = 0; i < v.size(); ++i) {
        if (ticker && i % kTickValues == 0) ticker->at(double(i) / double(v.size()));
        if (!std::isfinite(v[i]))
            fail(GMPU_ERROR_INVALID_INPUT, name, "vertex " + std::to_string(i / 3) + " has a non-finite " + what +
                                                     " (" + std::to_string(v[i]) + ")");
    }
}

}  // namespace

void check_points(const Parsed &parsed, const std::string &name, const ReadTicker *ticker) {
    if (parsed.positions.empty()) fail(GMPU_ERROR_INVALID_INPUT, name, "no points");
    check_finite(parsed.positions, name, "coordinate", ticker);
    check_finite(parsed.normals, name, "normal", ticker);
}

void check_mesh(const Parsed &parsed, const std::string &name) {
    if (parsed.positions.empty()) fail(GMPU_ERROR_INVALID_INPUT, name, "no vertices");
    check_finite(parsed.positions, name, "coordinate", nullptr);
}

}  // namespace detail

using detail::fail;

PointCloud read_points(const std::string &path, const ReadOptions &options) {
    const detail::FormatRow &format = detail::format_of(path, detail::Role::read_points);
    detail::InputFile file(path);
    detail::ReadTicker ticker{options.progress};
    const double budget = options.max_memory > 0.0 ? options.max_memory : default_memory_budget();
    detail::Parsed parsed = format.read_points(file, path, detail::Want::points, budget, ticker);
    ticker.pass(0.9, 0.1);
    detail::check_points(parsed, path, &ticker);
    PointCloud cloud;
    cloud.positions = std::move(parsed.positions);
    cloud.normals = std::move(parsed.normals);
    cloud.colors = std::move(parsed.colors);
    return cloud;
}

MeshData read_mesh(const std::string &path) {
    const detail::FormatRow &format = detail::format_of(path, detail::Role::read_mesh);
    detail::InputFile file(path);
    detail::ReadTicker ticker;
    detail::Parsed parsed = format.read_mesh(file, path, detail::Want::mesh, default_memory_budget(), ticker);
    detail::check_mesh(parsed, path);
    MeshData mesh;
    mesh.vertices = std::move(parsed.positions);
    mesh.triangles = std::move(parsed.triangles);
    return mesh;
}

namespace {

// The writers trust their input; check it here, before any file is created.
void check_arrays(const std::string &path, const double *xyz, const double *normals, size_t count) {
    if (count > 0 && !xyz) fail(GMPU_ERROR_INVALID_ARGUMENT, path, "vertex array is NULL");
    for (size_t i = 0; i < 3 * count; ++i) {
        if (!std::isfinite(xyz[i]))
            fail(GMPU_ERROR_INVALID_INPUT, path, "vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
        if (normals && !std::isfinite(normals[i]))
            fail(GMPU_ERROR_INVALID_INPUT, path, "vertex " + std::to_string(i / 3) + " has a non-finite normal");
    }
}

}  // namespace

void write_mesh(const std::string &path, const MeshView &mesh) {
    const detail::FormatRow &format = detail::format_of(path, detail::Role::write_mesh);
    check_arrays(path, mesh.vertices, mesh.normals, mesh.vertex_count);
    if (mesh.triangle_count > 0 && !mesh.triangles)
        fail(GMPU_ERROR_INVALID_ARGUMENT, path, "triangle array is NULL");
    // PLY stores indices as int.
    if (mesh.vertex_count > static_cast<size_t>(INT32_MAX))
        fail(GMPU_ERROR_INVALID_INPUT, path, "more than 2^31 - 1 vertices");
    for (size_t i = 0; i < 3 * mesh.triangle_count; ++i)
        if (mesh.triangles[i] >= mesh.vertex_count)
            fail(GMPU_ERROR_INVALID_INPUT, path, "triangle " + std::to_string(i / 3) + " uses vertex " +
                                                     std::to_string(mesh.triangles[i]) + " of " +
                                                     std::to_string(mesh.vertex_count));
    AtomicFile out(path);
    format.write_mesh(out, mesh);
    out.commit();
}

void write_points(const std::string &path, const double *xyz, const double *normals, size_t count) {
    const detail::FormatRow &format = detail::format_of(path, detail::Role::write_points);
    check_arrays(path, xyz, normals, count);
    AtomicFile out(path);
    format.write_points(out, xyz, normals, count);
    out.commit();
}

}  // namespace gmpu::io
