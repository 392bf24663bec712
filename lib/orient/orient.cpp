#include "orient/orient.hpp"

#include <cmath>

#include "core/parallel.hpp"
#include "core/resize_reporting.hpp"
#include "orient/advancing_front.hpp"
#include "orient/leaf_graph.hpp"
#include "orient/outward.hpp"

namespace gmpu {

namespace {

// Signs each leaf by its points' normals: ∇f must point inward, against the normals.
void sign_leaves_by_normals(Octree &tree, const PointSet &points, const float *normals, Progress &progress) {
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    Eigen::Vector3d g;
    for (Cell &c : tree.cells) {
        progress.poll(double(&c - tree.cells.data()) / double(tree.cells.size()));  // O(n) in all
        if (!c.is_leaf()) continue;
        idx.assign(tree.order.begin() + c.point_begin, tree.order.begin() + c.point_end);
        if (idx.empty()) points.nearest(c.centre, 8, idx, d2);  // a leaf holding no point
        double vote = 0.0;
        for (uint32_t i : idx) {
            c.shape.value(points.point(i) - c.centre, tree.pieces, &g);
            vote += g.dot(Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]));
        }
        c.sign = vote > 0.0 ? -1 : 1;
        c.oriented = true;
    }
}

// Inner cells follow their oriented children: the sign that makes the cell's gradient
// agree with theirs at the children's points. Children come after parents, so a reverse
// sweep sees every child oriented before its parent.
void sign_inner_cells(Octree &tree, const PointSet &points, Progress &progress) {
    constexpr uint32_t kSamplesPerChild = 16;
    Eigen::Vector3d gp, gc;
    for (size_t i = tree.cells.size(); i-- > 0;) {
        progress.poll(1.0 - double(i) / double(tree.cells.size()));
        Cell &c = tree.cells[i];
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
                child.value(p, tree.pieces, &gc);
                vote += gp.normalized().dot(gc.normalized());
            }
        }
        c.sign = vote < 0.0 ? -1 : 1;
        c.oriented = true;
    }
}

}  // namespace

OrientStats orient_octree(Octree &tree, const PointSet &points, const float *normals, Workers &workers,
                          Progress &progress, const FrontOptions &front) {
    for (Cell &c : tree.cells) c.sign = 1, c.oriented = false;
    OrientStats stats;
    // The steps' shares of the progress this function is handed.
    Progress leaves_progress = progress.slice(0.0, 0.9), inner_progress = progress.slice(0.9, 1.0);
    if (normals) {
        sign_leaves_by_normals(tree, points, normals, leaves_progress);
        stats.components = 1;
    } else {
        Progress graph_progress = leaves_progress.slice(0.0, 0.1), front_progress = leaves_progress.slice(0.1, 0.85),
                 outward_progress = leaves_progress.slice(0.85, 1.0);
        LeafGraph graph = build_leaf_graph(tree, workers, graph_progress);
        graph_progress.report(1.0);
        std::vector<uint32_t> component = connected_components(graph, stats.components);
        std::vector<int8_t> label =
            propagate_orientation(tree, graph, component, stats.components, front, front_progress);
        for (uint32_t v = 0; v < graph.size(); ++v) {
            Cell &c = tree.cells[graph.cell_of[v]];
            c.sign = label[v];
            c.oriented = true;
        }
        make_components_outward(tree, points, graph, component, stats.components, outward_progress);
    }
    progress.throw_if_cancelled();
    sign_inner_cells(tree, points, inner_progress);
    for (const Cell &c : tree.cells) stats.flipped_leaves += c.is_leaf() && c.sign < 0;
    return stats;
}

std::vector<float> point_normals(const MpuFunction &f, const PointSet &points, Workers &workers,
                                 Progress &progress) {
    const Octree &tree = f.tree();
    std::vector<float> out;
    assign_reporting(out, 3 * points.size(), progress);
    std::vector<uint32_t> leaves;
    for (uint32_t i = 0; i < tree.cells.size(); ++i)
        if (tree.cells[i].is_leaf() && tree.cells[i].point_end > tree.cells[i].point_begin) leaves.push_back(i);
    parallel_for(0, leaves.size(), workers, progress, [&](size_t l) {
        const Cell &c = tree.cells[leaves[l]];
        // The leaves blending inside this cell, gathered once for all its points.
        thread_local std::vector<uint32_t> near;
        const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * c.size);
        f.gather(Eigen::AlignedBox3d(c.centre - half, c.centre + half), near);
        Eigen::Vector3d g;
        for (uint32_t k = c.point_begin; k < c.point_end; ++k) {
            // A coarse leaf can hold thousands of points: report within it too.
            if ((k - c.point_begin) % 16 == 15) progress.tick();
            uint32_t i = tree.order[k];
            Eigen::Vector3d p = points.point(i);
            f.value_among(near, p, &g);
            double gn = g.norm();
            if (!(gn > 1e-12) || !g.allFinite()) {
                c.value(p, tree.pieces, &g);  // ∇f vanishes: the oriented local fit
                gn = g.norm();
            }
            Eigen::Vector3d n = gn > 0.0 ? Eigen::Vector3d(-g / gn) : Eigen::Vector3d::UnitZ();
            for (int d = 0; d < 3; ++d) out[3 * i + d] = float(n[d]);
        }
    }, 1);  // leaves come coarsest first: one per chunk
    progress.throw_if_cancelled();
    return out;
}

}  // namespace gmpu
