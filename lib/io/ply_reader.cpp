// PLY 1.0 reader: ascii, binary_little_endian and binary_big_endian bodies, any scalar
// type, any extra elements and properties (skipped). Only the `vertex` element's
// x y z [nx ny nz] [red green blue, uchar] and, for meshes, the `face` element's
// vertex_indices are decoded.
//
// Hostile input: element counts come from the header and are never trusted. Elements of
// fixed-size records are bounds-checked (count × record ≤ bytes left) before anything is
// allocated; elements with list properties are walked record by record and every record
// consumes at least one byte, so no loop runs longer than the file; reservations are
// capped by what the remaining bytes can hold.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "core/huge_pages.hpp"
#include "io/errors.hpp"
#include "io/formats.hpp"
#include "io/text_scan.hpp"

namespace gmpu::io::detail {

namespace {

enum class Scalar : uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

size_t size_of(Scalar t) {
    static constexpr size_t sizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
    return sizes[static_cast<int>(t)];
}

bool is_integral(Scalar t) { return t != Scalar::f32 && t != Scalar::f64; }

bool scalar_from_name(std::string_view name, Scalar &t) {
    struct Entry {
        const char *name;
        Scalar type;
    };
    static constexpr Entry table[] = {
        {"char", Scalar::i8},     {"int8", Scalar::i8},      {"uchar", Scalar::u8},
        {"uint8", Scalar::u8},    {"short", Scalar::i16},    {"int16", Scalar::i16},
        {"ushort", Scalar::u16},  {"uint16", Scalar::u16},   {"int", Scalar::i32},
        {"int32", Scalar::i32},   {"uint", Scalar::u32},     {"uint32", Scalar::u32},
        {"float", Scalar::f32},   {"float32", Scalar::f32},  {"double", Scalar::f64},
        {"float64", Scalar::f64},
    };
    for (const Entry &e : table) {
        if (name == e.name) {
            t = e.type;
            return true;
        }
    }
    return false;
}

struct Property {
    std::string name;
    Scalar type = Scalar::f32;  // of the value, or of each list item
    bool is_list = false;
    Scalar count_type = Scalar::u8;  // lists only
};

struct Element {
    std::string name;
    uint64_t count = 0;
    std::vector<Property> props;
    size_t header_line = 0;

    bool has_lists() const {
        return std::any_of(props.begin(), props.end(), [](const Property &p) { return p.is_list; });
    }
    // Fewest bytes one binary record can take (a list may be empty).
    size_t min_record_size() const {
        size_t n = 0;
        for (const Property &p : props) n += size_of(p.is_list ? p.count_type : p.type);
        return n;
    }
    int find(std::string_view prop) const {
        for (size_t i = 0; i < props.size(); ++i)
            if (props[i].name == prop) return static_cast<int>(i);
        return -1;
    }
};

enum class Encoding { ascii, little, big };

struct Header {
    Encoding encoding = Encoding::ascii;
    std::vector<Element> elements;
    size_t body_offset = 0;  // first byte after "end_header\n"
    size_t body_line = 0;    // line number of the body's first line (ascii messages)
};

Header parse_header(const char *data, size_t size, const std::string &name) {
    LineReader lines(data, data + size, name);
    std::string_view line, tok;
    if (!lines.next(line) || line != "ply")
        fail(GMPU_ERROR_PARSE, name, "not a PLY file (the first line is not 'ply')");
    Header h;
    bool have_format = false;
    // Duplicate checks by hash, not by scanning what came before: a hostile header may list
    // hundreds of thousands of elements or properties.
    std::unordered_set<std::string> element_names;
    std::unordered_set<std::string> property_keys;  // element index, '\0', property name
    std::vector<std::string_view> args;             // of the current line
    while (lines.next(line)) {
        const size_t ln = lines.line_number();
        auto where = [&] { return "header line " + std::to_string(ln) + ": "; };
        std::string_view rest = line;
        if (!next_token(rest, tok)) continue;  // blank lines are harmless
        if (tok == "comment" || tok == "obj_info") continue;
        if (tok == "end_header") {
            if (!have_format) fail(GMPU_ERROR_PARSE, name, "no 'format' line before end_header");
            h.body_offset = static_cast<size_t>(lines.position() - data);
            h.body_line = ln + 1;
            return h;
        }
        const std::string_view keyword = tok;
        args.clear();
        while (next_token(rest, tok)) args.push_back(tok);
        if (keyword == "format") {
            if (args.size() != 2) fail(GMPU_ERROR_PARSE, name, where() + "expected 'format <type> 1.0'");
            if (args[0] == "ascii") h.encoding = Encoding::ascii;
            else if (args[0] == "binary_little_endian") h.encoding = Encoding::little;
            else if (args[0] == "binary_big_endian") h.encoding = Encoding::big;
            else fail(GMPU_ERROR_UNSUPPORTED, name, where() + "unknown PLY format " + quoted(args[0]));
            double version = 0;
            if (parse_double(args[1], version) != NumberStatus::ok || version != 1.0)
                fail(GMPU_ERROR_UNSUPPORTED, name, where() + "unsupported PLY version " + quoted(args[1]));
            have_format = true;
        } else if (keyword == "element") {
            int64_t count = -1;
            if (args.size() != 2 || !parse_integer(args[1], count) || count < 0)
                fail(GMPU_ERROR_PARSE, name, where() + "expected 'element <name> <count>'");
            Element e;
            e.name = std::string(args[0]);
            e.count = static_cast<uint64_t>(count);
            e.header_line = ln;
            if (!element_names.insert(e.name).second)
                fail(GMPU_ERROR_PARSE, name, where() + "duplicate element " + quoted(e.name));
            h.elements.push_back(std::move(e));
        } else if (keyword == "property") {
            if (h.elements.empty()) fail(GMPU_ERROR_PARSE, name, where() + "property before any element");
            Property p;
            if (!args.empty() && args[0] == "list") {
                if (args.size() != 4)
                    fail(GMPU_ERROR_PARSE, name, where() + "expected 'property list <count type> <type> <name>'");
                if (!scalar_from_name(args[1], p.count_type) || !scalar_from_name(args[2], p.type))
                    fail(GMPU_ERROR_UNSUPPORTED, name, where() + "unsupported list type");
                if (!is_integral(p.count_type))
                    fail(GMPU_ERROR_PARSE, name, where() + "list count type must be an integer type");
                p.is_list = true;
                p.name = std::string(args[3]);
            } else {
                if (args.size() != 2) fail(GMPU_ERROR_PARSE, name, where() + "expected 'property <type> <name>'");
                if (!scalar_from_name(args[0], p.type))
                    fail(GMPU_ERROR_UNSUPPORTED, name, where() + "unsupported property type " + quoted(args[0]));
                p.name = std::string(args[1]);
            }
            Element &e = h.elements.back();
            std::string key = std::to_string(h.elements.size() - 1);
            key += '\0';
            key += p.name;
            if (!property_keys.insert(std::move(key)).second)
                fail(GMPU_ERROR_PARSE, name, where() + "duplicate property " + quoted(p.name));
            e.props.push_back(std::move(p));
        } else {
            fail(GMPU_ERROR_PARSE, name, where() + "unknown header keyword " + quoted(keyword) +
                                                " (is end_header missing?)");
        }
    }
    fail(GMPU_ERROR_PARSE, name, "no end_header line");
}

// ---- binary bodies ----------------------------------------------------------------------

constexpr bool host_is_little = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

template <class T>
T load(const unsigned char *p, bool swap) {
    unsigned char b[sizeof(T)];
    if (swap) {
        for (size_t i = 0; i < sizeof(T); ++i) b[i] = p[sizeof(T) - 1 - i];
    } else {
        std::memcpy(b, p, sizeof(T));
    }
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

double load_scalar(const unsigned char *p, Scalar t, bool swap) {
    switch (t) {
        case Scalar::i8: return load<int8_t>(p, swap);
        case Scalar::u8: return load<uint8_t>(p, swap);
        case Scalar::i16: return load<int16_t>(p, swap);
        case Scalar::u16: return load<uint16_t>(p, swap);
        case Scalar::i32: return load<int32_t>(p, swap);
        case Scalar::u32: return load<uint32_t>(p, swap);
        case Scalar::f32: return load<float>(p, swap);
        case Scalar::f64: return load<double>(p, swap);
    }
    return 0;
}

// The fields a reader wants from one element: the property index whose value goes to
// out[k], or -1.
struct Wanted {
    int prop[9] = {-1, -1, -1, -1, -1, -1, -1, -1, -1};
    size_t n = 0;  // how many of prop[] are used (unfound ones stay -1)
};

// Vertex slots: x y z, then nx ny nz, then red green blue.
constexpr size_t kNormalSlot = 3, kColourSlot = 6;

class Body {
public:
    Body(const char *data, size_t size, const Header &h, const std::string &name, Want want, const ReadTicker *ticker)
        : h_(h), name_(name), want_(want), ticker_(ticker), size_(size),
          p_(reinterpret_cast<const unsigned char *>(data) + h.body_offset),
          end_(reinterpret_cast<const unsigned char *>(data) + size),
          tokens_(data + h.body_offset, data + size, h.body_line),
          swap_(h.encoding != Encoding::ascii && (h.encoding == Encoding::little) != host_is_little) {}

    Parsed run();

private:
    size_t left() const { return static_cast<size_t>(end_ - p_); }
    // Every kTickRecords records: the share of the buffer parsed (`ahead`: bytes past p_).
    static constexpr uint64_t kTickRecords = 1024;
    void tick(uint64_t item, size_t ahead = 0) const {
        if (!ticker_ || item % kTickRecords != 0) return;
        const size_t rest = h_.encoding == Encoding::ascii ? tokens_.remaining() : left() - ahead;
        ticker_->at(1.0 - double(rest) / double(std::max<size_t>(size_, 1)));
    }
    [[noreturn]] void truncated(const Element &e, uint64_t done) const {
        std::string what = e.name == "vertex" ? "vertices" : quoted(e.name) + " elements";
        fail(GMPU_ERROR_PARSE, name_, "expected " + std::to_string(e.count) + " " + what +
                                          ", file ends after " + std::to_string(done));
    }
    // ascii: the next token as a number; as an integer when `integral`.
    double ascii_value(const Element &e, uint64_t item, bool integral);
    // Reads one record, storing the wanted values in out; calls on_list(count, items) for
    // property `list_prop` (the face indices), skipping all other lists.
    template <class OnList>
    bool record(const Element &e, const Wanted &w, double *out, int list_prop, uint64_t item, OnList &&on_list);
    void vertices(const Element &e, Parsed &out);
    void faces(const Element &e, int list_prop, Parsed &out);
    void skip(const Element &e);

    const Header &h_;
    const std::string &name_;
    Want want_;
    const ReadTicker *ticker_;
    size_t size_;
    const unsigned char *p_;
    const unsigned char *end_;
    TokenReader tokens_;
    bool swap_;
    uint64_t vertex_count_ = 0;
    std::vector<uint32_t> polygon_;
};

double Body::ascii_value(const Element &e, uint64_t item, bool integral) {
    std::string_view tok;
    if (!tokens_.next(tok)) truncated(e, item);
    double v = 0;
    NumberStatus st = parse_double(tok, v);
    if (st == NumberStatus::out_of_range)
        fail(GMPU_ERROR_PARSE, name_, "line " + std::to_string(tokens_.line_number()) + ": number out of range " + quoted(tok));
    // Integers (list lengths, indices) must be whole and small enough to convert safely.
    if (st != NumberStatus::ok || (integral && !(std::trunc(v) == v && std::fabs(v) <= 9e15)))
        fail(GMPU_ERROR_PARSE, name_, "line " + std::to_string(tokens_.line_number()) + ": invalid " +
                                          (integral ? "integer " : "number ") + quoted(tok));
    return v;
}

template <class OnList>
bool Body::record(const Element &e, const Wanted &w, double *out, int list_prop, uint64_t item, OnList &&on_list) {
    const bool ascii = h_.encoding == Encoding::ascii;
    for (size_t pi = 0; pi < e.props.size(); ++pi) {
        const Property &p = e.props[pi];
        if (!p.is_list) {
            int slot = -1;
            for (size_t k = 0; k < w.n; ++k)
                if (w.prop[k] == static_cast<int>(pi)) slot = static_cast<int>(k);
            if (ascii) {
                if (slot >= 0) {
                    out[slot] = ascii_value(e, item, false);
                } else {
                    std::string_view tok;
                    if (!tokens_.next(tok)) truncated(e, item);
                }
            } else {
                size_t sz = size_of(p.type);
                if (left() < sz) truncated(e, item);
                if (slot >= 0) out[slot] = load_scalar(p_, p.type, swap_);
                p_ += sz;
            }
            continue;
        }
        // A list: its length, then that many items.
        double len_value;
        if (ascii) {
            len_value = ascii_value(e, item, true);
        } else {
            size_t sz = size_of(p.count_type);
            if (left() < sz) truncated(e, item);
            len_value = load_scalar(p_, p.count_type, swap_);
            p_ += sz;
        }
        if (len_value < 0)
            fail(GMPU_ERROR_PARSE, name_, quoted(e.name) + " " + std::to_string(item) + ": negative list length");
        const uint64_t len = static_cast<uint64_t>(len_value);
        const size_t item_size = size_of(p.type);
        // Bounds first: the length is the file's claim, not a fact.
        if (!ascii && len > left() / item_size) truncated(e, item);
        if (static_cast<int>(pi) == list_prop) {
            polygon_.clear();
            for (uint64_t k = 0; k < len; ++k) {
                double v;
                if (ascii) {
                    v = ascii_value(e, item, true);
                } else {
                    v = load_scalar(p_, p.type, swap_);
                    p_ += item_size;
                }
                if (v < 0 || v >= static_cast<double>(vertex_count_))
                    fail(GMPU_ERROR_PARSE, name_, "face " + std::to_string(item) + ": vertex index " +
                                                      std::to_string(static_cast<int64_t>(v)) + " out of range (" +
                                                      std::to_string(vertex_count_) + " vertices)");
                polygon_.push_back(static_cast<uint32_t>(v));
            }
            on_list(len);
        } else if (ascii) {
            std::string_view tok;
            for (uint64_t k = 0; k < len; ++k)
                if (!tokens_.next(tok)) truncated(e, item);
        } else {
            p_ += len * item_size;
        }
    }
    return true;
}

void Body::vertices(const Element &e, Parsed &out) {
    Wanted w;
    const char *names[] = {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue"};
    for (size_t k = 0; k < 9; ++k) {
        w.prop[k] = e.find(names[k]);
        if (w.prop[k] >= 0 && e.props[static_cast<size_t>(w.prop[k])].is_list)
            fail(GMPU_ERROR_PARSE, name_, "vertex property '" + std::string(names[k]) + "' is a list");
    }
    for (size_t k = 0; k < 3; ++k)
        if (w.prop[k] < 0)
            fail(GMPU_ERROR_PARSE, name_, "the vertex element has no '" + std::string(names[k]) + "' property");
    const int normals = (w.prop[3] >= 0) + (w.prop[4] >= 0) + (w.prop[5] >= 0);
    if (normals != 0 && normals != 3)
        fail(GMPU_ERROR_PARSE, name_, "the vertex element has some but not all of nx ny nz");
    // Colours are kept only as the common layout has them (all three, uchar); any other is
    // skipped like an unknown property.
    bool colours = true;
    for (size_t k = kColourSlot; k < 9; ++k)
        colours = colours && w.prop[k] >= 0 && e.props[static_cast<size_t>(w.prop[k])].type == Scalar::u8;
    if (!colours)
        for (size_t k = kColourSlot; k < 9; ++k) w.prop[k] = -1;
    const bool has_normals = normals != 0;
    w.n = colours ? 9 : has_normals ? 6 : 3;
    const auto keep = [&](const double *v) {
        out.positions.insert(out.positions.end(), v, v + 3);
        if (has_normals) out.normals.insert(out.normals.end(), v + kNormalSlot, v + kNormalSlot + 3);
        if (colours)
            for (size_t k = kColourSlot; k < 9; ++k)  // ascii may hold anything: out of range is 0
                out.colors.push_back(v[k] >= 0.0 && v[k] <= 255.0 ? static_cast<uint8_t>(v[k]) : 0);
    };

    const bool ascii = h_.encoding == Encoding::ascii;
    if (!ascii && !e.has_lists()) {
        // Fixed-size records: one bounds check, then a tight loop.
        const size_t rec = e.min_record_size();
        if (e.count > left() / rec) truncated(e, left() / rec);
        const size_t n = static_cast<size_t>(e.count);
        size_t offset[9];
        Scalar type[9];
        for (size_t k = 0; k < w.n; ++k) {
            offset[k] = 0;
            if (w.prop[k] < 0) continue;
            for (int pi = 0; pi < w.prop[k]; ++pi) offset[k] += size_of(e.props[static_cast<size_t>(pi)].type);
            type[k] = e.props[static_cast<size_t>(w.prop[k])].type;
        }
        // Reserved, then filled record by record: the pages are touched as the ticks go.
        out.positions.reserve(3 * n);
        advise_huge_pages(out.positions);
        if (has_normals) {
            out.normals.reserve(3 * n);
            advise_huge_pages(out.normals);
        }
        if (colours) out.colors.reserve(3 * n);
        double v[9];
        for (size_t i = 0; i < n; ++i) {
            tick(i, i * rec);
            const unsigned char *r = p_ + i * rec;
            for (size_t k = 0; k < w.n; ++k)
                if (w.prop[k] >= 0) v[k] = load_scalar(r + offset[k], type[k], swap_);
            keep(v);
        }
        p_ += n * rec;
        return;
    }
    // Records of varying size (a list in the vertex element) or text: one at a time, with
    // the reservation capped by what the remaining bytes can hold (a text record takes at
    // least two bytes per property: a digit and a separator).
    const size_t min_bytes = ascii ? 2 * e.props.size() : e.min_record_size();
    const size_t cap = (ascii ? tokens_.remaining() + 1 : left()) / min_bytes;
    const size_t reserve = static_cast<size_t>(std::min<uint64_t>(e.count, cap));
    out.positions.reserve(3 * reserve);
    if (has_normals) out.normals.reserve(3 * reserve);
    if (colours) out.colors.reserve(3 * reserve);
    double v[9];
    for (uint64_t i = 0; i < e.count; ++i) {
        tick(i);
        record(e, w, v, -1, i, [](uint64_t) {});
        keep(v);
    }
}

void Body::faces(const Element &e, int list_prop, Parsed &out) {
    const size_t min_bytes = h_.encoding == Encoding::ascii ? 2 : std::max<size_t>(e.min_record_size(), 1);
    const size_t cap = (h_.encoding == Encoding::ascii ? tokens_.remaining() + 1 : left()) / min_bytes;
    out.triangles.reserve(3 * static_cast<size_t>(std::min<uint64_t>(e.count, cap)));
    Wanted none;
    for (uint64_t i = 0; i < e.count; ++i) {
        tick(i);
        record(e, none, nullptr, list_prop, i, [&](uint64_t len) {
            if (len < 3)
                fail(GMPU_ERROR_PARSE, name_, "face " + std::to_string(i) + " has " + std::to_string(len) +
                                                  " vertices (at least 3 needed)");
            append_fan(out.triangles, polygon_.data(), polygon_.size());
        });
    }
}

void Body::skip(const Element &e) {
    if (e.props.empty()) return;  // nothing to read, however many the header claims
    if (h_.encoding != Encoding::ascii && !e.has_lists()) {
        const size_t rec = e.min_record_size();
        if (e.count > left() / rec) truncated(e, left() / rec);
        p_ += static_cast<size_t>(e.count) * rec;
        return;
    }
    Wanted none;
    for (uint64_t i = 0; i < e.count; ++i) {
        tick(i);
        record(e, none, nullptr, -1, i, [](uint64_t) {});
    }
}

Parsed Body::run() {
    const Element *vertex = nullptr;
    for (const Element &e : h_.elements)
        if (e.name == "vertex") vertex = &e;
    if (!vertex) fail(GMPU_ERROR_PARSE, name_, "no 'vertex' element");
    vertex_count_ = vertex->count;

    Parsed out;
    for (const Element &e : h_.elements) {
        if (&e == vertex) {
            vertices(e, out);
        } else if (want_ == Want::mesh && e.name == "face") {
            int list = e.find("vertex_indices");
            if (list < 0) list = e.find("vertex_index");
            if (list < 0 || !e.props[static_cast<size_t>(list)].is_list)
                fail(GMPU_ERROR_PARSE, name_, "the face element has no 'vertex_indices' list");
            if (!is_integral(e.props[static_cast<size_t>(list)].type))
                fail(GMPU_ERROR_PARSE, name_, "face 'vertex_indices' must have an integer type");
            faces(e, list, out);
        } else {
            skip(e);
        }
    }
    return out;
}

}  // namespace

bool check_ply_header(const char *data, size_t size, const std::string &name, uint64_t *vertices) {
    // The magic first: a file that is not a PLY fails on its first bytes.
    LineReader lines(data, data + size, name);
    std::string_view first;
    const char *nl = static_cast<const char *>(std::memchr(data, '\n', size));
    if ((nl || size >= 8) && (!lines.next(first) || first != "ply"))
        fail(GMPU_ERROR_PARSE, name, "not a PLY file (the first line is not 'ply')");
    // Then the whole header, once it is all there.
    for (const char *p = data;
         (p = static_cast<const char *>(std::memchr(p, '\n', size - static_cast<size_t>(p - data))));) {
        ++p;
        if (static_cast<size_t>(data + size - p) >= 10 && std::memcmp(p, "end_header", 10) == 0) {
            const Header h = parse_header(data, size, name);
            if (vertices) {
                *vertices = 0;
                for (const Element &e : h.elements)
                    if (e.name == "vertex") *vertices = e.count;
            }
            return true;
        }
    }
    return false;
}

Parsed parse_ply_buffer(const char *data, size_t size, const std::string &name, Want want, const ReadTicker *ticker) {
    Header h = parse_header(data, size, name);
    return Body(data, size, h, name, want, ticker).run();
}

}  // namespace gmpu::io::detail
