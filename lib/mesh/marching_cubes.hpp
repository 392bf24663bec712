// Marching cubes with one ambiguity rule everywhere: on a face whose corners alternate in
// sign, the inside (f > 0) corners are joined and the outside ones kept apart. The rule
// reads the face's four signs only, so the two cubes sharing a face cut it the same way and
// the surface closes across cubes. In each cube the face segments join into loops, and each loop becomes a disk of
// triangles whose diagonals never run along a cube face (a face edge then belongs to the
// two cubes sharing the face and to no other): closed and edge-manifold wherever the grid's
// boundary has one sign, with no vertices on the cubes' diagonals.
#pragma once

#include <cstdint>

namespace gmpu::mc {

// Corner c of a cube is at offset (c & 1, c >> 1 & 1, c >> 2 & 1). An edge joins two
// corners, from the lower to the upper one; a cube's edges run along one axis each.
struct Edge {
    uint8_t from, to;
};

// Direction of an edge: to − from as the bit pattern zyx, minus one (0, 1 or 3 for x, y, z);
// with the lower corner's grid index it names a grid edge, the key vertices weld by.
inline int edge_direction(const Edge &e) { return (e.to ^ e.from) - 1; }

// The surface in one cube for a sign pattern (bit c set: corner c is inside, f > 0):
// triangles (three vertices as cube edges) and quads (loops of four, split along the
// diagonal the march chooses), wound counter-clockwise seen from outside.
struct CubeCase {
    static constexpr int kMaxTriangles = 10, kMaxQuads = 3;
    uint8_t triangle_count = 0, quad_count = 0;
    Edge triangles[kMaxTriangles][3];
    Edge quads[kMaxQuads][4];
};
const CubeCase &cube_case(int inside_mask);

// Marches the n³ cubes of a block whose corner values value(i, j, k) are given for i, j, k
// in 0..n (the one-process polygonizer and the tiles' march share it, so tiled and untiled
// meshes are cut alike): for each corner of each triangle, in order, emit(i, j, k, edge) names the cube and the cube edge its vertex lies on. A quad q is
// split along q[0]–q[2] when split_02(i, j, k, q) says so, else along q[1]–q[3]: the
// choice stays inside the cube, so neighbouring cubes (and tiles) need not agree on it.
template <class Value, class Emit, class Split>
void march_block(int n, const Value &value, Emit &&emit, Split &&split_02) {
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int mask = 0;
                for (int c = 0; c < 8; ++c)
                    if (value(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)) > 0) mask |= 1 << c;
                if (mask == 0 || mask == 255) continue;
                const CubeCase &cc = cube_case(mask);
                for (int t = 0; t < cc.triangle_count; ++t)
                    for (int v = 0; v < 3; ++v) emit(i, j, k, cc.triangles[t][v]);
                for (int q = 0; q < cc.quad_count; ++q) {
                    const Edge *c = cc.quads[q];
                    const int order[2][6] = {{0, 1, 2, 0, 2, 3}, {0, 1, 3, 1, 2, 3}};
                    for (int v : order[split_02(i, j, k, c) ? 0 : 1]) emit(i, j, k, c[v]);
                }
            }
}

}  // namespace gmpu::mc
