// Input conversion for gmpu_surface_set_points and set_normals (see api/input.hpp).
#include "api/input.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "api/guard.hpp"
#include "core/error.hpp"
#include "geometry/outliers.hpp"

namespace gmpu::api {
namespace {

using gmpu::Error;

// Shortest exact-enough text for a number in a message ("16", "0.002", "1e+09").
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

Error clusters(const gmpu::OutlierScan &scan) {
    return Error(GMPU_ERROR_INVALID_INPUT, "the points are spaced " + number(scan.spacing) +
                                               " apart over an extent of " + number(scan.extent) +
                                               ": clusters this far apart cannot share one surface's scale; "
                                               "reconstruct each cluster on its own surface");
}

// The points as given; when they look collinear or coplanar, says so unless they are
// far-apart clusters (which look so from afar).
template <class T>
gmpu::PointSet points_or_clusters(const T *xyz, size_t count, size_t stride, size_t min_points,
                                  gmpu::Workers *workers) {
    try {
        return gmpu::PointSet::from_array(xyz, count, stride, min_points, workers);
    } catch (const Error &e) {
        if (e.status() != GMPU_ERROR_DEGENERATE_INPUT) throw;
        const gmpu::OutlierScan full = gmpu::find_outliers(xyz, count, stride, false);
        if (full.spacing > 0.0 && full.spacing < 1e-6 * full.extent) throw clusters(full);
        throw;
    }
}

// The points less the outliers: the scale comes from them, and only they join the fits.
// nearest[k]: the kept point nearest to outlier k (its normal stands in for the outlier's).
template <class T>
gmpu::PointSet kept_points(const T *xyz, size_t count, size_t stride, size_t min_points,
                           const std::vector<uint32_t> &outliers, std::vector<uint32_t> &nearest,
                           gmpu::Workers *workers) {
    const size_t step = stride ? stride : 3 * sizeof(T);
    const auto *bytes = reinterpret_cast<const unsigned char *>(xyz);
    auto read = [&](size_t i, T v[3]) { std::memcpy(v, bytes + i * step, 3 * sizeof(T)); };
    std::vector<T> kept;
    kept.reserve(3 * (count - outliers.size()));
    size_t next = 0;
    for (size_t i = 0; i < count; ++i) {
        if (next < outliers.size() && outliers[next] == i) {
            ++next;
            continue;
        }
        T v[3];
        read(i, v);
        kept.insert(kept.end(), v, v + 3);
    }
    gmpu::PointSet points = gmpu::PointSet::from_array(kept.data(), kept.size() / 3, 0, min_points, workers);
    points.set_outlier_count(outliers.size());
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    for (uint32_t o : outliers) {
        T v[3];
        read(o, v);
        const Eigen::Vector3d q = points.normalisation().to_unit({double(v[0]), double(v[1]), double(v[2])});
        points.nearest(q.cwiseMax(-1e15).cwiseMin(1e15), 1, idx, d2);
        nearest.push_back(idx.empty() ? 0 : idx[0]);
    }
    return points;
}

}  // namespace

void check_array(const void *data, size_t count, size_t stride, size_t element, const char *what) {
    require_arg(data, what);
    if (stride != 0 && stride < element)
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, std::string(what) + " stride " + std::to_string(stride) +
                                                     " is smaller than one point (" + std::to_string(element) +
                                                     " bytes)");
    size_t s = stride ? stride : element;
    // The last point ends at (count - 1) × stride + element bytes: that must be addressable.
    if (count > 0 && (count - 1 > (std::numeric_limits<size_t>::max() - element) / s ||
                      count > std::numeric_limits<uint32_t>::max() / 4))
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, std::string(what) + ": too many points");
}

template <class T>
InputPoints input_points(const T *xyz, size_t count, size_t stride, size_t min_points, OutlierScan scan,
                         bool remove_outliers, Workers *workers) {
    // The points' own spacing, not their bounding box, is the scale of the detail: one
    // octree in float coordinates resolves about a millionth of the extent.
    if (scan.spacing > 0.0 && scan.spacing < 1e-6 * scan.extent) throw clusters(scan);
    InputPoints in;
    if (remove_outliers && !scan.outliers.empty()) {
        in.points = kept_points(xyz, count, stride, min_points, scan.outliers, in.nearest, workers);
        in.outliers = std::move(scan.outliers);
    } else {  // kept in the fit, but still reported
        in.points = points_or_clusters(xyz, count, stride, min_points, workers);
        in.points.set_outlier_count(scan.outliers.size());
    }
    return in;
}

template <class T>
std::vector<float> unit_normals(const T *nxyz, size_t count, size_t stride, const std::vector<uint32_t> &outliers) {
    if (stride == 0) stride = 3 * sizeof(T);
    std::vector<float> unit;
    unit.reserve(3 * (count - outliers.size()));
    size_t next_outlier = 0;
    const auto *bytes = reinterpret_cast<const unsigned char *>(nxyz);
    for (size_t i = 0; i < count; ++i) {
        T v[3];
        std::memcpy(v, bytes + i * stride, sizeof v);
        Eigen::Vector3d n{double(v[0]), double(v[1]), double(v[2])};
        if (!n.allFinite())
            throw Error(GMPU_ERROR_INVALID_INPUT, "normal " + std::to_string(i) + " is NaN or infinite");
        // Only the direction matters: divide by the largest component first, so that
        // squaring neither underflows (1e-320) nor overflows (1e200).
        const double largest = n.cwiseAbs().maxCoeff();
        if (!(largest > 0.0)) throw Error(GMPU_ERROR_INVALID_INPUT, "normal " + std::to_string(i) + " is zero");
        n /= largest;
        n /= n.norm();
        if (next_outlier < outliers.size() && outliers[next_outlier] == i) {
            ++next_outlier;  // validated like the others, but no fit is near it
            continue;
        }
        for (int d = 0; d < 3; ++d) unit.push_back(float(n[d]));
    }
    return unit;
}

template InputPoints input_points(const float *, size_t, size_t, size_t, OutlierScan, bool, Workers *);
template InputPoints input_points(const double *, size_t, size_t, size_t, OutlierScan, bool, Workers *);
template std::vector<float> unit_normals(const float *, size_t, size_t, const std::vector<uint32_t> &);
template std::vector<float> unit_normals(const double *, size_t, size_t, const std::vector<uint32_t> &);

}  // namespace gmpu::api
