#include "orient/outward.hpp"

#include <cmath>

namespace gmpu {

namespace {

// Share of this step's progress for the leaves' moments; the nesting test takes the rest.
constexpr double kMomentsShare = 0.8;

// Oriented surface samples of one leaf, aggregated: Σ A n (the leaf's dipole), the centroid
// of its points, and its contribution to (1/3)∮ x·n dA.
struct LeafMoment {
    Eigen::Vector3d dipole = Eigen::Vector3d::Zero();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    double volume = 0.0;
    uint32_t count = 0;
};

LeafMoment leaf_moment(const Octree &tree, const PointSet &points, const Cell &c, int8_t sign) {
    LeafMoment m;
    // Area per point from the support's density: the ball meets the surface in about a disk.
    const double area = M_PI * c.radius * c.radius / double(std::max<uint32_t>(1, c.support_count));
    Eigen::Vector3d g;
    for (uint32_t k = c.point_begin; k < c.point_end; ++k) {
        Eigen::Vector3d p = points.point(tree.order[k]);
        oriented_value(c, sign, p, tree.pieces, &g);
        double gn = g.norm();
        if (!(gn > 0.0)) continue;
        Eigen::Vector3d n = -g / gn;  // outward if f is positive inside
        m.dipole += area * n;
        m.volume += area * p.dot(n) / 3.0;
        m.centroid += p;
        ++m.count;
    }
    if (m.count) m.centroid /= double(m.count);
    return m;
}

}  // namespace

size_t make_components_outward(const Octree &tree, CellSigns &signs, const PointSet &points, const LeafGraph &g,
                               const std::vector<uint32_t> &component, uint32_t count, Progress &progress) {
    std::vector<LeafMoment> moment(g.size());
    std::vector<double> volume(count, 0.0);
    for (uint32_t v = 0; v < g.size(); ++v) {
        progress.poll(kMomentsShare * double(v) / double(g.size()));  // every point once: O(n)
        moment[v] = leaf_moment(tree, points, tree.cells[g.cell_of[v]], signs[g.cell_of[v]]);
        volume[component[v]] += moment[v].volume;
    }
    // 1. Each piece on its own: positive enclosed volume.
    std::vector<int8_t> flip(count, 1);
    for (uint32_t c = 0; c < count; ++c)
        if (volume[c] < 0.0) flip[c] = -1;

    // 2. Nesting parity, only when there is more than one piece.
    if (count > 1) {
        std::vector<Eigen::Vector3d> lo(count, Eigen::Vector3d::Constant(INFINITY)),
            hi(count, Eigen::Vector3d::Constant(-INFINITY));
        std::vector<Eigen::Vector3d> probe(count);
        std::vector<uint32_t> probe_count(count, 0);
        for (uint32_t v = 0; v < g.size(); ++v) {
            const LeafMoment &m = moment[v];
            if (!m.count) continue;
            uint32_t c = component[v];
            lo[c] = lo[c].cwiseMin(m.centroid);
            hi[c] = hi[c].cwiseMax(m.centroid);
            if (m.count > probe_count[c]) probe_count[c] = m.count, probe[c] = m.centroid;
        }
        std::vector<int8_t> parity(count, 1);
        for (uint32_t c = 0; c < count; ++c) {
            progress.poll(kMomentsShare + (1.0 - kMomentsShare) * double(c) / double(count));  // O(count × leaves)
            if (!probe_count[c]) continue;
            const Eigen::Vector3d q = probe[c];
            std::vector<double> winding(count, 0.0);
            bool candidate = false;
            for (uint32_t d = 0; d < count; ++d)
                candidate |= d != c && (q.array() >= lo[d].array()).all() && (q.array() <= hi[d].array()).all();
            if (!candidate) continue;
            for (uint32_t v = 0; v < g.size(); ++v) {
                uint32_t d = component[v];
                if (d == c || !moment[v].count) continue;
                Eigen::Vector3d r = moment[v].centroid - q;
                double r3 = std::pow(r.squaredNorm(), 1.5);
                if (r3 > 0.0) winding[d] += flip[d] * moment[v].dipole.dot(r) / (4.0 * M_PI * r3);
            }
            int inside = 0;
            for (uint32_t d = 0; d < count; ++d) inside += d != c && winding[d] > 0.5;
            if (inside % 2 == 1) parity[c] = -1;
        }
        for (uint32_t c = 0; c < count; ++c) flip[c] = int8_t(flip[c] * parity[c]);
    }

    size_t flipped = 0;
    for (uint32_t v = 0; v < g.size(); ++v)
        if (flip[component[v]] < 0) {
            int8_t &sign = signs[g.cell_of[v]];
            sign = int8_t(-sign);
            ++flipped;
        }
    return flipped;
}

}  // namespace gmpu
