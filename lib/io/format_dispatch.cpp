// The public entry points of io.hpp: pick the format from the extension, open the file
// (a regular file, or an IO error), parse it, check the values; or validate, write through AtomicFile and commit.
#include <cctype>
#include <climits>
#include <cmath>
#include <string>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/input_file.hpp"
#include "io/io.hpp"

namespace gmpu::io {

namespace detail {

namespace {

enum class Format { ply, xyz, off, obj, stl, glb };

// What each entry point accepts, for lookup and for the error message.
struct Accepts {
    const char *purpose;
    const char *list;  // for the message
    bool ply, xyz, off, obj;
    bool stl_glb = false;  // binary STL and glTF: written, never read
};
constexpr Accepts reading_points{"reading points", ".ply, .xyz, .txt, .off, .obj", true, true, true, true};
constexpr Accepts reading_meshes{"reading meshes", ".ply, .off, .obj", true, false, true, true};
constexpr Accepts writing_meshes{"writing meshes", ".ply, .obj, .off, .stl, .glb", true, false, true, true, true};
constexpr Accepts writing_points{"writing points", ".ply, .xyz", true, true, false, false};

// Lower-cased extension of the file name (without the dot), "" when it has none.
std::string extension(const std::string &path) {
    const size_t slash = path.find_last_of('/');
    const size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot + 1);
    for (char &c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

Format format_of(const std::string &path, const Accepts &a) {
    const std::string ext = extension(path);
    if (a.ply && ext == "ply") return Format::ply;
    if (a.xyz && (ext == "xyz" || (ext == "txt" && &a == &reading_points))) return Format::xyz;
    if (a.off && ext == "off") return Format::off;
    if (a.obj && ext == "obj") return Format::obj;
    if (a.stl_glb && ext == "stl") return Format::stl;
    if (a.stl_glb && ext == "glb") return Format::glb;
    fail(GMPU_ERROR_UNSUPPORTED, path,
         (ext.empty() ? std::string("no file extension") : "unsupported extension '." + ext + "'") + " for " +
             a.purpose + " (expected " + a.list + ")");
}

// PLY: its header first, checked, and only then the body (read whole: binary bodies are
// parsed in place). A 2 GB file that is not a PLY fails on its first bytes.
std::string read_ply_bytes(InputFile &file, const std::string &path) {
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
        if (check_ply_header(bytes.data(), bytes.size(), path) || at_end) break;
        want = bytes.size();  // doubling: a long header is scanned a bounded number of times
    }
    file.read_rest(bytes);
    return bytes;
}

Parsed parse(Format f, InputFile &file, const std::string &path, Want want) {
    if (f == Format::ply) {
        const std::string bytes = read_ply_bytes(file, path);
        return parse_ply_buffer(bytes.data(), bytes.size(), path, want);
    }
    // Text formats: read in chunks, the arrays sized once from a count of the lines, so a
    // text file costs the memory of its numbers, not of its bytes as well.
    const uint64_t line_count = f == Format::off ? 0 : count_lines(file, path);
    LineReader lines(file, path);
    switch (f) {
        case Format::xyz: return parse_xyz_lines(lines, path, line_count);
        case Format::off: return parse_off_lines(lines, path, want);
        case Format::obj: return parse_obj_lines(lines, path, want, line_count);
        case Format::ply:
        case Format::stl:
        case Format::glb: break;  // PLY is read above; STL and glTF are never read
    }
    fail(GMPU_ERROR_INTERNAL, path, "unknown format");
}

void check_finite(const std::vector<double> &v, const std::string &name, const char *what) {
    for (size_t i = 0; i < v.size(); ++i)
        if (!std::isfinite(v[i]))
            fail(GMPU_ERROR_INVALID_INPUT, name, "vertex " + std::to_string(i / 3) + " has a non-finite " + what +
                                                     " (" + std::to_string(v[i]) + ")");
}

}  // namespace

void check_points(const Parsed &parsed, const std::string &name) {
    if (parsed.positions.empty()) fail(GMPU_ERROR_INVALID_INPUT, name, "no points");
    check_finite(parsed.positions, name, "coordinate");
    check_finite(parsed.normals, name, "normal");
}

void check_mesh(const Parsed &parsed, const std::string &name) {
    if (parsed.positions.empty()) fail(GMPU_ERROR_INVALID_INPUT, name, "no vertices");
    check_finite(parsed.positions, name, "coordinate");
}

}  // namespace detail

using detail::fail;

PointCloud read_points(const std::string &path) {
    const detail::Format f = detail::format_of(path, detail::reading_points);
    detail::InputFile file(path);
    detail::Parsed parsed = detail::parse(f, file, path, detail::Want::points);
    detail::check_points(parsed, path);
    PointCloud cloud;
    cloud.positions = std::move(parsed.positions);
    cloud.normals = std::move(parsed.normals);
    return cloud;
}

MeshData read_mesh(const std::string &path) {
    const detail::Format f = detail::format_of(path, detail::reading_meshes);
    detail::InputFile file(path);
    detail::Parsed parsed = detail::parse(f, file, path, detail::Want::mesh);
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
    const detail::Format f = detail::format_of(path, detail::writing_meshes);
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
    switch (f) {
        case detail::Format::ply: detail::write_ply(out, mesh, true); break;
        case detail::Format::obj: detail::write_obj(out, mesh); break;
        case detail::Format::off: detail::write_off(out, mesh); break;
        case detail::Format::stl: detail::write_stl(out, mesh); break;
        case detail::Format::glb: detail::write_glb(out, mesh); break;
        case detail::Format::xyz: break;  // not accepted for meshes
    }
    out.commit();
}

void write_points(const std::string &path, const double *xyz, const double *normals, size_t count) {
    const detail::Format f = detail::format_of(path, detail::writing_points);
    check_arrays(path, xyz, normals, count);
    AtomicFile out(path);
    if (f == detail::Format::ply) {
        MeshView view;
        view.vertices = xyz;
        view.vertex_count = count;
        view.normals = normals;
        detail::write_ply(out, view, false);
    } else {
        detail::write_xyz(out, xyz, normals, count);
    }
    out.commit();
}

}  // namespace gmpu::io
