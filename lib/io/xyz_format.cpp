// XYZ (also .txt): one point per line, "x y z" or "x y z nx ny nz", whitespace separated.
// Blank lines and '#' comments (to the end of the line) are skipped; the first data line
// fixes the column count and every other line must match it.
#include <string>
#include <string_view>

#include "io/atomic_file.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/number_format.hpp"
#include "io/text_scan.hpp"

namespace gmpu::io::detail {

Parsed parse_xyz_buffer(const char *data, size_t size, const std::string &name) {
    LineReader lines(data, data + size, name);
    return parse_xyz_lines(lines, name, 0);
}

Parsed parse_xyz_lines(LineReader &lines, const std::string &name, uint64_t line_count) {
    Parsed out;
    out.positions.reserve(3 * line_count);
    std::string_view line, tok;
    size_t columns = 0, first_line = 0;
    while (lines.next(line)) {
        line = line.substr(0, line.find('#'));
        double v[6];
        size_t n = 0;
        while (next_token(line, tok)) {
            auto at = [&] { return "line " + std::to_string(lines.line_number()) + ": "; };
            if (n == 6) fail(GMPU_ERROR_PARSE, name, at() + "more than 6 columns");
            NumberStatus st = parse_double(tok, v[n]);
            if (st == NumberStatus::out_of_range) fail(GMPU_ERROR_PARSE, name, at() + "number out of range " + quoted(tok));
            if (st != NumberStatus::ok) fail(GMPU_ERROR_PARSE, name, at() + "invalid number " + quoted(tok));
            ++n;
        }
        if (n == 0) continue;
        if (columns == 0) {
            if (n != 3 && n != 6)
                fail(GMPU_ERROR_PARSE, name, "line " + std::to_string(lines.line_number()) + ": " + std::to_string(n) +
                                                 " columns; expected 3 (x y z) or 6 (x y z nx ny nz)");
            columns = n;
            first_line = lines.line_number();
            if (columns == 6) out.normals.reserve(3 * line_count);
        } else if (n != columns) {
            fail(GMPU_ERROR_PARSE, name, "line " + std::to_string(lines.line_number()) + ": " + std::to_string(n) +
                                             " columns, but line " + std::to_string(first_line) + " has " +
                                             std::to_string(columns));
        }
        out.positions.insert(out.positions.end(), v, v + 3);
        if (columns == 6) out.normals.insert(out.normals.end(), v + 3, v + 6);
    }
    return out;
}

void write_xyz(AtomicFile &out, const double *xyz, const double *normals, size_t count) {
    NumberLine line;
    for (size_t i = 0; i < count; ++i) {
        line.clear();
        line.numbers(xyz + 3 * i, 3);
        if (normals) line.numbers(normals + 3 * i, 3);
        out.write(line.finish());
    }
}

}  // namespace gmpu::io::detail
