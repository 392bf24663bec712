// Shared by the pipeline tests: one reconstruction through the public C ABI, with the
// outputs as test-support types.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "gmpu/gmpu.h"
#include "triangle_mesh.hpp"

namespace gmpu::testing {

struct Reconstruction {
    gmpu_status status = GMPU_OK;
    std::string error;             // gmpu_last_error() of the failing call
    TriangleMesh mesh;
    std::vector<Vec3> mesh_normals;  // per mesh vertex
    std::vector<Vec3> normals;     // oriented normal per input point
    gmpu_surface *surface = nullptr;  // kept alive for evaluate(); freed by the destructor

    Reconstruction() = default;
    Reconstruction(const Reconstruction &) = delete;
    Reconstruction &operator=(const Reconstruction &) = delete;
    Reconstruction(Reconstruction &&o) noexcept { *this = std::move(o); }
    Reconstruction &operator=(Reconstruction &&o) noexcept {
        std::swap(status, o.status);
        std::swap(error, o.error);
        std::swap(mesh, o.mesh);
        std::swap(mesh_normals, o.mesh_normals);
        std::swap(normals, o.normals);
        std::swap(surface, o.surface);
        return *this;
    }
    ~Reconstruction() { gmpu_surface_destroy(surface); }

    // f at points (caller units); empty on failure.
    std::vector<double> evaluate(const std::vector<Vec3> &at, std::vector<Vec3> *gradients = nullptr) const;
    double stat(gmpu_stat key) const;
};

// set_points → [set_normals] → fit → orient → polygonize, with (key, value) parameters.
Reconstruction reconstruct(const std::vector<Vec3> &points,
                           const std::vector<std::pair<gmpu_param, double>> &params = {},
                           const std::vector<Vec3> *input_normals = nullptr);

// $GMPU_TEST_DATA (set by meson) or tests/data from the source root.
std::string test_data(const std::string &relative);

}  // namespace gmpu::testing
