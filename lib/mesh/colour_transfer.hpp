// Per-vertex colours for a mesh from a coloured point cloud: each vertex takes the colour of
// the input point nearest to it (the points the surface was reconstructed from, so the
// nearest one is the sample that vertex stands for).
#pragma once

#include <cstddef>
#include <cstdint>

#include "mesh/mesh.hpp"

namespace gmpu {

// Sets mesh.colors (3 per vertex) from count points xyz (3 doubles each) and their colours
// (3 bytes each). count must be at least 1.
void transfer_colours(Mesh &mesh, const double *xyz, const uint8_t *colours, size_t count);

}  // namespace gmpu
