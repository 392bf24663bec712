// Free-standing sheets (pipeline/free_sheet.hpp): a plate whose two faces lie closer together
// than the noise must come out as a thin slab around the plate, not as the dome that closing
// one consistently oriented sheet makes; a noisy closed shape must stay a solid.
#include <cmath>
#include <vector>

#include "mesh_checks.hpp"
#include "metrics.hpp"
#include "primitive_meshes.hpp"
#include "reconstruct.hpp"
#include "sampling.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu::testing;

namespace {

// Noise σ as a share of the shape's diagonal: as the corpus's heaviest noise.
constexpr double kNoise = 0.01;

std::vector<Vec3> noisy_samples(const TriangleMesh &mesh, size_t count) {
    MeshSamples s = sample_mesh(mesh, count, 3);
    add_gaussian_noise(s.positions, kNoise * bbox_diagonal(mesh), 5);
    return s.positions;
}

void noisy_thin_plate_becomes_a_slab(void **) {
    // 1 × 0.6 × 0.02: the faces 1.7 σ apart.
    const TriangleMesh plate = box_mesh(Vec3::Zero(), Vec3(0.5, 0.3, 0.01));
    Reconstruction r = reconstruct(noisy_samples(plate, 20000));
    assert_int_equal(r.status, GMPU_OK);
    const MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    const SurfaceComparison c = compare_surfaces(r.mesh, plate, {20000, 1, {0.005, 0.01}, 0});
    // Closed as one sheet, the surface bulges to a tenth of the plate's length on one side
    // (F at 1 % about 0.4).
    print_message("plate: F at 1 %% %.3f, thickness %.3f\n", c.fscores[1].fscore, bounding_box(r.mesh).sizes().z());
    assert_true(c.fscores[1].fscore >= 0.9);
    assert_true(bounding_box(r.mesh).sizes().z() < 0.1);
}

void noisy_sphere_stays_solid(void **) {
    const TriangleMesh sphere = icosphere(4, 0.5);
    Reconstruction r = reconstruct(noisy_samples(sphere, 20000));
    assert_int_equal(r.status, GMPU_OK);
    // Split as a sheet, the centre would fall outside the slab.
    const std::vector<double> f = r.evaluate({Vec3::Zero()});
    assert_int_equal(f.size(), 1);
    assert_true(f[0] > 0.0);
    const SurfaceComparison c = compare_surfaces(r.mesh, sphere, {20000, 1, {0.005, 0.01}, 0});
    print_message("sphere: F at 1 %% %.3f\n", c.fscores[1].fscore);
    assert_true(c.fscores[1].fscore >= 0.9);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(noisy_thin_plate_becomes_a_slab),
        cmocka_unit_test(noisy_sphere_stays_solid),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
