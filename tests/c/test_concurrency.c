/* The thread-safety contract of gmpu.h: on one oriented surface the const functions
 * (evaluate, copy_normals, get_param, get_stat, point_count) may run concurrently, and so
 * may every accessor (and the writers) of one mesh or point set; separate
 * handles share no mutable state, so whole pipelines on separate surfaces in separate
 * threads give exactly (bit for bit) what they give one at a time; gmpu_last_error() is per
 * thread. Run under ThreadSanitizer by `make test-tsan`, which also sees the library's own
 * worker threads. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <libgen.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gmpu/gmpu.h"
#include "robust_util.h"

enum { EVAL_THREADS = 8, PIPELINES = 4 };

static size_t g_n, g_q;
static double *g_points; /* a torus */
static double *g_queries;

static const double kTorusCentre[3] = {0.1, 0.2, -0.3};

static int setup(void **state) {
    (void)state;
    /* TSan runs 5-15x slower: keep the work small there. */
    const int small = robust_quick() || ROBUST_INSTRUMENTED;
    g_n = robust_quick() ? 2000 : small ? 4000 : 20000;
    g_q = robust_quick() ? 1000 : small ? 3000 : 20000;
    g_points = robust_torus(g_n, 1.0, 0.35, kTorusCentre, 21);
    g_queries = malloc(3 * g_q * sizeof *g_queries);
    if (!g_points || !g_queries) return -1;
    /* Half anywhere in a box around the torus (far field and blend), half near the samples. */
    robust_rng rng = {77};
    for (size_t i = 0; i < g_q; ++i)
        for (int k = 0; k < 3; ++k)
            g_queries[3 * i + k] = i % 2 ? kTorusCentre[k] + 3.0 * (2 * robust_uniform(&rng) - 1)
                                         : g_points[3 * (i % g_n) + k] + 0.02 * (2 * robust_uniform(&rng) - 1);
    return 0;
}

static int teardown(void **state) {
    (void)state;
    free(g_points);
    free(g_queries);
    return 0;
}

static gmpu_surface *oriented(const double *xyz, size_t n, unsigned threads) {
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_THREADS, threads));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 32));
    assert_ok(gmpu_surface_set_points_f64(s, xyz, n, 0));
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    return s;
}

/* ---- many threads, one surface ---- */

typedef struct {
    const gmpu_surface *s;
    const gmpu_mesh *mesh;     /* meshes and point sets: any accessor from any thread */
    const gmpu_points *points;
    int id;
    const double *ref_values, *ref_gradients, *ref_normals;
    atomic_int *go;
    int mismatches, failures;
    char failure[256];
} eval_job;

static char g_scratch[4096]; /* beside the executable: files the threads write */

/* Sum of the bytes of a mesh's arrays and a point set's: the same from every thread. */
static uint64_t fingerprint(const gmpu_mesh *m, const gmpu_points *p) {
    uint64_t h = 1469598103934665603ull;
    const unsigned char *b = (const unsigned char *)gmpu_mesh_vertices(m);
    for (size_t i = 0; i < 3 * gmpu_mesh_vertex_count(m) * sizeof(double); ++i) h = (h ^ b[i]) * 1099511628211ull;
    b = (const unsigned char *)gmpu_mesh_triangles(m);
    for (size_t i = 0; i < 3 * gmpu_mesh_triangle_count(m) * sizeof(uint32_t); ++i) h = (h ^ b[i]) * 1099511628211ull;
    b = (const unsigned char *)gmpu_mesh_normals(m);
    for (size_t i = 0; b && i < 3 * gmpu_mesh_vertex_count(m) * sizeof(double); ++i) h = (h ^ b[i]) * 1099511628211ull;
    b = (const unsigned char *)gmpu_points_positions(p);
    for (size_t i = 0; i < 3 * gmpu_points_count(p) * sizeof(double); ++i) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}
static uint64_t g_fingerprint;

static void *eval_worker(void *arg) {
    eval_job *j = arg;
    double *v = malloc(g_q * sizeof *v), *g = malloc(3 * g_q * sizeof *g), *n = malloc(3 * g_n * sizeof *n);
    while (!atomic_load(j->go)) sched_yield();
    /* Each thread walks the queries in its own chunk size and starting offset, so that the
     * threads are in different parts of the octree at the same moment. */
    const size_t chunk = 1 + (size_t)j->id * 97;
    for (int round = 0; round < 2; ++round) {
        for (size_t done = 0; done < g_q;) {
            size_t start = (done + (size_t)j->id * (g_q / EVAL_THREADS)) % g_q;
            size_t count = chunk;
            if (count > g_q - done) count = g_q - done;
            if (count > g_q - start) count = g_q - start;
            gmpu_status st = gmpu_surface_evaluate(j->s, g_queries + 3 * start, count, v + start,
                                                   (j->id + round) % 2 ? g + 3 * start : NULL);
            if (st != GMPU_OK && !j->failures++)
                snprintf(j->failure, sizeof j->failure, "evaluate: %s", gmpu_last_error());
            done += count;
        }
        for (size_t i = 0; i < g_q; ++i)
            if (memcmp(&v[i], &j->ref_values[i], sizeof *v) != 0) ++j->mismatches;
        if ((j->id + round) % 2)
            if (memcmp(g, j->ref_gradients, 3 * g_q * sizeof *g) != 0) ++j->mismatches;
        /* The other const calls, interleaved. */
        double x = 0;
        if (gmpu_surface_copy_normals(j->s, n, g_n) != GMPU_OK || memcmp(n, j->ref_normals, 3 * g_n * sizeof *n) != 0)
            ++j->mismatches;
        if (gmpu_surface_get_stat(j->s, GMPU_STAT_LEAVES, &x) != GMPU_OK || !(x > 0)) ++j->failures;
        if (gmpu_surface_get_param(j->s, GMPU_PARAM_RESOLUTION, &x) != GMPU_OK || x != 32) ++j->failures;
        if (gmpu_surface_point_count(j->s) != g_n) ++j->failures;
        /* One mesh and one point set read by every thread at once, and written to files. */
        if (fingerprint(j->mesh, j->points) != g_fingerprint) ++j->mismatches;
        if (g_scratch[0]) {
            char path[4200];
            snprintf(path, sizeof path, "%s/concurrency-%d-%d.ply", g_scratch, j->id, round);
            if (gmpu_mesh_write(j->mesh, path) != GMPU_OK || remove(path) != 0) ++j->failures;
            snprintf(path, sizeof path, "%s/concurrency-%d-%d.xyz", g_scratch, j->id, round);
            if (gmpu_points_write(j->points, path) != GMPU_OK || remove(path) != 0) ++j->failures;
        }
    }
    free(v);
    free(g);
    free(n);
    return NULL;
}

static void test_concurrent_evaluate_one_surface(void **state) {
    (void)state;
    gmpu_surface *s = oriented(g_points, g_n, 0);
    double *ref_v = malloc(g_q * sizeof *ref_v), *ref_g = malloc(3 * g_q * sizeof *ref_g);
    double *ref_n = malloc(3 * g_n * sizeof *ref_n);
    /* Single-threaded reference, one query at a time and all at once: the same bits. */
    assert_ok(gmpu_surface_evaluate(s, g_queries, g_q, ref_v, ref_g));
    for (size_t i = 0; i < g_q; i += 101) {
        double v1, g1[3];
        assert_ok(gmpu_surface_evaluate(s, g_queries + 3 * i, 1, &v1, g1));
        assert_memory_equal(&v1, &ref_v[i], sizeof v1);
        assert_memory_equal(g1, &ref_g[3 * i], sizeof g1);
    }
    assert_ok(gmpu_surface_copy_normals(s, ref_n, g_n));
    /* Sanity: the reference is a real field (inside positive, far outside negative). */
    double c[3] = {kTorusCentre[0] + 1.0, kTorusCentre[1], kTorusCentre[2]}, f = 0;
    assert_ok(gmpu_surface_evaluate(s, c, 1, &f, NULL));
    assert_true(f > 0.2);

    gmpu_mesh *mesh = NULL;
    gmpu_points *points = NULL;
    assert_ok(gmpu_surface_polygonize(s, &mesh));
    assert_ok(gmpu_points_create(g_points, ref_n, g_n, &points));
    g_fingerprint = fingerprint(mesh, points);
    char exe[4096];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    g_scratch[0] = '\0';
    if (len > 0) {
        exe[len] = '\0';
        snprintf(g_scratch, sizeof g_scratch, "%s", dirname(exe));
    }

    atomic_int go = 0;
    eval_job jobs[EVAL_THREADS];
    pthread_t tid[EVAL_THREADS];
    for (int t = 0; t < EVAL_THREADS; ++t) {
        jobs[t] = (eval_job){s, mesh, points, t, ref_v, ref_g, ref_n, &go, 0, 0, ""};
        assert_int_equal(pthread_create(&tid[t], NULL, eval_worker, &jobs[t]), 0);
    }
    atomic_store(&go, 1);
    for (int t = 0; t < EVAL_THREADS; ++t) pthread_join(tid[t], NULL);
    for (int t = 0; t < EVAL_THREADS; ++t) {
        if (jobs[t].failures) fail_msg("thread %d: %d failed calls (%s)", t, jobs[t].failures, jobs[t].failure);
        if (jobs[t].mismatches) fail_msg("thread %d: %d results differ from the single-threaded ones", t, jobs[t].mismatches);
    }
    free(ref_v);
    free(ref_g);
    free(ref_n);
    gmpu_mesh_destroy(mesh);
    gmpu_points_destroy(points);
    gmpu_surface_destroy(s);
}

/* ---- many threads, one thin shell: its field keeps what it has read (the rim test's
 * lattice nodes), so the first queries from every thread at once write it ---- */

enum { SHELL_POINTS = 1000, SHELL_QUERIES = 2000 };

typedef struct {
    const gmpu_surface *s;
    const double *queries, *ref;
    int id, mismatches, failures;
    atomic_int *go;
} shell_job;

static void *shell_worker(void *arg) {
    shell_job *j = arg;
    double v[SHELL_QUERIES];
    while (!atomic_load(j->go)) sched_yield();
    const size_t chunk = 1 + (size_t)j->id * 37;
    for (size_t done = 0; done < SHELL_QUERIES;) {
        const size_t start = (done + (size_t)j->id * (SHELL_QUERIES / EVAL_THREADS)) % SHELL_QUERIES;
        size_t count = chunk;
        if (count > SHELL_QUERIES - done) count = SHELL_QUERIES - done;
        if (count > SHELL_QUERIES - start) count = SHELL_QUERIES - start;
        if (gmpu_surface_evaluate(j->s, j->queries + 3 * start, count, v + start, NULL) != GMPU_OK) ++j->failures;
        done += count;
    }
    for (size_t i = 0; i < SHELL_QUERIES; ++i)
        if (memcmp(&v[i], &j->ref[i], sizeof *v) != 0) ++j->mismatches;
    return NULL;
}

static void test_concurrent_evaluate_thin_shell(void **state) {
    (void)state;
    /* A hollow sphere, radius 1, its wall 0.02 thick: at 1,000 points a thin shell. */
    static double xyz[3 * SHELL_POINTS], queries[3 * SHELL_QUERIES], ref[SHELL_QUERIES];
    robust_rng rng = {5};
    for (size_t i = 0; i < SHELL_POINTS; ++i) {
        double d[3];
        robust_direction(&rng, d);
        for (int k = 0; k < 3; ++k) xyz[3 * i + k] = (i % 2 ? 1.0 : 0.98) * d[k];
    }
    for (size_t i = 0; i < SHELL_QUERIES; ++i) {
        double d[3];
        robust_direction(&rng, d);
        const double r = 0.99 + 0.03 * (2 * robust_uniform(&rng) - 1);
        for (int k = 0; k < 3; ++k) queries[3 * i + k] = r * d[k];
    }
    /* The reference from a surface of its own, one thread; the threads share a fresh one. */
    gmpu_surface *reference = oriented(xyz, SHELL_POINTS, 1), *s = oriented(xyz, SHELL_POINTS, 0);
    assert_ok(gmpu_surface_evaluate(reference, queries, SHELL_QUERIES, ref, NULL));
    /* Read as a shell: the wall is inside, the cavity outside (a solid sphere's would be in). */
    const double wall[3] = {0.99, 0, 0}, cavity[3] = {0.5, 0, 0};
    double f_wall = 0, f_cavity = 0;
    assert_ok(gmpu_surface_evaluate(reference, wall, 1, &f_wall, NULL));
    assert_ok(gmpu_surface_evaluate(reference, cavity, 1, &f_cavity, NULL));
    assert_true(f_wall > 0 && f_cavity < 0);
    atomic_int go = 0;
    shell_job jobs[EVAL_THREADS];
    pthread_t tid[EVAL_THREADS];
    for (int t = 0; t < EVAL_THREADS; ++t) {
        jobs[t] = (shell_job){s, queries, ref, t, 0, 0, &go};
        assert_int_equal(pthread_create(&tid[t], NULL, shell_worker, &jobs[t]), 0);
    }
    atomic_store(&go, 1);
    for (int t = 0; t < EVAL_THREADS; ++t) pthread_join(tid[t], NULL);
    for (int t = 0; t < EVAL_THREADS; ++t) {
        if (jobs[t].failures) fail_msg("thread %d: %d failed evaluations", t, jobs[t].failures);
        if (jobs[t].mismatches) fail_msg("thread %d: %d values differ from a single thread's", t, jobs[t].mismatches);
    }
    gmpu_surface_destroy(reference);
    gmpu_surface_destroy(s);
}

/* ---- one surface per thread ---- */

typedef struct {
    const double *xyz;
    size_t n;
    unsigned lib_threads;
    atomic_int *go;
    /* results */
    gmpu_status status;
    char error[256];
    size_t vertices, triangles;
    double *mesh_vertices; /* copy */
    double *values;        /* evaluate at g_queries */
    double cells;
    int progress_calls;
} pipeline_job;

static int count_progress(void *user, gmpu_stage stage, double fraction) {
    (void)stage, (void)fraction;
    ++*(int *)user;
    return 0;
}

static void *pipeline_worker(void *arg) {
    pipeline_job *j = arg;
    if (j->go)
        while (!atomic_load(j->go)) sched_yield();
    gmpu_surface *s = NULL;
    gmpu_mesh *m = NULL;
    j->status = gmpu_surface_create(&s);
    if (!j->status) j->status = gmpu_surface_set_param(s, GMPU_PARAM_THREADS, j->lib_threads);
    if (!j->status) j->status = gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 32);
    if (!j->status) j->status = gmpu_surface_set_progress(s, count_progress, &j->progress_calls);
    if (!j->status) j->status = gmpu_surface_set_points_f64(s, j->xyz, j->n, 0);
    if (!j->status) j->status = gmpu_surface_fit(s);
    if (!j->status) j->status = gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &j->cells);
    if (!j->status) j->status = gmpu_surface_orient(s);
    if (!j->status) j->status = gmpu_surface_polygonize(s, &m);
    if (!j->status) {
        j->values = malloc(g_q * sizeof *j->values);
        j->status = gmpu_surface_evaluate(s, g_queries, g_q, j->values, NULL);
    }
    if (j->status) {
        snprintf(j->error, sizeof j->error, "%s", gmpu_last_error());
    } else {
        j->vertices = gmpu_mesh_vertex_count(m);
        j->triangles = gmpu_mesh_triangle_count(m);
        j->mesh_vertices = malloc(3 * j->vertices * sizeof(double));
        memcpy(j->mesh_vertices, gmpu_mesh_vertices(m), 3 * j->vertices * sizeof(double));
    }
    /* The mesh outlives its surface. */
    gmpu_surface_destroy(s);
    if (m && robust_mesh_problem(m)) j->status = GMPU_ERROR_INTERNAL, snprintf(j->error, sizeof j->error, "bad mesh");
    gmpu_mesh_destroy(m);
    return NULL;
}

static void free_job(pipeline_job *j) {
    free(j->mesh_vertices);
    free(j->values);
}

static void test_separate_surfaces_in_parallel(void **state) {
    (void)state;
    /* Four different clouds (and two of the same one): a torus, a sphere, a bumpy sphere, the
     * torus again with its points in another order. */
    double *clouds[PIPELINES];
    size_t n = g_n;
    clouds[0] = g_points;
    const double c1[3] = {5, 5, 5};
    clouds[1] = robust_sphere(n, c1, 2.0, 3);
    clouds[2] = robust_bumpy_sphere(n, 4);
    clouds[3] = malloc(3 * n * sizeof(double));
    for (size_t i = 0; i < n; ++i) memcpy(clouds[3] + 3 * i, g_points + 3 * (n - 1 - i), 3 * sizeof(double));

    /* One at a time first: the reference. */
    pipeline_job ref[PIPELINES], par[PIPELINES];
    for (int k = 0; k < PIPELINES; ++k) {
        ref[k] = (pipeline_job){clouds[k], n, 1 + (unsigned)(k % 2), NULL, 0, "", 0, 0, NULL, NULL, 0, 0};
        pipeline_worker(&ref[k]);
        if (ref[k].status) fail_msg("cloud %d alone: %s", k, ref[k].error);
    }
    /* Then all at once, each surface in its own thread (each with its own worker threads). */
    atomic_int go = 0;
    pthread_t tid[PIPELINES];
    for (int k = 0; k < PIPELINES; ++k) {
        par[k] = (pipeline_job){clouds[k], n, 1 + (unsigned)(k % 2), &go, 0, "", 0, 0, NULL, NULL, 0, 0};
        assert_int_equal(pthread_create(&tid[k], NULL, pipeline_worker, &par[k]), 0);
    }
    atomic_store(&go, 1);
    for (int k = 0; k < PIPELINES; ++k) pthread_join(tid[k], NULL);
    for (int k = 0; k < PIPELINES; ++k) {
        if (par[k].status) fail_msg("cloud %d in parallel: %s", k, par[k].error);
        assert_true(par[k].cells == ref[k].cells);
        assert_int_equal(par[k].vertices, ref[k].vertices);
        assert_int_equal(par[k].triangles, ref[k].triangles);
        assert_memory_equal(par[k].mesh_vertices, ref[k].mesh_vertices, 3 * ref[k].vertices * sizeof(double));
        assert_memory_equal(par[k].values, ref[k].values, g_q * sizeof(double));
        assert_true(par[k].progress_calls >= 6); /* each surface's callback, on its own thread */
    }
    /* The reordered torus is the same solid: same cell count and volume-ish mesh size. */
    assert_true(fabs((double)ref[3].triangles - (double)ref[0].triangles) < 0.05 * (double)ref[0].triangles);
    for (int k = 0; k < PIPELINES; ++k) free_job(&ref[k]), free_job(&par[k]);
    free(clouds[1]);
    free(clouds[2]);
    free(clouds[3]);
}

/* ---- the last error is per thread ---- */

typedef struct {
    int id;
    atomic_int *go;
    int wrong;
} error_job;

static void *error_worker(void *arg) {
    error_job *j = arg;
    gmpu_surface *s = NULL;
    if (gmpu_surface_create(&s) != GMPU_OK) {
        j->wrong = -1;
        return NULL;
    }
    char mine[32];
    snprintf(mine, sizeof mine, "= %d ", 5000 + j->id);
    while (!atomic_load(j->go)) sched_yield();
    for (int i = 0; i < 2000; ++i) {
        if (gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 5000 + j->id) != GMPU_ERROR_INVALID_ARGUMENT ||
            !strstr(gmpu_last_error(), mine) || !strstr(gmpu_surface_last_error(s), mine))
            ++j->wrong;
        /* Successes on this thread do not clear it either. */
        double v;
        if (gmpu_surface_get_param(s, GMPU_PARAM_RESOLUTION, &v) != GMPU_OK || !strstr(gmpu_last_error(), mine))
            ++j->wrong;
    }
    gmpu_surface_destroy(s);
    return NULL;
}

static void test_last_error_is_per_thread(void **state) {
    (void)state;
    atomic_int go = 0;
    error_job jobs[EVAL_THREADS];
    pthread_t tid[EVAL_THREADS];
    for (int t = 0; t < EVAL_THREADS; ++t) {
        jobs[t] = (error_job){t, &go, 0};
        assert_int_equal(pthread_create(&tid[t], NULL, error_worker, &jobs[t]), 0);
    }
    atomic_store(&go, 1);
    for (int t = 0; t < EVAL_THREADS; ++t) pthread_join(tid[t], NULL);
    for (int t = 0; t < EVAL_THREADS; ++t)
        if (jobs[t].wrong) fail_msg("thread %d saw another thread's message %d times", t, jobs[t].wrong);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_concurrent_evaluate_one_surface),
        cmocka_unit_test(test_concurrent_evaluate_thin_shell),
        cmocka_unit_test(test_separate_surfaces_in_parallel),
        cmocka_unit_test(test_last_error_is_per_thread),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
