#include "mesh/marching_tetrahedra.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gmpu::mt {

// Paths 000 → e_i → e_i + e_j → 111 for the six axis orders.
const uint8_t kTetCorners[kTetrahedra][4] = {
    {0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7},
};

namespace {

Eigen::Vector3d corner_position(int c) { return {double(c & 1), double(c >> 1 & 1), double(c >> 2 & 1)}; }

Edge make_edge(int a, int b) {
    // Corners on a Kuhn path are ordered: the lower one has a subset of the bits.
    return (a & b) == a ? Edge{uint8_t(a), uint8_t(b)} : Edge{uint8_t(b), uint8_t(a)};
}

Eigen::Vector3d midpoint(const Edge &e) { return 0.5 * (corner_position(e.from) + corner_position(e.to)); }

// Winds the triangle so its normal points from the inside corners to the outside ones.
void orient(Edge (&t)[3], const Eigen::Vector3d &outward) {
    Eigen::Vector3d n = (midpoint(t[1]) - midpoint(t[0])).cross(midpoint(t[2]) - midpoint(t[0]));
    if (n.dot(outward) < 0) std::swap(t[1], t[2]);
}

struct Table {
    TetCase cases[kTetrahedra][16];
    Table() {
        for (int t = 0; t < kTetrahedra; ++t)
            for (int mask = 0; mask < 16; ++mask) build(t, mask);
    }
    void build(int t, int mask) {
        TetCase &tc = cases[t][mask];
        int in[4], out[4], ni = 0, no = 0;
        Eigen::Vector3d cin = Eigen::Vector3d::Zero(), cout = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) {
            int c = kTetCorners[t][k];
            if (mask >> k & 1) in[ni++] = c, cin += corner_position(c);
            else out[no++] = c, cout += corner_position(c);
        }
        if (ni == 0 || no == 0) return;
        Eigen::Vector3d outward = cout / no - cin / ni;
        if (ni == 1 || no == 1) {
            // One corner alone: a triangle across its three edges.
            int lone = ni == 1 ? in[0] : out[0];
            const int *others = ni == 1 ? out : in;
            tc.triangle_count = 1;
            for (int k = 0; k < 3; ++k) tc.triangles[0][k] = make_edge(lone, others[k]);
            orient(tc.triangles[0], outward);
        } else {
            // Two and two: the quad a–c, a–d, b–d, b–c split along its interior diagonal.
            int a = in[0], b = in[1], c = out[0], d = out[1];
            Edge q[4] = {make_edge(a, c), make_edge(a, d), make_edge(b, d), make_edge(b, c)};
            tc.triangle_count = 2;
            tc.triangles[0][0] = q[0], tc.triangles[0][1] = q[1], tc.triangles[0][2] = q[2];
            tc.triangles[1][0] = q[0], tc.triangles[1][1] = q[2], tc.triangles[1][2] = q[3];
            orient(tc.triangles[0], outward);
            orient(tc.triangles[1], outward);
        }
    }
};

}  // namespace

const TetCase &tet_case(int tet, int inside_mask) {
    static const Table table;
    return table.cases[tet][inside_mask];
}

}  // namespace gmpu::mt
