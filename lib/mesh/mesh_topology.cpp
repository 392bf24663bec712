#include "mesh/mesh_topology.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/union_find.hpp"

namespace gmpu {

namespace {

// The directed edges of the triangles, grouped by their first vertex: a vertex's outgoing
// edges are few (about 6), so a lookup scans its group, and grouping is O(n) where one
// sort of all the edges was the cost of the check on large meshes.
struct OutgoingEdges {
    std::vector<uint32_t> begin;  // per vertex, into `to` and `triangle`; n + 1 entries
    std::vector<uint32_t> to, triangle;

    // Each group sorted by (to, triangle), like a sort of all (from, to, triangle).
    OutgoingEdges(size_t n, const std::vector<uint32_t> &tri) : begin(n + 1, 0) {
        auto skip = [&](size_t f) {
            const uint32_t a = tri[3 * f], b = tri[3 * f + 1], c = tri[3 * f + 2];
            return a == b || b == c || c == a;
        };
        for (size_t f = 0; f < tri.size() / 3; ++f)
            if (!skip(f))
                for (int k = 0; k < 3; ++k) ++begin[tri[3 * f + k] + 1];
        for (size_t v = 0; v < n; ++v) begin[v + 1] += begin[v];
        to.resize(begin[n]);
        triangle.resize(begin[n]);
        std::vector<uint32_t> fill(begin.begin(), begin.end() - 1);
        for (size_t f = 0; f < tri.size() / 3; ++f) {  // triangles ascending: each group stays sorted by triangle
            if (skip(f)) continue;
            for (int k = 0; k < 3; ++k) {
                const uint32_t from = tri[3 * f + k], at = fill[from]++;
                to[at] = tri[3 * f + (k + 1) % 3];
                triangle[at] = uint32_t(f);
            }
        }
        std::vector<std::pair<uint32_t, uint32_t>> group;
        for (size_t v = 0; v < n; ++v) {
            group.clear();
            for (uint32_t e = begin[v]; e < begin[v + 1]; ++e) group.push_back({to[e], triangle[e]});
            std::sort(group.begin(), group.end());
            for (uint32_t e = begin[v]; e < begin[v + 1]; ++e) to[e] = group[e - begin[v]].first, triangle[e] = group[e - begin[v]].second;
        }
    }
    // How many triangles hold from→to.
    size_t count(uint32_t from, uint32_t to_vertex) const {
        size_t k = 0;
        for (uint32_t e = begin[from]; e < begin[from + 1]; ++e) k += to[e] == to_vertex;
        return k;
    }
    // The first (lowest) triangle holding from→to.
    bool first(uint32_t from, uint32_t to_vertex, uint32_t &f) const {
        for (uint32_t e = begin[from]; e < begin[from + 1]; ++e)
            if (to[e] == to_vertex) return f = triangle[e], true;
        return false;
    }
};

}  // namespace

MeshTopology mesh_topology(const Mesh &mesh, std::vector<uint32_t> *culprits) {
    MeshTopology t;
    const size_t n = mesh.vertex_count();
    const std::vector<uint32_t> &tri = mesh.triangles;
    UnionFind pieces(n);
    std::vector<uint32_t> incident(n, 0);
    size_t faces = 0;
    for (size_t f = 0; f < tri.size() / 3; ++f) {
        const uint32_t a = tri[3 * f], b = tri[3 * f + 1], c = tri[3 * f + 2];
        if (a == b || b == c || c == a) {
            ++t.degenerate_triangles;
            continue;
        }
        ++faces;
        for (uint32_t v : {a, b, c}) ++incident[v];
        for (uint32_t v : {b, c}) pieces.join(a, v);
    }
    const OutgoingEdges edges(n, tri);
    // A triangle duplicates an earlier one on the same three vertices: that one holds the
    // edge a→b (same winding) or b→a (opposite), with c as its third vertex.
    for (size_t f = 0; f < tri.size() / 3; ++f) {
        const uint32_t a = tri[3 * f], b = tri[3 * f + 1], c = tri[3 * f + 2];
        if (a == b || b == c || c == a) continue;
        auto duplicates = [&](uint32_t from, uint32_t to) {
            for (uint32_t e = edges.begin[from]; e < edges.begin[from + 1]; ++e) {
                const uint32_t g = edges.triangle[e];
                if (edges.to[e] != to || g >= f) continue;
                const uint64_t third = uint64_t(tri[3 * g]) + tri[3 * g + 1] + tri[3 * g + 2] - from - to;
                if (third == c) return true;
            }
            return false;
        };
        t.duplicate_triangles += duplicates(a, b) || duplicates(b, a);
    }
    // Undirected edges: each counted once, from its smaller end (or from its only direction).
    size_t undirected = 0;
    for (uint32_t a = 0; a < n; ++a)
        for (uint32_t i = edges.begin[a]; i < edges.begin[a + 1];) {
            uint32_t j = i;
            while (j < edges.begin[a + 1] && edges.to[j] == edges.to[i]) ++j;
            const uint32_t b = edges.to[i];
            const size_t forward = j - i, backward = edges.count(b, a);
            if (a < b || backward == 0) {
                ++undirected;
                if (forward + backward == 1) ++t.boundary_edges;
                else if (forward != 1 || backward != 1) {
                    ++t.nonmanifold_edges;
                    if (culprits) culprits->insert(culprits->end(), {a, b});
                }
            }
            i = j;
        }
    // A vertex is manifold when walking across its edges from one of its triangles reaches
    // all of them: one fan (closed, or open at two boundary edges).
    std::vector<uint32_t> first(n, UINT32_MAX);
    for (size_t f = 0; f < tri.size() / 3; ++f)
        for (int k = 0; k < 3; ++k)
            if (first[tri[3 * f + k]] == UINT32_MAX) first[tri[3 * f + k]] = uint32_t(f);
    auto corner_of = [&](uint32_t f, uint32_t v) {
        for (int k = 0; k < 3; ++k)
            if (tri[3 * f + k] == v) return k;
        return -1;
    };
    size_t used = 0;
    if (t.nonmanifold_edges == 0 && t.degenerate_triangles == 0) {
        for (uint32_t v = 0; v < n; ++v) {
            if (incident[v] == 0) continue;
            const uint32_t start = first[v];
            size_t seen = 1;
            // Around v one way: the triangle across v's outgoing edge v→x holds x→v.
            uint32_t f = start;
            bool closed = false;
            for (;;) {
                const int k = corner_of(f, v);
                const uint32_t x = tri[3 * f + (k + 1) % 3];
                uint32_t g;
                if (!edges.first(x, v, g)) break;
                if (g == start) { closed = true; break; }
                if (++seen > incident[v]) break;
                f = g;
            }
            if (!closed) {  // and the other way, across the incoming edge y→v
                f = start;
                for (;;) {
                    const int k = corner_of(f, v);
                    const uint32_t y = tri[3 * f + (k + 2) % 3];
                    uint32_t g;
                    if (!edges.first(v, y, g) || g == start) break;
                    if (++seen > incident[v]) break;
                    f = g;
                }
            }
            if (seen != incident[v]) {
                ++t.nonmanifold_vertices;
                if (culprits) culprits->push_back(v);
            }
        }
    }
    std::vector<char> root_seen(n, 0);
    for (uint32_t v = 0; v < n; ++v) {
        if (incident[v] == 0) continue;
        ++used;
        const uint32_t r = pieces.find(v);
        if (!root_seen[r]) root_seen[r] = 1, ++t.components;
    }
    t.euler_characteristic = long(used) - long(undirected) + long(faces);
    return t;
}

}  // namespace gmpu
