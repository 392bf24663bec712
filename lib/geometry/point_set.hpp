// The input points, validated and normalised into a unit box, with a kd-tree (nanoflann)
// for support-ball and nearest-neighbour queries. Every later stage works in normalised
// coordinates, so thresholds are scale-free and 1e-30 or 1e30 inputs behave alike.
#pragma once

#include <cstddef>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace gmpu {

class Workers;

// Maps caller coordinates to the normalised frame: q = (p - centre) * scale, so the
// bounding box's longest side becomes 1 and its centre the origin.
struct Normalisation {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double scale = 1.0;
    Eigen::Vector3d to_unit(const Eigen::Vector3d &p) const { return (p - centre) * scale; }
    Eigen::Vector3d to_world(const Eigen::Vector3d &q) const { return q / scale + centre; }
};

class PointSet {
public:
    // Validates and copies count points of type T (double or float), `stride` bytes apart.
    // Throws INVALID_INPUT (non-finite coordinate, too few points) or DEGENERATE_INPUT.
    // With workers, a large set's kd-tree is built on their threads (the same tree).
    template <class T>
    static PointSet from_array(const T *xyz, size_t count, size_t stride, size_t min_points,
                               Workers *workers = nullptr);

    PointSet();
    PointSet(PointSet &&) noexcept;
    PointSet &operator=(PointSet &&) noexcept;
    ~PointSet();

    size_t size() const { return points_.size() / 3; }
    bool empty() const { return points_.empty(); }
    Eigen::Vector3d point(size_t i) const {
        return {points_[3 * i], points_[3 * i + 1], points_[3 * i + 2]};
    }
    const float *data() const { return points_.data(); }
    const Normalisation &normalisation() const { return norm_; }
    // Bounding box in the normalised frame and its diagonal in caller units.
    const Eigen::Vector3d &box_min() const { return box_min_; }
    const Eigen::Vector3d &box_max() const { return box_max_; }
    double world_diagonal() const { return world_diagonal_; }
    // Input points set aside as outliers (see outliers.hpp); they are not in this set.
    size_t outlier_count() const { return outlier_count_; }
    void set_outlier_count(size_t n) { outlier_count_ = n; }

    // Indices of the points within `radius` of `centre` (normalised frame), appended to out.
    void within(const Eigen::Vector3d &centre, double radius, std::vector<uint32_t> &out) const;
    // The same on a fixed, spatially uniform subsample of at most kCoarsePoints points
    // (all points when there are few): for cells so large that a full support would only
    // cost time. Indices refer to the full set; coarse_ratio() = size() / subsample size.
    void coarse_within(const Eigen::Vector3d &centre, double radius, std::vector<uint32_t> &out) const;
    double coarse_ratio() const { return coarse_ratio_; }
    static constexpr size_t kCoarsePoints = 1u << 16;

    // Number of points within `radius`, stopping early once `enough` are found.
    size_t count_within(const Eigen::Vector3d &centre, double radius, size_t enough) const;
    // The k nearest points (indices and squared distances, nearest first), only among those
    // closer than max_radius (fewer than k, or none, when the ball holds fewer).
    void nearest(const Eigen::Vector3d &centre, size_t k, std::vector<uint32_t> &indices,
                 std::vector<float> &squared_distances, double max_radius = INFINITY) const;

private:
    struct Index;
    std::vector<float> points_;  // normalised, 3 per point (12 bytes a point)
    Normalisation norm_;
    Eigen::Vector3d box_min_, box_max_;
    double world_diagonal_ = 0.0;
    size_t outlier_count_ = 0;
    std::unique_ptr<Index> index_, coarse_index_;
    std::vector<uint32_t> coarse_ids_;
    double coarse_ratio_ = 1.0;
    void build_index(Workers *workers);
};

}  // namespace gmpu
