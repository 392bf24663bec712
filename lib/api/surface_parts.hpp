// A surface whose points are spatially separated clusters (geometry/clusters.hpp). Each
// cluster is a surface of its own, reconstructed at its own scale through the same C ABI
// (so each has its own outliers, octree, ε, orientation and grid); the owner's verbs run
// them in turn and merge what they give: one mesh, normals in input order, a field that is
// the nearest cluster's.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/clusters.hpp"
#include "gmpu/gmpu.h"
#include "mesh/mesh.hpp"

namespace gmpu::api {

class SurfaceParts {
public:
    explicit SurfaceParts(const Clusters &clusters);
    ~SurfaceParts();
    SurfaceParts(const SurfaceParts &) = delete;
    SurfaceParts &operator=(const SurfaceParts &) = delete;

    size_t size() const { return parts_.size(); }
    // Every cluster's surface gets the owner's parameter (before set_points and each stage).
    void set_param(gmpu_param key, double value);
    // Each cluster gets its own points (and normals), in input order.
    template <class T>
    void set_points(const T *xyz, size_t count, size_t stride);
    template <class T>
    void set_normals(const T *nxyz, size_t count, size_t stride);

    // The stage on every cluster in turn, reported to `fn` as one stage (each cluster's share
    // in proportion to its points); a failure or cancel of one is the whole stage's.
    void fit(gmpu_progress_fn fn, void *user);
    void orient(gmpu_progress_fn fn, void *user);
    Mesh polygonize(gmpu_progress_fn fn, void *user);

    // Each query answered by the cluster whose box is nearest to it.
    void evaluate(const double *xyz, size_t count, double *values, double *gradients) const;
    void copy_normals(double *out, size_t count) const;
    // The normals of the given input points (valid indices), each from its cluster.
    void copy_normals_at(const int64_t *indices, size_t count, double *out) const;
    // Counts summed over the clusters, depth and resolution their maximum; the noise and ε
    // (fractions of a diagonal) are the largest cluster's; the diagonal the whole cloud's.
    double stat(gmpu_stat key) const;

private:
    struct Progress;
    template <class Verb>
    void each(gmpu_progress_fn fn, void *user, Verb &&verb);

    std::vector<gmpu_surface *> parts_;
    std::vector<std::vector<uint32_t>> members_;  // input indices per cluster, increasing
    std::vector<std::array<double, 6>> boxes_;
    double diagonal_ = 0.0;
};

}  // namespace gmpu::api
