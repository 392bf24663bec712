// Marching cubes (marching_cubes.hpp) over blocks of a lattice that several independent runs
// share (the tiles of a distributed reconstruction): the caller gives every corner's value,
// so two runs that march neighbouring blocks with the same values on their shared face cut
// it identically, and each vertex is named by its global lattice edge so the pieces weld
// into one mesh whichever run made them.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"

namespace gmpu {

// A lattice of cubes of side `cell` from `origin`, `cells` cubes along each axis, cut in
// blocks of kGridBlock cubes a side.
struct GlobalGrid {
    static constexpr int kGridBlock = 8;
    double origin[3] = {0, 0, 0};
    double cell = 0.0;
    int64_t cells[3] = {0, 0, 0};

    // Lattice corner (x, y, z): the one formula every run uses, so shared corners and
    // edge vertices agree bit for bit.
    double coordinate(int axis, int64_t index) const { return origin[axis] + cell * double(index); }
    uint64_t corner_id(int64_t x, int64_t y, int64_t z) const {
        return uint64_t(x + (cells[0] + 1) * (y + (cells[1] + 1) * z));
    }
};

// The mesh of the zero set in the given blocks (3 block coordinates each), with
// `corner_values` per block the (kGridBlock + 1)³ values at its corners, x fastest
// (positive inside). Vertices are in the grid's frame, unwelded across blocks only where
// the blocks are not given together; `edge_keys` gets per vertex its lattice edge
// (corner id × 8 + axis direction).
Mesh march_grid_blocks(const GlobalGrid &grid, const int64_t *blocks, size_t block_count, const double *corner_values,
                       std::vector<uint64_t> &edge_keys);

}  // namespace gmpu
