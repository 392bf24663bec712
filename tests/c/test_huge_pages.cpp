// Large arrays ask for transparent huge pages (core/huge_pages.hpp): the advice must reach
// the kernel for the arrays the pipeline fills point by point. Checked on the mapping's
// flags (VmFlags "hg" in /proc/self/smaps), which the advice sets whether or not huge pages
// are free at the moment, so the test does not depend on the machine's memory state. The
// working arrays' allocator (core/huge_page_allocator.hpp) is checked the same way.
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/huge_page_allocator.hpp"
#include "core/huge_pages.hpp"
#include "core/progress.hpp"
#include "core/resize_reporting.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu;

namespace {

// Whether the kernel takes the advice at all (THP compiled in and not switched off).
bool thp_available() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string mode((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return !mode.empty() && mode.find("[never]") == std::string::npos;
}

// The VmFlags of the mapping holding `address`, or "" when none does.
std::string vm_flags(const void *address) {
    const uintptr_t a = reinterpret_cast<uintptr_t>(address);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
            inside = lo <= a && a < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line;
    }
    return "";
}

bool advised(const void *address) { return vm_flags(address).find(" hg") != std::string::npos; }

const void *inside_aligned_part(const void *data) {
    constexpr uintptr_t kHuge = uintptr_t(2) << 20;
    return reinterpret_cast<const void *>((reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1));
}

void reported_arrays_are_advised(void **) {
    if (!thp_available()) skip();
    Progress silent(nullptr, nullptr, GMPU_STAGE_FIT);
    std::vector<float> big;
    assign_reporting(big, size_t(16) << 20, silent);  // 64 MB
    assert_true(advised(inside_aligned_part(big.data())));
}

// Eigen vectors sized uninitialised, as the solvers' work vectors are.
void eigen_vectors_are_advised(void **) {
    if (!thp_available()) skip();
    Eigen::VectorXd v(Eigen::Index(1) << 20);  // 8 MB
    advise_huge_pages(v);
    assert_true(advised(inside_aligned_part(v.data())));
}

void small_arrays_are_left_alone(void **) {
    if (!thp_available()) skip();
    std::vector<char> small(1 << 20);
    advise_huge_pages(small);  // less than one aligned 2 MB page: nothing to advise
    assert_false(advised(small.data()));
}

// A working array of 2 MB or more starts on a 2 MB boundary and lies on advised pages to its
// end; one grown past that size by push_back moves there with its contents.
void working_arrays_lie_on_whole_huge_pages(void **) {
    HugePageVector<double> big(size_t(3) << 18);  // 6 MB, value-initialised
    assert_int_equal(reinterpret_cast<uintptr_t>(big.data()) % kHugePageBytes, 0);
    for (double v : big) assert_true(v == 0.0);
    if (thp_available()) {
        assert_true(advised(big.data()));
        assert_true(advised(&big.back()));
    }
    HugePageVector<uint32_t> grown;
    for (uint32_t i = 0; i < (uint32_t(1) << 20); ++i) grown.push_back(i);  // 4 MB at the end
    assert_int_equal(reinterpret_cast<uintptr_t>(grown.data()) % kHugePageBytes, 0);
    for (uint32_t i = 0; i < grown.size(); ++i) assert_int_equal(grown[i], i);
    if (thp_available()) assert_true(advised(grown.data()));
}

void small_working_arrays_are_left_alone(void **) {
    HugePageVector<char> small(1 << 20);
    if (thp_available()) assert_false(advised(small.data()));
    small.assign(small.size(), 'x');
    assert_int_equal(small.back(), 'x');
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(reported_arrays_are_advised),
        cmocka_unit_test(eigen_vectors_are_advised),
        cmocka_unit_test(small_arrays_are_left_alone),
        cmocka_unit_test(working_arrays_lie_on_whole_huge_pages),
        cmocka_unit_test(small_working_arrays_are_left_alone),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
