// Status names, the thread-local last error, and the version queries.
#include "api/guard.hpp"
#include "gmpu/gmpu.h"

#define GMPU_STR2(x) #x
#define GMPU_STR(x) GMPU_STR2(x)
static_assert(GMPU_VERSION_NUMBER ==
                  GMPU_VERSION_MAJOR * 10000 + GMPU_VERSION_MINOR * 100 + GMPU_VERSION_PATCH,
              "GMPU_VERSION_NUMBER disagrees with its parts");

extern "C" {

GMPU_API const char *gmpu_status_name(gmpu_status status) {
    switch (gmpu::api::enum_int(status)) {  // any int may come from C (see enum_int)
        case GMPU_OK: return "GMPU_OK";
        case GMPU_ERROR_INVALID_ARGUMENT: return "GMPU_ERROR_INVALID_ARGUMENT";
        case GMPU_ERROR_INVALID_INPUT: return "GMPU_ERROR_INVALID_INPUT";
        case GMPU_ERROR_DEGENERATE_INPUT: return "GMPU_ERROR_DEGENERATE_INPUT";
        case GMPU_ERROR_WRONG_ORDER: return "GMPU_ERROR_WRONG_ORDER";
        case GMPU_ERROR_OUT_OF_MEMORY: return "GMPU_ERROR_OUT_OF_MEMORY";
        case GMPU_ERROR_LIMIT_EXCEEDED: return "GMPU_ERROR_LIMIT_EXCEEDED";
        case GMPU_ERROR_CANCELLED: return "GMPU_ERROR_CANCELLED";
        case GMPU_ERROR_IO: return "GMPU_ERROR_IO";
        case GMPU_ERROR_PARSE: return "GMPU_ERROR_PARSE";
        case GMPU_ERROR_UNSUPPORTED: return "GMPU_ERROR_UNSUPPORTED";
        case GMPU_ERROR_INTERNAL: return "GMPU_ERROR_INTERNAL";
        case GMPU_ERROR_BUSY: return "GMPU_ERROR_BUSY";
    }
    return "GMPU_UNKNOWN_STATUS";
}

GMPU_API const char *gmpu_last_error(void) { return gmpu::api::thread_error(); }

GMPU_API uint32_t gmpu_version_number(void) { return GMPU_VERSION_NUMBER; }

GMPU_API const char *gmpu_version_string(void) { return GMPU_STR(GMPU_VERSION_MAJOR) "." GMPU_STR(GMPU_VERSION_MINOR) "." GMPU_STR(
        GMPU_VERSION_PATCH); }

GMPU_API uint32_t gmpu_abi_version(void) { return GMPU_ABI_VERSION; }

}  // extern "C"
