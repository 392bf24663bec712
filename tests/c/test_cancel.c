/* Progress and cancellation, as gmpu.h promises them: the callback runs on the calling
 * thread at least every 50 ms of that thread's CPU time with a non-decreasing fraction in
 * [0, 1] that ends at 1; returning non-zero makes fit, orient and polygonize return
 * GMPU_ERROR_CANCELLED within 100 ms of work, at any point of the stage; the surface keeps
 * the stages completed before, and a later full run succeeds.
 *
 * The cloud (a bumpy sphere sampled in the test) is big enough that every stage runs for
 * about a second in an optimised build. Both promises are about work, not about how the
 * machine shares its cores, so both are measured in CPU time, which other jobs on the
 * machine do not inflate (`make test-load` runs this suite beside two busy loops):
 *  - gaps: the calling thread's CPU time between callbacks, from the call to the first
 *    callback, and from the last one to the return — the whole stage, tails included;
 *  - latency: the CPU time of the whole process (the calling thread and every worker) from
 *    the cancelling callback's return to the stage's return. Counting every thread's work
 *    makes it an upper bound of the wall time an idle machine would take.
 * Cancellation is requested at callbacks spread over a full run's callbacks, from the first
 * to the last (the forced one at fraction 1, which must cancel too). Wall times are printed.
 * A latency over its limit is measured again (up to four times) and the smallest kept.
 *
 * GMPU_CANCEL_POINTS overrides the cloud size; GMPU_CANCEL_VERBOSE=1 prints every
 * measurement. The timing promises are for optimised builds: under ASan/UBSan/TSan (with
 * the fuzzer's coverage instrumentation, Eigen code runs ~20x slower) and under
 * GMPU_TEST_QUICK (valgrind) the cloud is small and only the semantics are checked, with a
 * 2 s bound on the latency that still catches a cancel that is ignored. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gmpu/gmpu.h"
#include "robust_util.h"

static size_t g_n;
static double *g_points;
static double g_latency_limit; /* seconds: 0.1 in an optimised build */
static double g_gap_limit;     /* seconds: 0.05 promised; see setup */
static int g_verbose;
static int g_timing; /* 0 under valgrind or sanitizers: semantics only */

static const char *stage_name(gmpu_stage s) {
    return s == GMPU_STAGE_FIT ? "fit" : s == GMPU_STAGE_ORIENT ? "orient" : "polygonize";
}

static int setup(void **state) {
    (void)state;
    const char *env = getenv("GMPU_CANCEL_POINTS");
    g_timing = !robust_quick() && !ROBUST_INSTRUMENTED;
    g_n = env ? (size_t)atol(env) : robust_quick() ? 3000 : ROBUST_INSTRUMENTED ? 15000 : 400000;
    g_verbose = getenv("GMPU_CANCEL_VERBOSE") != NULL;
    /* The header's promises: back within 100 ms of a cancel, a callback every 50 ms of work. */
    g_latency_limit = g_timing ? 0.1 : 2.0;
    g_gap_limit = 0.05;
    g_points = robust_bumpy_sphere(g_n, 11);
    return g_points ? 0 : -1;
}

static int teardown(void **state) {
    (void)state;
    free(g_points);
    return 0;
}

/* ---- the recording / cancelling callback ---- */

static double cpu_clock(clockid_t id) {
    struct timespec t;
    clock_gettime(id, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
static double thread_cpu(void) { return cpu_clock(CLOCK_THREAD_CPUTIME_ID); }
static double process_cpu(void) { return cpu_clock(CLOCK_PROCESS_CPUTIME_ID); }

typedef struct {
    pthread_t caller;
    gmpu_stage stage;         /* the stage being watched */
    double start;             /* when the stage's function was called */
    int cancel_at_call;       /* the callback (1 = the first) that cancels; 0: never */
    double cancelled_at;      /* when the cancelling callback returned (0: not yet) */
    double cancelled_cpu;     /* the process's CPU time then */
    double last;              /* previous callback (or start) */
    double cpu_last;          /* the same, in the calling thread's CPU time */
    double max_gap, max_gap_at, max_gap_fraction; /* CPU time */
    double max_wall_gap;
    double last_fraction;
    double reached_one; /* when the fraction first reached 1 (0: never) */
    int calls, wrong_thread, wrong_stage, bad_fraction, calls_after_cancel;
    int distinct; /* callbacks whose fraction differs from the previous one's */
} watch;

static void watch_begin(watch *w, gmpu_stage stage, int cancel_at_call) {
    memset(w, 0, sizeof *w);
    w->caller = pthread_self();
    w->stage = stage;
    w->cancel_at_call = cancel_at_call;
    w->last_fraction = -1;
    w->start = w->last = robust_now();
    w->cpu_last = thread_cpu();
}

static int on_progress(void *user, gmpu_stage stage, double fraction) {
    watch *w = user;
    double t = robust_now(), cpu = thread_cpu();
    if (!pthread_equal(pthread_self(), w->caller)) w->wrong_thread++;
    if (stage != w->stage) w->wrong_stage++;
    if (!(fraction >= 0 && fraction <= 1) || fraction < w->last_fraction) w->bad_fraction++;
    if (w->cancelled_at > 0) w->calls_after_cancel++;
    if (cpu - w->cpu_last > w->max_gap) w->max_gap = cpu - w->cpu_last, w->max_gap_at = w->last - w->start,
                                        w->max_gap_fraction = w->last_fraction;
    w->max_wall_gap = fmax(w->max_wall_gap, t - w->last);
    w->last = t;
    w->cpu_last = cpu;
    if (fraction != w->last_fraction) w->distinct++;
    w->last_fraction = fraction;
    if (fraction >= 1.0 && w->reached_one == 0) w->reached_one = t;
    w->calls++;
    if (w->cancel_at_call > 0 && w->cancelled_at == 0 && w->calls >= w->cancel_at_call) {
        w->cancelled_at = robust_now(); /* the moment this callback returns */
        w->cancelled_cpu = process_cpu();
        return 1;
    }
    return 0;
}

/* Ends the watch when the stage returned: the tail from the last callback counts as a gap. */
static void watch_end(watch *w, double end) {
    double cpu = thread_cpu();
    if (cpu - w->cpu_last > w->max_gap) w->max_gap = cpu - w->cpu_last, w->max_gap_at = w->last - w->start,
                                        w->max_gap_fraction = w->last_fraction;
    w->max_wall_gap = fmax(w->max_wall_gap, end - w->last);
}

static gmpu_status run_stage(gmpu_surface *s, gmpu_stage stage, gmpu_mesh **mesh, watch *w) {
    gmpu_status st;
    double t0 = robust_now();
    w->start = w->last = t0;
    w->cpu_last = thread_cpu();
    if (stage == GMPU_STAGE_FIT)
        st = gmpu_surface_fit(s);
    else if (stage == GMPU_STAGE_ORIENT)
        st = gmpu_surface_orient(s);
    else
        st = gmpu_surface_polygonize(s, mesh);
    watch_end(w, robust_now());
    assert_int_equal(w->wrong_thread, 0); /* the callback runs on the calling thread only */
    assert_int_equal(w->wrong_stage, 0);
    assert_int_equal(w->bad_fraction, 0); /* in [0, 1] and non-decreasing */
    return st;
}

static gmpu_surface *surface_at(gmpu_stage stage, watch *w) {
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_set_points_f64(s, g_points, g_n, 0));
    if (stage > GMPU_STAGE_FIT) assert_ok(gmpu_surface_fit(s));
    if (stage > GMPU_STAGE_ORIENT) assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_set_progress(s, on_progress, w));
    return s;
}

/* ---- one full run: cadence and durations ---- */

static double g_duration[4];  /* by gmpu_stage, from the cadence test */
static size_t g_triangles;

static void test_progress_cadence(void **state) {
    (void)state;
    double worst[4] = {0, INFINITY, INFINITY, INFINITY}, where[4] = {0}, fraction[4] = {0}, wall[4] = {0};
    for (int attempt = 0; attempt < 3; ++attempt) {
        watch w;
        watch_begin(&w, GMPU_STAGE_FIT, 0);
        gmpu_surface *s = surface_at(GMPU_STAGE_FIT, &w);
        gmpu_mesh *m = NULL;
        int over = 0;
        for (gmpu_stage st = GMPU_STAGE_FIT; st <= GMPU_STAGE_POLYGONIZE; ++st) {
            watch_begin(&w, st, 0);
            double t0 = robust_now();
            assert_ok(run_stage(s, st, &m, &w));
            double end = robust_now(), took = end - t0;
            /* 1 means done: the fraction reaches it at the end, not long before. */
            if (w.reached_one > 0 && end - w.reached_one > 0.1 * took + 0.05)
                fail_msg("%s reported fraction 1 after %.3f s of %.3f s", stage_name(st), w.reached_one - t0, took);
            if (attempt == 0) g_duration[st] = took;
            assert_true(w.calls >= 2);
            /* A progress bar that moves: fit's fraction keeps growing across its octree's
             * levels instead of starting each level over (on a second-long fit). */
            if (st == GMPU_STAGE_FIT && g_timing && took > 0.5 && w.distinct < 20)
                fail_msg("fit reported only %d distinct fractions in %d callbacks over %.3f s", w.distinct, w.calls, took);
            assert_true(w.last_fraction == 1.0); /* 1 when the stage completes */
            if (w.max_gap < worst[st]) worst[st] = w.max_gap, where[st] = w.max_gap_at, fraction[st] = w.max_gap_fraction;
            over |= worst[st] > g_gap_limit;
            wall[st] = fmax(wall[st], w.max_wall_gap);
            if (g_verbose)
                fprintf(stderr, "# %s: %.3f s, %d callbacks (%d distinct fractions), largest gap %.1f ms CPU (%.1f ms wall) after %.3f s (fraction %.3f)\n",
                        stage_name(st), took, w.calls, w.distinct, 1e3 * w.max_gap, 1e3 * w.max_wall_gap, w.max_gap_at,
                        w.max_gap_fraction);
        }
        g_triangles = gmpu_mesh_triangle_count(m);
        assert_null(robust_mesh_problem(m));
        gmpu_mesh_destroy(m);
        gmpu_surface_destroy(s);
        if (!over || !g_timing) break;
    }
    for (gmpu_stage st = GMPU_STAGE_FIT; st <= GMPU_STAGE_POLYGONIZE; ++st) {
        fprintf(stderr, "# %zu points, %s: %.3f s, largest progress gap %.1f ms of the calling thread's CPU "
                        "(after %.3f s, fraction %.3f; limit %.0f ms; %.1f ms of wall time)\n",
                g_n, stage_name(st), g_duration[st], 1e3 * worst[st], where[st], fraction[st], 1e3 * g_gap_limit,
                1e3 * wall[st]);
        if (g_timing && worst[st] > g_gap_limit)
            fail_msg("%s: no progress callback for %.1f ms of work, after %.3f s at fraction %.3f (limit %.0f ms)",
                     stage_name(st), 1e3 * worst[st], where[st], fraction[st], 1e3 * g_gap_limit);
    }
}

/* The cloud must keep every stage busy for at least half a second to cancel it at many
 * points: on a machine fast enough to do a stage quicker, the cloud grows (once). */
static void test_cloud_is_big_enough(void **state) {
    (void)state;
    if (!g_timing || getenv("GMPU_CANCEL_POINTS")) skip();
    double shortest = fmin(g_duration[GMPU_STAGE_FIT], fmin(g_duration[GMPU_STAGE_ORIENT], g_duration[GMPU_STAGE_POLYGONIZE]));
    if (shortest >= 0.5) return;
    size_t n = (size_t)((double)g_n * fmin(4.0, 0.65 / shortest));
    fprintf(stderr, "# the shortest stage took %.3f s: %zu points instead of %zu\n", shortest, n, g_n);
    free(g_points);
    g_n = n;
    g_points = robust_bumpy_sphere(g_n, 11);
    assert_non_null(g_points);
    test_progress_cadence(state);
    for (gmpu_stage st = GMPU_STAGE_FIT; st <= GMPU_STAGE_POLYGONIZE; ++st)
        if (g_duration[st] < 0.5) fprintf(stderr, "# %s still takes only %.3f s\n", stage_name(st), g_duration[st]);
}

/* ---- cancellation at chosen points ---- */

/* What must hold after a cancelled stage: the stages before are kept, this one is not. */
static void check_after_cancel(gmpu_surface *s, gmpu_stage stage, gmpu_mesh *mesh, double cells_before) {
    double cells = -1, f = 0;
    const double centre[3] = {0, 0, 0};
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells));
    assert_non_null(strstr(gmpu_surface_last_error(s), "GMPU_ERROR_CANCELLED"));
    assert_non_null(strstr(gmpu_last_error(), stage_name(stage)));
    assert_true(cells == cells_before); /* no partial octree; a fit done before is kept */
    switch ((int)stage) {
        case GMPU_STAGE_FIT:
            if (cells_before == 0) check_failure(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");
            break;
        case GMPU_STAGE_ORIENT:
            check_failure(gmpu_surface_evaluate(s, centre, 1, &f, NULL), GMPU_ERROR_WRONG_ORDER, "orient");
            break;
        case GMPU_STAGE_POLYGONIZE:
            assert_null(mesh);
            assert_ok(gmpu_surface_evaluate(s, centre, 1, &f, NULL)); /* still oriented */
            assert_true(f > 0.5);
            break;
    }
}

/* Runs the pipeline from `from` to the end without cancelling: the same mesh as ever. */
static void finish_pipeline(gmpu_surface *s, gmpu_stage from, watch *w) {
    gmpu_mesh *m = NULL;
    for (gmpu_stage st = from; st <= GMPU_STAGE_POLYGONIZE; ++st) {
        watch_begin(w, st, 0);
        assert_ok(run_stage(s, st, &m, w));
    }
    assert_int_equal(gmpu_mesh_triangle_count(m), g_triangles); /* the same mesh as uncancelled */
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
}

/* Cancels `stage` on s at its callback number `call`; returns the latency (process CPU
 * seconds), or, if the stage made fewer callbacks, minus the number it made. */
static double cancel_once(gmpu_surface *s, watch *w, gmpu_stage stage, int call, double *wall) {
    double cells_before = 0;
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells_before));
    watch_begin(w, stage, call);
    gmpu_mesh *m = NULL;
    gmpu_status st = run_stage(s, stage, &m, w);
    double end = robust_now(), end_cpu = process_cpu();
    if (w->cancelled_at == 0) {
        assert_ok(st); /* finished before that callback: nothing to measure */
        gmpu_mesh_destroy(m);
        return -(double)w->calls;
    }
    if (st != GMPU_ERROR_CANCELLED)
        fail_msg("%s cancelled after %.3f s returned %s (%s)", stage_name(stage), w->cancelled_at - w->start,
                 gmpu_status_name(st), gmpu_last_error());
    assert_int_equal(w->calls_after_cancel, 0); /* no callback after the one that cancelled */
    check_after_cancel(s, stage, m, cells_before);
    *wall = end - w->cancelled_at;
    return end_cpu - w->cancelled_cpu;
}

/* Cancels one stage at callbacks spread over a full run's, on one surface (a cancelled stage
 * leaves it ready for the next attempt), then finishes the pipeline on it. */
static void cancel_stage(gmpu_stage stage) {
    if (g_duration[stage] == 0) fail_msg("test_progress_cadence must run first");
    const int points = g_timing ? 12 : 4;
    watch w;
    watch_begin(&w, stage, 0);
    gmpu_surface *s = surface_at(stage, &w);
    /* The stage's callbacks now, warm (a first run also pays for page faults): the
     * cancellations are spread over them. */
    gmpu_mesh *m = NULL;
    double duration = INFINITY;
    int calls = 1 << 30;
    /* The fewer callbacks of two runs: a callback near the end must still come when the
     * machine gets quieter meanwhile (the callback interval is wall time). */
    for (int run = 0; run < 2; ++run) {
        watch_begin(&w, stage, 0);
        double t0 = robust_now();
        assert_ok(run_stage(s, stage, &m, &w));
        duration = fmin(duration, robust_now() - t0);
        calls = calls < w.calls ? calls : w.calls;
        gmpu_mesh_destroy(m);
        m = NULL;
    }
    double worst = 0, worst_wall = 0, worst_fraction = 0;
    int measured = 0, worst_call = 0;
    for (int k = 0; k < points; ++k) {
        /* Spread over the callbacks, from the very first to the last (fraction 1). */
        int at = 1 + (int)lround((double)(calls - 1) * k / (points - 1));
        const int last = k == points - 1;
        double best = INFINITY, best_wall = 0, fraction = 0;
        for (int attempt = 0; attempt < 4; ++attempt) {
            double wall = 0, latency = cancel_once(s, &w, stage, at, &wall);
            if (latency < 0) {
                /* This run made fewer callbacks (the machine got quieter): aim at the same
                 * share of them, or at its last one. */
                at = last ? (int)-latency : (int)fmax(1, fmin(at - 1, -latency * at / calls));
                continue;
            }
            if (latency < best) best = latency, best_wall = wall, fraction = w.last_fraction;
            if (g_verbose)
                fprintf(stderr, "# %s cancelled at callback %d of ~%d (fraction %.3f): returned after %.1f ms of CPU (%.1f ms wall)\n",
                        stage_name(stage), at, calls, w.last_fraction, 1e3 * latency, 1e3 * wall);
            if (best <= g_latency_limit) break;
        }
        if (!isfinite(best)) continue;
        ++measured;
        if (best > worst) worst = best, worst_wall = best_wall, worst_call = at, worst_fraction = fraction;
    }
    fprintf(stderr, "# %s: %d cancellations over %d callbacks (%.3f s), slowest returned after %.1f ms of CPU "
                    "(%.1f ms wall; at callback %d, fraction %.3f; limit %.0f ms)\n",
            stage_name(stage), measured, calls, duration, 1e3 * worst, 1e3 * worst_wall, worst_call, worst_fraction,
            1e3 * g_latency_limit);
    assert_true(measured >= points - 1); /* every target but perhaps one was reached */
    if (worst > g_latency_limit)
        fail_msg("%s cancelled at callback %d (fraction %.3f) took %.1f ms of CPU to return (limit %.0f ms)",
                 stage_name(stage), worst_call, worst_fraction, 1e3 * worst, 1e3 * g_latency_limit);
    finish_pipeline(s, stage, &w);
    gmpu_surface_destroy(s);
}

static void test_cancel_fit(void **state) {
    (void)state;
    cancel_stage(GMPU_STAGE_FIT);
}
static void test_cancel_orient(void **state) {
    (void)state;
    cancel_stage(GMPU_STAGE_ORIENT);
}
static void test_cancel_polygonize(void **state) {
    (void)state;
    cancel_stage(GMPU_STAGE_POLYGONIZE);
}

/* A cancelled re-fit keeps the earlier, complete pipeline: still oriented. */
static void test_cancel_keeps_earlier_result(void **state) {
    (void)state;
    watch w;
    watch_begin(&w, GMPU_STAGE_POLYGONIZE, 0);
    gmpu_surface *s = surface_at(GMPU_STAGE_POLYGONIZE, &w);
    double f = 0, cells = 0, cells_after = 0;
    const double centre[3] = {0, 0, 0};
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells));
    watch_begin(&w, GMPU_STAGE_FIT, 1);
    check_failure(run_stage(s, GMPU_STAGE_FIT, NULL, &w), GMPU_ERROR_CANCELLED, "fit cancelled");
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells_after));
    assert_true(cells_after == cells);
    assert_ok(gmpu_surface_evaluate(s, centre, 1, &f, NULL));
    assert_true(f > 0.5);
    /* A callback removed with NULL is not called again. */
    assert_ok(gmpu_surface_set_progress(s, NULL, NULL));
    w.calls = 0;
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_int_equal(w.calls, 0);
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_progress_cadence), /* first: measures the durations */
        cmocka_unit_test(test_cloud_is_big_enough),
        cmocka_unit_test(test_cancel_fit),
        cmocka_unit_test(test_cancel_orient),
        cmocka_unit_test(test_cancel_polygonize),
        cmocka_unit_test(test_cancel_keeps_earlier_result),
    };
    /* GMPU_TEST_FILTER=test_progress_cadence runs only the matching tests (cmocka's wildcards). */
    if (getenv("GMPU_TEST_FILTER")) cmocka_set_test_filter(getenv("GMPU_TEST_FILTER"));
    return cmocka_run_group_tests(tests, setup, teardown);
}
