// A sparse noisy cloud is solved a second time from the smooth field's own normals
// (pipeline/smooth_surface.cpp, kSmoothFromNoise for clouds under kGuideBelowPoints). At
// 1,000 points the orientation leaves a few percent of the normals wrong, in patches, and
// the first field, pulled by them, filled the space between the dinosaur's legs where no
// point lies: a mesh enclosing far more than the truth's volume and far from it in places.
// Solved again from the field's own normals at the points, which agree with their
// neighbours and outvote the patches, the legs stand apart. (This draw, 0.5 % noise: 1.68
// of the truth's volume and precision at 1 % 0.54 from the first field alone.)
#include <cmath>
#include <vector>

#include "files.hpp"
#include "mesh_checks.hpp"
#include "metrics.hpp"
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

void sparse_noisy_dinosaur_keeps_its_legs_apart(void **) {
    const TriangleMesh dino = load_mesh(test_data("corpus/meshes/dino.off"));
    const uint64_t seed = 3;
    MeshSamples s = sample_mesh(dino, 1000, seed);
    add_gaussian_noise(s.positions, 0.005 * bbox_diagonal(dino), seed + 1);
    Reconstruction r = reconstruct(s.positions);
    assert_int_equal(r.status, GMPU_OK);
    const MeshCheck check = check_mesh(r.mesh);
    assert_true(check.watertight);
    const SurfaceComparison c = compare_surfaces(r.mesh, dino, {20000, 1, {0.01}, 0});
    const double volume = check.signed_volume / std::fabs(check_mesh(dino).signed_volume);
    print_message("sparse noisy dinosaur: %.2f of the truth's volume, precision at 1 %% %.3f, F %.3f\n", volume,
                  c.fscores[0].precision, c.fscores[0].fscore);
    assert_true(volume < 1.3);
    assert_true(c.fscores[0].precision > 0.65);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sparse_noisy_dinosaur_keeps_its_legs_apart),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
