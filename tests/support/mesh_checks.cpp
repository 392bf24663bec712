#include "mesh_checks.hpp"

#include <algorithm>
#include <numeric>
#include <utility>

namespace gmpu::testing {

namespace {

class UnionFind {
public:
    explicit UnionFind(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
    uint32_t find(uint32_t x) {
        while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];  // path halving
        return x;
    }
    void unite(uint32_t a, uint32_t b) { parent_[find(a)] = find(b); }

private:
    std::vector<uint32_t> parent_;
};

// One triangle's use of an undirected edge; corners are numbered 3·triangle + slot.
struct EdgeUse {
    uint64_t key;        // lower vertex << 32 | higher vertex
    uint32_t low_corner;  // the corner at the lower vertex
    uint32_t high_corner;
    bool forward;        // the triangle walks it from the lower vertex to the higher
};

}  // namespace

MeshCheck check_mesh(const TriangleMesh &mesh) {
    MeshCheck r;
    r.vertices = mesh.vertices.size();
    r.triangles = mesh.triangles.size();
    const size_t nt = mesh.triangles.size();

    std::vector<bool> valid(nt);  // three distinct vertices
    size_t valid_count = 0;
    std::vector<Triangle> sorted_triangles;
    for (size_t t = 0; t < nt; ++t) {
        Triangle s = mesh.triangles[t];
        std::sort(s.begin(), s.end());
        valid[t] = s[0] != s[1] && s[1] != s[2];
        valid_count += valid[t];
        if (!valid[t] || !(triangle_cross(mesh, t).squaredNorm() > 0)) ++r.degenerate_triangles;
        sorted_triangles.push_back(s);
        r.signed_volume += mesh.vertices[mesh.triangles[t][0]].dot(
                               mesh.vertices[mesh.triangles[t][1]].cross(
                                   mesh.vertices[mesh.triangles[t][2]])) / 6;
    }
    std::sort(sorted_triangles.begin(), sorted_triangles.end());
    for (size_t i = 1; i < sorted_triangles.size(); ++i)
        r.duplicate_triangles += sorted_triangles[i] == sorted_triangles[i - 1];
    r.area = surface_area(mesh);

    // Components by shared vertices.
    UnionFind vertex_sets(mesh.vertices.size());
    for (size_t t = 0; t < nt; ++t)
        if (valid[t]) {
            const Triangle &tri = mesh.triangles[t];
            vertex_sets.unite(tri[0], tri[1]);
            vertex_sets.unite(tri[1], tri[2]);
        }

    // Every edge use, grouped by undirected edge.
    std::vector<EdgeUse> uses;
    uses.reserve(3 * nt);
    for (size_t t = 0; t < nt; ++t) {
        if (!valid[t]) continue;
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t u = mesh.triangles[t][k], v = mesh.triangles[t][(k + 1) % 3];
            const auto cu = static_cast<uint32_t>(3 * t + k);
            const auto cv = static_cast<uint32_t>(3 * t + (k + 1) % 3);
            const bool forward = u < v;
            const uint64_t key = forward ? (uint64_t{u} << 32 | v) : (uint64_t{v} << 32 | u);
            uses.push_back({key, forward ? cu : cv, forward ? cv : cu, forward});
        }
    }
    std::sort(uses.begin(), uses.end(),
              [](const EdgeUse &a, const EdgeUse &b) { return a.key < b.key; });

    // Per-component tallies, indexed by the component's root vertex for now.
    std::vector<ComponentReport> by_root(mesh.vertices.size());
    std::vector<bool> root_broken(mesh.vertices.size());

    // Corners around a vertex are joined when their triangles share an edge at it; a
    // vertex whose corners end up in more than one group is a bowtie (non-manifold).
    UnionFind fans(3 * nt);
    for (size_t i = 0, j; i < uses.size(); i = j) {
        size_t forward = 0;
        for (j = i; j < uses.size() && uses[j].key == uses[i].key; ++j) {
            forward += uses[j].forward;
            fans.unite(uses[j].low_corner, uses[i].low_corner);
            fans.unite(uses[j].high_corner, uses[i].high_corner);
        }
        const size_t count = j - i, backward = count - forward;
        const bool boundary = count == 1, nonmanifold = count > 2;
        const bool misoriented = forward > 1 || backward > 1;
        r.boundary_edges += boundary;
        r.nonmanifold_edges += nonmanifold;
        r.misoriented_edges += misoriented;
        const uint32_t root = vertex_sets.find(static_cast<uint32_t>(uses[i].key >> 32));
        ++by_root[root].edges;
        if (boundary || nonmanifold || misoriented) root_broken[root] = true;
    }

    std::vector<std::pair<uint32_t, uint32_t>> vertex_fans;  // (vertex, fan root)
    vertex_fans.reserve(3 * nt);
    for (size_t t = 0; t < nt; ++t)
        if (valid[t])
            for (uint32_t k = 0; k < 3; ++k)
                vertex_fans.emplace_back(mesh.triangles[t][k],
                                         fans.find(static_cast<uint32_t>(3 * t + k)));
    std::sort(vertex_fans.begin(), vertex_fans.end());
    vertex_fans.erase(std::unique(vertex_fans.begin(), vertex_fans.end()), vertex_fans.end());
    for (size_t i = 0; i < vertex_fans.size(); ++i) {
        const uint32_t v = vertex_fans[i].first, root = vertex_sets.find(v);
        ++by_root[root].vertices;  // once per vertex: counted at its first fan
        if (i + 1 < vertex_fans.size() && vertex_fans[i + 1].first == v) {
            ++r.nonmanifold_vertices;
            root_broken[root] = true;
            while (i + 1 < vertex_fans.size() && vertex_fans[i + 1].first == v) ++i;
        }
    }

    for (size_t t = 0; t < nt; ++t) {
        if (!valid[t]) continue;
        const Triangle &tri = mesh.triangles[t];
        ComponentReport &c = by_root[vertex_sets.find(tri[0])];
        ++c.triangles;
        c.signed_volume +=
            mesh.vertices[tri[0]].dot(mesh.vertices[tri[1]].cross(mesh.vertices[tri[2]])) / 6;
    }
    for (size_t v = 0; v < by_root.size(); ++v) {
        ComponentReport c = by_root[v];
        if (c.triangles == 0) continue;
        c.euler_characteristic = static_cast<long>(c.vertices) - static_cast<long>(c.edges) +
                                 static_cast<long>(c.triangles);
        c.closed_manifold = !root_broken[v];
        if (c.closed_manifold) c.genus = static_cast<int>((2 - c.euler_characteristic) / 2);
        r.euler_characteristic += c.euler_characteristic;
        r.component_reports.push_back(c);
    }
    std::stable_sort(r.component_reports.begin(), r.component_reports.end(),
                     [](const ComponentReport &a, const ComponentReport &b) {
                         return a.triangles > b.triangles;
                     });
    r.components = r.component_reports.size();
    r.edge_manifold = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
    r.consistently_wound = r.misoriented_edges == 0;
    r.watertight = valid_count > 0 && r.edge_manifold && r.consistently_wound;
    return r;
}

}  // namespace gmpu::testing
