/* Misuse and bad input through the surface half of the C ABI, from C: NULL handles and
 * buffers for every function, calls in the wrong order, too few / identical / collinear /
 * coplanar / non-finite points, bad strides, counts and parameters, and coordinates at
 * 1e±30. Every failure must give its documented status, a message naming the problem, leave
 * outputs untouched and the handle usable: each test ends with a full reconstruction on the
 * handle it abused. (Readers and the points/mesh functions: test_io.cpp, test_io_abi.c.) */
#define _GNU_SOURCE
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gmpu/gmpu.h"
#include "robust_util.h"

#define N_GOOD 2000
static const double kCentre[3] = {0.3, -0.2, 0.5};
static double *g_good; /* N_GOOD points on the unit sphere around kCentre */

static int setup(void **state) {
    (void)state;
    g_good = robust_sphere(N_GOOD, kCentre, 1.0, 1);
    return g_good ? 0 : -1;
}

static int teardown(void **state) {
    (void)state;
    free(g_good);
    return 0;
}

static gmpu_surface *new_surface(void) {
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_non_null(s);
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 24)); /* quick polygonize */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 0));     /* quick orient: no smooth solve */
    return s;
}

/* The handle still works after whatever the test did to it: a full reconstruction of the
 * good sphere gives a closed outward mesh, and evaluate is positive at the centre. */
static void check_usable_and_destroy(gmpu_surface *s) {
    gmpu_mesh *m = robust_reconstruct(s, g_good, N_GOOD);
    const char *problem = robust_mesh_problem(m);
    if (problem) fail_msg("mesh after misuse: %s", problem);
    assert_true(robust_signed_volume(m) > 3.0); /* 4π/3 ≈ 4.19 */
    double f = 0;
    assert_ok(gmpu_surface_evaluate(s, kCentre, 1, &f, NULL));
    assert_true(f > 0.5);
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
}

static void test_null_handles_and_buffers(void **state) {
    (void)state;
    gmpu_surface *s = NULL;
    check_failure(gmpu_surface_create(NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");
    gmpu_surface_destroy(NULL); /* a no-op */
    assert_string_equal(gmpu_surface_last_error(NULL), "");
    assert_int_equal(gmpu_surface_point_count(NULL), 0);

    double v = 42;
    check_failure(gmpu_surface_set_param(NULL, GMPU_PARAM_ERROR, 0.01), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_get_param(NULL, GMPU_PARAM_ERROR, &v), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_get_stat(NULL, GMPU_STAT_POINTS, &v), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    assert_true(v == 42);
    check_failure(gmpu_surface_set_progress(NULL, NULL, NULL), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_set_points_f64(NULL, g_good, N_GOOD, 0), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    float fp[3] = {0, 0, 0};
    check_failure(gmpu_surface_set_points_f32(NULL, fp, 1, 0), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_set_normals_f64(NULL, g_good, N_GOOD, 0), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_set_normals_f32(NULL, fp, 1, 0), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_fit(NULL), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_orient(NULL), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    double q[3] = {0, 0, 0}, val = 7, grad[3] = {7, 7, 7};
    check_failure(gmpu_surface_evaluate(NULL, q, 1, &val, grad), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_surface_copy_normals(NULL, grad, 1), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    gmpu_mesh *m = (gmpu_mesh *)&m; /* garbage that must not be freed nor kept */
    check_failure(gmpu_surface_polygonize(NULL, &m), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
    check_failure(gmpu_mesh_write(NULL, "x.ply"), GMPU_ERROR_INVALID_ARGUMENT, "mesh is NULL");

    /* NULL buffers on a real surface, at every stage; each leaves the handle as it was. */
    s = new_surface();
    check_failure(gmpu_surface_get_param(s, GMPU_PARAM_ERROR, NULL), GMPU_ERROR_INVALID_ARGUMENT, "value is NULL");
    check_failure(gmpu_surface_get_stat(s, GMPU_STAT_POINTS, NULL), GMPU_ERROR_INVALID_ARGUMENT, "value is NULL");
    check_failure(gmpu_surface_set_points_f64(s, NULL, N_GOOD, 0), GMPU_ERROR_INVALID_ARGUMENT, "xyz is NULL");
    check_failure(gmpu_surface_set_points_f32(s, NULL, N_GOOD, 0), GMPU_ERROR_INVALID_ARGUMENT, "xyz is NULL");
    check_failure(gmpu_surface_set_points_f64(s, NULL, 0, 0), GMPU_ERROR_INVALID_ARGUMENT, "xyz is NULL");
    assert_int_equal(gmpu_surface_point_count(s), 0);
    check_failure(gmpu_surface_polygonize(s, NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");

    gmpu_mesh *mesh = robust_reconstruct(s, g_good, N_GOOD);
    gmpu_mesh_destroy(mesh);
    check_failure(gmpu_surface_set_normals_f64(s, NULL, N_GOOD, 0), GMPU_ERROR_INVALID_ARGUMENT, "nxyz is NULL");
    check_failure(gmpu_surface_set_normals_f32(s, NULL, N_GOOD, 0), GMPU_ERROR_INVALID_ARGUMENT, "nxyz is NULL");
    check_failure(gmpu_surface_evaluate(s, NULL, 1, &val, grad), GMPU_ERROR_INVALID_ARGUMENT, "xyz is NULL");
    check_failure(gmpu_surface_evaluate(s, q, 1, NULL, NULL), GMPU_ERROR_INVALID_ARGUMENT,
                  "values and gradients are both NULL");
    assert_true(val == 7 && grad[0] == 7 && grad[1] == 7 && grad[2] == 7); /* untouched */
    check_failure(gmpu_surface_copy_normals(s, NULL, N_GOOD), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");
    check_failure(gmpu_surface_polygonize(s, NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");
    /* The failures above did not drop the orientation: const calls still work. */
    assert_ok(gmpu_surface_evaluate(s, kCentre, 1, &val, NULL));
    assert_true(val > 0.5);
    /* count 0 needs no buffer content. */
    assert_ok(gmpu_surface_evaluate(s, q, 0, &val, NULL));
    /* gmpu_surface_set_progress(s, NULL, ...) removes the callback: not an error. */
    assert_ok(gmpu_surface_set_progress(s, NULL, NULL));
    check_usable_and_destroy(s);
}

static void test_wrong_order(void **state) {
    (void)state;
    gmpu_surface *s = new_surface();
    double q[3] = {0, 0, 0}, val = 7, n[3 * N_GOOD];
    gmpu_mesh *m = (gmpu_mesh *)&m;

    /* Nothing set. */
    check_failure2(gmpu_surface_fit(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit", "gmpu_surface_set_points");
    assert_non_null(strstr(gmpu_surface_last_error(s), "GMPU_ERROR_WRONG_ORDER"));
    check_failure2(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient", "gmpu_surface_fit");
    check_failure2(gmpu_surface_polygonize(s, &m), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_polygonize",
                   "gmpu_surface_orient");
    assert_null(m); /* *out is NULL on failure */
    check_failure2(gmpu_surface_evaluate(s, q, 1, &val, NULL), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_evaluate",
                   "gmpu_surface_orient");
    assert_true(val == 7);
    check_failure(gmpu_surface_copy_normals(s, n, 0), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    check_failure2(gmpu_surface_set_normals_f64(s, g_good, N_GOOD, 0), GMPU_ERROR_WRONG_ORDER,
                   "gmpu_surface_set_normals", "gmpu_surface_set_points");
    double stat = -1;
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &stat));
    assert_true(stat == 0); /* 0 before the stage ran */

    /* Points only. */
    assert_ok(gmpu_surface_set_points_f64(s, g_good, N_GOOD, 0));
    check_failure(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");
    check_failure(gmpu_surface_polygonize(s, &m), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    check_failure(gmpu_surface_evaluate(s, q, 1, &val, NULL), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    check_failure(gmpu_surface_copy_normals(s, n, N_GOOD), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    {
        const int64_t first = 0;
        check_failure2(gmpu_surface_copy_normals_at(s, &first, 1, n), GMPU_ERROR_WRONG_ORDER,
                       "gmpu_surface_copy_normals_at", "gmpu_surface_orient");
    }

    /* Fitted only. */
    assert_ok(gmpu_surface_fit(s));
    check_failure(gmpu_surface_polygonize(s, &m), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    assert_null(m);
    check_failure(gmpu_surface_evaluate(s, q, 1, &val, NULL), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");

    /* Oriented, then a parameter that discards the fit: back to "needs fit". */
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_evaluate(s, q, 1, &val, NULL));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 32)); /* does not refit */
    assert_ok(gmpu_surface_evaluate(s, q, 1, &val, NULL));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_ERROR, 0.003)); /* refits */
    check_failure(gmpu_surface_evaluate(s, q, 1, &val, NULL), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    check_failure(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");

    /* New points discard fit and orientation. */
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_set_points_f64(s, g_good, N_GOOD, 0));
    check_failure(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");

    /* Normals after orient discard the orientation only. */
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    for (size_t i = 0; i < N_GOOD; ++i)
        for (int k = 0; k < 3; ++k) n[3 * i + k] = g_good[3 * i + k] - kCentre[k];
    assert_ok(gmpu_surface_set_normals_f64(s, n, N_GOOD, 0));
    check_failure(gmpu_surface_evaluate(s, q, 1, &val, NULL), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_orient");
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_evaluate(s, kCentre, 1, &val, NULL));
    assert_true(val > 0.5);
    check_usable_and_destroy(s);
}

/* A set_points failure keeps the previous points and the stages built on them. */
static void check_rejected_keeps_state(gmpu_surface *s) {
    assert_int_equal(gmpu_surface_point_count(s), N_GOOD);
    double f = 0;
    assert_ok(gmpu_surface_evaluate(s, kCentre, 1, &f, NULL));
    assert_true(f > 0.5);
}

static gmpu_surface *oriented_surface(void) {
    gmpu_surface *s = new_surface();
    assert_ok(gmpu_surface_set_points_f64(s, g_good, N_GOOD, 0));
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    return s;
}

static void test_too_few_points(void **state) {
    (void)state;
    gmpu_surface *s = oriented_surface();
    const char *last_error_before = NULL;
    (void)last_error_before;
    /* 0 to 3 points (and up to the minimum of 15): too few, with the count and the minimum. */
    for (size_t n = 0; n <= 14; n = n < 3 ? n + 1 : n + 11) {
        char needle[64];
        snprintf(needle, sizeof needle, "%zu points given; at least 15", n);
        check_failure(gmpu_surface_set_points_f64(s, g_good, n, 0), GMPU_ERROR_INVALID_INPUT, needle);
        assert_non_null(strstr(gmpu_surface_last_error(s), needle)); /* the handle's copy too */
        float f32[3 * 14];
        for (size_t i = 0; i < 3 * n; ++i) f32[i] = (float)g_good[i];
        check_failure(gmpu_surface_set_points_f32(s, f32, n, 0), GMPU_ERROR_INVALID_INPUT, needle);
        check_rejected_keeps_state(s);
    }
    /* The minimum follows GMPU_PARAM_MIN_POINTS (this discards the fit). */
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MIN_POINTS, 6));
    check_failure(gmpu_surface_set_points_f64(s, g_good, 5, 0), GMPU_ERROR_INVALID_INPUT, "at least 6");
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MIN_POINTS, 15));
    check_usable_and_destroy(s);
}

/* Clouds just above the minimum: a clean error or a closed mesh, never a crash. */
static void test_tiny_clouds(void **state) {
    (void)state;
    const size_t sizes[] = {15, 16, 20, 30, 60};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; ++k) {
        gmpu_surface *s = new_surface();
        assert_ok(gmpu_surface_set_points_f64(s, g_good, sizes[k], 0));
        gmpu_mesh *m = NULL;
        gmpu_status st = gmpu_surface_fit(s);
        if (st == GMPU_OK) st = gmpu_surface_orient(s);
        if (st == GMPU_OK) st = gmpu_surface_polygonize(s, &m);
        if (st == GMPU_OK) {
            const char *problem = robust_mesh_problem(m);
            if (problem) fail_msg("%zu points: %s", sizes[k], problem);
            /* An empty mesh is no success: it must be an error with a message. */
            if (gmpu_mesh_triangle_count(m) == 0) fail_msg("%zu points: an empty mesh and GMPU_OK", sizes[k]);
        } else {
            assert_null(m);
            assert_true(strlen(gmpu_last_error()) > strlen(gmpu_status_name(st)) + 4);
            assert_true(st != GMPU_ERROR_INTERNAL);
        }
        gmpu_mesh_destroy(m);
        gmpu_surface_destroy(s);
    }
}

static void test_degenerate_clouds(void **state) {
    (void)state;
    gmpu_surface *s = oriented_surface();
    enum { N = 500 };
    double p[3 * N];
    float p32[3 * N];
    robust_rng rng = {99};

    /* All identical, also at 1e300 and 1e-300, and identical to 12 digits. */
    const double where[][3] = {{1, 2, 3}, {0, 0, 0}, {-1e300, 1e300, 5e299}, {1e-300, -1e-300, 0}};
    for (size_t w = 0; w < 4; ++w) {
        for (size_t i = 0; i < N; ++i)
            for (int k = 0; k < 3; ++k) p[3 * i + k] = where[w][k];
        check_failure(gmpu_surface_set_points_f64(s, p, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "identical");
        check_rejected_keeps_state(s);
    }
    for (size_t i = 0; i < N; ++i)
        for (int k = 0; k < 3; ++k) p[3 * i + k] = 1e6 * (k + 1) * (1 + 1e-15 * robust_uniform(&rng));
    check_failure(gmpu_surface_set_points_f64(s, p, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "identical");
    for (size_t i = 0; i < 3 * N; ++i) p32[i] = 2.5f;
    check_failure(gmpu_surface_set_points_f32(s, p32, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "identical");

    /* Collinear: on a line in a general direction, with repeats, at two scales. */
    for (int scale = 0; scale < 2; ++scale) {
        double unit = scale ? 1e20 : 1.0;
        for (size_t i = 0; i < N; ++i) {
            double t = floor(50 * robust_uniform(&rng)) / 7.0; /* many repeated points */
            p[3 * i] = unit * (1 + 1 * t), p[3 * i + 1] = unit * (2 - 2 * t), p[3 * i + 2] = unit * (3 + 0.5 * t);
        }
        check_failure(gmpu_surface_set_points_f64(s, p, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "collinear");
        check_rejected_keeps_state(s);
    }
    /* Two distinct points repeated: collinear too. */
    for (size_t i = 0; i < N; ++i)
        for (int k = 0; k < 3; ++k) p[3 * i + k] = (i & 1) ? k : -k;
    check_failure(gmpu_surface_set_points_f64(s, p, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "collinear");

    /* Coplanar: a tilted square patch (plane x + 2y - z = 1), f64 and f32; also a flat disk of
     * points in z = 0 with repeats. No closed surface exists: the message says so. */
    for (size_t i = 0; i < N; ++i) {
        double a = robust_uniform(&rng), b = robust_uniform(&rng);
        p[3 * i] = a, p[3 * i + 1] = b, p[3 * i + 2] = a + 2 * b - 1;
        for (int k = 0; k < 3; ++k) p32[3 * i + k] = (float)p[3 * i + k];
    }
    check_failure2(gmpu_surface_set_points_f64(s, p, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "coplanar",
                   "no closed surface");
    check_failure2(gmpu_surface_set_points_f32(s, p32, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "coplanar",
                   "no closed surface");
    for (size_t i = 0; i < N; ++i) {
        double r = floor(10 * robust_uniform(&rng)) / 10, t = 2 * M_PI * robust_uniform(&rng);
        p[3 * i] = 1e-30 * r * cos(t), p[3 * i + 1] = 1e-30 * r * sin(t), p[3 * i + 2] = 0;
    }
    check_failure(gmpu_surface_set_points_f64(s, p, N, 0), GMPU_ERROR_DEGENERATE_INPUT, "coplanar");
    check_rejected_keeps_state(s);
    check_usable_and_destroy(s);
}

static void test_nonfinite_points(void **state) {
    (void)state;
    gmpu_surface *s = oriented_surface();
    double *p = malloc(3 * N_GOOD * sizeof *p);
    float *p32 = malloc(3 * N_GOOD * sizeof *p32);
    const double bad[] = {NAN, INFINITY, -INFINITY};
    /* Position of the first bad value: (point, coordinate); a second bad value comes later. */
    const size_t at[][2] = {{0, 0}, {37, 1}, {N_GOOD - 1, 2}, {1234, 2}};
    for (size_t b = 0; b < 3; ++b)
        for (size_t a = 0; a < 4; ++a) {
            memcpy(p, g_good, 3 * N_GOOD * sizeof *p);
            p[3 * at[a][0] + at[a][1]] = bad[b];
            if (at[a][0] + 5 < N_GOOD) p[3 * (at[a][0] + 5)] = NAN;
            for (size_t i = 0; i < 3 * N_GOOD; ++i) p32[i] = (float)p[i];
            char needle[64];
            snprintf(needle, sizeof needle, "point %zu has a NaN or infinite coordinate", at[a][0]);
            check_failure(gmpu_surface_set_points_f64(s, p, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, needle);
            check_failure(gmpu_surface_set_points_f32(s, p32, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, needle);
            check_rejected_keeps_state(s);
        }
    /* A double finite but beyond float: the f64 entry point copes (it normalises first). */
    memcpy(p, g_good, 3 * N_GOOD * sizeof *p);
    for (size_t i = 0; i < 3 * N_GOOD; ++i) p[i] *= 1e200;
    assert_ok(gmpu_surface_set_points_f64(s, p, N_GOOD, 0));
    free(p);
    free(p32);
    check_usable_and_destroy(s);
}

static void test_strides_and_counts(void **state) {
    (void)state;
    gmpu_surface *s = new_surface();
    check_failure(gmpu_surface_set_points_f64(s, g_good, N_GOOD, 16), GMPU_ERROR_INVALID_ARGUMENT,
                  "stride 16 is smaller than one point (24 bytes)");
    float f[3 * 20] = {0};
    check_failure(gmpu_surface_set_points_f32(s, f, 20, 8), GMPU_ERROR_INVALID_ARGUMENT,
                  "stride 8 is smaller than one point (12 bytes)");
    check_failure(gmpu_surface_set_points_f64(s, g_good, SIZE_MAX / 2, 0), GMPU_ERROR_INVALID_ARGUMENT, "too many points");
    check_failure(gmpu_surface_set_points_f64(s, g_good, SIZE_MAX / 8, 24), GMPU_ERROR_INVALID_ARGUMENT, "too many points");
    check_failure(gmpu_surface_set_points_f32(s, f, (size_t)1 << 62, 4096), GMPU_ERROR_INVALID_ARGUMENT, "too many points");
    assert_int_equal(gmpu_surface_point_count(s), 0);

    /* Interleaved records (x y z w, w = NaN garbage that must never be read), f64 and f32,
     * give the same cloud as the packed array. */
    double *rec = malloc(4 * N_GOOD * sizeof *rec);
    float *rec32 = malloc(5 * N_GOOD * sizeof *rec32);
    for (size_t i = 0; i < N_GOOD; ++i) {
        for (int k = 0; k < 3; ++k) rec[4 * i + k] = g_good[3 * i + k], rec32[5 * i + k] = (float)g_good[3 * i + k];
        rec[4 * i + 3] = NAN;
        rec32[5 * i + 3] = rec32[5 * i + 4] = NAN;
    }
    double diag_packed = 0, diag = 0;
    assert_ok(gmpu_surface_set_points_f64(s, g_good, N_GOOD, 0));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag_packed));
    assert_ok(gmpu_surface_set_points_f64(s, rec, N_GOOD, 4 * sizeof(double)));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
    assert_true(diag == diag_packed);
    /* Unaligned stride (20 bytes for floats is fine; the header promises any stride ≥ a point). */
    assert_ok(gmpu_surface_set_points_f32(s, rec32, N_GOOD, 5 * sizeof(float)));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
    assert_true(fabs(diag - diag_packed) < 1e-5 * diag_packed);
    unsigned char *odd = malloc(N_GOOD * 25 + 1);
    for (size_t i = 0; i < N_GOOD; ++i) memcpy(odd + 1 + 25 * i, g_good + 3 * i, 24);
    assert_ok(gmpu_surface_set_points_f64(s, (const double *)(const void *)(odd + 1), N_GOOD, 25));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
    assert_true(diag == diag_packed);
    free(odd);
    free(rec);
    free(rec32);

    /* Normals: count mismatch, NaN / inf / zero with their index, bad stride. */
    double *n = malloc(3 * N_GOOD * sizeof *n);
    for (size_t i = 0; i < 3 * N_GOOD; ++i) n[i] = g_good[i] - kCentre[i % 3];
    check_failure(gmpu_surface_set_normals_f64(s, n, N_GOOD - 1, 0), GMPU_ERROR_INVALID_INPUT,
                  "1999 normals given for 2000 points");
    check_failure(gmpu_surface_set_normals_f64(s, n, N_GOOD, 8), GMPU_ERROR_INVALID_ARGUMENT, "stride 8");
    n[3 * 17 + 1] = NAN;
    check_failure(gmpu_surface_set_normals_f64(s, n, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, "normal 17 is NaN or infinite");
    n[3 * 17 + 1] = 0;
    n[3 * 3] = -INFINITY;
    check_failure(gmpu_surface_set_normals_f64(s, n, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, "normal 3 is NaN or infinite");
    n[3 * 3] = 1;
    n[3 * 1999] = n[3 * 1999 + 1] = n[3 * 1999 + 2] = 0;
    check_failure(gmpu_surface_set_normals_f64(s, n, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, "normal 1999 is zero");
    float n32[3 * N_GOOD];
    for (size_t i = 0; i < 3 * N_GOOD; ++i) n32[i] = (float)n[i];
    check_failure(gmpu_surface_set_normals_f32(s, n32, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, "normal 1999 is zero");
    free(n);
    check_usable_and_destroy(s);
}

static void test_parameters(void **state) {
    (void)state;
    gmpu_surface *s = new_surface();
    struct {
        gmpu_param key;
        const char *name;
        double bad[6];
        int nbad;
        double good;
    } cases[] = {
        {GMPU_PARAM_ERROR, "GMPU_PARAM_ERROR", {0, -0.1, 1, 2, NAN, INFINITY}, 6, 0.004},
        {GMPU_PARAM_MAX_DEPTH, "GMPU_PARAM_MAX_DEPTH", {0, 17, 2.5, -1, NAN, 1e300}, 6, 8},
        {GMPU_PARAM_MIN_POINTS, "GMPU_PARAM_MIN_POINTS", {5, 1001, 10.5, -INFINITY, NAN, 0}, 6, 20},
        {GMPU_PARAM_SUPPORT_SCALE, "GMPU_PARAM_SUPPORT_SCALE", {0.49, 2.01, NAN, INFINITY, 0, -1}, 6, 1.0},
        {GMPU_PARAM_SHARP_FEATURES, "GMPU_PARAM_SHARP_FEATURES", {2, -1, 0.5, NAN, 0, 0}, 4, 0},
        {GMPU_PARAM_RESOLUTION, "GMPU_PARAM_RESOLUTION", {4, 4097, 7, 64.5, -8, NAN}, 6, 40},
        {GMPU_PARAM_LEVEL, "GMPU_PARAM_LEVEL", {-1, 17, 1.5, NAN, 0, 0}, 4, 3},
        {GMPU_PARAM_THREADS, "GMPU_PARAM_THREADS", {-1, 1025, 1.5, NAN, 0, 0}, 4, 2},
        {GMPU_PARAM_MAX_CELLS, "GMPU_PARAM_MAX_CELLS", {0, 2e9, 10.5, NAN, -5, INFINITY}, 6, 1e6},
        {GMPU_PARAM_MAX_TRIANGLES, "GMPU_PARAM_MAX_TRIANGLES", {0, 3e9, 0.5, NAN, -5, INFINITY}, 6, 1e6},
        {GMPU_PARAM_NOISE_SCALE, "GMPU_PARAM_NOISE_SCALE", {-0.1, 20.5, NAN, INFINITY, 0, 0}, 4, 2},
        {GMPU_PARAM_MAX_MEMORY, "GMPU_PARAM_MAX_MEMORY", {0, 999999, 2e15, NAN, -1, INFINITY}, 6, 5e9},
        {GMPU_PARAM_REMOVE_OUTLIERS, "GMPU_PARAM_REMOVE_OUTLIERS", {2, -1, 0.5, NAN, 0, 0}, 4, 0},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; ++c) {
        double before = -1, after = -1;
        assert_ok(gmpu_surface_get_param(s, cases[c].key, &before));
        for (int b = 0; b < cases[c].nbad; ++b) {
            /* RESOLUTION 4 and 7 have their own message: "0 (automatic) or 8..4096". */
            check_failure(gmpu_surface_set_param(s, cases[c].key, cases[c].bad[b]), GMPU_ERROR_INVALID_ARGUMENT,
                          cases[c].name);
            assert_non_null(strstr(gmpu_surface_last_error(s), cases[c].name));
            assert_ok(gmpu_surface_get_param(s, cases[c].key, &after));
            if (after != before) fail_msg("%s changed to %g by a rejected value", cases[c].name, after);
        }
        assert_ok(gmpu_surface_set_param(s, cases[c].key, cases[c].good));
        assert_ok(gmpu_surface_get_param(s, cases[c].key, &after));
        assert_true(after == cases[c].good);
        assert_ok(gmpu_surface_set_param(s, cases[c].key, before));
    }
    /* The range is in the message. */
    check_failure(gmpu_surface_set_param(s, GMPU_PARAM_MAX_DEPTH, 17), GMPU_ERROR_INVALID_ARGUMENT, "16");
    /* Unknown keys, both directions. */
    double v = 5;
    check_failure(gmpu_surface_set_param(s, (gmpu_param)0, 1), GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key 0");
    check_failure(gmpu_surface_set_param(s, (gmpu_param)999, 1), GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key 999");
    check_failure(gmpu_surface_get_param(s, (gmpu_param)-3, &v), GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key -3");
    check_failure(gmpu_surface_get_stat(s, (gmpu_stat)0, &v), GMPU_ERROR_INVALID_ARGUMENT, "unknown statistic key 0");
    check_failure(gmpu_surface_get_stat(s, (gmpu_stat)77, &v), GMPU_ERROR_INVALID_ARGUMENT, "unknown statistic key 77");
    assert_true(v == 5);
    assert_string_equal(gmpu_status_name((gmpu_status)12345), "GMPU_UNKNOWN_STATUS");
    assert_string_equal(gmpu_status_name(GMPU_ERROR_CANCELLED), "GMPU_ERROR_CANCELLED");
    assert_int_equal(gmpu_version_number(), GMPU_VERSION_NUMBER);
    assert_int_equal(gmpu_abi_version(), GMPU_ABI_VERSION);
    check_usable_and_destroy(s);
}

/* copy_normals_at on an index set with every kind of point (first, last, backwards,
 * repeated, and `extra` more, e.g. outliers) gives copy_normals' rows bit for bit. */
static void assert_normals_at_match(const gmpu_surface *s, size_t n, const int64_t *extra, size_t extra_count) {
    double *all = malloc(3 * n * sizeof *all);
    assert_ok(gmpu_surface_copy_normals(s, all, n));
    int64_t idx[16] = {(int64_t)n - 1, 0, (int64_t)n / 2, 0, 1, (int64_t)n / 3};
    size_t count = 6;
    for (size_t k = 0; k < extra_count && count < 16; ++k) idx[count++] = extra[k];
    double at[3 * 16];
    for (size_t k = 0; k < 3 * 16; ++k) at[k] = NAN;
    assert_ok(gmpu_surface_copy_normals_at(s, idx, count, at));
    for (size_t k = 0; k < count; ++k) assert_memory_equal(at + 3 * k, all + 3 * idx[k], 3 * sizeof(double));
    assert_ok(gmpu_surface_copy_normals_at(s, NULL, 0, NULL)); /* nothing asked: nothing done */
    free(all);
}

static void test_evaluate_and_normals_errors(void **state) {
    (void)state;
    gmpu_surface *s = oriented_surface();
    double q[12] = {0, 0, 0, 1, 1, 1, 0, NAN, 0, INFINITY, 0, 0};
    double vals[4] = {7, 7, 7, 7}, grads[12];
    for (int i = 0; i < 12; ++i) grads[i] = 7;
    check_failure(gmpu_surface_evaluate(s, q, 4, vals, grads), GMPU_ERROR_INVALID_INPUT,
                  "query point 2 is NaN or infinite");
    for (int i = 0; i < 4; ++i) assert_true(vals[i] == 7); /* outputs untouched */
    for (int i = 0; i < 12; ++i) assert_true(grads[i] == 7);
    check_failure(gmpu_surface_evaluate(s, q + 9, 1, NULL, grads), GMPU_ERROR_INVALID_INPUT, "query point 0");
    /* Far, huge and tiny queries are finite and have the right sign. */
    const double far[] = {1e300, -1e300, 1e300, 1e10, 0, 0, kCentre[0] + 1e-300, kCentre[1], kCentre[2]};
    assert_ok(gmpu_surface_evaluate(s, far, 3, vals, grads));
    for (int i = 0; i < 3; ++i) assert_true(isfinite(vals[i]) || i == 0);
    assert_true(vals[1] < 0 && vals[2] > 0);
    for (int i = 3; i < 9; ++i) assert_true(isfinite(grads[i]));

    double *n = malloc(3 * N_GOOD * sizeof *n);
    check_failure(gmpu_surface_copy_normals(s, n, N_GOOD - 1), GMPU_ERROR_INVALID_ARGUMENT,
                  "count 1999 differs from the 2000 points");
    check_failure(gmpu_surface_copy_normals(s, n, 0), GMPU_ERROR_INVALID_ARGUMENT, "count 0");
    assert_ok(gmpu_surface_copy_normals(s, n, N_GOOD));
    /* Normals of chosen points: a bad index is named, and out is untouched. */
    {
        const int64_t bad[3] = {5, (int64_t)N_GOOD, 7}, negative[2] = {0, -1};
        double at[9] = {7, 7, 7, 7, 7, 7, 7, 7, 7};
        check_failure(gmpu_surface_copy_normals_at(s, bad, 3, at), GMPU_ERROR_INVALID_ARGUMENT,
                      "indices[1] = 2000 is not a point: there are 2000 points");
        check_failure(gmpu_surface_copy_normals_at(s, negative, 2, at), GMPU_ERROR_INVALID_ARGUMENT, "indices[1] = -1");
        for (int k = 0; k < 9; ++k) assert_true(at[k] == 7);
        check_failure(gmpu_surface_copy_normals_at(s, NULL, 1, at), GMPU_ERROR_INVALID_ARGUMENT, "indices is NULL");
        check_failure(gmpu_surface_copy_normals_at(s, bad, 1, NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");
        check_failure(gmpu_surface_copy_normals_at(NULL, bad, 1, at), GMPU_ERROR_INVALID_ARGUMENT, "surface is NULL");
        assert_normals_at_match(s, N_GOOD, NULL, 0);
    }
    /* Outward on a sphere. */
    size_t outward = 0;
    for (size_t i = 0; i < N_GOOD; ++i) {
        double d = 0;
        for (int k = 0; k < 3; ++k) d += n[3 * i + k] * (g_good[3 * i + k] - kCentre[k]);
        outward += d > 0.9;
    }
    assert_true(outward > N_GOOD * 99 / 100);
    free(n);

    /* A mesh write that fails leaves no file and the mesh usable. */
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    check_failure(gmpu_mesh_write(m, "/nonexistent-dir-gmpu/x.ply"), GMPU_ERROR_IO, "/nonexistent-dir-gmpu/x.ply");
    check_failure(gmpu_mesh_write(m, "mesh.wrl"), GMPU_ERROR_UNSUPPORTED, "'.wrl'");
    assert_null(fopen("mesh.wrl", "rb"));
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    check_usable_and_destroy(s);
}

/* The last failure's message is per thread and per handle: a later success does not clear
 * it, another handle's failure does not overwrite this handle's. */
static void test_error_messages(void **state) {
    (void)state;
    gmpu_surface *a = new_surface(), *b = new_surface();
    assert_string_equal(gmpu_surface_last_error(a), "");
    check_failure(gmpu_surface_fit(a), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");
    check_failure(gmpu_surface_set_param(b, GMPU_PARAM_LEVEL, 99), GMPU_ERROR_INVALID_ARGUMENT, "GMPU_PARAM_LEVEL");
    assert_non_null(strstr(gmpu_surface_last_error(a), "gmpu_surface_fit"));
    assert_non_null(strstr(gmpu_surface_last_error(b), "GMPU_PARAM_LEVEL"));
    assert_non_null(strstr(gmpu_last_error(), "GMPU_PARAM_LEVEL"));
    /* Every message starts with the status name. */
    assert_int_equal(strncmp(gmpu_surface_last_error(a), "GMPU_ERROR_WRONG_ORDER: ", 24), 0);
    gmpu_surface_destroy(b);
    check_usable_and_destroy(a);
}

/* Distance of every mesh vertex to the torus (major R, minor r, centre c, axis z), as a
 * fraction of r: the largest. */
static double torus_deviation(const gmpu_mesh *m, const double c[3], double R, double r) {
    const double *v = gmpu_mesh_vertices(m);
    double worst = 0;
    for (size_t i = 0; i < gmpu_mesh_vertex_count(m); ++i) {
        double x = (v[3 * i] - c[0]) / r, y = (v[3 * i + 1] - c[1]) / r, z = (v[3 * i + 2] - c[2]) / r;
        double d = fabs(hypot(hypot(x, y) - R / r, z) - 1);
        worst = fmax(worst, d);
    }
    return worst;
}

/* Coordinates at 1e30 and 1e-30 (and 1e±290, f32 at 1e±30), centred far from the origin or
 * not: the library normalises, so a torus (which needs a real octree, unlike a sphere that
 * one quadric fits) gives the same octree and the same mesh scaled, f scales with the
 * units, and the statistics are in caller units. Beyond ±1e300 or below a 1e-300 span, a
 * clean INVALID_INPUT. */
static void test_extreme_scales(void **state) {
    (void)state;
    const size_t N = robust_quick() ? 2500 : 4000; /* valgrind: fewer points and cases */
    const double R = 1.0, r = 0.4;
    const double scales[] = {1.0, 1e30, 1e-30, 1e290, 1e-290};
    const double offsets[] = {0.0, 1000.0};
    const size_t nscales = robust_quick() ? 3 : 5, noffsets = robust_quick() ? 1 : 2;
    double ref_cells = 0, ref_dev = 0;
    for (size_t si = 0; si < nscales; ++si)
        for (size_t oi = 0; oi < noffsets; ++oi) {
            const double scale = scales[si];
            double c[3];
            for (int k = 0; k < 3; ++k) c[k] = scale * (kCentre[k] + offsets[oi]);
            double *p = robust_torus(N, scale * R, scale * r, c, 4);
            gmpu_surface *s = new_surface();
            assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 32));
            gmpu_status st = gmpu_surface_set_points_f64(s, p, N, 0);
            if (st != GMPU_OK) fail_msg("scale %g offset %g: %s", scale, offsets[oi], gmpu_last_error());
            double diag = 0, expected = scale * 2 * sqrt((R + r) * (R + r) * 2 + r * r);
            assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
            if (!(fabs(diag / expected - 1) < 0.01))
                fail_msg("scale %g: bbox diagonal %g, expected %g", scale, diag, expected);
            assert_ok(gmpu_surface_fit(s));
            double cells = 0;
            assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells));
            assert_ok(gmpu_surface_orient(s));
            gmpu_mesh *m = NULL;
            assert_ok(gmpu_surface_polygonize(s, &m));
            const char *problem = robust_mesh_problem(m);
            if (problem) fail_msg("scale %g: %s", scale, problem);
            const double dev = torus_deviation(m, c, scale * R, scale * r);
            if (si == 0 && oi == 0) ref_cells = cells, ref_dev = dev;
            assert_true(cells > 50); /* a real octree: the test would not see a broken ε otherwise */
            /* The same octree (to float rounding of the normalised points) and the same mesh. */
            if (!(fabs(cells - ref_cells) <= 0.02 * ref_cells && dev < 0.15 && fabs(dev - ref_dev) < 0.02))
                fail_msg("scale %g offset %g: %g cells, mesh within %g r of the torus (scale 1: %g cells, %g r)",
                         scale, offsets[oi], cells, dev, ref_cells, ref_dev);
            /* f in caller units: about +r inside the tube, about -r at the centre hole. */
            double q[6] = {c[0] + scale * R, c[1], c[2], c[0], c[1], c[2]}, f[2], g[6];
            assert_ok(gmpu_surface_evaluate(s, q, 2, f, g));
            if (!(f[0] > 0.5 * scale * r && f[0] < 2 * scale * r && f[1] < -0.3 * scale * (R - r) &&
                  f[1] > -3 * scale * (R - r)))
                fail_msg("scale %g: f(tube centre) = %g, f(hole) = %g", scale, f[0], f[1]);
            for (int i = 0; i < 6; ++i) assert_true(isfinite(g[i]));
            /* Normals are unit and finite whatever the scale. */
            const double *mn = gmpu_mesh_normals(m);
            for (size_t i = 0; i < gmpu_mesh_vertex_count(m); ++i) {
                double len = sqrt(mn[3 * i] * mn[3 * i] + mn[3 * i + 1] * mn[3 * i + 1] + mn[3 * i + 2] * mn[3 * i + 2]);
                if (!(fabs(len - 1) < 1e-6)) fail_msg("scale %g: vertex normal %zu has length %g", scale, i, len);
            }
            gmpu_mesh_destroy(m);
            gmpu_surface_destroy(s);

            /* float input at 1e±30 (1e±290 is not representable). */
            if (scale >= 1e-30 && scale <= 1e30) {
                float *p32 = malloc(3 * N * sizeof *p32);
                for (size_t i = 0; i < 3 * N; ++i) p32[i] = (float)p[i];
                s = new_surface();
                assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 32));
                assert_ok(gmpu_surface_set_points_f32(s, p32, N, 0));
                assert_ok(gmpu_surface_fit(s));
                assert_ok(gmpu_surface_orient(s));
                assert_ok(gmpu_surface_polygonize(s, &m));
                assert_null(robust_mesh_problem(m));
                /* float keeps ~7 digits: 1000 radii off centre leaves ~4 for the shape */
                double fdev = torus_deviation(m, c, scale * R, scale * r);
                if (!(fdev < 0.15)) fail_msg("f32 scale %g offset %g: mesh within %g r", scale, offsets[oi], fdev);
                gmpu_mesh_destroy(m);
                gmpu_surface_destroy(s);
                free(p32);
            }
            free(p);
        }

    /* Beyond what can be normalised: a clean INVALID_INPUT that says how to fix it. */
    const struct {
        double scale, offset;
        const char *needle;
    } bad[] = {
        {1e301, 0, "beyond 1e300"},            /* coordinates near the largest double */
        {1e307, 0, "beyond 1e300"},            /* extent would overflow to inf */
        {1e295, 2e300, "beyond 1e300"},        /* a small cloud very far out */
        {1e-305, 0, "below 1e-300"},           /* span would underflow the normalisation */
        {1e-310, 0, "below 1e-300"},           /* subnormal: 1 / span overflows */
    };
    for (size_t b = 0; b < sizeof bad / sizeof *bad; ++b) {
        double c[3] = {bad[b].offset, bad[b].offset, 0};
        double *p = robust_sphere(N_GOOD, c, bad[b].scale, 2);
        gmpu_surface *s = oriented_surface();
        check_failure2(gmpu_surface_set_points_f64(s, p, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, bad[b].needle,
                       "rescale the points");
        check_rejected_keeps_state(s);
        free(p);
        check_usable_and_destroy(s);
    }
}

/* Calls on a surface from its own progress callback. Each would free or rebuild what the
 * running stage reads (the points, the octree, the surface itself): they must be refused
 * with GMPU_ERROR_BUSY, naming the running stage, and change nothing; destroy is deferred
 * until the stage returns (cancelling it). A second surface stays usable from the callback. */
enum reentry { RE_SET_POINTS, RE_SET_NORMALS, RE_SET_PARAM, RE_SET_PROGRESS, RE_FIT, RE_ORIENT, RE_POLYGONIZE,
               RE_EVALUATE, RE_COPY_NORMALS, RE_GET_PARAM, RE_GET_STAT, RE_DESTROY, RE_OTHER_SURFACE, RE_COUNT };
static const char *const kReentryNames[RE_COUNT] = {
    "gmpu_surface_set_points", "gmpu_surface_set_normals", "gmpu_surface_set_param", "gmpu_surface_set_progress",
    "gmpu_surface_fit", "gmpu_surface_orient", "gmpu_surface_polygonize", "gmpu_surface_evaluate",
    "gmpu_surface_copy_normals", "gmpu_surface_get_param", "gmpu_surface_get_stat", "gmpu_surface_destroy",
    "another surface"};

struct reentry_probe {
    gmpu_surface *s;
    enum reentry what;
    gmpu_stage during;
    int calls;             /* callback calls during `during` that made the re-entrant call */
    gmpu_status status;    /* of the first one */
    char message[512];
};

static int reentering_progress(void *user, gmpu_stage stage, double fraction) {
    (void)fraction;
    struct reentry_probe *p = user;
    if (stage != p->during || p->calls++ > 0) return 0;
    gmpu_surface *s = p->s;
    double v[6] = {0, 0, 0, 0, 0, 0}, n[3 * N_GOOD];
    gmpu_mesh *m = NULL;
    gmpu_status st = GMPU_OK;
    for (size_t i = 0; i < 3 * N_GOOD; ++i) n[i] = g_good[i] - kCentre[i % 3];
    switch (p->what) {
        case RE_SET_POINTS: st = gmpu_surface_set_points_f64(s, g_good, 100, 0); break;
        case RE_SET_NORMALS: st = gmpu_surface_set_normals_f64(s, n, N_GOOD, 0); break;
        case RE_SET_PARAM: st = gmpu_surface_set_param(s, GMPU_PARAM_ERROR, 0.01); break;
        case RE_SET_PROGRESS: st = gmpu_surface_set_progress(s, NULL, NULL); break;
        case RE_FIT: st = gmpu_surface_fit(s); break;
        case RE_ORIENT: st = gmpu_surface_orient(s); break;
        case RE_POLYGONIZE: st = gmpu_surface_polygonize(s, &m); break;
        case RE_EVALUATE: st = gmpu_surface_evaluate(s, kCentre, 1, v, NULL); break;
        case RE_COPY_NORMALS: st = gmpu_surface_copy_normals(s, n, N_GOOD); break;
        case RE_GET_PARAM: st = gmpu_surface_get_param(s, GMPU_PARAM_ERROR, v); break;
        case RE_GET_STAT: st = gmpu_surface_get_stat(s, GMPU_STAT_CELLS, v); break;
        case RE_DESTROY: gmpu_surface_destroy(s); break;
        case RE_OTHER_SURFACE: {
            gmpu_surface *other = NULL;
            st = gmpu_surface_create(&other);
            if (st == GMPU_OK) st = gmpu_surface_set_param(other, GMPU_PARAM_RESOLUTION, 24);
            gmpu_mesh *om = st == GMPU_OK ? robust_reconstruct(other, g_good, N_GOOD) : NULL;
            if (!om) st = GMPU_ERROR_INTERNAL;
            gmpu_mesh_destroy(om);
            gmpu_surface_destroy(other);
            break;
        }
        case RE_COUNT: break;
    }
    gmpu_mesh_destroy(m);
    p->status = st;
    snprintf(p->message, sizeof p->message, "%s", gmpu_last_error());
    return 0;
}

static void test_reentrant_calls_refused(void **state) {
    (void)state;
    static const char *const stage_names[4] = {"", "gmpu_surface_fit", "gmpu_surface_orient",
                                               "gmpu_surface_polygonize"};
    for (int during = GMPU_STAGE_FIT; during <= GMPU_STAGE_POLYGONIZE; ++during)
        for (int what = 0; what < RE_COUNT; ++what) {
            /* Under valgrind each call is tried during one stage only, each stage in turn. */
            if (robust_quick() && what % 3 != during - GMPU_STAGE_FIT) continue;
            struct reentry_probe p = {NULL, (enum reentry)what, (gmpu_stage)during, 0, GMPU_OK, ""};
            gmpu_surface *s = new_surface();
            p.s = s;
            /* Oriented already, so that evaluate and copy_normals would otherwise succeed. */
            gmpu_mesh *first = robust_reconstruct(s, g_good, N_GOOD);
            gmpu_mesh_destroy(first);
            double cells_before = 0, cells_after = 0;
            assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells_before));
            assert_ok(gmpu_surface_set_progress(s, reentering_progress, &p));
            gmpu_mesh *m = NULL;
            gmpu_status st = during == GMPU_STAGE_FIT      ? gmpu_surface_fit(s)
                             : during == GMPU_STAGE_ORIENT ? gmpu_surface_orient(s)
                                                           : gmpu_surface_polygonize(s, &m);
            if (p.calls == 0) fail_msg("%s: the callback never ran", stage_names[during]);
            if (what == RE_DESTROY) {
                /* Deferred: the surface is gone once the stage returns, which it cancelled. */
                if (st != GMPU_ERROR_CANCELLED && st != GMPU_OK)
                    fail_msg("destroy during %s: the stage returned %s", stage_names[during], gmpu_status_name(st));
                gmpu_mesh_destroy(m);
                continue;
            }
            if (what == RE_OTHER_SURFACE) {
                if (p.status != GMPU_OK) fail_msg("another surface during %s: %s", stage_names[during], p.message);
            } else {
                if (p.status != GMPU_ERROR_BUSY || !strstr(p.message, "GMPU_ERROR_BUSY") ||
                    !strstr(p.message, kReentryNames[what]) || !strstr(p.message, stage_names[during]))
                    fail_msg("%s during %s: %s, \"%s\"", kReentryNames[what], stage_names[during],
                             gmpu_status_name(p.status), p.message);
            }
            if (st != GMPU_OK) fail_msg("%s after a refused %s: %s", stage_names[during], kReentryNames[what], gmpu_last_error());
            /* Nothing changed underneath the stage: same points, same parameters. */
            assert_int_equal(gmpu_surface_point_count(s), N_GOOD);
            double e = 0;
            assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_ERROR, &e));
            assert_true(e == 0.002);
            assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_CELLS, &cells_after));
            assert_true(cells_after == cells_before);
            if (m) {
                const char *problem = robust_mesh_problem(m);
                if (problem) fail_msg("mesh of the polygonize with a refused call: %s", problem);
            }
            gmpu_mesh_destroy(m);
            assert_ok(gmpu_surface_set_progress(s, NULL, NULL));
            check_usable_and_destroy(s);
        }
    assert_string_equal(gmpu_status_name(GMPU_ERROR_BUSY), "GMPU_ERROR_BUSY");
    assert_int_equal(GMPU_ERROR_BUSY, 12);
}

/* A few points far from the rest (a scanner's stray returns, a wrong line in a file) must not
 * set the scale: with two of them at ±100 to ±1e6 sphere radii, the sphere is still meshed
 * as without them (they used to leave it smaller than one grid cube: an empty mesh and
 * GMPU_OK, or a blob around the outliers, or "collinear"). They are counted in
 * GMPU_STAT_OUTLIERS, still count as input points, and get the nearest point's normal. */
static void test_outliers_set_aside(void **state) {
    (void)state;
    const size_t n = N_GOOD + 2;
    double *xyz = malloc(3 * n * sizeof *xyz), *normals = malloc(3 * n * sizeof *normals);
    memcpy(xyz, g_good, 3 * N_GOOD * sizeof *xyz);
    gmpu_surface *clean = new_surface();
    gmpu_mesh *reference = robust_reconstruct(clean, g_good, N_GOOD);
    double clean_outliers = -1, clean_diag = 0;
    assert_ok(gmpu_surface_get_stat(clean, GMPU_STAT_OUTLIERS, &clean_outliers));
    assert_ok(gmpu_surface_get_stat(clean, GMPU_STAT_BBOX_DIAGONAL, &clean_diag));
    assert_true(clean_outliers == 0);
    const double offsets[] = {100, 1000, 1e4, 1e6};
    for (size_t k = 0; k < sizeof offsets / sizeof *offsets; ++k) {
        for (int d = 0; d < 3; ++d) {
            xyz[3 * N_GOOD + d] = kCentre[d] + offsets[k];
            xyz[3 * N_GOOD + 3 + d] = kCentre[d] - offsets[k] * (d == 1 ? 0.5 : 1.0);
        }
        gmpu_surface *s = new_surface();
        gmpu_mesh *m = robust_reconstruct(s, xyz, n);
        double outliers = 0, points = 0, diag = 0;
        assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_OUTLIERS, &outliers));
        assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_POINTS, &points));
        assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
        if (outliers != 2) fail_msg("outliers at %g: %g found", offsets[k], outliers);
        assert_true(points == (double)n && gmpu_surface_point_count(s) == n);
        assert_true(diag == clean_diag); /* the scale is the sphere's */
        /* The same mesh as without the outliers. */
        assert_int_equal(gmpu_mesh_triangle_count(m), gmpu_mesh_triangle_count(reference));
        assert_memory_equal(gmpu_mesh_vertices(m), gmpu_mesh_vertices(reference),
                            3 * gmpu_mesh_vertex_count(m) * sizeof(double));
        /* Normals for every input point, the outliers included (unit length). */
        assert_ok(gmpu_surface_copy_normals(s, normals, n));
        {
            const int64_t outliers[2] = {(int64_t)N_GOOD + 1, (int64_t)N_GOOD};
            assert_normals_at_match(s, n, outliers, 2);
        }
        for (size_t i = N_GOOD; i < n; ++i) {
            const double *v = normals + 3 * i;
            assert_true(fabs(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - 1) < 1e-6);
        }
        /* Input normals count the outliers too. */
        assert_ok(gmpu_surface_set_normals_f64(s, normals, n, 0));
        check_failure(gmpu_surface_set_normals_f64(s, normals, N_GOOD, 0), GMPU_ERROR_INVALID_INPUT, "2002 points");
        gmpu_mesh_destroy(m);
        gmpu_surface_destroy(s);
    }
    gmpu_mesh_destroy(reference);
    gmpu_surface_destroy(clean);

    /* GMPU_PARAM_REMOVE_OUTLIERS = 0: found and counted, but kept: they set the box again. */
    gmpu_surface *s = new_surface();
    double v = -1, outliers = 0, diag = 0;
    assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_REMOVE_OUTLIERS, &v));
    assert_true(v == 1);
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_REMOVE_OUTLIERS, 0));
    for (int d = 0; d < 3; ++d) xyz[3 * N_GOOD + d] = kCentre[d] + 100, xyz[3 * N_GOOD + 3 + d] = kCentre[d] - 100;
    assert_ok(gmpu_surface_set_points_f64(s, xyz, n, 0));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_OUTLIERS, &outliers));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
    assert_true(outliers == 2 && diag > 300);
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_REMOVE_OUTLIERS, 1));
    assert_ok(gmpu_surface_set_points_f64(s, xyz, n, 0));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
    assert_true(diag == clean_diag);
    check_usable_and_destroy(s);
    free(xyz);
    free(normals);
}

/* Vertices of m within `radius` × (1 ± tolerance) of c, and every triangle's three vertices on
 * the same side of x = split: the count of vertices near c. */
static size_t sphere_vertices(const gmpu_mesh *m, const double c[3], double radius, double split, int left) {
    const double *v = gmpu_mesh_vertices(m);
    const uint32_t *t = gmpu_mesh_triangles(m);
    for (size_t i = 0; i < gmpu_mesh_triangle_count(m); ++i)
        for (int k = 1; k < 3; ++k)
            assert_true((v[3 * t[3 * i]] < split) == (v[3 * t[3 * i + k]] < split)); /* no bridge */
    size_t n = 0;
    for (size_t i = 0; i < gmpu_mesh_vertex_count(m); ++i) {
        const double *p = v + 3 * i;
        if ((p[0] < split) != left) continue;
        const double r = sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]));
        if (fabs(r - radius) > 0.03 * radius) fail_msg("vertex %zu at %g from the centre of a sphere of radius %g", i, r, radius);
        ++n;
    }
    return n;
}

/* Progress of a clustered surface: one stage from 0 to 1 across its clusters; a cancel in
 * the second cluster's share stops the whole stage. */
typedef struct {
    double last, cancel_at;
    int decreasing, calls;
} cluster_watch;
static int on_cluster_progress(void *user, gmpu_stage stage, double fraction) {
    cluster_watch *w = user;
    (void)stage;
    w->decreasing |= fraction < w->last;
    w->last = fraction;
    ++w->calls;
    return w->cancel_at > 0 && fraction >= w->cancel_at;
}

/* Clusters far apart (a unit sphere and one of radius 1000 a million units away): each is
 * reconstructed at its own scale, exactly as if alone (the merged mesh is the two meshes one
 * after the other), normals come back in input order, and evaluate answers with the nearest
 * cluster's field. They used to be refused ("clusters this far apart"); at one scale the small
 * sphere would be far below one grid cube. */
static void test_separate_clusters(void **state) {
    (void)state;
    const double far_centre[3] = {1e6, 3, -2};
    double *big = robust_sphere(N_GOOD, far_centre, 1000.0, 5);
    double *xyz = malloc(6 * N_GOOD * sizeof *xyz), *normals = malloc(6 * N_GOOD * sizeof *normals);
    /* Interleaved, so that each cluster's points are spread through the input. */
    for (size_t i = 0; i < 2 * N_GOOD; ++i) memcpy(xyz + 3 * i, (i % 2 ? big : g_good) + 3 * (i / 2), 3 * sizeof *xyz);
    gmpu_surface *alone_small = new_surface(), *alone_big = new_surface(), *s = new_surface();
    gmpu_mesh *small_mesh = robust_reconstruct(alone_small, g_good, N_GOOD);
    gmpu_mesh *big_mesh = robust_reconstruct(alone_big, big, N_GOOD);
    gmpu_mesh *m = robust_reconstruct(s, xyz, 2 * N_GOOD);
    const char *problem = robust_mesh_problem(m);
    if (problem) fail_msg("merged mesh: %s", problem);
    const double split = 5e5;
    assert_true(sphere_vertices(m, kCentre, 1.0, split, 1) > 100);
    assert_true(sphere_vertices(m, far_centre, 1000.0, split, 0) > 100);
    /* Each cluster exactly as reconstructed alone, in the order of their first points. */
    const size_t ns = gmpu_mesh_vertex_count(small_mesh), nb = gmpu_mesh_vertex_count(big_mesh);
    assert_int_equal(gmpu_mesh_vertex_count(m), ns + nb);
    assert_int_equal(gmpu_mesh_triangle_count(m), gmpu_mesh_triangle_count(small_mesh) + gmpu_mesh_triangle_count(big_mesh));
    assert_memory_equal(gmpu_mesh_vertices(m), gmpu_mesh_vertices(small_mesh), 3 * ns * sizeof(double));
    assert_memory_equal(gmpu_mesh_vertices(m) + 3 * ns, gmpu_mesh_vertices(big_mesh), 3 * nb * sizeof(double));
    double components = 0, points = 0, diag = 0;
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_COMPONENTS, &components));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_POINTS, &points));
    assert_ok(gmpu_surface_get_stat(s, GMPU_STAT_BBOX_DIAGONAL, &diag));
    assert_true(components == 2 && points == 2 * N_GOOD && diag > 1e6);
    /* Normals in input order: outward on each sphere. */
    assert_ok(gmpu_surface_copy_normals(s, normals, 2 * N_GOOD));
    {
        const int64_t each_cluster[4] = {3, 2 * N_GOOD - 2, 2 * N_GOOD - 1, 1};
        assert_normals_at_match(s, 2 * N_GOOD, each_cluster, 4);
    }
    for (size_t i = 0; i < 2 * N_GOOD; ++i) {
        const double *c = i % 2 ? far_centre : kCentre, r = i % 2 ? 1000.0 : 1.0, *p = xyz + 3 * i, *n = normals + 3 * i;
        const double dot = ((p[0] - c[0]) * n[0] + (p[1] - c[1]) * n[1] + (p[2] - c[2]) * n[2]) / r;
        if (dot < 0.9) fail_msg("normal %zu: %g along the outward radius", i, dot);
    }
    /* The field: inside each sphere positive, on it about zero, in its own units. */
    const double q[12] = {kCentre[0], kCentre[1], kCentre[2], kCentre[0] + 1, kCentre[1], kCentre[2],
                          far_centre[0], far_centre[1], far_centre[2], far_centre[0], far_centre[1] + 1000, far_centre[2]};
    double f[4], g[12];
    assert_ok(gmpu_surface_evaluate(s, q, 4, f, g));
    assert_true(f[0] > 0.5 && fabs(f[1]) < 0.05 && f[2] > 500 && fabs(f[3]) < 50);
    assert_true(g[3] < -0.5 && g[10] < -0.5); /* the field falls outward */
    /* Input normals go to their clusters too. */
    assert_ok(gmpu_surface_set_normals_f64(s, normals, 2 * N_GOOD, 0));
    check_failure(gmpu_surface_evaluate(s, q, 1, f, NULL), GMPU_ERROR_WRONG_ORDER, "orient");
    assert_ok(gmpu_surface_orient(s));
    /* One fit from 0 to 1 over both clusters; cancelled in the second, it is cancelled. */
    cluster_watch w = {0, 0, 0, 0};
    assert_ok(gmpu_surface_set_progress(s, on_cluster_progress, &w));
    assert_ok(gmpu_surface_fit(s));
    assert_true(!w.decreasing && w.last == 1.0 && w.calls >= 3);
    cluster_watch stop = {0, 0.75, 0, 0};
    assert_ok(gmpu_surface_set_progress(s, on_cluster_progress, &stop));
    check_failure(gmpu_surface_fit(s), GMPU_ERROR_CANCELLED, "cluster 2 of 2");
    assert_ok(gmpu_surface_set_progress(s, NULL, NULL));
    /* The clusters no longer share one fit: none is kept (one surface keeps its old one). */
    check_failure(gmpu_surface_orient(s), GMPU_ERROR_WRONG_ORDER, "gmpu_surface_fit");
    gmpu_mesh_destroy(m);
    gmpu_mesh_destroy(small_mesh);
    gmpu_mesh_destroy(big_mesh);
    gmpu_surface_destroy(alone_small);
    gmpu_surface_destroy(alone_big);
    free(big);
    free(xyz);
    free(normals);
    check_usable_and_destroy(s); /* back to one cluster */
}

/* Counts whose byte sizes overflow size_t are rejected before any read. */
static void test_overflowing_counts(void **state) {
    (void)state;
    gmpu_surface *s = new_surface();
    gmpu_mesh *first = robust_reconstruct(s, g_good, N_GOOD);
    gmpu_mesh_destroy(first);
    double q[3] = {0, 0, 0}, v[1] = {7}, g[3] = {7, 7, 7};
    const size_t huge[] = {SIZE_MAX, SIZE_MAX / 3 + 1, SIZE_MAX / 24 + 1, ((size_t)1 << 62) + 1};
    for (size_t k = 0; k < sizeof huge / sizeof *huge; ++k) {
        check_failure(gmpu_surface_evaluate(s, q, huge[k], v, g), GMPU_ERROR_INVALID_ARGUMENT, "count");
        assert_true(v[0] == 7 && g[0] == 7);
        check_failure(gmpu_surface_set_points_f64(s, g_good, huge[k], 0), GMPU_ERROR_INVALID_ARGUMENT, "too many");
        check_failure(gmpu_surface_set_points_f32(s, (const float *)g_good, huge[k], 0), GMPU_ERROR_INVALID_ARGUMENT,
                      "too many");
        check_failure(gmpu_surface_set_normals_f64(s, g_good, huge[k], 0), GMPU_ERROR_INVALID_ARGUMENT, "too many");
        gmpu_mesh *m = NULL;
        const uint32_t tri[3] = {0, 0, 0};
        check_failure(gmpu_mesh_create(q, huge[k], tri, 1, &m), GMPU_ERROR_INVALID_ARGUMENT, "too large");
        check_failure(gmpu_mesh_create(q, 1, tri, huge[k], &m), GMPU_ERROR_INVALID_ARGUMENT, "too large");
        assert_null(m);
    }
    /* The stride times the count overflows, though each alone is modest. */
    check_failure(gmpu_surface_set_points_f64(s, g_good, (size_t)1 << 40, (size_t)1 << 30), GMPU_ERROR_INVALID_ARGUMENT,
                  "too many");
    check_usable_and_destroy(s);
}

/* Normals are directions: any finite, non-zero length is accepted, however tiny or huge. */
static void test_normals_of_any_length(void **state) {
    (void)state;
    gmpu_surface *s = new_surface();
    assert_ok(gmpu_surface_set_points_f64(s, g_good, N_GOOD, 0));
    double *n = malloc(3 * N_GOOD * sizeof *n);
    const double scales[] = {1e-320, 5e-324, 1e-160, 1e200, 1e300, DBL_MAX};
    for (size_t k = 0; k < sizeof scales / sizeof *scales; ++k) {
        for (size_t i = 0; i < 3 * N_GOOD; ++i) n[i] = (g_good[i] - kCentre[i % 3]) * scales[k];
        if (scales[k] == DBL_MAX) /* the components themselves stay finite: clamp */
            for (size_t i = 0; i < 3 * N_GOOD; ++i) n[i] = fmax(-DBL_MAX, fmin(DBL_MAX, n[i]));
        if (gmpu_surface_set_normals_f64(s, n, N_GOOD, 0) != GMPU_OK)
            fail_msg("normals scaled by %g: %s", scales[k], gmpu_last_error());
        assert_ok(gmpu_surface_fit(s));
        assert_ok(gmpu_surface_orient(s));
        double f = 0;
        assert_ok(gmpu_surface_evaluate(s, kCentre, 1, &f, NULL));
        if (!(f > 0.5)) fail_msg("normals scaled by %g: f(centre) = %g", scales[k], f);
    }
    free(n);
    check_usable_and_destroy(s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_null_handles_and_buffers),
        cmocka_unit_test(test_wrong_order),
        cmocka_unit_test(test_too_few_points),
        cmocka_unit_test(test_tiny_clouds),
        cmocka_unit_test(test_degenerate_clouds),
        cmocka_unit_test(test_nonfinite_points),
        cmocka_unit_test(test_strides_and_counts),
        cmocka_unit_test(test_parameters),
        cmocka_unit_test(test_evaluate_and_normals_errors),
        cmocka_unit_test(test_error_messages),
        cmocka_unit_test(test_extreme_scales),
        cmocka_unit_test(test_reentrant_calls_refused),
        cmocka_unit_test(test_overflowing_counts),
        cmocka_unit_test(test_normals_of_any_length),
        cmocka_unit_test(test_outliers_set_aside),
        cmocka_unit_test(test_separate_clusters),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
