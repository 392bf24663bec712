#include "io/text_scan.hpp"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/error.hpp"

namespace gmpu::io::detail {

LineReader::LineReader(const char *begin, const char *end, const std::string &name)
    : p_(begin), end_(end), name_(name) {
    skip_bom();
}

LineReader::LineReader(ByteSource &source, const std::string &name)
    : p_(nullptr), end_(nullptr), source_(&source), buffer_(size_t{1} << 20), name_(name) {
    p_ = end_ = buffer_.data();
    refill();
    skip_bom();
}

void LineReader::too_long(uint64_t line) const {
    throw Error(GMPU_ERROR_PARSE, name_ + ": line " + std::to_string(line) + " is longer than " +
                                      std::to_string(max_line_bytes >> 20) + " MiB (not a text file?)");
}

void LineReader::skip_bom() {
    if (end_ - p_ >= 3 && std::memcmp(p_, "\xEF\xBB\xBF", 3) == 0) p_ += 3;
}

bool LineReader::refill() {
    if (!source_) return false;
    // Keep the partial line, moved to the front; a line longer than the buffer grows it.
    const size_t keep = static_cast<size_t>(end_ - p_);
    if (keep > 0 && p_ != buffer_.data()) std::memmove(buffer_.data(), p_, keep);
    if (keep == buffer_.size()) {
        if (keep >= max_line_bytes) too_long(line_ + 1);
        buffer_.resize(2 * buffer_.size());
    }
    p_ = buffer_.data();
    const size_t got = source_->read(buffer_.data() + keep, buffer_.size() - keep);
    end_ = p_ + keep + got;
    return got > 0;
}

bool LineReader::next(std::string_view &line) {
    const char *nl = nullptr;
    for (;;) {
        if (p_ != end_) nl = static_cast<const char *>(std::memchr(p_, '\n', static_cast<size_t>(end_ - p_)));
        if (nl) break;
        if (!refill()) break;  // the last line, without its newline
    }
    if (p_ == end_) return false;
    const char *stop = nl ? nl : end_;
    if (static_cast<size_t>(stop - p_) > max_line_bytes) too_long(line_ + 1);
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
