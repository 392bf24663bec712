#include "core/release_memory.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace gmpu {

void release_free_memory() noexcept {
#if defined(__GLIBC__)
    malloc_trim(0);  // other C libraries return memory on their own terms: nothing to do
#endif
}

}  // namespace gmpu
