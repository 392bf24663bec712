#include "io/text_scan.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

namespace gmpu::io::detail {

bool LineReader::next(std::string_view &line) {
    if (p_ == end_) return false;
    const char *nl = static_cast<const char *>(std::memchr(p_, '\n', static_cast<size_t>(end_ - p_)));
    const char *stop = nl ? nl : end_;
    const char *line_end = stop;
    if (line_end != p_ && line_end[-1] == '\r') --line_end;
    line = std::string_view(p_, static_cast<size_t>(line_end - p_));
    p_ = nl ? nl + 1 : end_;
    ++line_;
    return true;
}

bool next_token(std::string_view &rest, std::string_view &token) {
    size_t i = 0;
    while (i < rest.size() && is_space(rest[i])) ++i;
    if (i == rest.size()) {
        rest = {};
        return false;
    }
    size_t j = i;
    while (j < rest.size() && !is_space(rest[j])) ++j;
    token = rest.substr(i, j - i);
    rest.remove_prefix(j);
    return true;
}

bool TokenReader::next(std::string_view &token) {
    while (p_ != end_ && is_space(*p_)) {
        if (*p_ == '\n') ++line_;
        ++p_;
    }
    if (p_ == end_) return false;
    const char *start = p_;
    while (p_ != end_ && !is_space(*p_)) ++p_;
    token = std::string_view(start, static_cast<size_t>(p_ - start));
    return true;
}

NumberStatus parse_double(std::string_view token, double &value) {
    const char *first = token.data();
    const char *last = first + token.size();
    // from_chars rejects the leading '+' that some writers emit; strip it (but not "+-1").
    if (first != last && *first == '+' && last - first > 1 && first[1] != '-') ++first;
    auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec == std::errc::result_out_of_range && ptr == last) {
        // from_chars cannot tell overflow from underflow; strtod on a copy can.
        std::string copy(first, last);
        double v = std::strtod(copy.c_str(), nullptr);
        if (std::isinf(v)) return NumberStatus::out_of_range;
        value = v;
        return NumberStatus::ok;
    }
    if (ec != std::errc() || ptr != last) return NumberStatus::invalid;
    return NumberStatus::ok;
}

bool parse_integer(std::string_view token, int64_t &value) {
    const char *first = token.data();
    const char *last = first + token.size();
    if (first != last && *first == '+' && last - first > 1 && first[1] != '-') ++first;
    auto [ptr, ec] = std::from_chars(first, last, value);
    return ec == std::errc() && ptr == last;
}

}  // namespace gmpu::io::detail
