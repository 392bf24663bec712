/* Linked into every cmocka suite here: a failed check aborts the process instead of
 * longjmp-ing back to cmocka's runner.
 *
 * The jump skips every C++ destructor between the check and the runner. A gmpu::Workers pool
 * on the test's stack is then never stopped nor joined: its threads stay blocked on the pool's
 * condition variable in the abandoned frame; the next test builds its pool over that memory
 * while they wait, the condition variable's state no longer counts its waiters, and that pool's
 * destructor joins a thread no notification reaches: the suite hangs until meson's timeout.
 * A jump is no better from a check on a worker thread, or from a callback inside a library
 * loop. Under CMOCKA_TEST_ABORT=1 cmocka prints the failure and aborts, so the suite fails at
 * once, at that check (the tests after it do not run).
 *
 * Set from a constructor rather than meson's test environment so that a suite run by hand
 * behaves the same; CMOCKA_TEST_ABORT=0 in the environment keeps the jump. */
#define _POSIX_C_SOURCE 200809L
#include <stdlib.h>

__attribute__((constructor)) static void abort_on_failed_check(void) { setenv("CMOCKA_TEST_ABORT", "1", 0); }
