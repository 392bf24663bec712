/* gmpu-reconstruct on bad input and misuse, as a user meets it: for each case the exact
 * exit status (1: a failure, 2: bad usage), one line on stderr that names the problem (and
 * the file), no output file (nor a temporary beside it), an existing output left as it was,
 * and never a signal. Also the good cases at 1e±30 scale and with a list property in the
 * vertex element. The reader itself is tested in ../c/test_io.cpp; this is the CLI side.
 *
 * Registered in ../c/meson.build; it runs the gmpu-reconstruct of its own build directory
 * (GMPU_CLI overrides), found from /proc/self/exe, so the sanitizer build tests its own. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <limits.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "gmpu/gmpu.h"
#include "../c/robust_util.h"
#include "../c/scratch_dir.h"

extern char **environ;

static char g_cli[PATH_MAX];
static int setup(void **state) {
    (void)state;
    const char *override = getenv("GMPU_CLI");
    if (override)
        snprintf(g_cli, sizeof g_cli, "%s", override);
    else /* this test runs from <build>/tests/c */
        snprintf(g_cli, sizeof g_cli, "%s/../../examples/gmpu-reconstruct", scratch_exe_dir());
    if (access(g_cli, X_OK) != 0) {
        fprintf(stderr, "gmpu-reconstruct not found at %s (set GMPU_CLI)\n", g_cli);
        return -1;
    }
    return scratch_create("cli-scratch");
}

static int teardown(void **state) {
    (void)state;
    return scratch_remove();
}

/* ---- running the CLI ---- */

typedef struct {
    int status;        /* exit status; -1 when killed by a signal */
    int signal;
    char err[8192];    /* stderr */
    int err_lines;
} run_result;

static run_result run_cli(const char *const *args) {
    run_result r;
    memset(&r, 0, sizeof r);
    const char *argv[32] = {g_cli};
    int argc = 1;
    for (; args[argc - 1] && argc < 31; ++argc) argv[argc] = args[argc - 1];
    argv[argc] = NULL;
    static char err_path[PATH_MAX + 32];
    snprintf(err_path, sizeof err_path, "%s/stderr.txt", scratch_dir);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid;
    if (posix_spawn(&pid, g_cli, &fa, NULL, (char *const *)argv, environ) != 0) fail_msg("cannot run %s", g_cli);
    posix_spawn_file_actions_destroy(&fa);
    int ws = 0;
    while (waitpid(pid, &ws, 0) < 0) {
    }
    if (WIFSIGNALED(ws)) r.status = -1, r.signal = WTERMSIG(ws);
    else r.status = WEXITSTATUS(ws);
    FILE *f = fopen(err_path, "rb");
    if (f) {
        size_t got = fread(r.err, 1, sizeof r.err - 1, f);
        r.err[got] = '\0';
        fclose(f);
    }
    remove(err_path);
    for (const char *p = r.err; *p; ++p) r.err_lines += *p == '\n';
    if (r.err[0] && r.err[strlen(r.err) - 1] != '\n') ++r.err_lines;
    return r;
}

static int exists(const char *path) {
    struct stat st;
    return stat(path, &st) == 0;
}

#define check_run(r, want_status, needle)                                                                   \
    check_run_at(r, want_status, needle, __FILE__, __LINE__)

/* status, no signal, no sanitizer report; a failure is exactly one line on stderr, starting
 * with "gmpu-reconstruct: " and containing needle. */
static void check_run_at(const run_result *r, int want_status, const char *needle, const char *file, int line) {
    if (r->status == -1) fail_msg("%s:%d: killed by signal %d; stderr:\n%s", file, line, r->signal, r->err);
    if (strstr(r->err, "Sanitizer") || strstr(r->err, "runtime error"))
        fail_msg("%s:%d: sanitizer report:\n%s", file, line, r->err);
    if (r->status != want_status)
        fail_msg("%s:%d: exit status %d, expected %d; stderr:\n%s", file, line, r->status, want_status, r->err);
    if (want_status == 1) {
        if (r->err_lines != 1 || strncmp(r->err, "gmpu-reconstruct: ", 18) != 0)
            fail_msg("%s:%d: expected one 'gmpu-reconstruct: ' line on stderr, got %d lines:\n%s", file, line,
                     r->err_lines, r->err);
    }
    if (needle && !strstr(r->err, needle))
        fail_msg("%s:%d: stderr lacks \"%s\":\n%s", file, line, needle, r->err);
}

/* ---- inputs ---- */

static void put(const char *path, const void *data, size_t size) {
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    fclose(f);
}

static void put_text(const char *path, const char *text) { put(path, text, strlen(text)); }

/* n points as an .xyz file. */
static void put_xyz(const char *path, const double *p, size_t n) {
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    for (size_t i = 0; i < n; ++i) fprintf(f, "%.17g %.17g %.17g\n", p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    fclose(f);
}

/* n points as a binary little-endian PLY of doubles; with `extra_list`, each vertex also
 * carries a list property (uchar count, int items) between y and z. */
static void put_ply_le(const char *path, const double *p, size_t n, int extra_list) {
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fprintf(f, "ply\nformat binary_little_endian 1.0\ncomment made by test_cli\nelement vertex %zu\n"
               "property double x\nproperty double y\n%sproperty double z\nend_header\n",
            n, extra_list ? "property list uchar int tags\n" : "");
    for (size_t i = 0; i < n; ++i) {
        fwrite(&p[3 * i], sizeof(double), 2, f);
        if (extra_list) {
            unsigned char count = (unsigned char)(i % 4);
            fwrite(&count, 1, 1, f);
            for (int k = 0; k < count; ++k) {
                int32_t tag = (int32_t)(i * 7 + (size_t)k);
                fwrite(&tag, sizeof tag, 1, f);
            }
        }
        fwrite(&p[3 * i + 2], sizeof(double), 1, f);
    }
    fclose(f);
}

static double *g_sphere; /* 3000 points on the unit sphere at the origin */
enum { N_SPHERE = 3000 };

static int group_setup(void **state) {
    if (setup(state) != 0) return -1;
    const double c[3] = {0, 0, 0};
    g_sphere = robust_sphere(N_SPHERE, c, 1.0, 9);
    return g_sphere ? 0 : -1;
}

static int group_teardown(void **state) {
    free(g_sphere);
    return teardown(state);
}

/* An OFF mesh written by the CLI: watertight, and the radius range of its vertices about c. */
static void check_off_sphere(const char *path, const double c[3], double radius, double tolerance) {
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char magic[8] = "";
    size_t nv = 0, nt = 0, ne = 0;
    assert_int_equal(fscanf(f, "%7s %zu %zu %zu", magic, &nv, &nt, &ne), 4);
    assert_string_equal(magic, "OFF");
    double *v = malloc(3 * nv * sizeof *v);
    uint32_t *t = malloc(3 * nt * sizeof *t);
    for (size_t i = 0; i < 3 * nv; ++i) assert_int_equal(fscanf(f, "%lf", &v[i]), 1);
    for (size_t i = 0; i < nt; ++i) {
        unsigned k = 0;
        assert_int_equal(fscanf(f, "%u %u %u %u", &k, &t[3 * i], &t[3 * i + 1], &t[3 * i + 2]), 4);
        assert_int_equal(k, 3);
    }
    fclose(f);
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_mesh_create(v, nv, t, nt, &m));
    const char *problem = robust_mesh_problem(m);
    if (problem) fail_msg("%s: %s", path, problem);
    assert_true(robust_signed_volume(m) > 0);
    for (size_t i = 0; i < nv; ++i) {
        double d = sqrt(pow((v[3 * i] - c[0]) / radius, 2) + pow((v[3 * i + 1] - c[1]) / radius, 2) +
                        pow((v[3 * i + 2] - c[2]) / radius, 2));
        if (fabs(d - 1) > tolerance) fail_msg("%s: vertex %zu at %g radii from the centre", path, i, d);
    }
    gmpu_mesh_destroy(m);
    free(v);
    free(t);
}

/* ---- the cases ---- */

/* Every failing case below: one line, exit 1, the named problem, no output. */
static void expect_failure(const char *input, const char *needle, const char *needle2) {
    const char *out = scratch_path("out.ply");
    remove(out);
    const char *args[] = {input, "-o", out, "--quiet", "--resolution", "24", NULL};
    run_result r = run_cli(args);
    check_run(&r, 1, needle);
    if (needle2 && !strstr(r.err, needle2)) fail_msg("stderr lacks \"%s\":\n%s", needle2, r.err);
    assert_false(exists(out));
    assert_int_equal(scratch_count(scratch_dir, "out."), 0); /* no temporary either */
}

static void test_missinscratch_directory_and_unknown_inputs(void **state) {
    (void)state;
    const char *missing = scratch_path("no-such-cloud.ply");
    expect_failure(missing, "no-such-cloud.ply", "No such file or directory");
    expect_failure(missing, "GMPU_ERROR_IO", NULL);
    const char *dir = scratch_path("cloud-dir.ply");
    assert_int_equal(mkdir(dir, 0755), 0);
    expect_failure(dir, "cloud-dir.ply", "Is a directory");
    expect_failure(scratch_dir, "GMPU_ERROR_UNSUPPORTED", "no file extension");
    const char *stl = scratch_path("cloud.stl");
    put_text(stl, "solid x\nendsolid x\n");
    expect_failure(stl, "GMPU_ERROR_UNSUPPORTED", "'.stl'");
    const char *empty = scratch_path("empty.xyz");
    put_text(empty, "");
    expect_failure(empty, "GMPU_ERROR_INVALID_INPUT", "no points");
    const char *comments = scratch_path("comments.xyz");
    put_text(comments, "# only a comment\n\n");
    expect_failure(comments, "GMPU_ERROR_INVALID_INPUT", "no points");
    /* Unreadable (unless running as root, which reads anything). */
    const char *locked = scratch_path("locked.xyz");
    put_xyz(locked, g_sphere, 100);
    chmod(locked, 0);
    if (geteuid() != 0) expect_failure(locked, "GMPU_ERROR_IO", "Permission denied");
    chmod(locked, 0644);
}

static void test_too_few_and_degenerate_clouds(void **state) {
    (void)state;
    const char *in = scratch_path("few.xyz");
    for (size_t n = 1; n <= 3; ++n) {
        put_xyz(in, g_sphere, n);
        char needle[64];
        snprintf(needle, sizeof needle, "%zu points given; at least 15", n);
        expect_failure(in, "GMPU_ERROR_INVALID_INPUT", needle);
    }
    enum { N = 400 };
    double p[3 * N];
    robust_rng rng = {5};
    for (size_t i = 0; i < N; ++i) p[3 * i] = 1.5, p[3 * i + 1] = -2, p[3 * i + 2] = 1e3;
    put_xyz(in, p, N);
    expect_failure(in, "GMPU_ERROR_DEGENERATE_INPUT", "identical");
    for (size_t i = 0; i < N; ++i) {
        double t = robust_uniform(&rng);
        p[3 * i] = 1 + t, p[3 * i + 1] = 2 - 3 * t, p[3 * i + 2] = 0.5 * t;
    }
    put_xyz(in, p, N);
    expect_failure(in, "GMPU_ERROR_DEGENERATE_INPUT", "collinear");
    for (size_t i = 0; i < N; ++i) {
        double a = robust_uniform(&rng), b = robust_uniform(&rng);
        p[3 * i] = a, p[3 * i + 1] = b, p[3 * i + 2] = 2 * a - b + 4;
    }
    const char *ply = scratch_path("plane.ply");
    put_ply_le(ply, p, N, 0);
    expect_failure(ply, "GMPU_ERROR_DEGENERATE_INPUT", "coplanar");
    expect_failure(ply, "no closed surface", NULL);
}

static void test_nonfinite_and_garbage_values(void **state) {
    (void)state;
    double *p = malloc(3 * N_SPHERE * sizeof *p);
    memcpy(p, g_sphere, 3 * N_SPHERE * sizeof *p);
    p[3 * 41 + 1] = NAN;
    p[3 * 900] = INFINITY;
    const char *ply = scratch_path("nan.ply");
    put_ply_le(ply, p, N_SPHERE, 0);
    expect_failure(ply, "GMPU_ERROR_INVALID_INPUT", "vertex 41 ");
    const char *xyz = scratch_path("inf.xyz");
    p[3 * 41 + 1] = 0;
    put_xyz(xyz, p, N_SPHERE); /* prints "inf" */
    expect_failure(xyz, "GMPU_ERROR_INVALID_INPUT", "vertex 900 ");
    free(p);
    /* Garbage in ascii numbers: the line is named. */
    put_text(xyz, "0 0 0\n1 0 0\n0 1 0\n0 0 1x\n");
    expect_failure(xyz, "GMPU_ERROR_PARSE", "line 4");
    const char *aply = scratch_path("garbage.ply");
    put_text(aply, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n0 0 0\n1 2 three\n4 5 6\n");
    expect_failure(aply, "GMPU_ERROR_PARSE", "three");
    /* Bytes that are not printable ASCII are escaped: the message stays one clean line. */
    put_text(xyz, "0 0 0\n1 2 \x01\x85\xffz\n");
    expect_failure(xyz, "GMPU_ERROR_PARSE", "'\\x01\\x85\\xffz'");
    put_text(aply, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n0 0 0\n1 2 1e99999\n4 5 6\n");
    {
        const char *out = scratch_path("out.ply");
        const char *args[] = {aply, "-o", out, "--quiet", NULL};
        run_result r = run_cli(args);
        check_run(&r, 1, "garbage.ply"); /* out of range: PARSE or INVALID_INPUT, either names the file */
        assert_false(exists(out));
    }
}

static void test_truncated_and_lying_files(void **state) {
    (void)state;
    /* Binary PLY that declares more vertices than it holds, and one cut mid-value. */
    const char *ply = scratch_path("short.ply");
    put_ply_le(ply, g_sphere, N_SPHERE, 0);
    FILE *f = fopen(ply, "r+b");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    assert_int_equal(truncate(ply, size - 24 * 1000 - 5), 0);
    expect_failure(ply, "GMPU_ERROR_PARSE", "file ends after 1999");
    /* A header that claims a billion vertices: fails at once, without allocating them. */
    const char *liar = scratch_path("liar.ply");
    put_text(liar, "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty double x\n"
                   "property double y\nproperty double z\nend_header\n\x01\x02\x03");
    double t0 = robust_now();
    expect_failure(liar, "GMPU_ERROR_PARSE", "expected 1000000000 vertices");
    assert_true(robust_now() - t0 < 5.0);
    /* OFF declaring 50 vertices, holding 3. */
    const char *off = scratch_path("short.off");
    put_text(off, "OFF\n50 0 0\n0 0 0\n1 0 0\n0 1 0\n");
    expect_failure(off, "GMPU_ERROR_PARSE", "short.off");
    /* No end_header; an unknown PLY format; a PLY that is not one. */
    put_text(liar, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
    expect_failure(liar, "GMPU_ERROR_PARSE", "end_header");
    put_text(liar, "ply\nformat binary_middle_endian 1.0\nelement vertex 1\nproperty float x\nend_header\n");
    expect_failure(liar, "GMPU_ERROR_UNSUPPORTED", "binary_middle_endian");
    put_text(liar, "PK\x03\x04 this is a zip file, not a ply\n");
    expect_failure(liar, "GMPU_ERROR_PARSE", "not a PLY file");
    /* A list property in the vertex element, with a count that runs past the end. */
    put_text(liar, "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty list uchar int t\n"
                   "property float y\nproperty float z\nend_header\n0 2 1 2 0 0\n1 200 1 2 3\n");
    expect_failure(liar, "GMPU_ERROR_PARSE", "liar.ply");
}

/* A list property in the vertex element is skipped: the cloud still reconstructs. */
static void test_list_property_in_vertex_element(void **state) {
    (void)state;
    const char *in = scratch_path("listy.ply"), *out = scratch_path("listy.off");
    put_ply_le(in, g_sphere, N_SPHERE, 1);
    const char *args[] = {in, "-o", out, "--quiet", "--resolution", "24", NULL};
    run_result r = run_cli(args);
    check_run(&r, 0, NULL);
    assert_string_equal(r.err, ""); /* --quiet: nothing on stderr */
    const double c[3] = {0, 0, 0};
    check_off_sphere(out, c, 1.0, 0.05);
    remove(out);
}

/* Outliers are reported on stderr; set aside by default, fitted with --keep-outliers. */
static void test_outliers_reported_kept_or_set_aside(void **state) {
    (void)state;
    double *p = malloc(3 * (N_SPHERE + 2) * sizeof *p);
    memcpy(p, g_sphere, 3 * N_SPHERE * sizeof *p);
    const double strays[6] = {3, 0.5, 0, -2, -3, 1};
    memcpy(p + 3 * N_SPHERE, strays, sizeof strays);
    const char *in = scratch_path("strays.xyz"), *out = scratch_path("strays.off");
    put_xyz(in, p, N_SPHERE + 2);
    const char *set_aside[] = {in, "-o", out, "--resolution", "24", NULL};
    run_result r = run_cli(set_aside);
    check_run(&r, 0, "gmpu: 2 outlier points (far from all others) set aside");
    check_off_sphere(out, (const double[3]){0, 0, 0}, 1.0, 0.05);
    const char *kept[] = {in, "-o", out, "--keep-outliers", "--resolution", "24", NULL};
    r = run_cli(kept);
    check_run(&r, 0, "gmpu: 2 outlier points (far from all others) kept (--keep-outliers)");
    remove(out);
    free(p);
}

/* 1e30 and 1e-30: the mesh is the sphere at that scale. */
static void test_extreme_scales(void **state) {
    (void)state;
    const double scales[] = {1e30, 1e-30};
    for (int k = 0; k < 2; ++k) {
        double c[3] = {3 * scales[k], -scales[k], 0};
        double *p = robust_sphere(N_SPHERE, c, scales[k], 10 + (uint64_t)k);
        const char *in = scratch_path("scaled.ply"), *out = scratch_path("scaled.off");
        put_ply_le(in, p, N_SPHERE, 0);
        const char *args[] = {in, "-o", out, "--quiet", "--resolution", "24", NULL};
        run_result r = run_cli(args);
        check_run(&r, 0, NULL);
        check_off_sphere(out, c, scales[k], 0.05);
        remove(out);
        free(p);
    }
    /* Beyond what normalises: a clean error. */
    double c[3] = {0, 0, 0};
    double *p = robust_sphere(200, c, 1e305, 11);
    const char *in = scratch_path("huge.ply");
    put_ply_le(in, p, 200, 0);
    expect_failure(in, "GMPU_ERROR_INVALID_INPUT", "rescale the points");
    free(p);
}

static void test_outputs(void **state) {
    (void)state;
    const char *in = scratch_path("sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    /* Into a missing directory, or with an unknown extension: nothing written. */
    const char *deep = scratch_path("no/such/dir/out.ply");
    const char *a1[] = {in, "-o", deep, "--quiet", "--resolution", "24", NULL};
    run_result r = run_cli(a1);
    check_run(&r, 1, "No such file or directory");
    assert_non_null(strstr(r.err, "out.ply"));
    const char *wrl = scratch_path("out.wrl");
    const char *a2[] = {in, "-o", wrl, "--quiet", "--resolution", "24", NULL};
    r = run_cli(a2);
    check_run(&r, 1, "'.wrl'");
    assert_false(exists(wrl));
    /* An existing output survives a failed run untouched. */
    const char *out = scratch_path("out.ply");
    put_text(out, "previous result");
    const char *missing = scratch_path("missing.xyz");
    const char *a3[] = {missing, "-o", out, "--quiet", NULL};
    r = run_cli(a3);
    check_run(&r, 1, "missing.xyz");
    FILE *f = fopen(out, "rb");
    char buf[32] = "";
    assert_non_null(f);
    assert_non_null(fgets(buf, sizeof buf, f));
    fclose(f);
    assert_string_equal(buf, "previous result");
    remove(out);
    /* --normals-out that cannot be written: all or nothing, the mesh is removed too. */
    const char *off = scratch_path("out.off");
    const char *a4[] = {in, "-o", off, "--normals-out", scratch_path("no/dir/n.ply"), "--quiet", "--resolution", "24", NULL};
    r = run_cli(a4);
    check_run(&r, 1, "no/dir/n.ply");
    assert_false(exists(off));
    /* --use-normals on a cloud without normals. */
    const char *a5[] = {in, "-o", off, "--use-normals", "--quiet", NULL};
    r = run_cli(a5);
    check_run(&r, 1, "has no normals");
    assert_false(exists(off));
    /* Without --quiet, a failure after the progress lines still ends with its one line. */
    const char *a6[] = {in, "-o", wrl, "--resolution", "24", NULL};
    r = run_cli(a6);
    assert_int_equal(r.status, 1);
    const char *last = r.err + strlen(r.err) - 1;
    while (last > r.err && last[-1] != '\n') --last;
    assert_int_equal(strncmp(last, "gmpu-reconstruct: cannot write mesh: GMPU_ERROR_UNSUPPORTED", 58), 0);
    /* And the good run: exit 0, a closed sphere, the statistics on stderr. */
    const char *a7[] = {in, "-o", off, "--param", "resolution=24", NULL};
    r = run_cli(a7);
    check_run(&r, 0, "3000 points");
    const double c[3] = {0, 0, 0};
    check_off_sphere(off, c, 1.0, 0.05);
    assert_int_equal(scratch_count(scratch_dir, "out."), 1); /* no temporaries left beside it */
    remove(off);
}

static void test_bad_usage(void **state) {
    (void)state;
    const char *in = scratch_path("sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *out = scratch_path("out.ply");
    struct {
        const char *args[8];
        int status;
        const char *needle;
    } cases[] = {
        {{NULL}, 2, "missing INPUT"},
        {{in, NULL}, 2, "missing -o OUTPUT"},
        {{in, "-o", NULL}, 2, "missing -o OUTPUT"},
        {{in, "-o", out, "--bogus", NULL}, 2, "unknown option '--bogus'"},
        {{in, in, "-o", out, NULL}, 2, "unexpected argument"},
        {{in, "-o", out, "--error", "abc", NULL}, 2, "--error needs a number, got 'abc'"},
        {{in, "-o", out, "--error", NULL}, 2, "--error needs a number"},
        {{in, "-o", out, "--resolution", "nan", NULL}, 2, "--resolution needs a number"},
        {{in, "-o", out, "--threads", "1e999", NULL}, 2, "--threads needs a number"},
        {{in, "-o", out, "--error", "5", "--quiet", NULL}, 1, "GMPU_PARAM_ERROR"},
        {{in, "-o", out, "--resolution", "4", "--quiet", NULL}, 1, "GMPU_PARAM_RESOLUTION"},
        {{in, "-o", out, "--max-depth", "99", "--quiet", NULL}, 1, "GMPU_PARAM_MAX_DEPTH"},
        {{in, "-o", out, "--level", "-1", "--quiet", NULL}, 1, "GMPU_PARAM_LEVEL"},
        {{in, "-o", out, "--param", "no_such=1", NULL}, 2, "unknown parameter 'no_such'"},
        {{in, "-o", out, "--param", "max_depth", NULL}, 2, "--param needs NAME=VALUE"},
        {{in, "-o", out, "--param", "max_depth=abc", NULL}, 2, "max_depth needs a number, got 'abc'"},
        {{in, "-o", out, "--param", "max_depth=99", "--quiet", NULL}, 1, "GMPU_PARAM_MAX_DEPTH"},
        {{in, "-o", out, "--param", "GMPU_PARAM_NOISE_SCALE=-1", "--quiet", NULL}, 1, "GMPU_PARAM_NOISE_SCALE"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        run_result r = run_cli(cases[k].args);
        check_run(&r, cases[k].status, cases[k].needle);
        assert_false(exists(out));
    }
    const char *help[] = {"--help", NULL};
    run_result r = run_cli(help);
    check_run(&r, 0, NULL);
}


/* ---- outputs: never lose a file, checked before any work ---- */

static char *slurp_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *data = malloc((size_t)n + 1);
    *size = fread(data, 1, (size_t)n, f);
    data[*size] = '\0';
    fclose(f);
    return data;
}

static void assert_file_is(const char *path, const char *text) {
    size_t n = 0;
    char *data = slurp_file(path, &n);
    if (!data) fail_msg("%s is gone", path);
    if (n != strlen(text) || memcmp(data, text, n) != 0) fail_msg("%s changed: '%.60s'", path, data);
    free(data);
}

/* Whether a staging file ("<name>.gmpu-<pid>-<k>.<ext>") or a library temporary
 * ("<name>.tmp-gmpu-<pid>-<n>") is in dir: what an interrupted or failed run leaves behind. */
static int staging_in(const char *dir) {
    DIR *d = opendir(dir);
    struct dirent *e;
    int found = 0;
    while (d && (e = readdir(d)) != NULL) found |= strstr(e->d_name, ".gmpu-") || strstr(e->d_name, "tmp-gmpu");
    if (d) closedir(d);
    return found;
}

static void assert_no_staging_left(void) { assert_false(staging_in(scratch_dir)); }

/* The input named as the output, with a --normals-out that cannot be written: the cloud
 * survives (the mesh once replaced it and the failed points write removed it). */
static void test_input_never_lost(void **state) {
    (void)state;
    const char *cloud = scratch_path("keep-cloud.xyz");
    put_xyz(cloud, g_sphere, N_SPHERE);
    size_t n0 = 0;
    char *before = slurp_file(cloud, &n0);
    const char *a1[] = {cloud, "-o", cloud, "--normals-out", scratch_path("no/dir/n.ply"), "--quiet", NULL};
    run_result r = run_cli(a1);
    check_run(&r, 1, NULL);
    /* Same with the mesh extension the CLI writes, through another name for the same file. */
    const char *cloud_ply = scratch_path("keep-cloud.ply");
    put_ply_le(cloud_ply, g_sphere, N_SPHERE, 0);
    size_t p0 = 0;
    char *ply_before = slurp_file(cloud_ply, &p0);
    const char *alias = scratch_path("alias.ply");
    assert_int_equal(symlink(cloud_ply, alias), 0);
    const char *a2[] = {cloud_ply, "-o", alias, "--quiet", "--resolution", "24", NULL};
    r = run_cli(a2);
    check_run(&r, 1, "is the input file");
    const char *a3[] = {cloud_ply, "-o", cloud_ply, "--normals-out", scratch_path("no/dir/n.ply"), "--quiet", NULL};
    r = run_cli(a3);
    check_run(&r, 1, NULL);
    size_t n1 = 0, p1 = 0;
    char *after = slurp_file(cloud, &n1), *ply_after = slurp_file(cloud_ply, &p1);
    assert_non_null(after);
    assert_non_null(ply_after);
    assert_true(n0 == n1 && memcmp(before, after, n0) == 0);
    assert_true(p0 == p1 && memcmp(ply_before, ply_after, p0) == 0);
    free(before), free(after), free(ply_before), free(ply_after);
    remove(alias);
    assert_no_staging_left();
}

/* An older good output survives a run whose oriented points cannot be written; -o X
 * --normals-out X is refused (the points used to replace the mesh silently). */
static void test_older_output_and_same_file(void **state) {
    (void)state;
    const char *in = scratch_path("keep-sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *out = scratch_path("keep-out.ply");
    put_text(out, "previous result");
    const char *a1[] = {in, "-o", out, "--normals-out", scratch_path("no/dir/n.ply"), "--resolution", "24", NULL};
    run_result r = run_cli(a1);
    check_run(&r, 1, "no/dir/n.ply");
    assert_null(strstr(r.err, "gmpu: fit")); /* refused before any work: no progress */
    assert_file_is(out, "previous result");
    /* A points write that fails after the work (as root, /proc passes the access check but
     * takes no new file): the mesh, though written, does not replace the older output. */
    const char *a1b[] = {in, "-o", out, "--normals-out", "/proc/gmpu-points.xyz", "--quiet", "--resolution", "24", NULL};
    r = run_cli(a1b);
    check_run(&r, 1, "/proc/gmpu-points.xyz");
    assert_file_is(out, "previous result");
    const char *a2[] = {in, "-o", out, "--normals-out", scratch_path("points.xyz"), "--normals-out", out,
                        "--quiet", NULL};
    r = run_cli(a2);
    check_run(&r, 1, "are the same file");
    assert_file_is(out, "previous result");
    const char *fresh = scratch_path("fresh.ply");
    const char *a3[] = {in, "-o", fresh, "--normals-out", fresh, "--quiet", NULL};
    r = run_cli(a3);
    check_run(&r, 1, "are the same file");
    assert_false(exists(fresh));
    /* Output checks happen before the input is even read: a bad directory, a directory as
     * the output, an unknown extension all fail with one line and no progress. */
    const char *bad[] = {scratch_path("no/such/dir/m.ply"), scratch_dir, scratch_path("m.wrl"),
                         scratch_path("keep-sphere.xyz")};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; ++k) {
        const char *a4[] = {in, "-o", bad[k], "--resolution", "24", NULL};
        r = run_cli(a4);
        check_run(&r, 1, NULL);
        assert_null(strstr(r.err, "gmpu: fit"));
    }
    assert_no_staging_left();
}

/* getopt_long: --opt=value works; a flag is never taken as a file name. */
static void test_option_syntax(void **state) {
    (void)state;
    const char *in = scratch_path("keep-sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *a1[] = {in, "-o", "--threads", "2", "--quiet", NULL};
    run_result r = run_cli(a1);
    check_run(&r, 2, "-o needs a file name, got '--threads'");
    assert_false(exists("--threads"));
    const char *a2[] = {in, "-o", scratch_path("m.off"), "--normals-out", "--quiet", NULL};
    r = run_cli(a2);
    check_run(&r, 2, "--normals-out needs a file name");
    const char *out = scratch_path("eq.off");
    char output_eq[PATH_MAX + 16];
    snprintf(output_eq, sizeof output_eq, "--output=%s", out);
    const char *a3[] = {"--resolution=24", output_eq, "--threads=2", "--quiet", in, NULL};
    r = run_cli(a3);
    check_run(&r, 0, NULL);
    const double c[3] = {0, 0, 0};
    check_off_sphere(out, c, 1.0, 0.05);
    remove(out);
    const char *a4[] = {in, "-o", out, "--resolution=abc", NULL};
    r = run_cli(a4);
    check_run(&r, 2, "--resolution needs a number, got 'abc'");
    const char *version[] = {"--version", NULL};
    r = run_cli(version);
    check_run(&r, 0, NULL);
    /* The memory budget and the noise floor reach the library: a budget far too small fails
     * cleanly with the library's message, an out-of-range noise scale is a bad parameter. */
    const char *a5[] = {in, "-o", out, "--max-memory=1e6", "--quiet", NULL};
    r = run_cli(a5);
    check_run(&r, 1, "GMPU_PARAM_MAX_MEMORY");
    check_run(&r, 1, "cannot read input"); /* the reader has the budget too */
    check_run(&r, 1, "reading it needs about");
    assert_false(exists(out));
    const char *a6[] = {in, "-o", out, "--noise-scale", "-1", "--quiet", NULL};
    r = run_cli(a6);
    check_run(&r, 1, "bad parameter");
    const char *a7[] = {in, "-o", out, "--noise-scale=0", "--resolution=24", "--quiet", NULL};
    r = run_cli(a7);
    check_run(&r, 0, NULL);
    check_off_sphere(out, c, 1.0, 0.05);
    remove(out);
    assert_no_staging_left();
}

/* A symlinked output is written through: the link stays, its target gets the mesh. A
 * 251-character output name works (its temporaries fit in NAME_MAX). */
static void test_symlink_and_long_names(void **state) {
    (void)state;
    const char *in = scratch_path("keep-sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *dir = scratch_path("keep-real");
    mkdir(dir, 0755);
    const char *target = scratch_path("keep-real/mesh.off");
    put_text(target, "old");
    const char *link = scratch_path("keep-link.off");
    assert_int_equal(symlink("keep-real/mesh.off", link), 0);
    const char *a1[] = {in, "-o", link, "--quiet", "--resolution", "24", NULL};
    run_result r = run_cli(a1);
    check_run(&r, 0, NULL);
    struct stat st;
    assert_int_equal(lstat(link, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    const double c[3] = {0, 0, 0};
    check_off_sphere(target, c, 1.0, 0.05);
    assert_int_equal(scratch_count(dir, ""), 1);
    assert_false(staging_in(dir));
    /* The format follows the name written on the command line, not the link target's. */
    const char *data = scratch_path("keep-real/mesh.data");
    put_text(data, "old");
    const char *link2 = scratch_path("keep-link2.off");
    assert_int_equal(symlink("keep-real/mesh.data", link2), 0);
    const char *a1b[] = {in, "-o", link2, "--quiet", "--resolution", "24", NULL};
    r = run_cli(a1b);
    check_run(&r, 0, NULL);
    check_off_sphere(data, c, 1.0, 0.05);
    assert_int_equal(scratch_count(dir, ""), 2);

    char name[260];
    memset(name, 'n', 247);
    strcpy(name + 247, ".off");
    assert_int_equal(strlen(name), 251);
    const char *long_out = scratch_path(name);
    const char *a2[] = {in, "-o", long_out, "--quiet", "--resolution", "24", "--normals-out", scratch_path("keep-p.xyz"),
                        NULL};
    r = run_cli(a2);
    check_run(&r, 0, NULL);
    check_off_sphere(long_out, c, 1.0, 0.05);
    remove(long_out);
    remove(scratch_path("keep-p.xyz"));
    assert_no_staging_left();
}

/* A write that fails midway (here the file-size limit, EFBIG) is reported with the path the
 * user gave, not the name of the staging file (or of the library's temporary beside it) that
 * the user never saw; nothing is left behind, and the older output is untouched. */
static void test_write_failure_names_the_output(void **state) {
    (void)state;
    const char *in = scratch_path("keep-sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *outs[] = {"limited.ply", "limited-small.ply"};
    for (int k = 0; k < 2; ++k) {
        char out[PATH_MAX], points[PATH_MAX];
        snprintf(out, sizeof out, "%s", scratch_path(outs[k]));
        snprintf(points, sizeof points, "%s", scratch_path("limited-points.ply"));
        put_text(out, "older");
        /* k = 0: the mesh's write fails; k = 1: the mesh fits, the oriented points do not. */
        const char *args[] = {in, "-o", out, "--normals-out", points, "--quiet", "--resolution", k ? "8" : "40", NULL};
        struct rlimit old, small;
        assert_int_equal(getrlimit(RLIMIT_FSIZE, &old), 0);
        small = old;
        small.rlim_cur = k ? 100000 : 20000; /* bytes: mesh at 8 about 55 kB, points about 150 kB */
        void (*was)(int) = signal(SIGXFSZ, SIG_IGN); /* write() fails with EFBIG instead */
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
        run_result r = run_cli(args);
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &old), 0);
        signal(SIGXFSZ, was);
        check_run(&r, 1, "File too large");
        check_run(&r, 1, k ? points : out);
        if (strstr(r.err, ".gmpu-") || strstr(r.err, "tmp-gmpu")) fail_msg("message names a staging file: %s", r.err);
        assert_file_is(out, "older");
        assert_false(exists(points));
        assert_no_staging_left();
        remove(out);
    }
}

/* Runs a reconstruction and sends `sig` the moment a staging file appears; 1 if the signal
 * killed it mid-write, 0 if the run finished writing first (then the caller retries). */
static int kill_during_write(const char *in, const char *out, int sig) {
    const char *argv[] = {g_cli, in, "-o", out, "--quiet", "--resolution", "100", NULL};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
    pid_t pid;
    assert_int_equal(posix_spawn(&pid, g_cli, &fa, NULL, (char *const *)argv, environ), 0);
    posix_spawn_file_actions_destroy(&fa);
    int ws = 0, done = 0;
    while (!done) {
        if (staging_in(scratch_dir)) {
            kill(pid, sig);
            break;
        }
        done = waitpid(pid, &ws, WNOHANG) == pid;
        usleep(200);
    }
    if (!done) waitpid(pid, &ws, 0);
    if (!WIFSIGNALED(ws)) {
        assert_int_equal(WEXITSTATUS(ws), 0);
        return 0;
    }
    assert_int_equal(WTERMSIG(ws), sig);
    return 1;
}

/* SIGTERM or SIGINT while the mesh is being written: the process dies of it and leaves
 * neither the output nor a staging file or temporary beside it. */
static void test_sigterm_during_write_leaves_nothing(void **state) {
    (void)state;
    const char *in = scratch_path("keep-sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *out = scratch_path("big.obj");
    const int signals[] = {SIGTERM, SIGINT};
    for (int k = 0; k < 2; ++k) {
        int caught = 0;
        for (int attempt = 0; attempt < 4 && !caught; ++attempt) {
            remove(out);
            caught = kill_during_write(in, out, signals[k]);
            if (caught) assert_false(exists(out));
            assert_false(staging_in(scratch_dir));
            remove(out);
        }
        if (!caught) fail_msg("the write never outlasted the polling: signal %d was not tested", signals[k]);
    }
}

/* SIGKILL cannot be caught: its staging files stay. The next run ignores them (fresh names,
 * never theirs) and leaves them alone: they are not its files. */
static void test_leftovers_of_a_killed_run_are_ignored(void **state) {
    (void)state;
    const char *in = scratch_path("keep-sphere.xyz");
    put_xyz(in, g_sphere, N_SPHERE);
    const char *out = scratch_path("killed.obj");
    int caught = 0;
    for (int attempt = 0; attempt < 4 && !caught; ++attempt) {
        remove(out);
        caught = kill_during_write(in, out, SIGKILL);
    }
    if (!caught) fail_msg("the write never outlasted the polling: SIGKILL was not tested");
    assert_true(staging_in(scratch_dir));
    const int left = scratch_count(scratch_dir, "killed.obj.");
    assert_true(left >= 1);
    const char *args[] = {in, "-o", out, "--normals-out", scratch_path("killed.obj.xyz"), "--quiet", "--resolution",
                          "24", NULL};
    run_result r = run_cli(args);
    check_run(&r, 0, NULL);
    assert_true(exists(out));
    assert_int_equal(scratch_count(scratch_dir, "killed.obj."), left + 1); /* + the points file */
    /* Clean up what the killed run left. */
    DIR *d = opendir(scratch_dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL)
        if (strncmp(e->d_name, "killed.", 7) == 0) remove(scratch_path(e->d_name));
    if (d) closedir(d);
    assert_no_staging_left();
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missinscratch_directory_and_unknown_inputs),
        cmocka_unit_test(test_too_few_and_degenerate_clouds),
        cmocka_unit_test(test_nonfinite_and_garbage_values),
        cmocka_unit_test(test_truncated_and_lying_files),
        cmocka_unit_test(test_list_property_in_vertex_element),
        cmocka_unit_test(test_extreme_scales),
        cmocka_unit_test(test_outliers_reported_kept_or_set_aside),
        cmocka_unit_test(test_outputs),
        cmocka_unit_test(test_bad_usage),
        cmocka_unit_test(test_input_never_lost),
        cmocka_unit_test(test_older_output_and_same_file),
        cmocka_unit_test(test_option_syntax),
        cmocka_unit_test(test_symlink_and_long_names),
        cmocka_unit_test(test_write_failure_names_the_output),
        cmocka_unit_test(test_sigterm_during_write_leaves_nothing),
        cmocka_unit_test(test_leftovers_of_a_killed_run_are_ignored),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
