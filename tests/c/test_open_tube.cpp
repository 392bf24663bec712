// Far regions that reach into the solid (mesh/block_grid.hpp): the bore of an open-ended tube
// connects to the grid's edge through its ends, so as one far region it was outside, and
// the surface closed around the band's inner edge: a second, invented tube inside the bore
// (genus 1, where the sampled sheet bounds a solid cylinder). The winding number says the
// bore is inside; the surface must close across the tube's ends instead.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mesh_checks.hpp"
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

constexpr double kRadius = 0.3, kLength = 1.0;

// The side of a cylinder about z, without its end discs (a scan of a solid cylinder that
// never saw its ends, or a pipe whose two faces the noise merged into one sheet).
std::vector<Vec3> tube_side(size_t count, double noise) {
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), height(-0.5 * kLength, 0.5 * kLength);
    std::normal_distribution<double> jitter(0.0, noise);
    std::vector<Vec3> points;
    for (size_t i = 0; i < count; ++i) {
        const double a = angle(random);
        points.emplace_back(kRadius * std::cos(a) + jitter(random), kRadius * std::sin(a) + jitter(random),
                            height(random) + jitter(random));
    }
    return points;
}

void check_solid_cylinder(const std::vector<Vec3> &points, const char *what) {
    Reconstruction r = reconstruct(points);
    assert_int_equal(r.status, GMPU_OK);
    const MeshCheck check = check_mesh(r.mesh);
    // The nearest surface to the axis along the tube's middle half: the sheet itself, not a
    // second tube around the band's inner edge (about half the radius in).
    double nearest_axis = INFINITY, lowest = INFINITY, highest = -INFINITY;
    for (const Vec3 &v : r.mesh.vertices) {
        if (std::abs(v.z()) < 0.25 * kLength) nearest_axis = std::min(nearest_axis, std::hypot(v.x(), v.y()));
        lowest = std::min(lowest, v.z());
        highest = std::max(highest, v.z());
    }
    const double solid = M_PI * kRadius * kRadius * kLength;
    print_message("%s: genus %d, volume %.3f of the solid cylinder's %.3f, nearest the axis %.3f, ends %.3f %.3f\n",
                  what, check.component_reports.empty() ? -1 : check.component_reports[0].genus, check.signed_volume, solid, nearest_axis, lowest,
                  highest);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    assert_int_equal(check.component_reports[0].genus, 0);
    assert_true(nearest_axis > 0.9 * kRadius);
    // Closed across the ends, within a radius of them (the caps sit on the far blocks'
    // faces, a block of the grid at most past where the winding number crosses ½).
    assert_true(lowest > -0.5 * kLength - kRadius && highest < 0.5 * kLength + kRadius);
    assert_true(check.signed_volume > 0.9 * solid && check.signed_volume < 1.3 * solid);
}

void open_tube_closes_across_its_ends(void **) { check_solid_cylinder(tube_side(20000, 0.0), "clean"); }

// At 1 % of the diagonal, as the corpus's pipe_noise1.0, whose two faces merged.
void noisy_open_tube_closes_across_its_ends(void **) {
    check_solid_cylinder(tube_side(20000, 0.01 * std::sqrt(2 * 4 * kRadius * kRadius + kLength * kLength)), "noisy");
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(open_tube_closes_across_its_ends),
        cmocka_unit_test(noisy_open_tube_closes_across_its_ends),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
