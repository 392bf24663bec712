/* The parameter table through the C ABI: gmpu_param_count, gmpu_param_info and
 * gmpu_param_key describe every key, and what they say is what gmpu_surface_set_param and
 * get_param do: the default is a new surface's value, the bounds are accepted or refused as
 * the exclusive flags say, integer types refuse fractions, and `refits` says whether a new
 * value discards the fit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gmpu/gmpu.h"
#include "robust_util.h"

static gmpu_param_info_t info_of(int key) {
    gmpu_param_info_t info;
    memset(&info, 0, sizeof info);
    assert_ok(gmpu_param_info((gmpu_param)key, &info));
    return info;
}

static int accepted(int key, double value) {
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    const gmpu_status st = gmpu_surface_set_param(s, (gmpu_param)key, value);
    gmpu_surface_destroy(s);
    assert_true(st == GMPU_OK || st == GMPU_ERROR_INVALID_ARGUMENT);
    return st == GMPU_OK;
}

static void test_every_key_is_described(void **state) {
    (void)state;
    const int count = gmpu_param_count();
    assert_true(count >= GMPU_PARAM_MAX_MEMORY); /* keys are 1..count; docs_match checks gmpu.h has them all */
    for (int key = 1; key <= count; ++key) {
        const gmpu_param_info_t info = info_of(key);
        assert_non_null(info.name);
        assert_non_null(info.doc);
        assert_true(strlen(info.name) > 0 && strlen(info.doc) > 10);
        assert_true(info.type == GMPU_TYPE_INT || info.type == GMPU_TYPE_REAL);
        assert_true(info.min < info.max);
        /* Both spellings of the name find the key. */
        assert_int_equal(gmpu_param_key(info.name), key);
        char enumerator[64] = "GMPU_PARAM_";
        for (const char *c = info.name; *c; ++c) {
            const size_t n = strlen(enumerator);
            enumerator[n] = (char)toupper((unsigned char)*c);
            enumerator[n + 1] = '\0';
        }
        assert_int_equal(gmpu_param_key(enumerator), key);
    }
}

static void test_unknown_keys_and_names_are_refused(void **state) {
    (void)state;
    gmpu_param_info_t info;
    check_failure(gmpu_param_info((gmpu_param)0, &info), GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key 0");
    check_failure(gmpu_param_info((gmpu_param)(gmpu_param_count() + 1), &info), GMPU_ERROR_INVALID_ARGUMENT,
                  "unknown parameter key");
    check_failure(gmpu_param_info((gmpu_param)-7, &info), GMPU_ERROR_INVALID_ARGUMENT, "unknown parameter key");
    check_failure(gmpu_param_info(GMPU_PARAM_ERROR, NULL), GMPU_ERROR_INVALID_ARGUMENT, "info is NULL");
    assert_int_equal(gmpu_param_key(NULL), 0);
    assert_int_equal(gmpu_param_key(""), 0);
    assert_int_equal(gmpu_param_key("no_such_parameter"), 0);
    assert_int_equal(gmpu_param_key("MAX_DEPTH"), 0); /* neither the name nor the enumerator */
}

static void test_default_is_a_new_surfaces_value(void **state) {
    (void)state;
    gmpu_surface *s = NULL;
    assert_ok(gmpu_surface_create(&s));
    for (int key = 1; key <= gmpu_param_count(); ++key) {
        double v = NAN;
        assert_ok(gmpu_surface_get_param(s, (gmpu_param)key, &v));
        assert_true(v == info_of(key).default_value);
    }
    gmpu_surface_destroy(s);
}

static void test_range_is_what_set_param_accepts(void **state) {
    (void)state;
    for (int key = 1; key <= gmpu_param_count(); ++key) {
        const gmpu_param_info_t info = info_of(key);
        assert_int_equal(accepted(key, info.min), !info.min_exclusive);
        assert_int_equal(accepted(key, info.max), !info.max_exclusive);
        assert_false(accepted(key, nextafter(info.min, -INFINITY)));
        assert_false(accepted(key, nextafter(info.max, INFINITY)));
        assert_false(accepted(key, NAN));
        assert_true(accepted(key, info.default_value));
        /* A fraction between the bounds: refused for integers only. */
        const double fraction = floor((info.min + info.max) / 2) + 0.5;
        assert_int_equal(accepted(key, fraction), info.type == GMPU_TYPE_REAL);
    }
}

/* A value different from the default that set_param accepts. */
static double another_value(int key, const gmpu_param_info_t *info) {
    const double candidates[] = {info->default_value + 1, info->default_value - 1, info->max, info->min,
                                 info->default_value * 1.5};
    for (size_t i = 0; i < sizeof candidates / sizeof candidates[0]; ++i) {
        const double v = candidates[i];
        if (v != info->default_value && accepted(key, v)) return v;
    }
    return info->default_value;
}

static void test_refits_says_whether_the_fit_is_discarded(void **state) {
    (void)state;
    const double centre[3] = {0, 0, 0};
    const size_t n = 600;
    double *xyz = robust_sphere(n, centre, 1.0, 3);
    assert_non_null(xyz);
    for (int key = 1; key <= gmpu_param_count(); ++key) {
        const gmpu_param_info_t info = info_of(key);
        gmpu_surface *s = NULL;
        assert_ok(gmpu_surface_create(&s));
        assert_ok(gmpu_surface_set_points_f64(s, xyz, n, 0));
        assert_ok(gmpu_surface_fit(s));
        const double v = another_value(key, &info);
        assert_true(v != info.default_value);
        assert_ok(gmpu_surface_set_param(s, (gmpu_param)key, v));
        const gmpu_status st = gmpu_surface_orient(s);
        if (st != (info.refits ? GMPU_ERROR_WRONG_ORDER : GMPU_OK))
            fail_msg("%s (refits %d) set to %g: orient returned %s", info.name, info.refits, v, gmpu_status_name(st));
        gmpu_surface_destroy(s);
    }
    free(xyz);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_key_is_described),
        cmocka_unit_test(test_unknown_keys_and_names_are_refused),
        cmocka_unit_test(test_default_is_a_new_surfaces_value),
        cmocka_unit_test(test_range_is_what_set_param_accepts),
        cmocka_unit_test(test_refits_says_whether_the_fit_is_discarded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
