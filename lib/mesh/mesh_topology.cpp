#include "mesh/mesh_topology.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <vector>

namespace gmpu {

namespace {

uint32_t find(std::vector<uint32_t> &parent, uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
}

struct DirectedEdge {
    uint32_t from, to, triangle;
    bool operator<(const DirectedEdge &o) const {
        return from != o.from ? from < o.from : to != o.to ? to < o.to : triangle < o.triangle;
    }
};

}  // namespace

MeshTopology mesh_topology(const Mesh &mesh, std::vector<uint32_t> *culprits) {
    MeshTopology t;
    const size_t n = mesh.vertex_count();
    const std::vector<uint32_t> &tri = mesh.triangles;
    std::vector<DirectedEdge> edges;
    edges.reserve(tri.size());
    std::vector<uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
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
        edges.push_back({a, b, uint32_t(f)});
        edges.push_back({b, c, uint32_t(f)});
        edges.push_back({c, a, uint32_t(f)});
        for (uint32_t v : {b, c}) {
            uint32_t ra = find(parent, a), rv = find(parent, v);
            if (ra != rv) parent[std::max(ra, rv)] = std::min(ra, rv);
        }
    }
    std::sort(edges.begin(), edges.end());
    {
        std::vector<std::array<uint32_t, 3>> sorted;
        sorted.reserve(faces);
        for (size_t f = 0; f < tri.size() / 3; ++f) {
            std::array<uint32_t, 3> k{tri[3 * f], tri[3 * f + 1], tri[3 * f + 2]};
            if (k[0] == k[1] || k[1] == k[2] || k[2] == k[0]) continue;
            std::sort(k.begin(), k.end());
            sorted.push_back(k);
        }
        std::sort(sorted.begin(), sorted.end());
        for (size_t i = 1; i < sorted.size(); ++i) t.duplicate_triangles += sorted[i] == sorted[i - 1];
    }
    auto twin_count = [&](uint32_t from, uint32_t to) {
        auto lo = std::lower_bound(edges.begin(), edges.end(), DirectedEdge{from, to, 0});
        size_t k = 0;
        while (lo != edges.end() && lo->from == from && lo->to == to) ++lo, ++k;
        return k;
    };
    // Undirected edges: each counted once, from its smaller end (or from its only direction).
    size_t undirected = 0;
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && edges[j].from == edges[i].from && edges[j].to == edges[i].to) ++j;
        const uint32_t a = edges[i].from, b = edges[i].to;
        const size_t forward = j - i, backward = twin_count(b, a);
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
    auto only_triangle = [&](uint32_t from, uint32_t to, uint32_t &f) {
        auto lo = std::lower_bound(edges.begin(), edges.end(), DirectedEdge{from, to, 0});
        if (lo == edges.end() || lo->from != from || lo->to != to) return false;
        f = lo->triangle;
        return true;
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
                if (!only_triangle(x, v, g)) break;
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
                    if (!only_triangle(v, y, g) || g == start) break;
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
        const uint32_t r = find(parent, v);
        if (!root_seen[r]) root_seen[r] = 1, ++t.components;
    }
    t.euler_characteristic = long(used) - long(undirected) + long(faces);
    return t;
}

}  // namespace gmpu
