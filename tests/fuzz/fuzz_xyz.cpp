// libFuzzer target for the XYZ reader (parse_xyz_buffer; it has no faces, so both modes
// parse the same way).
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    gmpu::fuzz::run([](const char *d, size_t n, gmpu::io::detail::Want) {
        return gmpu::io::detail::parse_xyz_buffer(d, n, "fuzz.xyz");
    }, data, size);
    return 0;
}
