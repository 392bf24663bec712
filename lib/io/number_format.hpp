// Text output of doubles for the ascii writers. std::to_chars writes the shortest string
// that reads back as exactly the same double (what "%.17g" guarantees, but shorter:
// "0.1", not "0.10000000000000001") and is several times faster than printf.
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace gmpu::io::detail {

// One output line: a prefix, then space-separated numbers.
class NumberLine {
public:
    void clear() { line_.clear(); }
    void text(std::string_view s) { line_ += s; }
    // Appends without a separator.
    template <class T>
    void raw(T v) {
        char buf[32];  // the longest double is 24 characters
        line_.append(buf, static_cast<size_t>(std::to_chars(buf, buf + sizeof buf, v).ptr - buf));
    }
    // Appends each value, space-separated from what came before.
    void numbers(const double *v, size_t count) {
        for (size_t k = 0; k < count; ++k) number(v[k]);
    }
    template <class T>
    void number(T v) {
        if (!line_.empty()) line_ += ' ';
        raw(v);
    }
    std::string_view finish() {
        line_ += '\n';
        return line_;
    }

private:
    std::string line_;  // reused: after the first line, no allocation
};

}  // namespace gmpu::io::detail
