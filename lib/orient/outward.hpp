// The global sign of each connected piece. Belief propagation makes a piece consistent but
// cannot tell inside from outside; that is geometry: with f positive inside, the outward
// normals n = −∇f/|∇f| of a closed surface enclose a positive volume (1/3)∮ x·n dA. A piece
// nested inside an odd number of others bounds a cavity, so its normals must point into
// the volume it encloses (a shell inside a shell is a hollow solid). Nesting is found with
// the winding number of the other pieces' oriented samples.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "model/octree.hpp"
#include "geometry/point_set.hpp"
#include "orient/leaf_graph.hpp"

namespace gmpu {

// Flips every leaf of a component whose sign is inward. Leaf signs must already be
// consistent within components. Returns the number of leaves flipped. Reports progress
// between 0.8 and 0.85 and throws CANCELLED.
size_t make_components_outward(const Octree &tree, CellSigns &signs, const PointSet &points, const LeafGraph &graph,
                               const std::vector<uint32_t> &component, uint32_t component_count,
                               Progress &progress);

}  // namespace gmpu
