// Removing whole closed components keeps a watertight mesh watertight: the clean-up the
// polygonizer does.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// Connected component (by shared vertices) of every vertex; returns the count. Both run on
// the calling thread over the whole mesh, so they tick progress every few thousand items.
uint32_t vertex_components(const Mesh &mesh, std::vector<uint32_t> &component, Progress &progress);

// Drops every connected component whose vertices received fewer than `min_votes` votes
// in total (votes: one count per vertex), and compacts the vertex arrays.
void remove_unsupported_components(Mesh &mesh, const std::vector<uint32_t> &votes, uint32_t min_votes,
                                   Progress &progress);

// Drops every connected component that fits in an axis-aligned cube of side `min_side`
// (its bounding box's longest side is shorter), except the one with the most vertices (a
// mesh is never emptied), and compacts the vertex arrays.
void remove_components_smaller_than(Mesh &mesh, double min_side, Progress &progress);

}  // namespace gmpu
