// The blend guided by the smooth field (implicit/guided_blend.hpp): on a sparse cloud the
// blend alone carries a thin part's surface on past its last points; held to the smooth
// field, the surface ends with the data, and the automatic choice takes that surface there.
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

// elephant_sparse5k: 5,000 noise-free points of a shape with a trunk, a tail and legs a few
// sample spacings across.
void guided_blend_ends_thin_parts_with_the_data(void **) {
    const std::vector<Vec3> points = load_points(test_data("clouds/elephant_sparse5k.ply")).positions;
    const TriangleMesh truth = load_mesh(test_data("meshes/elephant.off"));
    const ComparisonOptions options{30000, 1, {0.005, 0.01}, 0};
    Reconstruction blend = reconstruct(points, {{GMPU_PARAM_SURFACE, 0}});
    Reconstruction guided = reconstruct(points, {{GMPU_PARAM_SURFACE, 3}});
    assert_int_equal(blend.status, GMPU_OK);
    assert_int_equal(guided.status, GMPU_OK);
    const SurfaceComparison b = compare_surfaces(blend.mesh, truth, options);
    const SurfaceComparison g = compare_surfaces(guided.mesh, truth, options);
    print_message("blend: precision at 1 %% %.4f, F at 0.5 %% %.4f; guided: %.4f, %.4f\n", b.fscores[1].precision,
                  b.fscores[0].fscore, g.fscores[1].precision, g.fscores[0].fscore);
    // The blend's strays lie over 1 % of the diagonal from the truth; guided, none does.
    assert_true(b.fscores[1].precision < 0.999);
    assert_true(g.fscores[1].precision > 0.9995);
    assert_true(g.fscores[0].fscore >= b.fscores[0].fscore);
    const MeshCheck check = check_mesh(guided.mesh);
    assert_true(check.watertight);
    assert_int_equal(check.components, 1);
    // The default (automatic) surface on this noise-free 5k cloud is the guided one.
    Reconstruction automatic = reconstruct(points);
    assert_int_equal(automatic.status, GMPU_OK);
    assert_true(automatic.mesh.vertices == guided.mesh.vertices);
    assert_true(automatic.mesh.triangles == guided.mesh.triangles);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(guided_blend_ends_thin_parts_with_the_data),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
