// Generalized winding number of the oriented input points (Barill et al. 2018), evaluated
// hierarchically over the octree: far cells act as one dipole Σ A n at their centroid,
// near leaves sum their points exactly. It is about 1 inside the reconstructed solid and 0
// outside — even across holes in the data — and gives the implicit its sign far from the
// data, where no local fit is trustworthy.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "core/progress.hpp"
#include "model/octree.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

class WindingField {
public:
    WindingField() = default;
    // normals: unit outward, 3 per point; area: surface area each point stands for. Both are
    // read again by winding(), so they must outlive the field (the surface owns all three).
    // O(n + cells) for the sums; each radius is a farthest-point search pruned by the
    // children's balls. With a progress, reports and throws CANCELLED.
    WindingField(const Octree &tree, const PointSet &points, const std::vector<float> &normals,
                 const std::vector<float> &area, Progress *progress = nullptr);

    // far_ratio: a cell counts as one dipole once q is beyond far_ratio × its radius; a
    // smaller ratio is cheaper and coarser (enough to tell 0 from 1 well away from the data).
    double winding(const Eigen::Vector3d &q, double far_ratio = 2.0) const;
    bool empty() const { return moments_.empty(); }
    // What point i adds to the winding number at q, as the near leaves sum it.
    double point_winding(uint32_t i, const Eigen::Vector3d &q) const;
    // The radius of cell `cell`'s points about their area-weighted centroid (0 for a cell
    // without area): what decides when the cell counts as one dipole.
    double radius(uint32_t cell) const { return moments_[cell].radius; }

private:
    struct Moment {
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        Eigen::Vector3d dipole = Eigen::Vector3d::Zero();  // Σ A n
        double radius = 0.0;                               // of the points about the centroid
    };
    double visit(uint32_t cell, const Eigen::Vector3d &q, double far_ratio2) const;
    // The largest of `best` and the distances from `from` to the points of cell `index`.
    double farthest(uint32_t index, const Eigen::Vector3d &from, double best, const std::vector<double> &total,
                    Progress *progress) const;
    const Octree *tree_ = nullptr;
    const PointSet *points_ = nullptr;
    std::vector<Moment> moments_;  // per cell
    const std::vector<float> *normals_ = nullptr, *area_ = nullptr;
    Eigen::Vector3d weighted(uint32_t i) const {  // A n of point i
        const std::vector<float> &n = *normals_;
        return double((*area_)[i]) * Eigen::Vector3d(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
    }
};

}  // namespace gmpu
