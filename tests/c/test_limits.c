/* Resource caps through the C ABI: GMPU_PARAM_MAX_CELLS and GMPU_PARAM_MAX_TRIANGLES fail
 * cleanly with GMPU_ERROR_LIMIT_EXCEEDED exactly past the cap (the cap itself is allowed),
 * quickly, without keeping a partial result, and leave the handle usable;
 * GMPU_PARAM_MAX_DEPTH caps GMPU_STAT_DEPTH; a process limit that refuses worker threads
 * costs parallelism, never the process or the result; GMPU_PARAM_MAX_MEMORY refuses what
 * would not fit the budget. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "gmpu/gmpu.h"
#include "robust_util.h"

static size_t g_n;
static double *g_bumpy; /* g_n points on a bumpy sphere: fit subdivides to depth ~6 */

static int setup(void **state) {
    (void)state;
    g_n = robust_quick() ? 4000 : ROBUST_INSTRUMENTED ? 8000 : 30000; /* valgrind, sanitizers: smaller */
    g_bumpy = robust_bumpy_sphere(g_n, 5);
    return g_bumpy ? 0 : -1;
}

static int teardown(void **state) {
    (void)state;
    free(g_bumpy);
    return 0;
}

static double stat_of(const gmpu_surface *s, gmpu_stat key) {
    double v = -1;
    assert_ok(gmpu_surface_get_stat(s, key, &v));
    return v;
}

static gmpu_surface *surface_with_points(void) {
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 40));
    /* The blend alone: orient's own memory and time, without the smooth solve that the
     * automatic surface adds on the smaller clouds of instrumented runs. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 0));
    assert_ok(gmpu_surface_set_points_f64(s, g_bumpy, g_n, 0));
    return s;
}

static void test_max_cells(void **state) {
    (void)state;
    gmpu_surface *s = surface_with_points();
    double v = 0;
    assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_MAX_CELLS, &v));
    assert_true(v == 2e7); /* the documented default */

    assert_ok(gmpu_surface_fit(s));
    const double cells = stat_of(s, GMPU_STAT_CELLS);
    const double full_fit_seconds = stat_of(s, GMPU_STAT_FIT_SECONDS);
    assert_true(cells > 200); /* the cloud needs a real octree for this test to mean anything */

    /* The cap itself is allowed; one fewer is not. Changing the cap discards the fit. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_CELLS, cells));
    assert_ok(gmpu_surface_fit(s));
    assert_true(stat_of(s, GMPU_STAT_CELLS) == cells);
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_CELLS, cells - 1));
    double f = 0;
    const double centre[3] = {0, 0, 0};
    check_failure(gmpu_surface_evaluate(s, centre, 1, &f, NULL), GMPU_ERROR_WRONG_ORDER, "orient");
    char needle[96];
    snprintf(needle, sizeof needle, "GMPU_PARAM_MAX_CELLS = %.0f", cells - 1);
    check_failure(gmpu_surface_fit(s), GMPU_ERROR_LIMIT_EXCEEDED, needle);
    assert_non_null(strstr(gmpu_surface_last_error(s), needle));
    /* Nothing partial is kept: no cells, and orient still needs a fit. */
    assert_true(stat_of(s, GMPU_STAT_CELLS) == 0);
    check_failure(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");

    /* Tiny caps fail fast, whatever the level at which they are crossed. */
    const double caps[] = {1, 8, 9, 60, cells / 4};
    for (size_t k = 0; k < sizeof caps / sizeof *caps; ++k) {
        assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_CELLS, floor(caps[k])));
        double t0 = robust_now();
        check_failure(gmpu_surface_fit(s), GMPU_ERROR_LIMIT_EXCEEDED, "GMPU_PARAM_MAX_CELLS");
        double took = robust_now() - t0;
        if (!robust_quick() && took > full_fit_seconds + 0.5)
            fail_msg("cap %g: the failing fit took %.3f s, the whole fit %.3f s", caps[k], took, full_fit_seconds);
    }

    /* Back to a big cap: the same handle fits, orients and meshes. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_CELLS, 1e9));
    gmpu_mesh *m = robust_reconstruct(s, g_bumpy, g_n);
    assert_true(stat_of(s, GMPU_STAT_CELLS) == cells);
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
}

static void test_max_triangles(void **state) {
    (void)state;
    gmpu_surface *s = surface_with_points();
    double v = 0;
    assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_MAX_TRIANGLES, &v));
    assert_true(v == 1e8);
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    const size_t tris = gmpu_mesh_triangle_count(m);
    const double full_seconds = stat_of(s, GMPU_STAT_POLYGONIZE_SECONDS);
    assert_true(tris > 1000);
    gmpu_mesh_destroy(m);

    /* The cap counts the triangles marching cubes makes, before pieces that no input
     * point supports are dropped, so its exact boundary is not observable from here: half
     * the final count fails, 1.5 times it succeeds. Neither discards the orientation. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_TRIANGLES, (double)(tris + tris / 2)));
    m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_int_equal(gmpu_mesh_triangle_count(m), tris);
    gmpu_mesh_destroy(m);
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_TRIANGLES, (double)(tris / 2)));
    m = (gmpu_mesh *)&m;
    char needle[96];
    snprintf(needle, sizeof needle, "GMPU_PARAM_MAX_TRIANGLES = %zu", tris / 2);
    check_failure(gmpu_surface_polygonize(s, &m), GMPU_ERROR_LIMIT_EXCEEDED, needle);
    assert_null(m);
    double f = 0;
    const double centre[3] = {0, 0, 0};
    assert_ok(gmpu_surface_evaluate(s, centre, 1, &f, NULL));
    assert_true(f > 0.5);

    /* A tiny cap on a fine grid fails fast: long before the whole grid is done. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_TRIANGLES, 100));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 400));
    double t0 = robust_now();
    check_failure(gmpu_surface_polygonize(s, &m), GMPU_ERROR_LIMIT_EXCEEDED, "GMPU_PARAM_MAX_TRIANGLES = 100");
    double took = robust_now() - t0;
    assert_null(m);
    if (!robust_quick() && took > 2 * full_seconds + 0.5)
        fail_msg("a cap of 100 triangles at resolution 400 took %.3f s to fail (resolution 40 takes %.3f s)",
                 took, full_seconds);

    /* Raised again: the same handle meshes. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_TRIANGLES, 2e9));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 40));
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_int_equal(gmpu_mesh_triangle_count(m), tris);
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
}

static void test_max_depth(void **state) {
    (void)state;
    gmpu_surface *s = surface_with_points();
    assert_ok(gmpu_surface_fit(s));
    const double natural = stat_of(s, GMPU_STAT_DEPTH);
    assert_true(natural >= 4);
    double cells_before = stat_of(s, GMPU_STAT_CELLS);
    for (int d = 1; d <= (int)natural + 1; ++d) {
        assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_DEPTH, d));
        assert_ok(gmpu_surface_fit(s));
        double depth = stat_of(s, GMPU_STAT_DEPTH), cells = stat_of(s, GMPU_STAT_CELLS);
        if (depth != fmin(d, natural)) fail_msg("GMPU_PARAM_MAX_DEPTH %d gave depth %g (natural %g)", d, depth, natural);
        if (d < natural) assert_true(cells < cells_before);
        /* Even the coarsest octree gives a closed, outward mesh. */
        assert_ok(gmpu_surface_orient(s));
        gmpu_mesh *m = NULL;
        assert_ok(gmpu_surface_polygonize(s, &m));
        const char *problem = robust_mesh_problem(m);
        if (problem) fail_msg("depth %d: %s", d, problem);
        assert_true(robust_signed_volume(m) > 0);
        gmpu_mesh_destroy(m);
    }
    gmpu_surface_destroy(s);
}

/* Resident memory in bytes (Linux /proc/self/statm), 0 if unknown. */
static size_t resident_bytes(void) {
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages_total = 0, pages_resident = 0;
    if (!f) return 0;
    int got = fscanf(f, "%lu %lu", &pages_total, &pages_resident);
    fclose(f);
    return got == 2 ? (size_t)pages_resident * 4096u : 0;
}

/* The stages free their temporaries and destroy frees the surface (its worker threads and
 * their caches included): once the host hands its free heap back to the system, the
 * process's resident size must fall back. Handing it back is the host's business (glibc
 * keeps freed heap unless asked), so this test does it, as the CLI does between stages. */
static void test_memory_returned(void **state) {
    (void)state;
    /* Sanitizers and valgrind (GMPU_TEST_QUICK) bring heaps of their own. */
    if (ROBUST_INSTRUMENTED || robust_quick() || resident_bytes() == 0) skip();
    const size_t n = 200000;
    const double centre[3] = {0, 0, 0};
    double *xyz = robust_sphere(n, centre, 1.0, 9);
    assert_non_null(xyz);
    const size_t before = resident_bytes();
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_set_points_f64(s, xyz, n, 0));
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    const size_t alive = resident_bytes();
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
#ifdef __GLIBC__
    malloc_trim(0);
#endif
    const size_t after = resident_bytes();
    free(xyz);
    print_message("resident: %.1f MB before, %.1f MB with the surface, %.1f MB after destroy\n",
                  before / 1e6, alive / 1e6, after / 1e6);
    assert_true(alive > before);
    if (after > before + (alive - before) / 4)
        fail_msg("%.1f of %.1f MB still resident after destroy", (after - before) / 1e6, (alive - before) / 1e6);
}

/* The mesh of g_bumpy with `threads` workers (resolution 40). */
static gmpu_mesh *bumpy_mesh(unsigned threads, gmpu_status *status) {
    gmpu_surface *s = surface_with_points();
    gmpu_mesh *m = NULL;
    *status = gmpu_surface_set_param(s, GMPU_PARAM_THREADS, threads);
    if (*status == GMPU_OK) *status = gmpu_surface_fit(s);
    if (*status == GMPU_OK) *status = gmpu_surface_orient(s);
    if (*status == GMPU_OK) *status = gmpu_surface_polygonize(s, &m);
    gmpu_surface_destroy(s);
    return m;
}

static int same_mesh(const gmpu_mesh *a, const gmpu_mesh *b) {
    const size_t nv = gmpu_mesh_vertex_count(a), nt = gmpu_mesh_triangle_count(a);
    return nv == gmpu_mesh_vertex_count(b) && nt == gmpu_mesh_triangle_count(b) &&
           memcmp(gmpu_mesh_vertices(a), gmpu_mesh_vertices(b), 3 * nv * sizeof(double)) == 0 &&
           memcmp(gmpu_mesh_triangles(a), gmpu_mesh_triangles(b), 3 * nt * sizeof(uint32_t)) == 0;
}

/* A process limit (a container's pids cap, `ulimit -u`) makes thread creation fail part way
 * through a stage's pool. The stage must go on with the threads it got, join them, and give
 * the same mesh as one thread; it used to terminate the process. Each limit runs in a forked
 * child under RLIMIT_NPROC; root ignores that limit, so a root child first becomes nobody
 * (which owns no other task here: a limit of k leaves room for k - 1 workers). */
static void test_thread_creation_refused(void **state) {
    (void)state;
    gmpu_status status;
    gmpu_mesh *reference = bumpy_mesh(1, &status);
    assert_ok(status);
    const rlim_t limits[] = {1, 2, 3, 5};
    for (size_t k = 0; k < sizeof limits / sizeof *limits; ++k) {
        fflush(NULL);
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(10);
            struct rlimit lim = {limits[k], limits[k]};
            if (setrlimit(RLIMIT_NPROC, &lim) != 0) _exit(11);
            gmpu_mesh *m = bumpy_mesh(16, &status);
            int code = status != GMPU_OK ? 12 : same_mesh(m, reference) ? 0 : 13;
            if (code) fprintf(stderr, "limit %d: %s\n", (int)limits[k], gmpu_last_error());
            gmpu_mesh_destroy(m);
            _exit(code); /* skips the leak checker's exit thread, which the limit refuses */
        }
        int wstatus = 0;
        assert_true(waitpid(pid, &wstatus, 0) == pid);
        if (WIFSIGNALED(wstatus))
            fail_msg("RLIMIT_NPROC %d: the child died of signal %d", (int)limits[k], WTERMSIG(wstatus));
        if (WEXITSTATUS(wstatus) != 0)
            fail_msg("RLIMIT_NPROC %d: child exit %d (12: failed, 13: another mesh)", (int)limits[k],
                     WEXITSTATUS(wstatus));
    }
    gmpu_mesh_destroy(reference);
}

/* GMPU_PARAM_MAX_MEMORY: half the physical memory by default; a stage whose estimated peak
 * exceeds it fails with LIMIT_EXCEEDED naming the estimate and the budget, before it
 * allocates what it cannot hold (a resolution of 4096 fails at once, instead of growing
 * until the system kills the process), and keeps the surface usable. Whatever the budget, a
 * stage either fails so or gives the mesh of an unlimited budget. */
static void test_max_memory(void **state) {
    (void)state;
    gmpu_surface *s = surface_with_points();
    double v = 0;
    assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_MAX_MEMORY, &v));
    const double half = 0.5 * (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    if (fabs(v - half) > 1) fail_msg("default GMPU_PARAM_MAX_MEMORY %g, half the physical memory %g", v, half);

    gmpu_status status;
    gmpu_mesh *reference = bumpy_mesh(0, &status);
    assert_ok(status);

    /* A budget too small for the points themselves: fit refuses at once. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, 1e6));
    check_failure(gmpu_surface_fit(s), GMPU_ERROR_LIMIT_EXCEEDED, "GMPU_PARAM_MAX_MEMORY = 1e+06 bytes");
    assert_non_null(strstr(gmpu_last_error(), "fit ("));

    /* Fitted and oriented with room to spare, then a huge grid on a small budget: refused
     * before the grid is allocated, in a fraction of a normal polygonize's time. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, v));
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, 2e8));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 4096));
    gmpu_mesh *m = (gmpu_mesh *)&m;
    struct timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    check_failure(gmpu_surface_polygonize(s, &m), GMPU_ERROR_LIMIT_EXCEEDED, "resolution 4096");
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    assert_null(m);
    assert_non_null(strstr(gmpu_last_error(), "GMPU_PARAM_MAX_MEMORY = 2e+08 bytes"));
    const double cpu = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (!robust_quick() && cpu > 0.5) fail_msg("the refused polygonize took %.3f s of CPU", cpu);

    /* Budgets from tiny to ample: each stage fails cleanly or gives the same mesh. Both checks
     * are met on the way: the one before the stage allocates, and the one as it goes. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 40));
    int refused = 0, fitted_ok = 0;
    for (double budget = 1e6; budget <= 1e9; budget *= 1.5) {
        assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, floor(budget)));
        m = NULL;
        status = gmpu_surface_fit(s);
        if (status == GMPU_OK) fitted_ok = 1, status = gmpu_surface_orient(s);
        if (status == GMPU_OK) status = gmpu_surface_polygonize(s, &m);
        if (status == GMPU_OK) {
            if (!same_mesh(m, reference)) fail_msg("budget %g: another mesh", budget);
            gmpu_mesh_destroy(m);
            break;
        }
        if (status != GMPU_ERROR_LIMIT_EXCEEDED || !strstr(gmpu_last_error(), "GMPU_PARAM_MAX_MEMORY"))
            fail_msg("budget %g: %s", budget, gmpu_last_error());
        assert_null(m);
        ++refused;
    }
    assert_true(refused > 0 && fitted_ok);
    /* Back to the default: the same handle meshes. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, v));
    m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_true(same_mesh(m, reference));
    gmpu_mesh_destroy(m);
    gmpu_mesh_destroy(reference);
    gmpu_surface_destroy(s);
}

/* Orient checks the budget before it starts, like fit and polygonize: a budget the fit
 * passed but orient's leaf graph, fronts, moments and measures would exceed fails with
 * LIMIT_EXCEEDED naming orient, and leaves the fit usable. */
static void test_orient_memory(void **state) {
    (void)state;
    gmpu_surface *s = surface_with_points();
    double ample = 0;
    assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_MAX_MEMORY, &ample));
    /* A coarse tree: orient's per-point memory outweighs fit's per-cell peak, so some budget
     * lies between the two whatever the exact cloud. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_DEPTH, 4));
    int window = 0;
    for (double budget = 1e6; budget <= 1e9 && !window; budget *= 1.1) {
        assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, floor(budget)));
        if (gmpu_surface_fit(s) != GMPU_OK) continue;
        const gmpu_status status = gmpu_surface_orient(s);
        if (status == GMPU_OK) break;
        check_failure2(status, GMPU_ERROR_LIMIT_EXCEEDED, "orient (", "GMPU_PARAM_MAX_MEMORY");
        window = 1;
    }
    if (!window) fail_msg("no budget passed fit but not orient");
    /* The fit stands: orient with room to spare needs no new fit. */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, ample));
    assert_ok(gmpu_surface_orient(s));
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_max_cells),
        cmocka_unit_test(test_max_triangles),
        cmocka_unit_test(test_max_depth),
        cmocka_unit_test(test_memory_returned),
        cmocka_unit_test(test_thread_creation_refused),
        cmocka_unit_test(test_max_memory),
        cmocka_unit_test(test_orient_memory),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
