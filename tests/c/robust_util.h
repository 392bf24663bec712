/* Helpers shared by the robustness suites (test_abi_errors.c, test_limits.c, test_cancel.c,
 * test_concurrency.c, ../cli/test_cli.c): status + message checks, reproducible clouds on
 * analytic shapes, a C watertightness check, a monotonic clock. Header-only (static inline)
 * so that each suite stays one executable; include after <cmocka.h>. */
#ifndef GMPU_TESTS_ROBUST_UTIL_H
#define GMPU_TESTS_ROBUST_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gmpu/gmpu.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* 1 when built with ASan, UBSan or TSan (gcc and clang spellings): timing promises are made
 * for optimised builds, so timing assertions are scaled under instrumentation. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ROBUST_INSTRUMENTED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define ROBUST_INSTRUMENTED 1
#endif
#endif
#ifndef ROBUST_INSTRUMENTED
#define ROBUST_INSTRUMENTED 0
#endif

static inline double robust_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* GMPU_TEST_QUICK=1 (set by `make test-valgrind`): small inputs, no timing assertions. */
static inline int robust_quick(void) {
    const char *q = getenv("GMPU_TEST_QUICK");
    return q && *q && strcmp(q, "0") != 0;
}

/* The status must be `expected`, and gmpu_last_error() must name it and contain `needle`
 * (and `needle2` unless NULL). */
static inline void robust_check_failure_at(gmpu_status got, gmpu_status expected, const char *needle,
                                           const char *needle2, const char *file, int line) {
    const char *msg = gmpu_last_error();
    if (got != expected)
        fail_msg("%s:%d: expected %s, got %s (last error: \"%s\")", file, line,
                 gmpu_status_name(expected), gmpu_status_name(got), msg);
    if (strstr(msg, gmpu_status_name(expected)) == NULL || strstr(msg, needle) == NULL ||
        (needle2 && strstr(msg, needle2) == NULL))
        fail_msg("%s:%d: message \"%s\" lacks \"%s\", \"%s\" or \"%s\"", file, line, msg,
                 gmpu_status_name(expected), needle, needle2 ? needle2 : "");
}
#define check_failure(got, expected, needle) \
    robust_check_failure_at((got), (expected), (needle), NULL, __FILE__, __LINE__)
#define check_failure2(got, expected, needle, needle2) \
    robust_check_failure_at((got), (expected), (needle), (needle2), __FILE__, __LINE__)
#define assert_ok(call)                                                                         \
    do {                                                                                        \
        gmpu_status st_ = (call);                                                               \
        if (st_ != GMPU_OK)                                                                     \
            fail_msg("%s:%d: %s returned %s (%s)", __FILE__, __LINE__, #call, gmpu_status_name(st_), \
                     gmpu_last_error());                                                        \
    } while (0)

/* xorshift64*: the same seed gives the same cloud on every platform. */
typedef struct {
    uint64_t s;
} robust_rng;
static inline double robust_uniform(robust_rng *r) {
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return (double)((r->s * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

/* A unit direction, uniform on the sphere. */
static inline void robust_direction(robust_rng *r, double d[3]) {
    double z = 2.0 * robust_uniform(r) - 1.0, phi = 2.0 * M_PI * robust_uniform(r);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    d[0] = s * cos(phi), d[1] = s * sin(phi), d[2] = z;
}

/* n points on the sphere (centre c, radius r), 3 doubles each; the caller frees. */
static inline double *robust_sphere(size_t n, const double c[3], double radius, uint64_t seed) {
    double *p = malloc(3 * n * sizeof *p);
    robust_rng rng = {seed * 2654435761u + 1};
    for (size_t i = 0; i < n && p; ++i) {
        double d[3];
        robust_direction(&rng, d);
        for (int k = 0; k < 3; ++k) p[3 * i + k] = c[k] + radius * d[k];
    }
    return p;
}

/* n points on a bumpy sphere r(d) = 1 + 0.15 sin(15x) sin(15y) sin(15z): enough detail that
 * fit subdivides deeply and every stage takes time in proportion to n. */
static inline double *robust_bumpy_sphere(size_t n, uint64_t seed) {
    double *p = malloc(3 * n * sizeof *p);
    robust_rng rng = {seed * 2654435761u + 7};
    for (size_t i = 0; i < n && p; ++i) {
        double d[3];
        robust_direction(&rng, d);
        double r = 1.0 + 0.15 * sin(15 * d[0]) * sin(15 * d[1]) * sin(15 * d[2]);
        for (int k = 0; k < 3; ++k) p[3 * i + k] = r * d[k];
    }
    return p;
}

/* n points on a torus around z (major R, minor r), roughly area-uniform. */
static inline double *robust_torus(size_t n, double R, double r, const double c[3], uint64_t seed) {
    double *p = malloc(3 * n * sizeof *p);
    robust_rng rng = {seed * 2654435761u + 3};
    for (size_t i = 0; i < n && p;) {
        double u = 2 * M_PI * robust_uniform(&rng), v = 2 * M_PI * robust_uniform(&rng);
        /* Rejection keeps the density proportional to the area element (R + r cos v). */
        if (robust_uniform(&rng) * (R + r) > R + r * cos(v)) continue;
        p[3 * i] = c[0] + (R + r * cos(v)) * cos(u);
        p[3 * i + 1] = c[1] + (R + r * cos(v)) * sin(u);
        p[3 * i + 2] = c[2] + r * sin(v);
        ++i;
    }
    return p;
}

static inline int robust_cmp_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* A watertight mesh: every directed edge used once and its reverse once (closed,
 * edge-manifold, consistently wound), indices in range, finite vertices, no repeated index
 * in a triangle, at least one triangle. Returns NULL when it is, else what is wrong. */
static inline const char *robust_mesh_problem(const gmpu_mesh *m) {
    size_t nv = gmpu_mesh_vertex_count(m), nt = gmpu_mesh_triangle_count(m);
    const double *v = gmpu_mesh_vertices(m);
    const uint32_t *t = gmpu_mesh_triangles(m);
    if (nt == 0) return "no triangles";
    for (size_t i = 0; i < 3 * nv; ++i)
        if (!isfinite(v[i])) return "a non-finite vertex";
    uint64_t *e = malloc(3 * nt * sizeof *e);
    if (!e) return "out of memory in the check";
    for (size_t i = 0; i < nt; ++i)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = t[3 * i + k], b = t[3 * i + (k + 1) % 3];
            if (a >= nv || b >= nv) {
                free(e);
                return "an index out of range";
            }
            if (a == b) {
                free(e);
                return "a triangle with a repeated vertex";
            }
            e[3 * i + k] = (uint64_t)a << 32 | b;
        }
    qsort(e, 3 * nt, sizeof *e, robust_cmp_u64);
    const char *problem = NULL;
    for (size_t i = 0; i < 3 * nt && !problem; ++i) {
        if (i > 0 && e[i] == e[i - 1]) problem = "a directed edge used twice (non-manifold or misoriented)";
        uint64_t rev = (e[i] & 0xffffffffu) << 32 | e[i] >> 32;
        if (!problem && !bsearch(&rev, e, 3 * nt, sizeof *e, robust_cmp_u64))
            problem = "a boundary edge (the mesh is not closed)";
    }
    free(e);
    return problem;
}

/* Σ a·(b×c)/6: positive for a closed mesh wound outward. */
static inline double robust_signed_volume(const gmpu_mesh *m) {
    const double *v = gmpu_mesh_vertices(m);
    const uint32_t *t = gmpu_mesh_triangles(m);
    double vol = 0;
    for (size_t i = 0; i < gmpu_mesh_triangle_count(m); ++i) {
        const double *a = v + 3 * t[3 * i], *b = v + 3 * t[3 * i + 1], *c = v + 3 * t[3 * i + 2];
        vol += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return vol / 6.0;
}

/* set_points → fit → orient → polygonize on s; fails the test on any error. */
static inline gmpu_mesh *robust_reconstruct(gmpu_surface *s, const double *xyz, size_t n) {
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_set_points_f64(s, xyz, n, 0));
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_non_null(m);
    return m;
}

#endif /* GMPU_TESTS_ROBUST_UTIL_H */
