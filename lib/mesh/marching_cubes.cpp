#include "mesh/marching_cubes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace gmpu::mc {

namespace {

constexpr int kEdges = 12;

struct CubeEdges {
    Edge edge[kEdges];
    int index[8][8];  // edge index between two corners, -1 if none
    CubeEdges() {
        for (auto &row : index)
            for (int &e : row) e = -1;
        int n = 0;
        for (int d = 0; d < 3; ++d)
            for (int c = 0; c < 8; ++c)
                if (!(c >> d & 1)) {
                    edge[n] = Edge{uint8_t(c), uint8_t(c | 1 << d)};
                    index[c][c | 1 << d] = index[c | 1 << d][c] = n++;
                }
    }
};

// Whether two cube edges lie in one face: a triangle edge between them would run along it.
bool share_face(const Edge &a, const Edge &b) {
    for (int d = 0; d < 3; ++d)
        for (int s = 0; s < 2; ++s)
            if ((a.from >> d & 1) == s && (a.to >> d & 1) == s && (b.from >> d & 1) == s && (b.to >> d & 1) == s)
                return true;
    return false;
}

double distance(const Edge &a, const Edge &b) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        const double pa = 0.5 * ((a.from >> k & 1) + (a.to >> k & 1)), pb = 0.5 * ((b.from >> k & 1) + (b.to >> k & 1));
        d2 += (pa - pb) * (pa - pb);
    }
    return std::sqrt(d2);
}

struct Table {
    CubeEdges edges;
    CubeCase cases[256];
    Table() {
        for (int mask = 0; mask < 256; ++mask) build(mask);
    }

    void build(int mask) {
        // The face segments, traced around the outside (f ≤ 0) corners: each runs from the
        // crossing where the face's cycle (counter-clockwise seen from outside the cube)
        // enters an outside corner to the next crossing where it leaves. That pairs each
        // outside corner of an alternating face with its own two crossings, so the face's two
        // inside corners stay joined: a solid part thinner than a cube, whose inside corners
        // touch only across faces' diagonals, stays one piece. The loops so traced run
        // clockwise seen from the inside, and are reversed.
        int next[kEdges];
        for (int &e : next) e = -1;
        for (int d = 0; d < 3; ++d)
            for (int s = 0; s < 2; ++s) {
                const int u = (d + 1) % 3, v = (d + 2) % 3;
                int q[4] = {0, 1 << u, 1 << u | 1 << v, 1 << v};  // counter-clockwise seen from +d
                if (s == 0) std::swap(q[1], q[3]);
                for (int &c : q) c |= s << d;
                auto out = [&](int i) { return !(mask >> q[i & 3] & 1); };
                for (int i = 0; i < 4; ++i) {
                    if (out(i) || !out(i + 1)) continue;  // not an entry
                    int j = i + 1;
                    while (!(out(j) && !out(j + 1))) ++j;  // the next exit
                    next[edges.index[q[i]][q[(i + 1) & 3]]] = edges.index[q[j & 3]][q[(j + 1) & 3]];
                }
            }
        CubeCase &cc = cases[mask];
        bool used[kEdges] = {};
        for (int start = 0; start < kEdges; ++start) {
            if (next[start] < 0 || used[start]) continue;
            std::vector<Edge> loop;
            for (int e = start; !used[e]; e = next[e]) used[e] = true, loop.push_back(edges.edge[e]);
            std::reverse(loop.begin(), loop.end());
            // A quad's two diagonals both cross the cube's inside (its opposite vertices
            // never share a face): the march picks one.
            if (loop.size() == 4 && !share_face(loop[0], loop[2]) && !share_face(loop[1], loop[3]) &&
                cc.quad_count < CubeCase::kMaxQuads)
                std::copy(loop.begin(), loop.end(), cc.quads[cc.quad_count++]);
            else
                triangulate(loop, cc);
        }
    }

    // The loop as a disk: the triangulation with the shortest diagonals among those whose
    // diagonals all cross the cube's inside (never along a face).
    static void triangulate(const std::vector<Edge> &p, CubeCase &cc) {
        const int n = int(p.size());
        auto allowed = [&](int i, int j) { return j - i == 1 || (i == 0 && j == n - 1) || !share_face(p[i], p[j]); };
        std::vector<double> cost(n * n, INFINITY);
        std::vector<int> split(n * n, -1);
        for (int i = 0; i + 1 < n; ++i) cost[i * n + i + 1] = 0.0;
        for (int span = 2; span < n; ++span)
            for (int i = 0; i + span < n; ++i) {
                const int j = i + span;
                for (int k = i + 1; k < j; ++k) {
                    if (!allowed(i, k) || !allowed(k, j)) continue;
                    const double c = cost[i * n + k] + cost[k * n + j] + (k - i > 1 ? distance(p[i], p[k]) : 0.0) +
                                     (j - k > 1 ? distance(p[k], p[j]) : 0.0);
                    if (c < cost[i * n + j]) cost[i * n + j] = c, split[i * n + j] = k;
                }
            }
        if (!std::isfinite(cost[n - 1])) throw std::logic_error("marching cubes: a loop without a face-free triangulation");
        std::vector<std::pair<int, int>> todo = {{0, n - 1}};
        while (!todo.empty()) {
            const auto [i, j] = todo.back();
            todo.pop_back();
            if (j - i < 2) continue;
            const int k = split[i * n + j];
            if (cc.triangle_count >= CubeCase::kMaxTriangles) throw std::logic_error("marching cubes: too many triangles");
            Edge *t = cc.triangles[cc.triangle_count++];
            t[0] = p[i], t[1] = p[k], t[2] = p[j];
            todo.push_back({i, k});
            todo.push_back({k, j});
        }
    }
};

}  // namespace

const CubeCase &cube_case(int inside_mask) {
    static const Table table;
    return table.cases[inside_mask];
}

}  // namespace gmpu::mc
