// Bounding-volume hierarchy over a triangle mesh for exact nearest-triangle queries.
// Built once (median split on the longest axis, O(n log n)); a query descends nearer
// child first and prunes every box farther than the best triangle so far, so it is
// exact and touches a few dozen triangles. 100k queries on 100k triangles: ~0.1 s per core.
#pragma once

#include "triangle_mesh.hpp"

#include <cstdint>
#include <limits>
#include <vector>

namespace gmpu::testing {

class AabbTree {
public:
    struct Nearest {
        Vec3 point = Vec3::Zero();                               // closest surface point
        double distance = std::numeric_limits<double>::infinity();
        uint32_t triangle = std::numeric_limits<uint32_t>::max(); // index into the mesh
    };

    // Indexes every triangle of non-zero area: a zero-area one adds no surface (its
    // points lie on its neighbours' edges) and has no normal to compare. Copies the
    // corners, so the mesh may go away.
    explicit AabbTree(const TriangleMesh &mesh);

    // Exact nearest point on the indexed triangles; distance is infinite when empty().
    Nearest nearest(const Vec3 &query) const;

    // nearest() for every query, split over threads (0: every core).
    std::vector<Nearest> nearest_all(const std::vector<Vec3> &queries,
                                     unsigned threads = 0) const;

    size_t size() const { return triangle_ids_.size(); }  // triangles indexed
    bool empty() const { return triangle_ids_.empty(); }

private:
    struct Node {
        Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
        uint32_t first = 0;  // leaf: first slot in triangle_ids_; inner: left child (right = +1)
        uint32_t count = 0;  // triangles in a leaf; 0 for an inner node
    };
    void build(uint32_t node, uint32_t begin, uint32_t end, std::vector<uint32_t> &order,
               const std::vector<std::array<Vec3, 3>> &corners,
               const std::vector<Vec3> &centroids);

    std::vector<Node> nodes_;
    std::vector<uint32_t> triangle_ids_;     // mesh indices in leaf order
    std::vector<std::array<Vec3, 3>> corners_; // same order as triangle_ids_
};

}  // namespace gmpu::testing
