// The exception firewall of the C ABI. Every exported function runs its body through
// guarded(): a gmpu::Error becomes its status, bad_alloc becomes OUT_OF_MEMORY, anything
// else INTERNAL; the message is recorded for gmpu_last_error() (thread-local) and, when
// the call modifies a handle, for that handle's last_error too.
#pragma once

#include <cstring>
#include <new>
#include <string>

#include "core/error.hpp"
#include "gmpu/gmpu.h"

namespace gmpu::api {

// Records a failure for gmpu_last_error() on this thread and, if given, in *handle_error.
void record_error(gmpu_status status, const char *message, std::string *handle_error) noexcept;

// Message of this thread's last failure ("" if none).
const char *thread_error() noexcept;

// The int a C caller passed for an enum (gmpu_param, gmpu_stat, gmpu_status). C allows any
// int there (a key of a newer header, say); in C++, loading an enum outside its enumerators'
// range is undefined, so the bits are read as an int and checked before the enum is used.
template <class E>
int enum_int(const E &e) noexcept {
    static_assert(sizeof(E) == sizeof(int), "C enums are int-sized");
    int v;
    std::memcpy(&v, &e, sizeof v);
    return v;
}

// Throws INVALID_ARGUMENT naming the parameter when p is null.
template <class T>
void require_arg(const T *p, const char *what) {
    if (p == nullptr) throw Error(GMPU_ERROR_INVALID_ARGUMENT, std::string(what) + " is NULL");
}

template <class Body>
gmpu_status guarded(std::string *handle_error, Body &&body) noexcept {
    try {
        body();
        return GMPU_OK;
    } catch (const Error &e) {
        record_error(e.status(), e.what(), handle_error);
        return e.status();
    } catch (const std::bad_alloc &) {
        record_error(GMPU_ERROR_OUT_OF_MEMORY, "out of memory", handle_error);
        return GMPU_ERROR_OUT_OF_MEMORY;
    } catch (const std::exception &e) {
        record_error(GMPU_ERROR_INTERNAL, e.what(), handle_error);
        return GMPU_ERROR_INTERNAL;
    } catch (...) {
        record_error(GMPU_ERROR_INTERNAL, "unknown internal error", handle_error);
        return GMPU_ERROR_INTERNAL;
    }
}

}  // namespace gmpu::api
