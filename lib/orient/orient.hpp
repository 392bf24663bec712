// Orient stage: a sign for every cell's local function (kept beside the fitted tree, which
// it does not change), so that the blend is one consistent field, positive inside. Without input normals: leaf graph → belief
// propagation advanced as a front per component → each component made outward. With
// input normals: each leaf takes the sign its points' normals vote for. Either way the
// inner cells (used by the level-of-detail cap and far-field fallback) then follow their
// oriented children.
#pragma once

#include <cstdint>
#include <vector>

#include "core/parallel.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "model/octree.hpp"
#include "geometry/point_set.hpp"
#include "orient/advancing_front.hpp"

namespace gmpu {

struct OrientStats {
    uint32_t components = 0;
    uint32_t flipped_leaves = 0;
};

struct Orientation {
    CellSigns signs;  // one per cell of the tree
    OrientStats stats;
};

// The fitted tree's signs. normals: 3 per point (normalised frame directions) or null.
// `front` is for measurements only (advancing_front.hpp); the C ABI always passes the defaults.
Orientation orient_octree(const Octree &tree, const PointSet &points, const float *normals, Workers &workers,
                          Progress &progress, const FrontOptions &front = {});

// Inner cells follow their oriented children: each takes the sign that makes its gradient
// agree with theirs at the children's points. After any change to the leaves' signs.
void sign_inner_cells(const Octree &tree, const PointSet &points, CellSigns &signs, Progress &progress);

// How many leaves have their fit's sign turned (OrientStats::flipped_leaves).
uint32_t flipped_leaves(const Octree &tree, const CellSigns &signs);

}  // namespace gmpu
