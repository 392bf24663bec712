// Meshes and point clouds on disk, through gmpu's own readers and writers (lib/io), so
// the benchmark reads exactly what gmpu and the peers wrote.
#pragma once

#include "triangle_mesh.hpp"

#include <string>

namespace gmpu::testing {

// .off, .obj or .ply; throws gmpu::Error (IO, PARSE, UNSUPPORTED) naming the file.
TriangleMesh load_mesh(const std::string &path);

// Any cloud gmpu reads; normals is empty when the file has none.
OrientedPoints load_points(const std::string &path);

// .ply (binary) or .xyz; normals are written when `with_normals` and present.
void save_points(const std::string &path, const OrientedPoints &points, bool with_normals);

}  // namespace gmpu::testing
