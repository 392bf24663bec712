// OFF (Geomview Object File Format), ascii only, one vertex or face per line.
//
// Header variants [ST][C][N]OFF are read; the "N" variant's nx ny nz (right after x y z)
// become normals, and every other extra column (colours, texture coordinates, or the
// normals some plain-OFF writers append, e.g. the bunny00.off test mesh) is ignored, as
// are colours after a face's indices. 4OFF / nOFF (other dimensions) and "OFF BINARY" are
// rejected with GMPU_ERROR_UNSUPPORTED. '#' starts a comment.
#include <algorithm>
#include <string>
#include <string_view>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/number_format.hpp"
#include "io/text_scan.hpp"

namespace gmpu::io::detail {

namespace {

// Lines with their comments removed; blank ones skipped.
class ContentLines {
public:
    explicit ContentLines(LineReader &lines) : lines_(lines) {}
    bool next(std::string_view &line) {
        while (lines_.next(line)) {
            line = line.substr(0, line.find('#'));
            if (line.find_first_not_of(" \t\r\v\f") != std::string_view::npos) return true;
        }
        return false;
    }
    std::string at() const { return "line " + std::to_string(lines_.line_number()) + ": "; }
    uint64_t remaining() const { return lines_.remaining(); }

private:
    LineReader &lines_;
};

// Whether the header keyword names a variant we read, and whether it has normals.
bool off_keyword(std::string_view kw, bool &normals, const std::string &name) {
    if (kw.size() < 3 || kw.substr(kw.size() - 3) != "OFF") return false;
    std::string_view prefix = kw.substr(0, kw.size() - 3);
    if (!prefix.empty() && (prefix.back() == '4' || prefix.back() == 'n'))
        fail(GMPU_ERROR_UNSUPPORTED, name, "unsupported OFF variant " + quoted(kw) + " (only 3D is read)");
    if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
    if (!prefix.empty() && prefix.front() == 'C') prefix.remove_prefix(1);
    normals = !prefix.empty() && prefix.front() == 'N';
    if (normals) prefix.remove_prefix(1);
    return prefix.empty();
}

uint64_t count_token(std::string_view tok, const ContentLines &lines, const std::string &name, const char *what) {
    int64_t v = -1;
    if (!parse_integer(tok, v) || v < 0)
        fail(GMPU_ERROR_PARSE, name, lines.at() + "invalid " + what + " count " + quoted(tok));
    return static_cast<uint64_t>(v);
}

}  // namespace

Parsed parse_off_buffer(const char *data, size_t size, const std::string &name, Want want) {
    LineReader lines(data, data + size, name);
    return parse_off_lines(lines, name, want);
}

Parsed parse_off_lines(LineReader &reader, const std::string &name, Want want) {
    ContentLines lines(reader);
    std::string_view line, tok;
    bool normals = false;
    if (!lines.next(line) || !next_token(line, tok) || !off_keyword(tok, normals, name))
        fail(GMPU_ERROR_PARSE, name, "not an OFF file (no OFF header)");
    std::string_view counts = line;  // the counts may share the header's line
    if (!next_token(counts, tok)) {
        if (!lines.next(counts)) fail(GMPU_ERROR_PARSE, name, "no vertex and face counts after the header");
        next_token(counts, tok);
    } else if (tok == "BINARY") {
        fail(GMPU_ERROR_UNSUPPORTED, name, "binary OFF is not supported");
    }
    const uint64_t nv = count_token(tok, lines, name, "vertex");
    if (!next_token(counts, tok)) fail(GMPU_ERROR_PARSE, name, lines.at() + "no face count");
    const uint64_t nf = count_token(tok, lines, name, "face");

    Parsed out;
    const size_t columns = normals ? 6 : 3;
    // A vertex line takes at least 6 bytes ("0 0 0\n"): cap the reservation by that.
    const size_t cap = static_cast<size_t>(std::min<uint64_t>(nv, (lines.remaining() + 1) / 6));
    out.positions.reserve(3 * cap);
    if (normals) out.normals.reserve(3 * cap);
    for (uint64_t i = 0; i < nv; ++i) {
        if (!lines.next(line))
            fail(GMPU_ERROR_PARSE, name, "expected " + std::to_string(nv) + " vertices, file ends after " + std::to_string(i));
        double v[6];
        for (size_t k = 0; k < columns; ++k) {
            if (!next_token(line, tok))
                fail(GMPU_ERROR_PARSE, name, lines.at() + "vertex " + std::to_string(i) + " has fewer than " +
                                                 std::to_string(columns) + " numbers");
            NumberStatus st = parse_double(tok, v[k]);
            if (st == NumberStatus::out_of_range) fail(GMPU_ERROR_PARSE, name, lines.at() + "number out of range " + quoted(tok));
            if (st != NumberStatus::ok) fail(GMPU_ERROR_PARSE, name, lines.at() + "invalid number " + quoted(tok));
        }
        out.positions.insert(out.positions.end(), v, v + 3);
        if (normals) out.normals.insert(out.normals.end(), v + 3, v + 6);
    }
    if (want == Want::points) return out;

    out.triangles.reserve(3 * static_cast<size_t>(std::min<uint64_t>(nf, (lines.remaining() + 1) / 8)));
    std::vector<uint32_t> polygon;
    for (uint64_t f = 0; f < nf; ++f) {
        if (!lines.next(line))
            fail(GMPU_ERROR_PARSE, name, "expected " + std::to_string(nf) + " faces, file ends after " + std::to_string(f));
        next_token(line, tok);
        const uint64_t n = count_token(tok, lines, name, "face vertex");
        if (n < 3)
            fail(GMPU_ERROR_PARSE, name, lines.at() + "face " + std::to_string(f) + " has " + std::to_string(n) +
                                             " vertices (at least 3 needed)");
        polygon.clear();
        for (uint64_t k = 0; k < n; ++k) {
            int64_t idx = -1;
            if (!next_token(line, tok))
                fail(GMPU_ERROR_PARSE, name, lines.at() + "face " + std::to_string(f) + " lists fewer than " +
                                                 std::to_string(n) + " indices");
            if (!parse_integer(tok, idx)) fail(GMPU_ERROR_PARSE, name, lines.at() + "invalid vertex index " + quoted(tok));
            if (idx < 0 || static_cast<uint64_t>(idx) >= nv)
                fail(GMPU_ERROR_PARSE, name, lines.at() + "vertex index " + std::to_string(idx) + " out of range (" +
                                                 std::to_string(nv) + " vertices)");
            polygon.push_back(static_cast<uint32_t>(idx));
        }
        append_fan(out.triangles, polygon.data(), polygon.size());
    }
    return out;
}

void write_off(AtomicFile &out, const MeshView &mesh) {
    NumberLine line;
    line.text("OFF");
    out.write(line.finish());
    line.clear();
    line.number(uint64_t{mesh.vertex_count});
    line.number(uint64_t{mesh.triangle_count});
    line.number(uint64_t{0});
    out.write(line.finish());
    for (size_t i = 0; i < mesh.vertex_count; ++i) {
        line.clear();
        line.numbers(mesh.vertices + 3 * i, 3);
        out.write(line.finish());
    }
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
        line.clear();
        line.number(uint64_t{3});
        for (size_t k = 0; k < 3; ++k) line.number(uint64_t{mesh.triangles[3 * t + k]});
        out.write(line.finish());
    }
}

}  // namespace gmpu::io::detail
