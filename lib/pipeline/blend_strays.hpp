// Whether the MPU blend strays from the data: the test behind the automatic surface's
// guided blend on dense, noise-free clouds (pipeline/smooth_surface.hpp).
//
// Where the points of a dense cloud thin out (the sparse end of a nonuniform scan, a foot,
// a tail) the blend's local quadrics carry on past them: a lump where a thin part ends, a
// bridge or handle where two parts nearly touch, a small closed piece inside another part.
// Most clouds have none, and there the guided blend's smooth solve would cost several times
// the rest of the run for nothing. So orient polygonizes the blend first and measures the
// share of the mesh's area that lies far from every input point, in units of the local
// sample spacing (mesh/confidence.hpp). Where the blend stays the surface, polygonize hands
// that mesh out with its confidence (pipeline/reconstruction.hpp), so the test adds one pass
// over the triangles. The
// caps over an open scan's holes lie as far out: there the smooth field is solved too, and
// makes about the same caps.
#pragma once

#include "mesh/mesh.hpp"

namespace gmpu {

// The share of the area of `mesh` (with its confidence) that lies over kStrayConfidence
// local sample spacings from every input point.
double stray_share(const Mesh &mesh);

// Whether that share says the blend strays.
bool blend_strays(double share);

}  // namespace gmpu
