#include "api/guard.hpp"

#include <cstdio>
#include <cstring>

namespace gmpu::api {

namespace {
// Fixed-size so that recording an error can never itself fail.
thread_local char last_message[1024] = "";
}  // namespace

void record_error(gmpu_status status, const char *message, std::string *handle_error) noexcept {
    const char *name = gmpu_status_name(status);
    std::snprintf(last_message, sizeof last_message, "%s: %s", name, message ? message : "");
    if (handle_error) {
        try {
            *handle_error = last_message;
        } catch (...) {
            // Out of memory while recording: the thread-local copy still has it.
        }
    }
}

const char *thread_error() noexcept { return last_message; }

}  // namespace gmpu::api
