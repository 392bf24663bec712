// The smooth field (implicit/smooth_field.hpp) over a misoriented patch. A noisy unit
// sphere whose oriented normals point inward on most of a cap (the misoriented patches
// belief propagation leaves at noise are mixed like this): the normals over the cap ask f
// to grow outward. Solved on the band around the points alone, with the band's edge left free,
// f kept growing along them to the band's edge, so outside the cap it was positive
// ("inside") out to where the band ended and the surface closed there: a blister a band's
// width off the sphere. With the outer field over the whole box at the band's edge, the
// cap's error relaxes into the space around it: outside the cap f turns negative within a
// few cells, and the far outside is outside everywhere.
#include <cmath>
#include <random>
#include <vector>

#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/smooth_field.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using Eigen::Vector3d;
using namespace gmpu;

namespace {

constexpr size_t kPoints = 20000;
constexpr double kCapFrom = 0.95;  // on the cap z > kCapFrom (unit sphere) ...
constexpr double kMisoriented = 0.6;  // ... this share of the normals point inward
constexpr double kResolution = 128;

void misoriented_cap_relaxes_outside(void **) {
    // Points on the unit sphere with noise of 1 % of the diagonal along the normal.
    std::mt19937_64 rng(17);
    std::normal_distribution<double> gauss;
    const double sigma = 0.01 * 2.0 * std::sqrt(3.0);
    std::vector<double> xyz;
    std::vector<Vector3d> outward;
    for (size_t i = 0; i < kPoints; ++i) {
        Vector3d d(gauss(rng), gauss(rng), gauss(rng));
        d.normalize();
        const Vector3d p = d * (1.0 + sigma * gauss(rng));
        xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
        outward.push_back(d.z() > kCapFrom && std::uniform_real_distribution<double>()(rng) < kMisoriented ? Vector3d(-d) : d);
    }
    const PointSet points = PointSet::from_array(xyz.data(), kPoints, 0, 1);
    // The sphere in the normalised frame.
    const Vector3d centre = 0.5 * (points.box_min() + points.box_max());
    const double radius = 0.5 * (points.box_max() - points.box_min()).maxCoeff() / (1.0 + 3.0 * sigma);

    PointMeasures measures;
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    const double area = 4.0 * M_PI * radius * radius / double(kPoints);
    for (size_t i = 0; i < kPoints; ++i) {
        for (int k = 0; k < 3; ++k) measures.blend_normals.push_back(float(outward[i][k]));
        points.nearest(points.point(i), 9, idx, d2);
        measures.trust_radius.push_back(float(1.5 * std::sqrt(double(d2.back()))));
        measures.widest_trust = std::max(measures.widest_trust, double(measures.trust_radius.back()));
        measures.area.push_back(float(area));
    }
    measures.normals = measures.blend_normals;

    const double h = 1.0 / kResolution;
    Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
    const SmoothField field(points, measures, h, 2.0 * h, 0.01, 1e10, quiet);
    assert_false(field.empty());

    // Along the cap's axis, outward from a few cells beyond the noise: outside everywhere.
    const double from = radius * (1.0 + 3.0 * sigma) + 3.0 * h;
    size_t positive = 0, evaluated = 0;
    for (double t = from; t < from + 0.1; t += 0.25 * h) {
        double f;
        if (!field.value(centre + Vector3d(0, 0, t), f, nullptr)) break;
        ++evaluated;
        positive += f > 0.0;
    }
    print_message("# along the inward cap's axis: %zu of %zu values beyond the noise inside\n", positive, evaluated);
    assert_true(evaluated > 4);
    assert_int_equal(positive, 0);
    // Opposite, over correct normals: outside too, and inside at the centre.
    double f;
    assert_true(field.value(centre - Vector3d(0, 0, from), f, nullptr));
    assert_true(f < 0.0);
    assert_true(field.value(centre, f, nullptr));
    assert_true(f > 0.0);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(misoriented_cap_relaxes_outside),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
