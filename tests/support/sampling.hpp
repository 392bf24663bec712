// Point clouds drawn from a triangle mesh, reproducible from a seed (std::mt19937_64):
// the benchmark's inputs and the metrics' samples both come from here.
#pragma once

#include "triangle_mesh.hpp"

#include <cstdint>
#include <vector>

namespace gmpu::testing {

struct SamplingOptions {
    // Gaussian noise added to each coordinate, sigma as a fraction of the mesh's
    // bounding-box diagonal (0.0025 = 0.25 %). Normals stay those of the clean surface.
    double noise = 0;
    // Density grows by `ratio` across the bounding box along `axis`, exponentially
    // (density ∝ ratio^t, t = 0..1; ratio ≥ 1), as in the shared data's *_nonuniform clouds.
    bool nonuniform = false;
    int axis = 0;
    double ratio = 10;
};

// Points the sparse variant draws (the shared data's elephant_sparse5k).
constexpr size_t kSparseSampleCount = 5000;

struct MeshSamples : OrientedPoints {
    std::vector<uint32_t> triangles;  // the triangle each point was drawn from
};

// count points, area-uniform (or as options say), each with the unit normal of its
// triangle. Zero-area triangles are never drawn. Throws std::invalid_argument when the
// mesh has no area. The same mesh, count, seed and options give the same points.
MeshSamples sample_mesh(const TriangleMesh &mesh, size_t count, uint64_t seed,
                        const SamplingOptions &options = {});

// Adds N(0, sigma²) to every coordinate (sigma in absolute units).
void add_gaussian_noise(std::vector<Vec3> &points, double sigma, uint64_t seed);

}  // namespace gmpu::testing
