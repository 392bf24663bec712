// Scanning ascii formats from an in-memory buffer: lines, whitespace-separated tokens and
// numbers. Numbers go through std::from_chars (locale-independent, no allocation) and a
// token counts as a number only if it was consumed whole, so "1.0abc" is rejected.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace gmpu::io::detail {

inline bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

// Lines of a buffer. "\r\n" endings lose their '\r'; a last line without '\n' counts.
class LineReader {
public:
    LineReader(const char *begin, const char *end) : p_(begin), end_(end) {}
    bool next(std::string_view &line);
    size_t line_number() const { return line_; }  // 1-based, of the line last returned
    const char *position() const { return p_; }   // start of the next line
    size_t remaining() const { return static_cast<size_t>(end_ - p_); }

private:
    const char *p_;
    const char *end_;
    size_t line_ = 0;
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
