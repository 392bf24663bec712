// The documentation states what the library does: every parameter's default and range in
// gmpu.h ("Default D, range R.") and in the README's parameter table match a fresh surface's
// values and what gmpu_surface_set_param accepts at and just beyond each bound; the
// progress cadence and cancel latency quoted in gmpu.h, the README and the bindings' docs
// are the library's own constants (core/progress.hpp).
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/progress.hpp"
#include "gmpu/gmpu.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <unistd.h>
extern "C" {
#include <cmocka.h>
}

namespace {

std::string source_file(const std::string &relative) {
    const char *root = std::getenv("GMPU_SOURCE_ROOT");
    if (!root) fail_msg("GMPU_SOURCE_ROOT is not set (meson sets it)");
    std::ifstream in(std::string(root) + "/" + relative);
    if (!in) fail_msg("cannot read %s", relative.c_str());
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// Comment markers dropped and whitespace collapsed, so a phrase may wrap across lines.
std::string prose(const std::string &text) {
    std::string out = std::regex_replace(text, std::regex(R"((^|\n)\s*(///|//|\*|/\*)?)"), " ");
    return std::regex_replace(out, std::regex(R"(\s+)"), " ");
}

struct Documented {
    std::string default_text, range;
};

// gmpu_param keys of gmpu.h with the comment above each.
std::map<std::string, Documented> header_params() {
    const std::string h = source_file("include/gmpu/gmpu.h");
    const size_t begin = h.find("typedef enum gmpu_param {"), end = h.find("} gmpu_param;");
    assert_true(begin != std::string::npos && end != std::string::npos);
    const std::string body = h.substr(begin, end - begin);
    std::map<std::string, Documented> out;
    const std::regex entry(R"(/\*([\s\S]*?)\*/\s*(GMPU_PARAM_\w+)\s*=\s*\d+)");
    const std::regex tail(R"(Default (\S+|half the physical memory), range (.+)\.\s*$)");
    for (std::sregex_iterator it(body.begin(), body.end(), entry), stop; it != stop; ++it) {
        const std::string comment = prose((*it)[1].str()), key = (*it)[2].str();
        std::smatch m;
        if (!std::regex_search(comment, m, tail))
            fail_msg("gmpu.h: the comment of %s does not end with \"Default D, range R.\": %s", key.c_str(),
                     comment.c_str());
        out[key] = {m[1].str(), m[2].str()};
    }
    return out;
}

const std::map<std::string, gmpu_param> kKeys = {
    {"GMPU_PARAM_ERROR", GMPU_PARAM_ERROR},
    {"GMPU_PARAM_MAX_DEPTH", GMPU_PARAM_MAX_DEPTH},
    {"GMPU_PARAM_MIN_POINTS", GMPU_PARAM_MIN_POINTS},
    {"GMPU_PARAM_SUPPORT_SCALE", GMPU_PARAM_SUPPORT_SCALE},
    {"GMPU_PARAM_SHARP_FEATURES", GMPU_PARAM_SHARP_FEATURES},
    {"GMPU_PARAM_RESOLUTION", GMPU_PARAM_RESOLUTION},
    {"GMPU_PARAM_LEVEL", GMPU_PARAM_LEVEL},
    {"GMPU_PARAM_THREADS", GMPU_PARAM_THREADS},
    {"GMPU_PARAM_MAX_CELLS", GMPU_PARAM_MAX_CELLS},
    {"GMPU_PARAM_MAX_TRIANGLES", GMPU_PARAM_MAX_TRIANGLES},
    {"GMPU_PARAM_NOISE_SCALE", GMPU_PARAM_NOISE_SCALE},
    {"GMPU_PARAM_MAX_MEMORY", GMPU_PARAM_MAX_MEMORY},
    {"GMPU_PARAM_REMOVE_OUTLIERS", GMPU_PARAM_REMOVE_OUTLIERS},
};


double number(const std::string &text, const std::string &what) {
    char *end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0') fail_msg("%s: \"%s\" is not a number", what.c_str(), text.c_str());
    return v;
}

// A documented default: a number, or "half" (of the physical memory: the budget's default
// depends on the machine, so the documentation names the rule).
double documented_default(const std::string &text, const std::string &what) {
    if (text.rfind("half", 0) == 0) {
        const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
        return 0.5 * double(pages) * double(page);
    }
    return number(text, what);
}

double library_default(gmpu_param key) {
    gmpu_surface *s = nullptr;
    assert_int_equal(gmpu_surface_create(&s), GMPU_OK);
    double v = NAN;
    assert_int_equal(gmpu_surface_get_param(s, key, &v), GMPU_OK);
    gmpu_surface_destroy(s);
    return v;
}

bool accepted(gmpu_param key, double value) {
    gmpu_surface *s = nullptr;
    assert_int_equal(gmpu_surface_create(&s), GMPU_OK);
    const gmpu_status st = gmpu_surface_set_param(s, key, value);
    gmpu_surface_destroy(s);
    if (st != GMPU_OK && st != GMPU_ERROR_INVALID_ARGUMENT) fail_msg("set_param returned %s", gmpu_status_name(st));
    return st == GMPU_OK;
}

// The range's bounds are accepted when closed and refused when open; a step beyond (1 for
// integers, the next double for reals) is refused.
void check_range(const std::string &key, gmpu_param k, const std::string &range) {
    std::smatch m;
    const std::string what = key + " range " + range;
    if (std::regex_match(range, m, std::regex(R"((-?[0-9.e+]+)\.\.(-?[0-9.e+]+))"))) {
        const double lo = number(m[1], what), hi = number(m[2], what);
        if (!accepted(k, lo) || !accepted(k, hi) || accepted(k, lo - 1) || accepted(k, hi + 1) ||
            accepted(k, lo + 0.5))
            fail_msg("%s: the library accepts a different set of values", what.c_str());
        return;
    }
    if (std::regex_match(range, m, std::regex(R"(([\[(])(-?[0-9.e+]+), (-?[0-9.e+]+)([\])]))"))) {
        const double lo = number(m[2], what), hi = number(m[3], what);
        const bool lo_in = m[1] == "[", hi_in = m[4] == "]";
        if (accepted(k, lo) != lo_in || accepted(k, hi) != hi_in || accepted(k, std::nextafter(lo, -INFINITY)) ||
            accepted(k, std::nextafter(hi, INFINITY)) || !accepted(k, std::nextafter(lo, INFINITY)) ||
            !accepted(k, std::nextafter(hi, -INFINITY)))
            fail_msg("%s: the library accepts a different set of values", what.c_str());
        return;
    }
    fail_msg("%s: not of the form a..b, [a, b] or (a, b)", what.c_str());
}

void header_defaults_and_ranges_are_the_librarys(void **) {
    const auto params = header_params();
    assert_int_equal(params.size(), kKeys.size());  // a new key needs its line in kKeys
    for (const auto &[key, doc] : params) {
        auto k = kKeys.find(key);
        if (k == kKeys.end()) fail_msg("gmpu.h documents %s, unknown to this test: add it to kKeys", key.c_str());
        const double expected = documented_default(doc.default_text, key + " default");
        const double actual = library_default(k->second);
        if (actual != expected)
            fail_msg("gmpu.h: %s default %s, the library's %.17g", key.c_str(), doc.default_text.c_str(), actual);
        check_range(key, k->second, doc.range);
    }
}

void readme_parameter_table_is_the_headers(void **) {
    const std::string readme = source_file("README.md");
    const size_t begin = readme.find("<!-- params:begin -->"), end = readme.find("<!-- params:end -->");
    assert_true(begin != std::string::npos && end != std::string::npos);
    const std::string table = readme.substr(begin, end - begin);
    const auto params = header_params();
    size_t rows = 0;
    const std::regex row(R"(\| `(GMPU_PARAM_\w+)` \| ([^|]+) \| ([^|]+) \|)");
    for (std::sregex_iterator it(table.begin(), table.end(), row), stop; it != stop; ++it, ++rows) {
        const std::string key = (*it)[1].str();
        auto doc = params.find(key);
        if (doc == params.end()) fail_msg("README documents %s, which gmpu.h does not", key.c_str());
        std::string shown = (*it)[2].str(), range = (*it)[3].str();
        shown = shown.substr(0, shown.find(' '));  // "0 (auto)" → "0"
        const double v = documented_default(shown, "README default of " + key), expected = library_default(kKeys.at(key));
        if (v != expected) fail_msg("README: %s default %s, the library's %.17g", key.c_str(), shown.c_str(), expected);
        if (range.compare(0, doc->second.range.size(), doc->second.range) != 0)
            fail_msg("README: %s range \"%s\", gmpu.h \"%s\"", key.c_str(), range.c_str(), doc->second.range.c_str());
    }
    assert_int_equal(rows, params.size());
}

// Every "at least every N ms", "at most every N ms" and "within N ms" of the progress
// documentation is the library's constant.
void documented_cadence_is_the_librarys(void **) {
    using std::chrono::milliseconds;
    const long at_least = milliseconds(gmpu::kMaxWorkBetweenReports).count(),
               at_most = milliseconds(gmpu::kReportInterval).count(),
               within = milliseconds(gmpu::kMaxCancelLatency).count();
    int header_figures = 0;
    for (const char *file : {"include/gmpu/gmpu.h", "README.md", "bindings/node/index.d.ts", "bindings/rust/src/lib.rs",
                             "bindings/python/gmpu/_progress.py"}) {
        const std::string text = prose(source_file(file));
        const std::regex figure(R"((at least every|at most every|within) (\d+) ms)");
        for (std::sregex_iterator it(text.begin(), text.end(), figure), stop; it != stop; ++it) {
            const std::string kind = (*it)[1].str();
            const long n = std::stol((*it)[2].str());
            const long expected = kind == "at least every" ? at_least : kind == "at most every" ? at_most : within;
            if (n != expected)
                fail_msg("%s: \"%s %ld ms\", the library's figure is %ld ms", file, kind.c_str(), n, expected);
            header_figures += std::string(file) == "include/gmpu/gmpu.h";
        }
    }
    assert_true(header_figures >= 3);  // gmpu.h states all three
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(header_defaults_and_ranges_are_the_librarys),
        cmocka_unit_test(readme_parameter_table_is_the_headers),
        cmocka_unit_test(documented_cadence_is_the_librarys),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
