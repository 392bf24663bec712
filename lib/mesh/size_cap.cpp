#include "mesh/size_cap.hpp"

#include "mesh/simplify.hpp"

namespace gmpu {

namespace {
// Aim a little under the budget, so the count stays under it whatever the last round of
// collapses does.
constexpr double kAim = 0.99;
}  // namespace

void cap_mesh_size(Mesh &mesh, size_t points, double max_error, Workers &workers, Progress &progress) {
    const double budget = kTrianglesPerPoint * double(points);
    if (double(mesh.triangle_count()) <= budget || max_error <= 0.0) return;
    progress.throw_if_cancelled();
    Mesh smaller = simplify_mesh(mesh, size_t(kAim * budget), max_error, nullptr, true, &workers, &progress);
    if (smaller.triangle_count() > 0 && smaller.triangle_count() < mesh.triangle_count()) mesh = std::move(smaller);
    progress.poll(1.0);
}

}  // namespace gmpu
