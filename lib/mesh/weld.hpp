// The polygonizer's last step over its blocks: one mesh vertex per grid edge, whichever
// blocks made it, so the blocks' pieces join into one watertight mesh.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "mesh/mesh.hpp"

namespace gmpu {

// What marching cubes made in one block.
struct BlockOutput {
    std::vector<uint64_t> vertex_key;         // grid edge per vertex: corner id × 8 + direction
    std::vector<Eigen::Vector3d> vertex_pos;  // normalised frame
    std::vector<Eigen::Vector3d> vertex_grad;
    std::vector<uint32_t> triangles;          // block-local vertex indices
    std::vector<uint32_t> votes;              // per vertex: input points in the block nearest to it
};

// One vertex per grid edge across blocks: sort every block's vertices by edge key.
// `votes` receives the point votes per welded vertex.
Mesh weld(std::vector<BlockOutput> &blocks, const Normalisation &norm, Progress &progress,
          std::vector<uint32_t> &votes);

}  // namespace gmpu
