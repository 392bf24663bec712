// The caller's arrays turned into the pipeline's input: points (outliers set aside, with the
// kept point nearest to each) and unit normals, with every refusal a clear status.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/outliers.hpp"
#include "geometry/point_set.hpp"

namespace gmpu::api {

// Throws INVALID_ARGUMENT for NULL data, a stride below one element, or more points than
// can be addressed.
void check_array(const void *data, size_t count, size_t stride, size_t element, const char *what);

struct InputPoints {
    PointSet points;                 // the input less the outliers
    std::vector<uint32_t> outliers;  // input indices set aside, increasing
    std::vector<uint32_t> nearest;   // per outlier: the kept point nearest to it
};

// count points, x y z each, stride bytes apart (0: packed), whose outlier scan is given.
// remove_outliers false keeps the outliers in the points (still counted). Throws
// INVALID_INPUT or DEGENERATE_INPUT (see gmpu_surface_set_points). The kd-tree is built on
// the workers' threads when given.
template <class T>
InputPoints input_points(const T *xyz, size_t count, size_t stride, size_t min_points, OutlierScan scan,
                         bool remove_outliers, Workers *workers = nullptr);

// The unit normals of the points that are not outliers (3 floats each), from count normals
// stride bytes apart (0: packed). Throws INVALID_INPUT naming a NaN, infinite or zero normal.
template <class T>
std::vector<float> unit_normals(const T *nxyz, size_t count, size_t stride, const std::vector<uint32_t> &outliers);

}  // namespace gmpu::api
