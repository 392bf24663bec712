// The thinning of polygonize's points (mesh/point_buckets.hpp): one representative per voxel,
// the lowest index in it, with its count, in voxel order. Checked against the plain
// definition (sort all (voxel, index) pairs, keep the first of each voxel) on clouds with
// duplicates, points before the origin and points past the last voxel.
#include <algorithm>
#include <cstdint>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "geometry/point_set.hpp"
#include "mesh/point_buckets.hpp"
#include "random_vectors.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using gmpu_test::draw_vector;

using namespace gmpu;

namespace {

struct Thinned {
    std::vector<uint32_t> rep, count;
};

Thinned by_definition(const PointSet &points, const Eigen::Vector3d &origin, double voxel) {
    std::vector<std::pair<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t>> keyed;
    for (uint32_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d v = (points.point(i) - origin) / voxel;
        auto at = [&](int d) { return uint32_t(std::clamp(v[d], 0.0, 65535.0)); };
        keyed.push_back({{at(2), at(1), at(0)}, i});
    }
    std::sort(keyed.begin(), keyed.end());
    Thinned t;
    for (size_t k = 0; k < keyed.size(); ++k) {
        if (k > 0 && keyed[k].first == keyed[k - 1].first) {
            ++t.count.back();
        } else {
            t.rep.push_back(keyed[k].second);
            t.count.push_back(1);
        }
    }
    return t;
}

PointSet cloud(size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> xyz;
    for (size_t i = 0; i < n; ++i) {
        // A sphere's surface, with every tenth point repeating an earlier one.
        Eigen::Vector3d p = draw_vector(u, rng);
        if (i % 10 == 9) p = Eigen::Vector3d(xyz[3 * (i / 2)], xyz[3 * (i / 2) + 1], xyz[3 * (i / 2) + 2]);
        else p.normalize();
        xyz.insert(xyz.end(), {p[0], p[1], p[2]});
    }
    return PointSet::from_array(xyz.data(), n, 0, 1, nullptr);
}

void expect_definition(const PointSet &points, const Eigen::Vector3d &origin, double voxel) {
    Progress silent(nullptr, nullptr, GMPU_STAGE_POLYGONIZE);
    Thinned got;
    voxel_representatives(points, origin, voxel, silent, 0.0, got.rep, got.count);
    const Thinned want = by_definition(points, origin, voxel);
    assert_int_equal(got.rep.size(), want.rep.size());
    assert_true(got.rep == want.rep);
    assert_true(got.count == want.count);
    size_t total = 0;
    for (uint32_t c : got.count) total += c;
    assert_int_equal(total, points.size());
}

void matches_the_definition(void **) {
    const PointSet points = cloud(20000, 7);
    // Voxels from coarse (many points each) to fine (mostly one each).
    for (double voxel : {0.2, 0.03, 0.004}) expect_definition(points, Eigen::Vector3d::Constant(-0.6), voxel);
}

void clamps_points_outside_the_voxel_range(void **) {
    const PointSet points = cloud(5000, 11);
    // The origin inside the cloud: the points before it share the voxels at 0.
    expect_definition(points, Eigen::Vector3d(0.1, -0.2, 0.0), 0.01);
    // Voxels so small that the far side of the cloud lies past the last one.
    expect_definition(points, Eigen::Vector3d::Constant(-0.6), 1e-5);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(matches_the_definition),
        cmocka_unit_test(clamps_points_outside_the_voxel_range),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
