// Wavefront OBJ: `v x y z [w] [r g b]` vertices (only x y z kept) and, for meshes,
// `f` faces whose entries are `a`, `a/b`, `a/b/c` or `a//c` (only the vertex index a is
// used; negative indices count back from the last vertex read). Every other statement
// (vn, vt, g, o, s, usemtl, mtllib, l, ...) and '#' comments are ignored.
#include <string>
#include <string_view>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/number_format.hpp"
#include "io/text_scan.hpp"

namespace gmpu::io::detail {

Parsed parse_obj_buffer(const char *data, size_t size, const std::string &name, Want want) {
    LineReader lines(data, data + size, name);
    return parse_obj_lines(lines, name, want, 0);
}

Parsed parse_obj_lines(LineReader &lines, const std::string &name, Want want, uint64_t line_count) {
    Parsed out;
    // Every line may be a vertex: the bound reserves address space that the faces, normals
    // and texture lines of a mesh never touch (so it costs no memory), and no vertex ever
    // makes the array grow by copying.
    out.positions.reserve(3 * line_count);
    std::string_view line, tok;
    std::vector<uint32_t> polygon;
    while (lines.next(line)) {
        line = line.substr(0, line.find('#'));
        if (!next_token(line, tok)) continue;
        auto at = [&] { return "line " + std::to_string(lines.line_number()) + ": "; };
        if (tok == "v") {
            double v[3];
            for (double &c : v) {
                if (!next_token(line, tok)) fail(GMPU_ERROR_PARSE, name, at() + "a vertex needs x y z");
                NumberStatus st = parse_double(tok, c);
                if (st == NumberStatus::out_of_range) fail(GMPU_ERROR_PARSE, name, at() + "number out of range " + quoted(tok));
                if (st != NumberStatus::ok) fail(GMPU_ERROR_PARSE, name, at() + "invalid number " + quoted(tok));
            }
            out.positions.insert(out.positions.end(), v, v + 3);
        } else if (tok == "f" && want == Want::mesh) {
            // Faces may only use vertices defined above them, which is also what gives
            // negative indices their meaning.
            const int64_t defined = static_cast<int64_t>(out.positions.size() / 3);
            polygon.clear();
            while (next_token(line, tok)) {
                std::string_view vertex = tok.substr(0, tok.find('/'));
                int64_t idx = 0;
                if (!parse_integer(vertex, idx) || idx == 0)
                    fail(GMPU_ERROR_PARSE, name, at() + "invalid face vertex " + quoted(tok));
                const int64_t zero_based = idx > 0 ? idx - 1 : defined + idx;
                if (zero_based < 0 || zero_based >= defined)
                    fail(GMPU_ERROR_PARSE, name, at() + "vertex index " + std::to_string(idx) + " out of range (" +
                                                     std::to_string(defined) + " vertices so far)");
                polygon.push_back(static_cast<uint32_t>(zero_based));
            }
            if (polygon.size() < 3)
                fail(GMPU_ERROR_PARSE, name, at() + "a face needs at least 3 vertices, this one has " +
                                                 std::to_string(polygon.size()));
            append_fan(out.triangles, polygon.data(), polygon.size());
        }
    }
    return out;
}

void write_obj(AtomicFile &out, const MeshView &mesh) {
    out.write("# written by gmpu\n");
    NumberLine line;
    for (size_t i = 0; i < mesh.vertex_count; ++i) {
        line.clear();
        line.text("v");
        line.numbers(mesh.vertices + 3 * i, 3);
        out.write(line.finish());
    }
    if (mesh.normals) {
        for (size_t i = 0; i < mesh.vertex_count; ++i) {
            line.clear();
            line.text("vn");
            line.numbers(mesh.normals + 3 * i, 3);
            out.write(line.finish());
        }
    }
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        line.clear();
        line.text("f");
        for (size_t k = 0; k < 3; ++k) {
            const uint64_t index = uint64_t{mesh.triangles[3 * t + k]} + 1;  // OBJ counts from 1
            line.number(index);
            if (mesh.normals) {  // vertex i uses normal i
                line.text("//");
                line.raw(index);
            }
        }
        out.write(line.finish());
    }
}

}  // namespace gmpu::io::detail
