#include "implicit/winding_field.hpp"

#include <cmath>

namespace gmpu {

namespace {
constexpr double kInv4Pi = 0.25 / M_PI;
}  // namespace

WindingField::WindingField(const Octree &tree, const PointSet &points, const std::vector<float> &normals,
                           const std::vector<float> &area, Progress *progress)
    : tree_(&tree), points_(&points), moments_(tree.cells.size()), normals_(&normals), area_(&area) {
    // Children follow parents, so a reverse sweep could aggregate; a direct pass over each
    // cell's contiguous point range is as simple and costs O(n · depth).
    for (size_t c = 0; c < tree.cells.size(); ++c) {
        if (progress) progress->poll(double(c) / double(tree.cells.size()));
        const Cell &cell = tree.cells[c];
        Moment &m = moments_[c];
        double total = 0.0;
        for (uint32_t k = cell.point_begin; k < cell.point_end; ++k) {
            // The root and the coarse cells span most of the points: report within them.
            if (progress && (k - cell.point_begin) % 8192 == 8191) progress->tick();
            double a = double(area[tree.order[k]]);
            m.centroid += a * points.point(tree.order[k]);
            m.dipole += weighted(tree.order[k]);
            total += a;
        }
        if (total <= 0.0) continue;
        m.centroid /= total;
        for (uint32_t k = cell.point_begin; k < cell.point_end; ++k)
            m.radius = std::max(m.radius, (points.point(tree.order[k]) - m.centroid).norm());
    }
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
        for (uint32_t k = c.point_begin; k < c.point_end; ++k) {
            Eigen::Vector3d rp = points_->point(tree_->order[k]) - q;
            double e2 = rp.squaredNorm();
            if (e2 > 1e-24) w += kInv4Pi * weighted(tree_->order[k]).dot(rp) / (e2 * std::sqrt(e2));
        }
        return w;
    }
    double w = 0.0;
    for (int o = 0; o < 8; ++o) {
        int32_t k = tree_->child(c, o);
        if (k >= 0) w += visit(uint32_t(k), q, far_ratio2);
    }
    return w;
}

double WindingField::winding(const Eigen::Vector3d &q, double far_ratio) const {
    return moments_.empty() ? 0.0 : visit(0, q, far_ratio * far_ratio);
}

}  // namespace gmpu
