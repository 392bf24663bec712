// What the C ABI's opaque handles really are. Only lib/api sees these definitions.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/io.hpp"
#include "mesh/mesh.hpp"

struct gmpu_mesh {
    gmpu::Mesh mesh;
    std::vector<uint64_t> grid_keys;  // per vertex for gmpu_grid_polygonize's meshes, else empty
};

struct gmpu_points {
    gmpu::io::PointCloud cloud;
};
