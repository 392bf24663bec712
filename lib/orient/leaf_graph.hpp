// The graph of paper §4.1: one node per leaf cell, an edge between leaves that share a face
// (the paper's "4-connected" neighbours: two cells sharing four corners; across a change of
// level, the smaller cell's face). Each edge carries J_ij = Σ_k sign(Q_i(x_k) Q_j(x_k)) over
// the corners x_k of the shared face (at a corner that lies on either fit's zero set, the
// sign of ∇Q_i · ∇Q_j instead), so the smoothness energy of eq. (5) is
// E_s(ℓ_i, ℓ_j) = −ℓ_i ℓ_j J_ij.
#pragma once

#include <cstdint>
#include <vector>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "model/octree.hpp"

namespace gmpu {

struct LeafGraph {
    std::vector<uint32_t> cell_of;       // node → cell index
    std::vector<uint32_t> offsets;       // CSR: node i's edges are [offsets[i], offsets[i+1])
    std::vector<uint32_t> neighbour;
    std::vector<int8_t> agreement;       // J_ij ∈ [−4, 4]

    size_t size() const { return cell_of.size(); }
    size_t degree(uint32_t i) const { return offsets[i + 1] - offsets[i]; }
};

LeafGraph build_leaf_graph(const Octree &tree, Workers &workers, Progress &progress);

// Connected components of the graph: component id per node, and their count.
std::vector<uint32_t> connected_components(const LeafGraph &graph, uint32_t &count);

}  // namespace gmpu
