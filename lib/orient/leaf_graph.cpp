#include "orient/leaf_graph.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

namespace gmpu {

namespace {

uint64_t cell_key(int depth, uint32_t x, uint32_t y, uint32_t z) {
    return uint64_t(depth) << 48 | uint64_t(x) << 32 | uint64_t(y) << 16 | uint64_t(z);
}

// Sorted (key, cell) pairs: a compact map from a cell's integer position to its index.
class CellLookup {
public:
    explicit CellLookup(const Octree &tree) {
        keys_.reserve(tree.cells.size());
        for (uint32_t i = 0; i < tree.cells.size(); ++i) {
            const Cell &c = tree.cells[i];
            keys_.push_back({cell_key(c.depth, c.coord[0], c.coord[1], c.coord[2]), i});
        }
        std::sort(keys_.begin(), keys_.end());
    }
    int64_t find(int depth, uint32_t x, uint32_t y, uint32_t z) const {
        std::pair<uint64_t, uint32_t> probe{cell_key(depth, x, y, z), 0};
        auto it = std::lower_bound(keys_.begin(), keys_.end(), probe);
        if (it == keys_.end() || it->first != probe.first) return -1;
        return it->second;
    }

private:
    std::vector<std::pair<uint64_t, uint32_t>> keys_;
};

// A corner this close to either shape's zero set (as a share of the cell size; the shapes
// are about signed distances) lies on that surface, and the sign of the value there says
// nothing: CAD parts have flat faces at round coordinates, which fall on the octree's cell
// faces, where the plane fits give every corner of a shared face ±0 and the edge a random
// J. There the two gradients, which the signs on either side of the surface follow, vote.
constexpr double kOnSurface = 1e-5;

// Sign agreement of two cells' raw shapes at the four corners of a's face (axis, side).
int8_t face_agreement(const Octree &tree, const Cell &a, const Cell &b, int axis, int side) {
    const double h = 0.5 * a.size;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    int sum = 0;
    for (int k = 0; k < 4; ++k) {
        Eigen::Vector3d x = a.centre;
        x[axis] += side * h;
        x[u] += (k & 1) ? h : -h;
        x[v] += (k & 2) ? h : -h;
        Eigen::Vector3d ga, gb;
        const double qa = a.shape.value(x - a.centre, tree.pieces, &ga);
        const double qb = b.shape.value(x - b.centre, tree.pieces, &gb);
        const double on = kOnSurface * a.size;
        const double p = std::abs(qa) <= on || std::abs(qb) <= on ? ga.dot(gb) : qa * qb;
        sum += (p > 0) - (p < 0);
    }
    return int8_t(sum);
}

struct HalfEdge {
    uint32_t a, b;  // node ids
    int8_t agreement;
};

}  // namespace

LeafGraph build_leaf_graph(const Octree &tree, Workers &workers, Progress &progress) {
    LeafGraph g;
    std::vector<uint32_t> node_of(tree.cells.size(), UINT32_MAX);
    for (uint32_t i = 0; i < tree.cells.size(); ++i)
        if (tree.cells[i].is_leaf()) {
            node_of[i] = uint32_t(g.cell_of.size());
            g.cell_of.push_back(i);
        }
    const CellLookup lookup(tree);

    // Each leaf finds its same-size neighbours with a higher index and every larger
    // neighbour; the smaller side of a level change always does the finding, so each edge
    // is found exactly once.
    std::vector<std::vector<HalfEdge>> found(g.size());
    parallel_for(0, g.size(), workers, progress, [&](size_t n) {
        const Cell &a = tree.cells[g.cell_of[n]];
        const int32_t extent = 1 << a.depth;
        for (int axis = 0; axis < 3; ++axis)
            for (int side = -1; side <= 1; side += 2) {
                int32_t pos[3] = {a.coord[0], a.coord[1], a.coord[2]};
                pos[axis] += side;
                if (pos[axis] < 0 || pos[axis] >= extent) continue;
                // The deepest existing cell at that position, walking up from a's level.
                int64_t hit = -1;
                for (int up = 0; up <= a.depth; ++up) {
                    hit = lookup.find(a.depth - up, uint32_t(pos[0]) >> up, uint32_t(pos[1]) >> up,
                                      uint32_t(pos[2]) >> up);
                    if (hit >= 0) break;
                }
                // Same size but subdivided: its leaves find us. Larger and internal: the part
                // next to us is empty space.
                if (hit >= 0 && !tree.cells[size_t(hit)].is_leaf()) hit = -1;
                if (hit < 0) continue;
                uint32_t nb = node_of[size_t(hit)];
                const Cell &b = tree.cells[size_t(hit)];
                if (b.depth == a.depth && nb < n) continue;  // found from the other side
                found[n].push_back({uint32_t(n), nb, face_agreement(tree, a, b, axis, side)});
            }
    }, 256);
    progress.throw_if_cancelled();

    // CSR with both directions.
    std::vector<uint32_t> degree(g.size() + 1, 0);
    for (auto &list : found)
        for (auto &e : list) ++degree[e.a], ++degree[e.b];
    g.offsets.assign(g.size() + 1, 0);
    for (size_t i = 0; i < g.size(); ++i) g.offsets[i + 1] = g.offsets[i] + degree[i];
    g.neighbour.resize(g.offsets.back());
    g.agreement.resize(g.offsets.back());
    std::vector<uint32_t> fill(g.offsets.begin(), g.offsets.end() - 1);
    for (auto &list : found)
        for (auto &e : list) {
            g.neighbour[fill[e.a]] = e.b, g.agreement[fill[e.a]++] = e.agreement;
            g.neighbour[fill[e.b]] = e.a, g.agreement[fill[e.b]++] = e.agreement;
        }
    return g;
}

std::vector<uint32_t> connected_components(const LeafGraph &g, uint32_t &count) {
    std::vector<uint32_t> comp(g.size(), UINT32_MAX);
    std::vector<uint32_t> stack;
    count = 0;
    for (uint32_t s = 0; s < g.size(); ++s) {
        if (comp[s] != UINT32_MAX) continue;
        comp[s] = count;
        stack.push_back(s);
        while (!stack.empty()) {
            uint32_t v = stack.back();
            stack.pop_back();
            for (uint32_t e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
                uint32_t w = g.neighbour[e];
                if (comp[w] == UINT32_MAX) comp[w] = count, stack.push_back(w);
            }
        }
        ++count;
    }
    return comp;
}

}  // namespace gmpu
