#include "geometry/point_set.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "geometry/counting_result_set.hpp"
#include "geometry/parallel_kdtree.hpp"

namespace gmpu {

namespace {

// nanoflann reads the points in place through this adaptor (no copy), optionally through
// a list of ids (the coarse subsample). It holds buffers, not vectors, so moving the
// PointSet (which keeps the buffers) keeps it valid.
struct CloudAdaptor {
    const float *pts;
    size_t count;
    const uint32_t *ids = nullptr;
    size_t kdtree_get_point_count() const { return count; }
    float kdtree_get_pt(size_t i, size_t dim) const { return pts[3 * (ids ? ids[i] : i) + dim]; }
    template <class Box>
    bool kdtree_get_bbox(Box &) const { return false; }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>,
                                                   CloudAdaptor, 3, uint32_t>;

// Appends indices of points inside a radius, without nanoflann's pair vector.
struct CollectingResultSet {
    float radius_sq;
    std::vector<uint32_t> *out;
    void init() {}
    void clear() {}
    size_t size() const { return out->size(); }
    bool full() const { return true; }
    bool addPoint(float dist, uint32_t index) {
        if (dist < radius_sq) out->push_back(index);
        return true;
    }
    float worstDist() const { return radius_sq; }
};

// The k nearest points within a radius: the radius prunes the search from the start, which
// makes queries far from the data (most of the polygonizer's) cheap.
struct BoundedKnnResultSet {
    size_t k;
    float radius_sq;
    uint32_t *indices;
    float *dists;
    size_t count = 0;
    void init() {}
    size_t size() const { return count; }
    bool full() const { return count == k; }
    float worstDist() const { return count < k ? radius_sq : dists[k - 1]; }
    bool addPoint(float dist, uint32_t index) {
        if (dist >= worstDist()) return true;
        size_t i = count < k ? count++ : k - 1;
        for (; i > 0 && dists[i - 1] > dist; --i) {
            dists[i] = dists[i - 1];
            indices[i] = indices[i - 1];
        }
        dists[i] = dist;
        indices[i] = index;
        return true;
    }
};

// %g text of a coordinate for messages ("1e+301").
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

}  // namespace

struct PointSet::Index {
    CloudAdaptor adaptor;
    KdTree tree;
    std::vector<std::unique_ptr<nanoflann::PooledAllocator>> subtrees;  // the nodes of a parallel build
    Index(const std::vector<float> &pts, const std::vector<uint32_t> *ids, Workers *workers)
        : adaptor{pts.data(), ids ? ids->size() : pts.size() / 3, ids ? ids->data() : nullptr},
          tree(3, adaptor,
               nanoflann::KDTreeSingleIndexAdaptorParams(16, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex)) {
        build_kdtree(tree, subtrees, workers);
    }
};

PointSet::PointSet() = default;
PointSet::PointSet(PointSet &&) noexcept = default;
PointSet &PointSet::operator=(PointSet &&) noexcept = default;
PointSet::~PointSet() = default;

template <class T>
PointSet PointSet::from_array(const T *xyz, size_t count, size_t stride, size_t min_points, Workers *workers) {
    if (stride == 0) stride = 3 * sizeof(T);
    if (count < min_points)
        throw Error(GMPU_ERROR_INVALID_INPUT,
                    std::to_string(count) + " points given; at least " + std::to_string(min_points) +
                        " are needed (GMPU_PARAM_MIN_POINTS) to fit a surface");
    const auto *bytes = reinterpret_cast<const unsigned char *>(xyz);
    auto read = [&](size_t i) {
        T v[3];
        std::memcpy(v, bytes + i * stride, sizeof v);  // stride need not keep alignment
        return Eigen::Vector3d(double(v[0]), double(v[1]), double(v[2]));
    };

    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (size_t i = 0; i < count; ++i) {
        Eigen::Vector3d p = read(i);
        if (!p.allFinite())
            throw Error(GMPU_ERROR_INVALID_INPUT, "point " + std::to_string(i) +
                                                      " has a NaN or infinite coordinate");
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    // Normalising must neither overflow nor underflow: extent, centre and diagonal are finite
    // and non-zero for coordinates within ±1e300 spanning more than 1e-300 (1e±30 is the
    // usual extreme); outside that, say so instead of meshing inf/NaN or reporting a wrong
    // diagonal (extent.norm() squares: 0 at 1e-300, inf at 1e300).
    double magnitude = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    if (magnitude > 1e300)
        throw Error(GMPU_ERROR_INVALID_INPUT, "a coordinate of magnitude " + number(magnitude) +
                                                  " is beyond 1e300: too close to the largest double to "
                                                  "normalise; rescale the points");
    Eigen::Vector3d extent = hi - lo;
    double longest = extent.maxCoeff();
    if (!(longest > 0.0) || longest <= magnitude * 1e-12)
        throw Error(GMPU_ERROR_DEGENERATE_INPUT,
                    "all points are identical (to 12 digits): they bound no volume");
    if (longest < 1e-300)
        throw Error(GMPU_ERROR_INVALID_INPUT, "the points span only " + number(longest) +
                                                  ", below 1e-300: too small to normalise; rescale the points");

    PointSet set;
    set.norm_.centre = 0.5 * (lo + hi);
    set.norm_.scale = 1.0 / longest;
    set.world_diagonal_ = extent.stableNorm();
    set.box_min_ = set.norm_.to_unit(lo);
    set.box_max_ = set.norm_.to_unit(hi);
    set.points_.reserve(3 * count);
    advise_huge_pages(set.points_);
    set.points_.resize(3 * count);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < count; ++i) {
        Eigen::Vector3d q = set.norm_.to_unit(read(i));
        for (int d = 0; d < 3; ++d) set.points_[3 * i + d] = float(q[d]);
        mean += q;
    }
    mean /= double(count);

    // Collinear or coplanar points enclose no volume: say so instead of meshing noise.
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < count; ++i) {
        Eigen::Vector3d d = set.point(i) - mean;
        cov.noalias() += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov / double(count), Eigen::EigenvaluesOnly);
    Eigen::Vector3d ev = eig.eigenvalues().cwiseMax(0.0);  // increasing
    // Thickness relative to the longest side (1 after normalisation); float storage limits
    // resolution to ~1e-7, so anything thinner than 1e-6 is flat for our purposes.
    if (std::sqrt(ev[1]) < 1e-6)
        throw Error(GMPU_ERROR_DEGENERATE_INPUT,
                    "all points are collinear: they bound no volume");
    if (std::sqrt(ev[0]) < 1e-6)
        throw Error(GMPU_ERROR_DEGENERATE_INPUT,
                    "all points are coplanar (an open flat patch): no closed surface encloses a volume");
    set.build_index(workers);
    return set;
}

template PointSet PointSet::from_array<double>(const double *, size_t, size_t, size_t, Workers *);
template PointSet PointSet::from_array<float>(const float *, size_t, size_t, size_t, Workers *);

void PointSet::build_index(Workers *workers) {
    index_ = std::make_unique<Index>(points_, nullptr, workers);
    const size_t n = size();
    if (n <= 2 * kCoarsePoints) return;
    // Every m-th point of a fixed pseudo-random order: uniform over the surface whatever
    // order the input came in (scan lines, sorted files).
    const uint64_t m = (n + kCoarsePoints - 1) / kCoarsePoints;
    for (uint32_t i = 0; i < n; ++i)
        if ((uint64_t(i) * 0x9E3779B97F4A7C15ull >> 32) % m == 0) coarse_ids_.push_back(i);
    coarse_ratio_ = double(n) / double(coarse_ids_.size());
    coarse_index_ = std::make_unique<Index>(points_, &coarse_ids_, workers);
}

void PointSet::coarse_within(const Eigen::Vector3d &c, double radius, std::vector<uint32_t> &out) const {
    if (!coarse_index_) return within(c, radius, out);
    const float q[3] = {float(c[0]), float(c[1]), float(c[2])};
    const size_t first = out.size();
    CollectingResultSet rs{float(radius * radius), &out};
    coarse_index_->tree.findNeighbors(rs, q, nanoflann::SearchParams(32, 0.0f, false));
    for (size_t k = first; k < out.size(); ++k) out[k] = coarse_ids_[out[k]];
}

void PointSet::within(const Eigen::Vector3d &c, double radius, std::vector<uint32_t> &out) const {
    const float q[3] = {float(c[0]), float(c[1]), float(c[2])};
    CollectingResultSet rs{float(radius * radius), &out};
    index_->tree.findNeighbors(rs, q, nanoflann::SearchParams(32, 0.0f, false));
}

size_t PointSet::count_within(const Eigen::Vector3d &c, double radius, size_t enough) const {
    const float q[3] = {float(c[0]), float(c[1]), float(c[2])};
    CountingResultSet<float> rs{float(radius * radius), enough};
    index_->tree.findNeighbors(rs, q, nanoflann::SearchParams(32, 0.0f, false));
    return rs.count;
}

void PointSet::nearest(const Eigen::Vector3d &c, size_t k, std::vector<uint32_t> &indices,
                       std::vector<float> &squared_distances, double max_radius) const {
    k = std::min(k, size());
    indices.resize(k);
    squared_distances.resize(k);
    const float q[3] = {float(c[0]), float(c[1]), float(c[2])};
    const float r2 = std::isfinite(max_radius) ? float(max_radius * max_radius) : INFINITY;
    BoundedKnnResultSet rs{k, r2, indices.data(), squared_distances.data()};
    if (k > 0) index_->tree.findNeighbors(rs, q, nanoflann::SearchParams(32, 0.0f, false));
    indices.resize(rs.count);
    squared_distances.resize(rs.count);
}

}  // namespace gmpu
