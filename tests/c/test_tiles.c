/* Tiles on a shared grid through the C ABI: gmpu_grid_polygonize run separately on two sets
 * of blocks (two "tiles") with the same corner values gives pieces that weld by
 * gmpu_mesh_grid_keys into the closed mesh one call over all blocks gives; each piece alone
 * is open at the cut. gmpu_surface_evaluate_grid is gmpu_surface_evaluate at the grid's
 * corners. Bad arguments get a status, never a crash. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gmpu/gmpu.h"
#include "robust_util.h"

enum { B = 8, C = 9, NB = 4 };                 /* 4³ blocks of 8³ cubes */
static const double kOrigin[3] = {-1, -1, -1};
static const double kCell = 2.0 / (NB * B);
static const int64_t kCells[3] = {NB * B, NB * B, NB * B};

/* A solid torus around z (positive inside), so the mesh has genus 1 and crosses the cut. */
static double field(const double p[3]) {
    const double q = sqrt(p[0] * p[0] + p[1] * p[1]) - 0.55;
    return 0.25 - sqrt(q * q + p[2] * p[2]);
}

/* Blocks with bx in [x_lo, x_hi), all by, bz; their 9³ corner values. */
static size_t tile_blocks(int x_lo, int x_hi, int64_t *blocks, double *values) {
    size_t n = 0;
    for (int bz = 0; bz < NB; ++bz)
        for (int by = 0; by < NB; ++by)
            for (int bx = x_lo; bx < x_hi; ++bx, ++n) {
                blocks[3 * n] = bx, blocks[3 * n + 1] = by, blocks[3 * n + 2] = bz;
                for (int k = 0; k < C; ++k)
                    for (int j = 0; j < C; ++j)
                        for (int i = 0; i < C; ++i) {
                            const double p[3] = {kOrigin[0] + kCell * (bx * B + i), kOrigin[1] + kCell * (by * B + j),
                                                 kOrigin[2] + kCell * (bz * B + k)};
                            values[n * C * C * C + i + C * (j + C * k)] = field(p);
                        }
            }
    return n;
}

static gmpu_mesh *march(int x_lo, int x_hi) {
    int64_t *blocks = malloc(3 * NB * NB * NB * sizeof *blocks);
    double *values = malloc((size_t)NB * NB * NB * C * C * C * sizeof *values);
    const size_t n = tile_blocks(x_lo, x_hi, blocks, values);
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_grid_polygonize(kOrigin, kCell, kCells, blocks, n, values, &m));
    free(blocks);
    free(values);
    return m;
}

typedef struct { uint64_t key; uint32_t index; } keyed;
static int cmp_keyed(const void *a, const void *b) { return robust_cmp_u64(&((const keyed *)a)->key, &((const keyed *)b)->key); }

/* One vertex per key across the pieces. */
static gmpu_mesh *weld(gmpu_mesh *const *pieces, int count) {
    size_t nv = 0, nt = 0;
    for (int p = 0; p < count; ++p) nv += gmpu_mesh_vertex_count(pieces[p]), nt += gmpu_mesh_triangle_count(pieces[p]);
    keyed *k = malloc(nv * sizeof *k);
    double *v = malloc(3 * nv * sizeof *v);
    uint32_t *t = malloc(3 * nt * sizeof *t), *id = malloc(nv * sizeof *id);
    size_t at = 0, tat = 0;
    for (int p = 0; p < count; ++p) {
        const uint64_t *keys = gmpu_mesh_grid_keys(pieces[p]);
        assert_non_null(keys);
        const size_t base = at;
        for (size_t i = 0; i < gmpu_mesh_vertex_count(pieces[p]); ++i, ++at) k[at] = (keyed){keys[i], (uint32_t)at};
        memcpy(v + 3 * base, gmpu_mesh_vertices(pieces[p]), 3 * gmpu_mesh_vertex_count(pieces[p]) * sizeof *v);
        for (size_t i = 0; i < 3 * gmpu_mesh_triangle_count(pieces[p]); ++i)
            t[tat++] = (uint32_t)base + gmpu_mesh_triangles(pieces[p])[i];
    }
    qsort(k, nv, sizeof *k, cmp_keyed);
    uint32_t unique = 0;
    for (size_t i = 0; i < nv; ++i) {
        if (i > 0 && k[i].key != k[i - 1].key) ++unique;
        id[k[i].index] = unique;
    }
    double *uv = malloc(3 * nv * sizeof *uv);
    for (size_t i = 0; i < nv; ++i) memcpy(uv + 3 * id[i], v + 3 * i, 3 * sizeof *uv);
    for (size_t i = 0; i < 3 * nt; ++i) t[i] = id[t[i]];
    gmpu_mesh *m = NULL;
    assert_ok(gmpu_mesh_create(uv, nv ? unique + 1 : 0, t, nt, &m));
    free(k), free(v), free(t), free(id), free(uv);
    return m;
}

static void test_two_tiles_weld_into_the_whole(void **state) {
    (void)state;
    gmpu_mesh *whole = march(0, NB);
    assert_null(robust_mesh_problem(whole));
    assert_true(robust_signed_volume(whole) > 0);
    gmpu_mesh *pieces[2] = {march(0, 2), march(2, NB)};
    /* Each tile alone is open where the torus crosses the cut. */
    assert_non_null(robust_mesh_problem(pieces[0]));
    assert_non_null(robust_mesh_problem(pieces[1]));
    gmpu_mesh *welded = weld(pieces, 2);
    assert_null(robust_mesh_problem(welded));
    assert_int_equal(gmpu_mesh_vertex_count(welded), gmpu_mesh_vertex_count(whole));
    assert_int_equal(gmpu_mesh_triangle_count(welded), gmpu_mesh_triangle_count(whole));
    assert_true(fabs(robust_signed_volume(welded) - robust_signed_volume(whole)) < 1e-12);
    /* A mesh from elsewhere has no keys. */
    assert_null(gmpu_mesh_grid_keys(welded));
    gmpu_mesh_destroy(whole), gmpu_mesh_destroy(pieces[0]), gmpu_mesh_destroy(pieces[1]), gmpu_mesh_destroy(welded);
}

static void test_evaluate_grid_is_evaluate_at_the_corners(void **state) {
    (void)state;
    const double c[3] = {0, 0, 0};
    double *p = robust_sphere(2000, c, 0.7, 3);
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    assert_ok(gmpu_surface_set_points_f64(s, p, 2000, 0));
    const int64_t blocks[6] = {1, 1, 2, 2, 3, 1};
    double values[2 * 512], direct[512], xyz[3 * 512];
    check_failure(gmpu_surface_evaluate_grid(s, kOrigin, kCell, blocks, 2, values), GMPU_ERROR_WRONG_ORDER, "orient");
    assert_ok(gmpu_surface_fit(s));
    assert_ok(gmpu_surface_orient(s));
    assert_ok(gmpu_surface_set_param(s, GMPU_PARAM_THREADS, 2));
    assert_ok(gmpu_surface_evaluate_grid(s, kOrigin, kCell, blocks, 2, values));
    for (int b = 0; b < 2; ++b) {
        for (int k = 0; k < B; ++k)
            for (int j = 0; j < B; ++j)
                for (int i = 0; i < B; ++i) {
                    const int corner[3] = {i, j, k};
                    for (int d = 0; d < 3; ++d)
                        xyz[3 * (i + B * (j + B * k)) + d] = kOrigin[d] + kCell * (double)(blocks[3 * b + d] * B + corner[d]);
                }
        assert_ok(gmpu_surface_evaluate(s, xyz, 512, direct, NULL));
        for (int i = 0; i < 512; ++i) assert_true(values[512 * b + i] == direct[i]);
    }
    gmpu_surface_destroy(s);
    free(p);
}

static void test_bad_arguments(void **state) {
    (void)state;
    int64_t block[3] = {0, 0, 0};
    double values[C * C * C];
    for (int i = 0; i < C * C * C; ++i) values[i] = i % 2 ? 1 : -1;
    gmpu_mesh *m = NULL;
    const int64_t odd[3] = {12, 16, 16};
    check_failure(gmpu_grid_polygonize(kOrigin, kCell, kCells, block, 1, values, NULL), GMPU_ERROR_INVALID_ARGUMENT, "out");
    check_failure(gmpu_grid_polygonize(NULL, kCell, kCells, block, 1, values, &m), GMPU_ERROR_INVALID_ARGUMENT, "grid_origin");
    check_failure(gmpu_grid_polygonize(kOrigin, 0.0, kCells, block, 1, values, &m), GMPU_ERROR_INVALID_ARGUMENT, "cell_size");
    check_failure(gmpu_grid_polygonize(kOrigin, NAN, kCells, block, 1, values, &m), GMPU_ERROR_INVALID_ARGUMENT, "cell_size");
    check_failure(gmpu_grid_polygonize(kOrigin, kCell, odd, block, 1, values, &m), GMPU_ERROR_INVALID_ARGUMENT, "grid_cells");
    check_failure(gmpu_grid_polygonize(kOrigin, kCell, kCells, NULL, 1, values, &m), GMPU_ERROR_INVALID_ARGUMENT, "blocks");
    block[1] = NB;
    check_failure(gmpu_grid_polygonize(kOrigin, kCell, kCells, block, 1, values, &m), GMPU_ERROR_INVALID_ARGUMENT, "outside the grid");
    block[1] = 0;
    values[100] = NAN;
    check_failure(gmpu_grid_polygonize(kOrigin, kCell, kCells, block, 1, values, &m), GMPU_ERROR_INVALID_INPUT, "NaN");
    assert_null(m);
    assert_ok(gmpu_grid_polygonize(kOrigin, kCell, kCells, block, 0, NULL, &m));
    assert_int_equal(gmpu_mesh_triangle_count(m), 0);
    gmpu_mesh_destroy(m);
    check_failure(gmpu_surface_evaluate_grid(NULL, kOrigin, kCell, block, 1, values), GMPU_ERROR_INVALID_ARGUMENT, "surface");
    assert_null(gmpu_mesh_grid_keys(NULL));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_tiles_weld_into_the_whole),
        cmocka_unit_test(test_evaluate_grid_is_evaluate_at_the_corners),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
