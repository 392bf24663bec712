// How the io module reports failures: every message starts with the file's path, so a
// caller juggling several files always knows which one is bad.
#pragma once

#include <cerrno>
#include <string>
#include <string_view>
#include <system_error>

#include "core/error.hpp"

namespace gmpu::io::detail {

[[noreturn]] inline void fail(gmpu_status status, const std::string &path,
                              const std::string &what) {
    throw Error(status, path + ": " + what);
}

// The system's reason for errno `err` ("No such file or directory"). Thread-safe, unlike
// strerror().
inline std::string system_reason(int err) {
    return std::error_code(err, std::generic_category()).message();
}

// A token from the file, quoted for a message and cut short: hostile files may hold
// megabyte-long "numbers". Bytes other than printable ASCII are shown as \xNN, so that the
// message stays one line of valid UTF-8 (bindings decode it, terminals print it).
inline std::string quoted(std::string_view token) {
    constexpr size_t max_shown = 40;
    static const char hex[] = "0123456789abcdef";
    std::string out = "'";
    for (size_t i = 0; i < token.size() && i < max_shown; ++i) {
        const unsigned char c = static_cast<unsigned char>(token[i]);
        if (c >= 0x20 && c < 0x7f) {
            out += char(c);
        } else {
            out += "\\x";
            out += hex[c >> 4];
            out += hex[c & 15];
        }
    }
    return out + (token.size() > max_shown ? "...'" : "'");
}

}  // namespace gmpu::io::detail
