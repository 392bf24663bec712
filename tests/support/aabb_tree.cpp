#include "aabb_tree.hpp"

#include "triangle_distance.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

namespace gmpu::testing {

namespace {

constexpr uint32_t kLeafSize = 4;
constexpr int kMaxStack = 128;  // median splits: depth ≤ log2(2^32 / kLeafSize) + 1

double box_squared_distance(const Vec3 &p, const Vec3 &lo, const Vec3 &hi) {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
}

}  // namespace

AabbTree::AabbTree(const TriangleMesh &mesh) {
    std::vector<uint32_t> ids;
    std::vector<std::array<Vec3, 3>> corners;
    std::vector<Vec3> centroids;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (!(triangle_cross(mesh, t).squaredNorm() > 0)) continue;
        const Triangle &tri = mesh.triangles[t];
        ids.push_back(static_cast<uint32_t>(t));
        corners.push_back({mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]});
        centroids.push_back((corners.back()[0] + corners.back()[1] + corners.back()[2]) / 3);
    }
    if (ids.empty()) return;

    // Build over a permutation, then lay the triangles out in leaf order once, so that a
    // leaf's corners are contiguous in memory.
    std::vector<uint32_t> order(ids.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    nodes_.reserve(2 * (ids.size() / kLeafSize + 1));
    nodes_.push_back({});
    build(0, 0, static_cast<uint32_t>(ids.size()), order, corners, centroids);
    triangle_ids_.reserve(ids.size());
    corners_.reserve(ids.size());
    for (uint32_t i : order) {
        triangle_ids_.push_back(ids[i]);
        corners_.push_back(corners[i]);
    }
}

// Makes nodes_[node] cover slots begin..end of order; an inner node gets two adjacent
// children, split at the median centroid along the longest axis of the centroids' box.
void AabbTree::build(uint32_t node, uint32_t begin, uint32_t end, std::vector<uint32_t> &order,
                     const std::vector<std::array<Vec3, 3>> &corners,
                     const std::vector<Vec3> &centroids) {
    Eigen::AlignedBox3d bounds, centre_bounds;
    for (uint32_t i = begin; i < end; ++i) {
        for (const Vec3 &v : corners[order[i]]) bounds.extend(v);
        centre_bounds.extend(centroids[order[i]]);
    }
    nodes_[node] = {bounds.min(), bounds.max(), begin, end - begin};
    if (end - begin <= kLeafSize) return;

    int axis = 0;
    centre_bounds.diagonal().maxCoeff(&axis);
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](uint32_t x, uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
    const auto left = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[node].first = left;
    nodes_[node].count = 0;
    build(left, begin, mid, order, corners, centroids);
    build(left + 1, mid, end, order, corners, centroids);
}

AabbTree::Nearest AabbTree::nearest(const Vec3 &query) const {
    Nearest best;
    if (empty()) return best;
    double best2 = std::numeric_limits<double>::infinity();
    uint32_t best_slot = 0;

    // Depth-first, nearer child on top; each entry keeps its box distance so that it is
    // skipped when a closer triangle was found since it was pushed.
    struct Entry { uint32_t node; double d2; };
    Entry stack[kMaxStack];
    int top = 0;
    stack[top++] = {0, box_squared_distance(query, nodes_[0].lo, nodes_[0].hi)};
    while (top > 0) {
        const Entry entry = stack[--top];
        if (entry.d2 >= best2) continue;
        const Node &node = nodes_[entry.node];
        if (node.count > 0) {
            for (uint32_t s = node.first; s < node.first + node.count; ++s) {
                const auto &c = corners_[s];
                const Vec3 q = closest_point_on_triangle(query, c[0], c[1], c[2]);
                const double d2 = (q - query).squaredNorm();
                if (d2 < best2) {
                    best2 = d2;
                    best.point = q;
                    best_slot = s;
                }
            }
            continue;
        }
        const Node &a = nodes_[node.first], &b = nodes_[node.first + 1];
        Entry near{node.first, box_squared_distance(query, a.lo, a.hi)};
        Entry far{node.first + 1, box_squared_distance(query, b.lo, b.hi)};
        if (far.d2 < near.d2) std::swap(near, far);
        if (far.d2 < best2) stack[top++] = far;
        if (near.d2 < best2) stack[top++] = near;
    }
    best.distance = std::sqrt(best2);
    best.triangle = triangle_ids_[best_slot];
    return best;
}

std::vector<AabbTree::Nearest> AabbTree::nearest_all(const std::vector<Vec3> &queries,
                                                     unsigned threads) const {
    std::vector<Nearest> out(queries.size());
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    threads = static_cast<unsigned>(std::min<size_t>(threads, queries.size() / 1024 + 1));
    // Interleaved blocks balance the load when one region of the queries is costlier.
    constexpr size_t kBlock = 256;
    auto work = [&](unsigned id) {
        for (size_t start = id * kBlock; start < queries.size(); start += threads * kBlock)
            for (size_t i = start; i < std::min(start + kBlock, queries.size()); ++i)
                out[i] = nearest(queries[i]);
    };
    std::vector<std::thread> pool;
    for (unsigned id = 1; id < threads; ++id) pool.emplace_back(work, id);
    work(0);
    for (std::thread &t : pool) t.join();
    return out;
}

}  // namespace gmpu::testing
