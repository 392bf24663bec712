// Meant to fail: a check fails while a gmpu::Workers pool is alive on the test's stack, then
// the next test builds a pool in the same place, as a suite's next test would. The suite must
// end at once with the failure (meson's should_fail), not hang until its timeout: see
// abort_on_failure.c. Without that, this hangs in almost every run (the pairs repeat to make
// it every run).
#include <chrono>
#include <thread>

#include "core/parallel.hpp"
#include "core/progress.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

namespace {

// Both tests use their pool from this one frame, so each pool lies where the last one was
// left. The sleep gives every helper a share of each loop.
__attribute__((noinline)) void loop_on_a_pool(unsigned threads, bool fail) {
    gmpu::Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    gmpu::Workers workers(threads);
    for (int loop = 0; loop < 2; ++loop)
        gmpu::parallel_for(0, 64, workers, progress,
                           [](size_t) { std::this_thread::sleep_for(std::chrono::milliseconds(1)); }, 1);
    assert_true(!fail);
}

void fails_with_a_live_pool(void **) { loop_on_a_pool(8, true); }

void next_test_with_a_pool(void **) { loop_on_a_pool(3, false); }

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fails_with_a_live_pool), cmocka_unit_test(next_test_with_a_pool),
        cmocka_unit_test(fails_with_a_live_pool), cmocka_unit_test(next_test_with_a_pool),
        cmocka_unit_test(fails_with_a_live_pool), cmocka_unit_test(next_test_with_a_pool),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
