#include "geometry/outliers.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include <nanoflann.hpp>

#include "core/median.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/counting_result_set.hpp"
#include "geometry/parallel_kdtree.hpp"

namespace gmpu {

namespace {

struct DoubleCloud {
    std::vector<double> xyz;
    size_t kdtree_get_point_count() const { return xyz.size() / 3; }
    double kdtree_get_pt(size_t i, size_t d) const { return xyz[3 * i + d]; }
    template <class Box>
    bool kdtree_get_bbox(Box &) const { return false; }
};
using DoubleTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, DoubleCloud>,
                                                       DoubleCloud, 3, uint32_t>;

// Whether, on some axis, the bounding box is over kBulkFactor times as wide as the range
// between the kBulkQuantile and 1 - kBulkQuantile quantiles of a sample: outliers that
// would set the scale widen the box so. Sets `finite` to whether every coordinate is within
// ±1e300.
bool box_wider_than_bulk(const unsigned char *bytes, size_t count, size_t stride, bool &finite,
                         double (*read)(const unsigned char *, int)) {
    constexpr size_t kSample = 1 << 14;
    constexpr double kBulkQuantile = 0.01, kBulkFactor = 2.0;
    const size_t step = std::max<size_t>(1, count / kSample);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    std::vector<double> sample[3];
    finite = true;
    for (size_t i = 0; i < count; ++i)
        for (int d = 0; d < 3; ++d) {
            const double c = read(bytes + i * stride, d);
            if (!(std::fabs(c) <= 1e300)) {
                finite = false;
                return false;
            }
            lo[d] = std::min(lo[d], c);
            hi[d] = std::max(hi[d], c);
            if (i % step == 0) sample[d].push_back(c);
        }
    for (int d = 0; d < 3; ++d) {
        std::vector<double> &v = sample[d];
        const size_t a = size_t(kBulkQuantile * double(v.size())), b = v.size() - 1 - a;
        std::nth_element(v.begin(), v.begin() + long(a), v.end());
        const double qa = v[a];
        std::nth_element(v.begin(), v.begin() + long(b), v.end());
        if (hi[d] - lo[d] > kBulkFactor * (v[b] - qa)) return true;
    }
    return false;
}

template <class T>
double read_coordinate(const unsigned char *point, int d) {
    T v;
    std::memcpy(&v, point + size_t(d) * sizeof(T), sizeof v);
    return double(v);
}

}  // namespace

template <class T>
OutlierScan find_outliers(const T *xyz, size_t count, size_t stride, bool only_if_box_is_wide, Workers *workers) {
    OutlierScan scan;
    if (stride == 0) stride = 3 * sizeof(T);
    const size_t k = kOutlierNeighbours;
    if (count <= 2 * k) return scan;  // too few points to call any of them far from the rest
    const auto *bytes = reinterpret_cast<const unsigned char *>(xyz);
    bool finite = true;
    const bool wide = box_wider_than_bulk(bytes, count, stride, finite, read_coordinate<T>);
    if (!finite || (only_if_box_is_wide && !wide)) return scan;
    DoubleCloud cloud;
    cloud.xyz.resize(3 * count);
    for (size_t i = 0; i < count; ++i)
        for (int d = 0; d < 3; ++d) cloud.xyz[3 * i + d] = read_coordinate<T>(bytes + i * stride, d);
    DoubleTree tree(3, cloud,
                    nanoflann::KDTreeSingleIndexAdaptorParams(16, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex));
    std::vector<std::unique_ptr<nanoflann::PooledAllocator>> subtrees;  // the nodes of a parallel build
    // The neighbour test below shares its work among the threads when the build did.
    const bool parallel = build_kdtree(tree, subtrees, workers);

    // Spacing: the median k-th neighbour distance (the point itself is the 0th) over a sample.
    constexpr size_t kSamples = 1024;
    const size_t step = std::max<size_t>(1, count / kSamples);
    std::vector<double> kth;
    uint32_t idx[k + 1];
    double d2[k + 1];
    for (size_t i = 0; i < count; i += step) {
        const size_t found = tree.knnSearch(&cloud.xyz[3 * i], k + 1, idx, d2);
        if (found == k + 1) kth.push_back(d2[k]);
    }
    if (kth.empty()) return scan;
    const double spacing_sq = median_in_place(kth);
    scan.spacing = std::sqrt(spacing_sq);
    if (!(spacing_sq > 0.0) || !std::isfinite(spacing_sq)) return scan;  // duplicates; the caller decides

    const double far_sq = kOutlierFar * kOutlierFar * spacing_sq;
    auto is_far = [&](size_t i) {
        CountingResultSet<double> near{far_sq, k + 1};
        tree.findNeighbors(near, &cloud.xyz[3 * i], nanoflann::SearchParams(32, 0.0, false));
        return near.count < k + 1;
    };
    if (parallel) {  // one flag per point, collected in order: the serial answer
        std::vector<uint8_t> far(count);
        Progress silent(nullptr, nullptr, GMPU_STAGE_FIT);
        parallel_for(0, count, *workers, silent, [&](size_t i) { far[i] = is_far(i); }, 4096);
        for (size_t i = 0; i < count; ++i)
            if (far[i]) scan.outliers.push_back(uint32_t(i));
    } else {
        for (size_t i = 0; i < count; ++i)
            if (is_far(i)) scan.outliers.push_back(uint32_t(i));
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t next_outlier = 0;
    for (size_t i = 0; i < count; ++i) {
        if (next_outlier < scan.outliers.size() && scan.outliers[next_outlier] == i) {
            ++next_outlier;
            continue;
        }
        for (int d = 0; d < 3; ++d) {
            lo[d] = std::min(lo[d], cloud.xyz[3 * i + d]);
            hi[d] = std::max(hi[d], cloud.xyz[3 * i + d]);
        }
    }
    for (int d = 0; d < 3; ++d) scan.extent = std::max(scan.extent, hi[d] - lo[d]);
    return scan;
}

template OutlierScan find_outliers<double>(const double *, size_t, size_t, bool, Workers *);
template OutlierScan find_outliers<float>(const float *, size_t, size_t, bool, Workers *);

}  // namespace gmpu
