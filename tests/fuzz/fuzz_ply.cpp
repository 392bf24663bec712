// libFuzzer target for the PLY reader (parse_ply_buffer).
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    gmpu::fuzz::run([](const char *d, size_t n, gmpu::io::detail::Want want) {
        return gmpu::io::detail::parse_ply_buffer(d, n, "fuzz.ply", want);
    }, data, size);
    return 0;
}
