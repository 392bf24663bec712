/* The point and mesh functions of the C ABI, through the public header only, from C:
 * argument checks, statuses and messages, round trips through files, and the shared data. */
#define _GNU_SOURCE /* mkdtemp, nftw */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gmpu/gmpu.h"
#include "scratch_dir.h"

static int setup(void **state) {
    (void)state;
    return scratch_create("io-abi-scratch");
}

static int teardown(void **state) {
    (void)state;
    return scratch_remove();
}

static void put(const char *path, const char *text) {
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* The status must be `expected` and gmpu_last_error() must name it and contain `needle`. */
static void check_failure(gmpu_status got, gmpu_status expected, const char *needle) {
    const char *msg = gmpu_last_error();
    if (got != expected)
        fail_msg("expected %s, got %s (%s)", gmpu_status_name(expected), gmpu_status_name(got), msg);
    if (strstr(msg, gmpu_status_name(expected)) == NULL || strstr(msg, needle) == NULL)
        fail_msg("message \"%s\" lacks \"%s\" or \"%s\"", msg, gmpu_status_name(expected), needle);
}

static const double tet[12] = {0.1, -0.0, 1e-300, 1, 2.5, 1.0 / 3.0, -7, 6.02214076e23, 0, 4, 5, 6};
static const uint32_t tet_faces[12] = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0};

static void test_points_create_and_access(void **state) {
    (void)state;
    const double n[12] = {0, 0, 1, 0, 1, 0, 1, 0, 0, 0, 0, -1};
    gmpu_points *p = NULL;
    assert_int_equal(gmpu_points_create(tet, n, 4, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 4);
    assert_memory_equal(gmpu_points_positions(p), tet, sizeof tet);
    assert_memory_equal(gmpu_points_normals(p), n, sizeof n);
    gmpu_points_destroy(p);

    assert_int_equal(gmpu_points_create(tet, NULL, 4, &p), GMPU_OK);
    assert_null(gmpu_points_normals(p));
    gmpu_points_destroy(p);

    /* NULL handles are harmless. */
    gmpu_points_destroy(NULL);
    assert_int_equal(gmpu_points_count(NULL), 0);
    assert_null(gmpu_points_positions(NULL));
    assert_null(gmpu_points_normals(NULL));
}

static void test_points_create_errors(void **state) {
    (void)state;
    gmpu_points *p = (gmpu_points *)&p; /* garbage that must become NULL */
    check_failure(gmpu_points_create(NULL, NULL, 3, &p), GMPU_ERROR_INVALID_ARGUMENT, "xyz is NULL");
    assert_null(p);
    check_failure(gmpu_points_create(tet, NULL, 4, NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");
    p = (gmpu_points *)&p;
    check_failure(gmpu_points_create(tet, NULL, 0, &p), GMPU_ERROR_INVALID_INPUT, "no points");
    assert_null(p);
    check_failure(gmpu_points_create(tet, NULL, SIZE_MAX / 2, &p), GMPU_ERROR_INVALID_ARGUMENT, "too large");

    double bad[6] = {0, 0, 0, 1, 2, NAN};
    p = (gmpu_points *)&p;
    check_failure(gmpu_points_create(bad, NULL, 2, &p), GMPU_ERROR_INVALID_INPUT, "point 1");
    assert_null(p);
    double badn[6] = {0, 0, 1, INFINITY, 0, 0};
    check_failure(gmpu_points_create(tet, badn, 2, &p), GMPU_ERROR_INVALID_INPUT, "normal of point 1");
    assert_null(p);
}

static void test_points_file_round_trip(void **state) {
    (void)state;
    const double n[12] = {0, 0, 1, 0, 1, 0, 1, 0, 0, 0.6, 0.8, 0};
    const char *names[] = {"p.ply", "p.xyz", "P.XYZ"};
    for (int i = 0; i < 3; ++i) {
        for (int with_normals = 0; with_normals < 2; ++with_normals) {
            gmpu_points *p = NULL, *q = NULL;
            assert_int_equal(gmpu_points_create(tet, with_normals ? n : NULL, 4, &p), GMPU_OK);
            const char *path = scratch_path(names[i]);
            assert_int_equal(gmpu_points_write(p, path), GMPU_OK);
            assert_int_equal(gmpu_points_read(path, &q), GMPU_OK);
            assert_int_equal(gmpu_points_count(q), 4);
            assert_memory_equal(gmpu_points_positions(q), tet, sizeof tet); /* bit-exact */
            if (with_normals)
                assert_memory_equal(gmpu_points_normals(q), n, sizeof n);
            else
                assert_null(gmpu_points_normals(q));
            gmpu_points_destroy(p);
            gmpu_points_destroy(q);
        }
    }
}

static void test_points_read_errors(void **state) {
    (void)state;
    gmpu_points *p = (gmpu_points *)&p;
    check_failure(gmpu_points_read(NULL, &p), GMPU_ERROR_INVALID_ARGUMENT, "path is NULL");
    assert_null(p);
    check_failure(gmpu_points_read(scratch_path("x.ply"), NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");

    const char *missing = scratch_path("missing.ply");
    p = (gmpu_points *)&p;
    check_failure(gmpu_points_read(missing, &p), GMPU_ERROR_IO, missing);
    assert_null(p);
    check_failure(gmpu_points_read(missing, &p), GMPU_ERROR_IO, "No such file or directory");
    check_failure(gmpu_points_read(scratch_dir, &p), GMPU_ERROR_UNSUPPORTED, "no file extension");
    check_failure(gmpu_points_read(scratch_path("a.stl"), &p), GMPU_ERROR_UNSUPPORTED, "'.stl'");

    const char *bad = scratch_path("bad.xyz");
    put(bad, "1 2 3\n4 5 six\n");
    check_failure(gmpu_points_read(bad, &p), GMPU_ERROR_PARSE, "line 2: invalid number 'six'");
    assert_null(p);
    put(bad, "1 2 3\n4 5 nan\n");
    check_failure(gmpu_points_read(bad, &p), GMPU_ERROR_INVALID_INPUT, "vertex 1");
    put(bad, "# nothing\n");
    check_failure(gmpu_points_read(bad, &p), GMPU_ERROR_INVALID_INPUT, "no points");
    const char *ply = scratch_path("bad.ply");
    put(ply, "ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n1 2 3\n");
    check_failure(gmpu_points_read(ply, &p), GMPU_ERROR_PARSE, "expected 9 vertices, file ends after 1");
    put(ply, "ply\nformat binary_middle_endian 1.0\nend_header\n");
    check_failure(gmpu_points_read(ply, &p), GMPU_ERROR_UNSUPPORTED, "binary_middle_endian");
    assert_null(p);
    /* Not regular files: a FIFO (would block for ever), a device (never ends), a directory. */
    const char *fifo = scratch_path("fifo.ply");
    assert_int_equal(mkfifo(fifo, 0644), 0);
    check_failure(gmpu_points_read(fifo, &p), GMPU_ERROR_IO, "FIFO");
    remove(fifo);
    const char *zero = scratch_path("zero.xyz");
    assert_int_equal(symlink("/dev/zero", zero), 0);
    check_failure(gmpu_points_read(zero, &p), GMPU_ERROR_IO, "not a regular file");
    remove(zero);
    const char *dir = scratch_path("dir.obj");
    assert_int_equal(mkdir(dir, 0755), 0);
    check_failure(gmpu_points_read(dir, &p), GMPU_ERROR_IO, "Is a directory");
    rmdir(dir);
    /* A UTF-8 byte order mark does not cost the first vertex. */
    const char *obj = scratch_path("bom.obj");
    put(obj, "\xEF\xBB\xBFv 1 2 3\nv 4 5 6\nv 7 8 9\n");
    assert_int_equal(gmpu_points_read(obj, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 3);
    assert_true(gmpu_points_positions(p)[0] == 1.0);
    gmpu_points_destroy(p);
    remove(obj);
}

/* The memory budget bounds reading: a file whose points would not fit is refused before its
 * body is read — a sparse PLY whose header agrees with its size, a text file by its line
 * count — with a message naming the estimate and the budget. */
static void test_points_read_budget(void **state) {
    (void)state;
    gmpu_points *p = (gmpu_points *)&p;
    const char *ply = scratch_path("sparse.ply");
    const char *header = "ply\nformat binary_little_endian 1.0\nelement vertex 5592405\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n";
    put(ply, header);
    assert_int_equal(truncate(ply, (off_t)(strlen(header) + 5592405ull * 12)), 0); /* 64 MB of holes */
    struct timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    check_failure(gmpu_points_read_with(ply, 1e8, NULL, NULL, &p), GMPU_ERROR_LIMIT_EXCEEDED, "5592405 points");
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    assert_null(p);
    assert_non_null(strstr(gmpu_last_error(), "memory budget of 1e+08 bytes"));
    assert_non_null(strstr(gmpu_last_error(), ply));
    /* Refused from the header: far less CPU than reading 64 MB and converting 5.6M points. */
    const double cpu = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (cpu > 0.05 && getenv("GMPU_TEST_QUICK") == NULL) fail_msg("the refused read took %.3f s of CPU", cpu);
    remove(ply);

    const char *xyz = scratch_path("many.xyz");
    FILE *f = fopen(xyz, "wb");
    assert_non_null(f);
    for (int i = 0; i < 100000; ++i) fprintf(f, "%d 0 1\n", i);
    fclose(f);
    check_failure(gmpu_points_read_with(xyz, 1e6, NULL, NULL, &p), GMPU_ERROR_LIMIT_EXCEEDED, "100000 points");
    assert_null(p);
    /* Within the budget (and at the default, 0), the same file reads. */
    assert_int_equal(gmpu_points_read_with(xyz, 1e8, NULL, NULL, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 100000);
    gmpu_points_destroy(p);
    assert_int_equal(gmpu_points_read_with(xyz, 0, NULL, NULL, &p), GMPU_OK);
    gmpu_points_destroy(p);
    /* A budget out of range is a bad argument. */
    const double bad[] = {-1, 5, 999999, 2e15, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; ++k) {
        p = (gmpu_points *)&p;
        check_failure(gmpu_points_read_with(xyz, bad[k], NULL, NULL, &p), GMPU_ERROR_INVALID_ARGUMENT, "max_memory");
        assert_null(p);
    }
    remove(xyz);
}

/* ---- reading reports progress and stops on cancel ---- */

typedef struct {
    double last_cpu, max_gap, last_fraction, cancel_at, cancelled_cpu;
    int reports, decreasing, wrong_stage;
} read_watch;

static double thread_cpu(void) {
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int on_read_progress(void *user, gmpu_stage stage, double fraction) {
    read_watch *w = user;
    const double now = thread_cpu();
    if (w->reports > 0 && now - w->last_cpu > w->max_gap) w->max_gap = now - w->last_cpu;
    w->last_cpu = now;
    w->wrong_stage |= stage != GMPU_STAGE_READ;
    w->decreasing |= fraction < w->last_fraction;
    w->last_fraction = fraction;
    ++w->reports;
    if (w->cancel_at > 0 && fraction >= w->cancel_at) {
        w->cancelled_cpu = now;
        return 1;
    }
    return 0;
}

/* A large .xyz and a large binary PLY: a report every 50 ms of the calling thread's CPU, the
 * fraction rising to 1; a cancel (in the count, in the parse) returns CANCELLED within 100 ms
 * of CPU, with no points. */
static void test_points_read_progress_and_cancel(void **state) {
    (void)state;
    /* Instrumented builds (gcc's and clang's spellings): the promises are for optimised ones. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    const int timing = 0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
    const int timing = 0;
#else
    const int timing = getenv("GMPU_TEST_QUICK") == NULL;
#endif
#else
    const int timing = getenv("GMPU_TEST_QUICK") == NULL;
#endif
    const size_t n = getenv("GMPU_TEST_QUICK") ? 20000 : 1000000; /* valgrind: small, no timing */
    const char *xyz = scratch_path("large.xyz"), *ply = scratch_path("large.ply");
    FILE *f = fopen(xyz, "wb");
    assert_non_null(f);
    for (size_t i = 0; i < n; ++i) fprintf(f, "%.6f %.6f %.6f\n", sin((double)i), cos(0.5 * (double)i), 1e-6 * (double)i);
    fclose(f);
    f = fopen(ply, "wb");
    assert_non_null(f);
    fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty float x\nproperty float y\n"
               "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n", 4 * n);
    float rec[6] = {0, 0, 0, 0, 0, 1};
    for (size_t i = 0; i < 4 * n; ++i) {
        rec[0] = (float)i, rec[1] = (float)(i % 7);
        fwrite(rec, sizeof rec, 1, f);
    }
    fclose(f);
    const char *files[] = {xyz, ply};
    for (int k = 0; k < 2; ++k) {
        read_watch w = {0};
        gmpu_points *p = NULL;
        assert_int_equal(gmpu_points_read_with(files[k], 0, on_read_progress, &w, &p), GMPU_OK);
        assert_int_equal(gmpu_points_count(p), k ? 4 * n : n);
        gmpu_points_destroy(p);
        assert_false(w.wrong_stage || w.decreasing);
        assert_true(w.last_fraction == 1.0 && (w.reports >= 3 || !timing));
        if (timing && w.max_gap > 0.05) fail_msg("%s: %.3f s of CPU between two reports", files[k], w.max_gap);
        const double cancel_at[] = {0.1, 0.6};
        for (int c = 0; c < 2; ++c) {
            read_watch wc = {0};
            wc.cancel_at = cancel_at[c];
            p = (gmpu_points *)&p;
            check_failure(gmpu_points_read_with(files[k], 0, on_read_progress, &wc, &p), GMPU_ERROR_CANCELLED,
                          "reading cancelled");
            const double latency = thread_cpu() - wc.cancelled_cpu;
            assert_null(p);
            assert_true(wc.cancelled_cpu > 0);
            if (timing && latency > 0.1) fail_msg("%s: back %.3f s of CPU after the cancel", files[k], latency);
        }
    }
    remove(xyz);
    remove(ply);
}

static void test_points_write_errors(void **state) {
    (void)state;
    gmpu_points *p = NULL;
    assert_int_equal(gmpu_points_create(tet, NULL, 4, &p), GMPU_OK);
    check_failure(gmpu_points_write(NULL, scratch_path("a.ply")), GMPU_ERROR_INVALID_ARGUMENT, "points is NULL");
    check_failure(gmpu_points_write(p, NULL), GMPU_ERROR_INVALID_ARGUMENT, "path is NULL");
    check_failure(gmpu_points_write(p, scratch_path("a.off")), GMPU_ERROR_UNSUPPORTED, "'.off'");
    const char *deep = scratch_path("no/such/dir/a.ply");
    check_failure(gmpu_points_write(p, deep), GMPU_ERROR_IO, deep);
    check_failure(gmpu_points_write(p, deep), GMPU_ERROR_IO, "No such file or directory");
    gmpu_points_destroy(p);
    assert_int_equal(scratch_count(scratch_dir, ""), 0); /* nothing created, not even a temporary */
}

static void test_mesh_create_and_access(void **state) {
    (void)state;
    gmpu_mesh *m = NULL;
    assert_int_equal(gmpu_mesh_create(tet, 4, tet_faces, 4, &m), GMPU_OK);
    assert_int_equal(gmpu_mesh_vertex_count(m), 4);
    assert_int_equal(gmpu_mesh_triangle_count(m), 4);
    assert_memory_equal(gmpu_mesh_vertices(m), tet, sizeof tet);
    assert_memory_equal(gmpu_mesh_triangles(m), tet_faces, sizeof tet_faces);
    assert_null(gmpu_mesh_normals(m)); /* made by gmpu_mesh_create */
    gmpu_mesh_destroy(m);

    /* An empty mesh is a valid mesh. */
    assert_int_equal(gmpu_mesh_create(NULL, 0, NULL, 0, &m), GMPU_OK);
    assert_int_equal(gmpu_mesh_vertex_count(m), 0);
    assert_int_equal(gmpu_mesh_triangle_count(m), 0);
    gmpu_mesh_destroy(m);

    gmpu_mesh_destroy(NULL);
    assert_int_equal(gmpu_mesh_vertex_count(NULL), 0);
    assert_int_equal(gmpu_mesh_triangle_count(NULL), 0);
    assert_null(gmpu_mesh_vertices(NULL));
    assert_null(gmpu_mesh_normals(NULL));
    assert_null(gmpu_mesh_triangles(NULL));
}

static void test_mesh_create_errors(void **state) {
    (void)state;
    gmpu_mesh *m = (gmpu_mesh *)&m;
    check_failure(gmpu_mesh_create(NULL, 4, tet_faces, 4, &m), GMPU_ERROR_INVALID_ARGUMENT, "vertices is NULL");
    assert_null(m);
    m = (gmpu_mesh *)&m;
    check_failure(gmpu_mesh_create(tet, 4, NULL, 4, &m), GMPU_ERROR_INVALID_ARGUMENT, "triangles is NULL");
    assert_null(m);
    check_failure(gmpu_mesh_create(tet, 4, tet_faces, 4, NULL), GMPU_ERROR_INVALID_ARGUMENT, "out is NULL");
    const uint32_t bad_faces[6] = {0, 1, 2, 0, 1, 4};
    m = (gmpu_mesh *)&m;
    check_failure(gmpu_mesh_create(tet, 4, bad_faces, 2, &m), GMPU_ERROR_INVALID_INPUT,
                  "triangle 1 uses vertex index 4, but vertex_count is 4");
    assert_null(m);
    double nan_v[9] = {0, 0, 0, 1, 0, 0, 0, INFINITY, 0};
    check_failure(gmpu_mesh_create(nan_v, 3, tet_faces, 1, &m), GMPU_ERROR_INVALID_INPUT, "vertex 2");
    assert_null(m);
}

static void test_mesh_write(void **state) {
    (void)state;
    gmpu_mesh *m = NULL;
    assert_int_equal(gmpu_mesh_create(tet, 4, tet_faces, 4, &m), GMPU_OK);
    const char *names[] = {"m.ply", "m.obj", "m.off", "M.OFF"};
    const char *magic[] = {"ply\nformat binary_little_endian 1.0\n", "# written by gmpu\nv ", "OFF\n4 4 0\n", "OFF\n"};
    for (int i = 0; i < 4; ++i) {
        const char *path = scratch_path(names[i]);
        assert_int_equal(gmpu_mesh_write(m, path), GMPU_OK);
        char head[64] = {0};
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        assert_true(fread(head, 1, strlen(magic[i]), f) == strlen(magic[i]));
        fclose(f);
        assert_string_equal(head, magic[i]);
        /* The vertices read back bit-exact, whatever the format. */
        gmpu_points *p = NULL;
        assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
        assert_int_equal(gmpu_points_count(p), 4);
        assert_memory_equal(gmpu_points_positions(p), tet, sizeof tet);
        gmpu_points_destroy(p);
    }

    mkdir(scratch_path("w"), 0755);
    check_failure(gmpu_mesh_write(NULL, scratch_path("w/a.ply")), GMPU_ERROR_INVALID_ARGUMENT, "mesh is NULL");
    check_failure(gmpu_mesh_write(m, NULL), GMPU_ERROR_INVALID_ARGUMENT, "path is NULL");
    check_failure(gmpu_mesh_write(m, scratch_path("w/a.wrl")), GMPU_ERROR_UNSUPPORTED, "'.wrl'");
    check_failure(gmpu_mesh_write(m, scratch_path("w/a.xyz")), GMPU_ERROR_UNSUPPORTED, "'.xyz'");
    const char *deep = scratch_path("w/missing/a.obj");
    check_failure(gmpu_mesh_write(m, deep), GMPU_ERROR_IO, deep);
    check_failure(gmpu_mesh_write(m, deep), GMPU_ERROR_IO, "No such file or directory");
    mkdir(scratch_path("w/dir.ply"), 0755);
    check_failure(gmpu_mesh_write(m, scratch_path("w/dir.ply")), GMPU_ERROR_IO, "Is a directory");
    assert_int_equal(scratch_count(scratch_path("w"), ""), 1); /* only dir.ply: no temporaries */
    assert_int_equal(scratch_count(scratch_path("w/dir.ply"), ""), 0);
    gmpu_mesh_destroy(m);
}

/* A mesh built from arrays keeps what the arrays give: normals (made unit), confidence and
 * colours are written to .ply and read back. */
static void test_mesh_create_with_attributes(void **state) {
    (void)state;
    const double normals[12] = {0, 0, -2, 0, 0, 3, 1, 0, 0, 0, 0.5, 0};
    const double confidence[4] = {0.25, 1, 2, INFINITY};
    const uint8_t colors[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30};
    gmpu_mesh *m = NULL;
    assert_int_equal(gmpu_mesh_create_with(tet, 4, tet_faces, 4, normals, confidence, colors, &m), GMPU_OK);
    const double *n = gmpu_mesh_normals(m);
    assert_non_null(n);
    const double unit[12] = {0, 0, -1, 0, 0, 1, 1, 0, 0, 0, 1, 0};
    for (int i = 0; i < 12; ++i) assert_true(n[i] == unit[i]);
    assert_memory_equal(gmpu_mesh_confidence(m), confidence, sizeof confidence);
    assert_memory_equal(gmpu_mesh_colors(m), colors, sizeof colors);
    const char *path = scratch_path("attributes.ply");
    assert_int_equal(gmpu_mesh_write(m, path), GMPU_OK);
    gmpu_points *p = NULL;
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    assert_memory_equal(gmpu_points_positions(p), tet, sizeof tet);
    assert_non_null(gmpu_points_normals(p));
    assert_memory_equal(gmpu_points_normals(p), unit, sizeof unit);
    assert_non_null(gmpu_points_colors(p));
    assert_memory_equal(gmpu_points_colors(p), colors, sizeof colors);
    gmpu_points_destroy(p);
    /* Simplify and trim carry the colours. */
    gmpu_mesh *t = NULL;
    assert_int_equal(gmpu_mesh_trim(m, 2.5, &t), GMPU_OK); /* keeps triangle 0 1 2: vertex 3 is +inf */
    assert_int_equal(gmpu_mesh_triangle_count(t), 1);
    assert_memory_equal(gmpu_mesh_colors(t), colors, 9);
    gmpu_mesh_destroy(t);
    gmpu_mesh_destroy(m);

    /* Without the optional arrays it is gmpu_mesh_create. */
    assert_int_equal(gmpu_mesh_create_with(tet, 4, tet_faces, 4, NULL, NULL, NULL, &m), GMPU_OK);
    assert_null(gmpu_mesh_normals(m));
    assert_null(gmpu_mesh_confidence(m));
    assert_null(gmpu_mesh_colors(m));
    gmpu_mesh_destroy(m);
    assert_null(gmpu_mesh_colors(NULL));

    m = (gmpu_mesh *)&m;
    const double zero_normal[12] = {0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 1};
    check_failure(gmpu_mesh_create_with(tet, 4, tet_faces, 4, zero_normal, NULL, NULL, &m), GMPU_ERROR_INVALID_INPUT,
                  "normal of vertex 2");
    assert_null(m);
    const double bad_confidence[4] = {0, -1, 0, 0};
    check_failure(gmpu_mesh_create_with(tet, 4, tet_faces, 4, NULL, bad_confidence, NULL, &m),
                  GMPU_ERROR_INVALID_INPUT, "confidence of vertex 1");
    assert_null(m);
}

/* PLY colours (uchar red green blue) are read, given to a mesh's vertices from the nearest
 * point, and written back out; other colour layouts are skipped like unknown properties. */
static void test_point_colours(void **state) {
    (void)state;
    const char *path = scratch_path("coloured.ply");
    put(path, "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\nend_header\n"
              "0 0 0 255 0 0 9\n1 0 0 0 255 0 9\n0 1 0 0 0 255 9\n0 0 1 10 20 30 9\n");
    gmpu_points *p = NULL;
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    const uint8_t expected[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30};
    const double corners[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    assert_non_null(gmpu_points_colors(p));
    assert_memory_equal(gmpu_points_colors(p), expected, sizeof expected);
    assert_memory_equal(gmpu_points_positions(p), corners, sizeof corners);

    /* Each vertex of a mesh near the points takes its nearest point's colour. */
    const double near[12] = {0.1, 0.1, 0.1, 0.9, 0.1, 0, 0, 0.8, 0.1, 0, 0.1, 0.7};
    gmpu_mesh *m = NULL, *coloured = NULL;
    assert_int_equal(gmpu_mesh_create(near, 4, tet_faces, 4, &m), GMPU_OK);
    assert_int_equal(gmpu_mesh_color_from_points(m, p, &coloured), GMPU_OK);
    assert_null(gmpu_mesh_colors(m)); /* the input is untouched */
    assert_memory_equal(gmpu_mesh_colors(coloured), expected, sizeof expected);
    const char *out = scratch_path("coloured_mesh.ply");
    assert_int_equal(gmpu_mesh_write(coloured, out), GMPU_OK);
    gmpu_points *back = NULL;
    assert_int_equal(gmpu_points_read(out, &back), GMPU_OK);
    assert_memory_equal(gmpu_points_colors(back), expected, sizeof expected);
    gmpu_points_destroy(back);
    gmpu_mesh *simple = NULL;
    assert_int_equal(gmpu_mesh_simplify(coloured, 0, 0.0, &simple), GMPU_OK);
    assert_non_null(gmpu_mesh_colors(simple));
    gmpu_mesh_destroy(simple);

    /* Points without colours cannot colour a mesh. */
    gmpu_points *plain = NULL;
    gmpu_mesh *none = (gmpu_mesh *)&none;
    assert_int_equal(gmpu_points_create(tet, NULL, 4, &plain), GMPU_OK);
    assert_null(gmpu_points_colors(plain));
    check_failure(gmpu_mesh_color_from_points(m, plain, &none), GMPU_ERROR_INVALID_ARGUMENT, "no colours");
    assert_null(none);
    gmpu_points_destroy(plain);
    /* ...but points made with colours can. */
    assert_int_equal(gmpu_points_create_with(corners, NULL, expected, 4, &plain), GMPU_OK);
    assert_memory_equal(gmpu_points_colors(plain), expected, sizeof expected);
    gmpu_mesh_destroy(coloured);
    assert_int_equal(gmpu_mesh_color_from_points(m, plain, &coloured), GMPU_OK);
    assert_memory_equal(gmpu_mesh_colors(coloured), expected, sizeof expected);
    gmpu_points_destroy(plain);
    gmpu_mesh_destroy(coloured);
    gmpu_mesh_destroy(m);
    gmpu_points_destroy(p);

    /* Float colours are not the common layout: skipped, the points still read. */
    put(path, "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
              "property float red\nproperty float green\nproperty float blue\nend_header\n"
              "0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 0 0 1\n0 0 1 .1 .2 .3\n");
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    assert_null(gmpu_points_colors(p));
    gmpu_points_destroy(p);
}

static void test_repository_data(void **state) {
    (void)state;
    const char *root = getenv("GMPU_TEST_DATA");
    char path[512];
    gmpu_points *p = NULL;
    snprintf(path, sizeof path, "%s/clouds/bunny_clean.ply", root ? root : "tests/data");
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 35000);
    assert_null(gmpu_points_normals(p));
    gmpu_points_destroy(p);
    snprintf(path, sizeof path, "%s/clouds/bunny_clean_gt.ply", root ? root : "tests/data");
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 35000);
    const double *n = gmpu_points_normals(p);
    assert_non_null(n);
    assert_true(fabs(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1) < 1e-4);
    gmpu_points_destroy(p);
    snprintf(path, sizeof path, "%s/scans/kitten.xyz", root ? root : "tests/data");
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 5210);
    assert_non_null(gmpu_points_normals(p));
    gmpu_points_destroy(p);
    snprintf(path, sizeof path, "%s/meshes/bunny00.off", root ? root : "tests/data");
    assert_int_equal(gmpu_points_read(path, &p), GMPU_OK);
    assert_int_equal(gmpu_points_count(p), 37706);
    gmpu_points_destroy(p);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_points_create_and_access),
        cmocka_unit_test(test_points_create_errors),
        cmocka_unit_test(test_points_write_errors), /* first to touch scratch_dir: counts entries */
        cmocka_unit_test(test_points_file_round_trip),
        cmocka_unit_test(test_points_read_errors),
        cmocka_unit_test(test_points_read_budget),
        cmocka_unit_test(test_points_read_progress_and_cancel),
        cmocka_unit_test(test_mesh_create_and_access),
        cmocka_unit_test(test_mesh_create_errors),
        cmocka_unit_test(test_mesh_write),
        cmocka_unit_test(test_mesh_create_with_attributes),
        cmocka_unit_test(test_point_colours),
        cmocka_unit_test(test_repository_data),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
