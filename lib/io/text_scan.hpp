// Scanning ascii formats from an in-memory buffer: lines, whitespace-separated tokens and
// numbers. Numbers go through std::from_chars (locale-independent, no allocation) and a
// token counts as a number only if it was consumed whole, so "1.0abc" is rejected.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace gmpu::io::detail {

inline bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

// Where a LineReader gets more bytes when it is not given them all at once.
class ByteSource {
public:
    virtual ~ByteSource() = default;
    virtual size_t read(char *dst, size_t n) = 0;  // 0 at the end
    virtual uint64_t unread() const = 0;           // bytes not read yet
};

// Lines of a buffer, or of a source read in chunks (so that a text file's bytes are never
// all in memory at once). "\r\n" endings lose their '\r'; a last line without '\n' counts;
// a UTF-8 byte order mark before the first line is skipped (editors on Windows write one).
// A line longer than max_line_bytes is a GMPU_ERROR_PARSE naming `name`: no format read
// here has such lines, and a file without newlines (binary data, a sparse file) must fail
// without being read whole.
class LineReader {
public:
    static constexpr size_t max_line_bytes = size_t{16} << 20;

    LineReader(const char *begin, const char *end, const std::string &name);
    LineReader(ByteSource &source, const std::string &name);
    bool next(std::string_view &line);
    size_t line_number() const { return line_; }  // 1-based, of the line last returned
    // Start of the next line (buffer readers only: a source's buffer moves).
    const char *position() const { return p_; }
    uint64_t remaining() const { return static_cast<uint64_t>(end_ - p_) + (source_ ? source_->unread() : 0); }

private:
    bool refill();  // false at the end of the source
    void skip_bom();
    [[noreturn]] void too_long(uint64_t line) const;

    const char *p_;
    const char *end_;
    size_t line_ = 0;
    ByteSource *source_ = nullptr;
    std::vector<char> buffer_;
    const std::string &name_;
};

// Pops the next whitespace-separated token off the front of `rest`; false when none left.
bool next_token(std::string_view &rest, std::string_view &token);

// Tokens of a whole buffer regardless of line breaks (ascii PLY bodies), counting lines
// for error messages.
class TokenReader {
public:
    TokenReader(const char *begin, const char *end, size_t first_line)
        : p_(begin), end_(end), line_(first_line) {}
    bool next(std::string_view &token);
    size_t line_number() const { return line_; }  // line of the token last returned
    size_t remaining() const { return static_cast<size_t>(end_ - p_); }

private:
    const char *p_;
    const char *end_;
    size_t line_;
};

enum class NumberStatus { ok, invalid, out_of_range };

// Parses a whole token as a double. "nan" and "inf" parse (the caller rejects non-finite
// values with the vertex index); a value too large for a double is out_of_range, one too
// small becomes the nearest subnormal or zero.
NumberStatus parse_double(std::string_view token, double &value);

// Parses a whole token as a decimal integer.
bool parse_integer(std::string_view token, int64_t &value);

}  // namespace gmpu::io::detail
