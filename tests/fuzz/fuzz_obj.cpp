// libFuzzer target for the OBJ reader (parse_obj_buffer).
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    gmpu::fuzz::run([](const char *d, size_t n, gmpu::io::detail::Want want) {
        return gmpu::io::detail::parse_obj_buffer(d, n, "fuzz.obj", want);
    }, data, size);
    return 0;
}
