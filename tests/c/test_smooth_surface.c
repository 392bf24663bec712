/* GMPU_PARAM_SURFACE: the smooth implicit solved from the oriented points, and the automatic
 * choice (2, the default) that uses it where the estimated noise is high. On a torus with
 * Gaussian noise of 1 % of its bounding-box diagonal the MPU blend follows the noise (extra
 * handles and small closed pieces); the default surface must have the torus's topology (one
 * component, genus 1) and stay close to it. A noise-free cloud keeps the blend. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gmpu/gmpu.h"
#include "robust_util.h"

enum { kPoints = 20000 };
static const double kMajor = 1.0, kMinor = 0.4;
/* The fewest points on which the automatic choice leaves a noise-free cloud to the blend. */
enum { kDenseCloud = 20000 };
/* The torus's bounding-box diagonal: 2(R + r) × 2(R + r) × 2r. */
static double diagonal(void) {
    const double w = 2 * (kMajor + kMinor), h = 2 * kMinor;
    return sqrt(2 * w * w + h * h);
}

/* Distance from p to the torus around z. */
static double torus_distance(const double p[3]) {
    const double rho = sqrt(p[0] * p[0] + p[1] * p[1]) - kMajor;
    return fabs(sqrt(rho * rho + p[2] * p[2]) - kMinor);
}

/* The torus with Gaussian noise of `sigma` along each point's tube normal (Box–Muller). */
static double *noisy_torus(size_t n, double sigma, uint64_t seed) {
    const double c[3] = {0, 0, 0};
    double *p = robust_torus(n, kMajor, kMinor, c, seed);
    robust_rng rng = {seed * 2654435761u + 11};
    for (size_t i = 0; i < n && p; ++i) {
        double *q = p + 3 * i;
        const double rho = sqrt(q[0] * q[0] + q[1] * q[1]);
        const double ring[3] = {kMajor * q[0] / rho, kMajor * q[1] / rho, 0};
        double d[3] = {q[0] - ring[0], q[1] - ring[1], q[2]};
        const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        const double u = fmax(robust_uniform(&rng), 1e-12), v = robust_uniform(&rng);
        const double e = sigma * sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
        for (int k = 0; k < 3; ++k) q[k] += e * d[k] / len;
    }
    return p;
}

static size_t find_root(size_t *parent, size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
}

typedef struct {
    size_t components;
    long euler; /* V − E + F over the whole mesh (closed: E = 3F/2) */
    double worst, rms; /* largest and root-mean-square vertex distance to the torus */
} mesh_facts;

static mesh_facts facts(const gmpu_mesh *m) {
    const size_t nv = gmpu_mesh_vertex_count(m), nt = gmpu_mesh_triangle_count(m);
    const double *v = gmpu_mesh_vertices(m);
    const uint32_t *t = gmpu_mesh_triangles(m);
    size_t *parent = malloc(nv * sizeof *parent);
    mesh_facts f = {0, (long)nv - (long)(3 * nt / 2) + (long)nt, 0, 0};
    for (size_t i = 0; i < nv; ++i) parent[i] = i;
    for (size_t i = 0; i < nt; ++i)
        for (int k = 1; k < 3; ++k) parent[find_root(parent, t[3 * i])] = find_root(parent, t[3 * i + k]);
    for (size_t i = 0; i < nv; ++i) {
        if (find_root(parent, i) == i) ++f.components;
        const double d = torus_distance(v + 3 * i);
        f.worst = fmax(f.worst, d);
        f.rms += d * d;
    }
    f.rms = sqrt(f.rms / (double)nv);
    free(parent);
    return f;
}

static void test_noisy_torus_keeps_its_topology(void **state) {
    (void)state;
    const double sigma = 0.01 * diagonal();
    double *xyz = noisy_torus(kPoints, sigma, 7);
    assert_non_null(xyz);
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    gmpu_mesh *m = robust_reconstruct(s, xyz, kPoints); /* every parameter at its default */
    assert_null(robust_mesh_problem(m));
    const mesh_facts f = facts(m);
    fprintf(stderr, "# noisy torus (σ = 1 %% of the diagonal): %zu components, Euler characteristic %ld, "
            "distance largest %.3f σ, rms %.3f σ\n", f.components, f.euler, f.worst / sigma, f.rms / sigma);
    assert_int_equal(f.components, 1);
    assert_int_equal(f.euler, 0); /* genus 1 */
    /* The MPU blend's vertices on this cloud: rms 0.22 σ, largest 0.61 σ. */
    assert_true(f.rms < 0.16 * sigma);
    assert_true(f.worst < 0.6 * sigma);

    /* evaluate is the field the mesh was made from: about 0 on its vertices (the vertices
     * interpolate grid corners), positive inside the tube, negative outside. */
    const size_t nv = gmpu_mesh_vertex_count(m);
    double *values = malloc(nv * sizeof *values);
    assert_non_null(values);
    assert_ok(gmpu_surface_evaluate(s, gmpu_mesh_vertices(m), nv, values, NULL));
    double largest = 0;
    for (size_t i = 0; i < nv; ++i) largest = fmax(largest, fabs(values[i]));
    assert_true(largest < 0.5 * sigma);
    const double inside[3] = {kMajor, 0, 0}, outside[3] = {0, 0, 0};
    double fi = 0, fo = 0;
    assert_ok(gmpu_surface_evaluate(s, inside, 1, &fi, NULL));
    assert_ok(gmpu_surface_evaluate(s, outside, 1, &fo, NULL));
    assert_true(fi > 0);
    assert_true(fo < 0);
    free(values);

    /* The point normals follow the smooth surface: −∇f/|∇f| of the field evaluate answers,
     * at the points (all but those beside a thin part; the torus has none). */
    double *normals = malloc(3 * kPoints * sizeof *normals), *gradients = malloc(3 * kPoints * sizeof *gradients);
    assert_non_null(normals);
    assert_non_null(gradients);
    assert_ok(gmpu_surface_copy_normals(s, normals, kPoints));
    assert_ok(gmpu_surface_evaluate(s, xyz, kPoints, NULL, gradients));
    size_t following = 0;
    for (size_t i = 0; i < kPoints; ++i) {
        const double *g = gradients + 3 * i, *n = normals + 3 * i;
        const double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (len > 0 && -(g[0] * n[0] + g[1] * n[1] + g[2] * n[2]) / len > 0.9999) ++following;
    }
    fprintf(stderr, "# noisy torus: %zu of %d point normals along -grad f\n", following, kPoints);
    assert_true(following >= 0.95 * kPoints);
    free(normals);
    free(gradients);
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
    free(xyz);
}

/* Without noise, on 20,000 points and more, the automatic choice keeps the MPU blend where it
 * keeps to the data, as on this torus: the same values as surface = 0 (fewer points, or a
 * blend that strays, guide it: tests/c/test_guided_blend.cpp). */
static void test_clean_cloud_keeps_the_blend(void **state) {
    (void)state;
    double *xyz = noisy_torus(kDenseCloud, 0.0, 3);
    assert_non_null(xyz);
    gmpu_surface *automatic = NULL, *blend = NULL;
    assert_ok(gmpu_surface_create(&automatic));
    assert_ok(gmpu_surface_create(&blend));
    assert_ok(gmpu_surface_set_param(blend, GMPU_PARAM_SURFACE, 0));
    gmpu_surface *both[2] = {automatic, blend};
    for (int k = 0; k < 2; ++k) {
        assert_ok(gmpu_surface_set_points_f64(both[k], xyz, kDenseCloud, 0));
        assert_ok(gmpu_surface_fit(both[k]));
        assert_ok(gmpu_surface_orient(both[k]));
    }
    /* Across the tube, through its inside and out: where the blend and the smooth field
     * differ by more than the guide's limit, a guided blend would answer otherwise. */
    enum { kQueries = 64 };
    double q[3 * kQueries], a[kQueries], b[kQueries];
    for (int i = 0; i < kQueries; ++i) {
        const double angle = 0.1 * i, across = kMajor + kMinor * (-1.5 + 3.0 * i / (kQueries - 1));
        q[3 * i] = across * cos(angle), q[3 * i + 1] = across * sin(angle), q[3 * i + 2] = 0.05;
    }
    assert_ok(gmpu_surface_evaluate(automatic, q, kQueries, a, NULL));
    assert_ok(gmpu_surface_evaluate(blend, q, kQueries, b, NULL));
    for (int i = 0; i < kQueries; ++i) assert_true(a[i] == b[i]);
    gmpu_surface_destroy(automatic);
    gmpu_surface_destroy(blend);
    free(xyz);
}

/* The parameter is read and bounded like every other; changing it after orient is honoured
 * by polygonize (which solves, drops or re-purposes the smooth field), and evaluate refuses until then
 * rather than answer from the other surface; the solve checks its memory estimate against
 * the budget before allocating. */
static void test_surface_parameter(void **state) {
    (void)state;
    gmpu_surface *s = NULL;
    double v = -1;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_get_param(s, GMPU_PARAM_SURFACE, &v));
    assert_true(v == 2);
    check_failure(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 4), GMPU_ERROR_INVALID_ARGUMENT, "SURFACE");
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 0));
    double *xyz = noisy_torus(3000, 0.0, 9);
    assert_non_null(xyz);
    assert_ok(gmpu_surface_set_points_f64(s, xyz, 3000, 0));
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    const double q[3] = {kMajor + kMinor - 0.02, 0, 0}; /* just inside the tube */
    double blend = 0, smooth = 0;
    assert_ok(gmpu_surface_evaluate(s, q, 1, &blend, NULL));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 1));
    check_failure(gmpu_surface_evaluate(s, q, 1, &smooth, NULL), GMPU_ERROR_WRONG_ORDER, "GMPU_PARAM_SURFACE");
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    assert_ok(gmpu_surface_evaluate(s, q, 1, &smooth, NULL));
    assert_true(smooth != blend);
    /* Guided (3): the same smooth field now holds the blend, again only once polygonize ran. */
    double guided = 0;
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 3));
    check_failure(gmpu_surface_evaluate(s, q, 1, &guided, NULL), GMPU_ERROR_WRONG_ORDER, "GMPU_PARAM_SURFACE");
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    assert_ok(gmpu_surface_evaluate(s, q, 1, &guided, NULL));
    assert_true(fabs(guided - smooth) <= fabs(blend - smooth));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 1));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, 1e6));
    m = NULL;
    check_failure2(gmpu_surface_orient(s), GMPU_ERROR_LIMIT_EXCEEDED, "smooth surface", "GMPU_PARAM_MAX_MEMORY");
    gmpu_surface_destroy(s);
    free(xyz);
}

/* The solve runs at the end of orient, in orient's last 15 %: the fractions stay
 * non-decreasing through it, a cancel there is honoured, and a new orient then succeeds. */
typedef struct {
    double last, cancel_from;
    int backwards;
} watch;

static int watch_progress(void *user, gmpu_stage stage, double fraction) {
    (void)stage;
    watch *w = user;
    if (fraction < w->last) ++w->backwards;
    w->last = fraction;
    return fraction >= w->cancel_from;
}

static void test_solve_reports_and_cancels(void **state) {
    (void)state;
    double *xyz = noisy_torus(4000, 0.0, 5);
    assert_non_null(xyz);
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_SURFACE, 1));
    assert_ok(gmpu_surface_set_points_f64(s, xyz, 4000, 0));
    assert_ok(gmpu_surface_fit(s));
    watch all = {0, 2, 0};
    assert_ok(gmpu_surface_set_progress(s, watch_progress, &all));
    assert_ok(gmpu_surface_orient(s));
    assert_int_equal(all.backwards, 0);
    assert_true(all.last == 1.0);
    watch late = {0, 0.86, 0};
    assert_ok(gmpu_surface_set_progress(s, watch_progress, &late));
    check_failure(gmpu_surface_orient(s), GMPU_ERROR_CANCELLED, "cancel");
    assert_ok(gmpu_surface_set_progress(s, NULL, NULL));
    assert_ok(gmpu_surface_orient(s));
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_surface_polygonize(s, &m));
    assert_null(robust_mesh_problem(m));
    gmpu_mesh_destroy(m);
    gmpu_surface_destroy(s);
    free(xyz);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_noisy_torus_keeps_its_topology),
        cmocka_unit_test(test_clean_cloud_keeps_the_blend),
        cmocka_unit_test(test_surface_parameter),
        cmocka_unit_test(test_solve_reports_and_cancels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
