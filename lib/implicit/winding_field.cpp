#include "implicit/winding_field.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {
constexpr double kInv4Pi = 0.25 / M_PI;
}  // namespace

WindingField::WindingField(const Octree &tree, const PointSet &points, const std::vector<float> &normals,
                           const std::vector<float> &area, Progress *progress)
    : tree_(&tree), points_(&points), moments_(tree.cells.size()), normals_(&normals), area_(&area) {
    // Children follow their parents, so a reverse sweep meets every child before its
    // parent: a leaf sums its own points, a parent its children's sums, O(n + cells) where a
    // pass over each cell's point range would cost O(n · depth).
    const size_t cells = tree.cells.size();
    std::vector<double> total(cells, 0.0);
    std::vector<Eigen::Vector3d> weighted_sum(cells, Eigen::Vector3d::Zero());
    for (size_t c = cells; c-- > 0;) {
        if (progress) progress->poll(0.5 * double(cells - c) / double(cells));
        const Cell &cell = tree.cells[c];
        Moment &m = moments_[c];
        if (cell.is_leaf()) {
            for (uint32_t k = cell.point_begin; k < cell.point_end; ++k) {
                const double a = double(area[tree.order[k]]);
                weighted_sum[c] += a * points.point(tree.order[k]);
                m.dipole += weighted(tree.order[k]);
                total[c] += a;
            }
        } else {
            for (int o = 0; o < 8; ++o) {
                const int32_t k = tree.child(cell, o);
                if (k < 0) continue;
                weighted_sum[c] += weighted_sum[size_t(k)];
                m.dipole += moments_[size_t(k)].dipole;
                total[c] += total[size_t(k)];
            }
        }
        if (total[c] > 0.0) m.centroid = weighted_sum[c] / total[c];
    }
    // The radius about each centroid, children first so that their balls bound the search.
    for (size_t c = cells; c-- > 0;) {
        if (progress) progress->poll(0.5 + 0.5 * double(cells - c) / double(cells));
        if (total[c] > 0.0) moments_[c].radius = farthest(uint32_t(c), moments_[c].centroid, 0.0, total, progress);
    }
}

double WindingField::farthest(uint32_t index, const Eigen::Vector3d &from, double best,
                              const std::vector<double> &total, Progress *progress) const {
    const Cell &c = tree_->cells[index];
    const Moment &m = moments_[index];
    // A cell with area holds its points within its radius of its centroid (computed
    // already: children come later in the array than the cell asking).
    if (total[index] > 0.0 && m.radius > 0.0 && (m.centroid - from).norm() + m.radius <= best) return best;
    if (c.is_leaf()) {
        if (progress) progress->tick();
        for (uint32_t k = c.point_begin; k < c.point_end; ++k)
            best = std::max(best, (points_->point(tree_->order[k]) - from).norm());
        return best;
    }
    for (int o = 0; o < 8; ++o) {
        const int32_t k = tree_->child(c, o);
        if (k >= 0) best = farthest(uint32_t(k), from, best, total, progress);
    }
    return best;
}

double WindingField::visit(uint32_t index, const Eigen::Vector3d &q, double far_ratio2) const {
    const Cell &c = tree_->cells[index];
    if (c.point_end == c.point_begin) return 0.0;
    const Moment &m = moments_[index];
    Eigen::Vector3d r = m.centroid - q;
    double d2 = r.squaredNorm();
    if (d2 > far_ratio2 * m.radius * m.radius)
        return kInv4Pi * m.dipole.dot(r) / (d2 * std::sqrt(d2));
    if (c.is_leaf()) {
        double w = 0.0;
        for (uint32_t k = c.point_begin; k < c.point_end; ++k) w += point_winding(tree_->order[k], q);
        return w;
    }
    double w = 0.0;
    for (int o = 0; o < 8; ++o) {
        int32_t k = tree_->child(c, o);
        if (k >= 0) w += visit(uint32_t(k), q, far_ratio2);
    }
    return w;
}

double WindingField::point_winding(uint32_t i, const Eigen::Vector3d &q) const {
    const Eigen::Vector3d rp = points_->point(i) - q;
    const double e2 = rp.squaredNorm();
    return e2 > 1e-24 ? kInv4Pi * weighted(i).dot(rp) / (e2 * std::sqrt(e2)) : 0.0;
}

double WindingField::winding(const Eigen::Vector3d &q, double far_ratio) const {
    return moments_.empty() ? 0.0 : visit(0, q, far_ratio * far_ratio);
}

}  // namespace gmpu
