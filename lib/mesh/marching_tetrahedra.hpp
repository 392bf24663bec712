// Marching tetrahedra on the Kuhn (Freudenthal) split of each grid cube into six
// tetrahedra around the 000–111 diagonal. The split is the same in every cube, so
// neighbouring cubes cut shared faces along the same diagonals, and the isosurface of the
// piecewise-linear interpolant is a closed 2-manifold wherever the grid's boundary has one
// sign. The polygonizer now uses marching cubes (marching_cubes.hpp: a third of the
// triangles), which shares this file's Edge.
#pragma once

#include <cstdint>

namespace gmpu::mt {

// Corner c of a cube is at offset (c & 1, c >> 1 & 1, c >> 2 & 1).
constexpr int kTetrahedra = 6;
extern const uint8_t kTetCorners[kTetrahedra][4];

// An edge between two cube corners, from the lower to the upper one (Kuhn edges always
// go up in every coordinate): one of 7 directions.
struct Edge {
    uint8_t from, to;
};

// Triangles of one tetrahedron for a sign pattern (bit k set: corner k of the tet is
// inside, f > 0). Each triangle lists its three vertices as cube edges, wound
// counter-clockwise seen from outside.
struct TetCase {
    uint8_t triangle_count = 0;
    Edge triangles[2][3];
};
const TetCase &tet_case(int tet, int inside_mask);

// Direction index (0..6) of the edge from corner `from` to corner `to`: to − from as the
// bit pattern xyz, minus one.
inline int edge_direction(const Edge &e) { return (e.to ^ e.from) - 1; }

// Marches the n³ cubes of a block whose corner values value(i, j, k) are given for i, j, k in
// 0..n: for each corner of each triangle, in order, emit(i, j, k, edge) names the cube and
// the cube edge its vertex lies on. The one-process polygonizer and the tiles' march share
// it, so both cut the same triangles from the same values.
template <class Value, class Emit>
void march_block(int n, const Value &value, Emit &&emit) {
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int mask8 = 0;
                for (int c = 0; c < 8; ++c)
                    if (value(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)) > 0) mask8 |= 1 << c;
                if (mask8 == 0 || mask8 == 255) continue;
                for (int t = 0; t < kTetrahedra; ++t) {
                    int mask = 0;
                    for (int q = 0; q < 4; ++q)
                        if (mask8 >> kTetCorners[t][q] & 1) mask |= 1 << q;
                    const TetCase &tc = tet_case(t, mask);
                    for (int tri = 0; tri < tc.triangle_count; ++tri)
                        for (int v = 0; v < 3; ++v) emit(i, j, k, tc.triangles[tri][v]);
                }
            }
}

}  // namespace gmpu::mt
