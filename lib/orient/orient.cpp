#include "orient/orient.hpp"

#include <cmath>

#include "core/parallel.hpp"
#include "orient/advancing_front.hpp"
#include "orient/leaf_graph.hpp"
#include "orient/outward.hpp"

namespace gmpu {

namespace {

// Signs each leaf by its points' normals: ∇f must point inward, against the normals.
void sign_leaves_by_normals(const Octree &tree, const PointSet &points, const float *normals, CellSigns &signs,
                            Progress &progress) {
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    Eigen::Vector3d g;
    for (const Cell &c : tree.cells) {
        const size_t index = size_t(&c - tree.cells.data());
        progress.poll(double(index) / double(tree.cells.size()));  // O(n) in all
        if (!c.is_leaf()) continue;
        idx.assign(tree.order.begin() + c.point_begin, tree.order.begin() + c.point_end);
        if (idx.empty()) points.nearest(c.centre, 8, idx, d2);  // a leaf holding no point
        double vote = 0.0;
        for (uint32_t i : idx) {
            c.shape.value(points.point(i) - c.centre, tree.pieces, &g);
            vote += g.dot(Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]));
        }
        signs[index] = vote > 0.0 ? -1 : 1;
    }
}

}  // namespace

// Children come after parents, so a reverse sweep sees every child oriented before its parent.
void sign_inner_cells(const Octree &tree, const PointSet &points, CellSigns &signs, Progress &progress) {
    constexpr uint32_t kSamplesPerChild = 16;
    Eigen::Vector3d gp, gc;
    for (size_t i = tree.cells.size(); i-- > 0;) {
        progress.poll(1.0 - double(i) / double(tree.cells.size()));
        const Cell &c = tree.cells[i];
        if (c.is_leaf()) continue;
        double vote = 0.0;
        for (int o = 0; o < 8; ++o) {
            int32_t k = tree.child(c, o);
            if (k < 0) continue;
            const Cell &child = tree.cells[size_t(k)];
            uint32_t n = child.point_end - child.point_begin;
            uint32_t step = std::max<uint32_t>(1, n / kSamplesPerChild);
            for (uint32_t j = child.point_begin; j < child.point_end; j += step) {
                Eigen::Vector3d p = points.point(tree.order[j]);
                c.shape.value(p - c.centre, tree.pieces, &gp);
                oriented_value(child, signs[size_t(k)], p, tree.pieces, &gc);
                vote += gp.normalized().dot(gc.normalized());
            }
        }
        signs[i] = vote < 0.0 ? -1 : 1;
    }
}

uint32_t flipped_leaves(const Octree &tree, const CellSigns &signs) {
    uint32_t count = 0;
    for (size_t i = 0; i < tree.cells.size(); ++i) count += tree.cells[i].is_leaf() && signs[i] < 0;
    return count;
}

Orientation orient_octree(const Octree &tree, const PointSet &points, const float *normals, Workers &workers,
                          Progress &progress, const FrontOptions &front) {
    Orientation result;
    CellSigns &signs = result.signs;
    OrientStats &stats = result.stats;
    signs.assign(tree.cells.size(), 1);
    // The steps' shares of the progress this function is handed.
    Progress leaves_progress = progress.slice(0.0, 0.9), inner_progress = progress.slice(0.9, 1.0);
    if (normals) {
        sign_leaves_by_normals(tree, points, normals, signs, leaves_progress);
        stats.components = 1;
    } else {
        Progress graph_progress = leaves_progress.slice(0.0, 0.1), front_progress = leaves_progress.slice(0.1, 0.85),
                 outward_progress = leaves_progress.slice(0.85, 1.0);
        LeafGraph graph = build_leaf_graph(tree, workers, graph_progress);
        graph_progress.report(1.0);
        std::vector<uint32_t> component = connected_components(graph, stats.components);
        std::vector<int8_t> label =
            propagate_orientation(tree, graph, component, stats.components, front, front_progress);
        for (uint32_t v = 0; v < graph.size(); ++v) signs[graph.cell_of[v]] = label[v];
        make_components_outward(tree, signs, points, graph, component, stats.components, outward_progress);
    }
    progress.throw_if_cancelled();
    sign_inner_cells(tree, points, signs, inner_progress);
    stats.flipped_leaves = flipped_leaves(tree, signs);
    return result;
}

}  // namespace gmpu
