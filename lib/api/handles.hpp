// What the C ABI's opaque handles really are. Only lib/api sees these definitions.
#pragma once

#include <string>
#include <vector>

#include "io/io.hpp"
#include "mesh/mesh.hpp"

struct gmpu_mesh {
    gmpu::Mesh mesh;
};

struct gmpu_points {
    gmpu::io::PointCloud cloud;
};
