// The one exception type of the C++ core. It carries the C ABI status it maps to, so the
// API layer (lib/api) can turn any failure into a status code and a message without
// guessing; nothing else is allowed to cross that layer.
#pragma once

#include <stdexcept>
#include <string>

#include "gmpu/gmpu.h"

namespace gmpu {

class Error : public std::runtime_error {
public:
    Error(gmpu_status status, const std::string &message)
        : std::runtime_error(message), status_(status) {}
    gmpu_status status() const noexcept { return status_; }

private:
    gmpu_status status_;
};

}  // namespace gmpu
