#include "sampling.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace gmpu::testing {

MeshSamples sample_mesh(const TriangleMesh &mesh, size_t count, uint64_t seed,
                        const SamplingOptions &options) {
    // Cumulative areas: a uniform draw over the total picks a triangle by area.
    std::vector<double> cumulative(mesh.triangles.size());
    double total = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        cumulative[t] = total += triangle_area(mesh, t);
    if (!(total > 0)) throw std::invalid_argument("sample_mesh: the mesh has no area");
    if (options.nonuniform && !(options.ratio >= 1 && options.axis >= 0 && options.axis < 3))
        throw std::invalid_argument("sample_mesh: nonuniform needs ratio >= 1, axis 0..2");

    const Eigen::AlignedBox3d box = bounding_box(mesh);
    const double lo = box.min()[options.axis];
    const double extent = box.max()[options.axis] - lo;

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    MeshSamples out;
    out.positions.reserve(count);
    out.normals.reserve(count);
    out.triangles.reserve(count);
    while (out.positions.size() < count) {
        const auto pick = std::upper_bound(cumulative.begin(), cumulative.end(),
                                           uniform(rng) * total);
        const size_t t = std::min<size_t>(pick - cumulative.begin(), cumulative.size() - 1);
        const Triangle &tri = mesh.triangles[t];
        // Uniform on the triangle: fold the unit square onto it (Osada et al. 2002).
        const double r1 = std::sqrt(uniform(rng)), r2 = uniform(rng);
        const Vec3 p = (1 - r1) * mesh.vertices[tri[0]] + r1 * (1 - r2) * mesh.vertices[tri[1]] +
                       r1 * r2 * mesh.vertices[tri[2]];
        if (options.nonuniform) {
            // Rejection keeps density ∝ ratio^t exactly, inside each triangle too.
            const double t01 = extent > 0 ? (p[options.axis] - lo) / extent : 1.0;
            if (uniform(rng) >= std::pow(options.ratio, t01 - 1)) continue;
        }
        out.positions.push_back(p);
        out.normals.push_back(triangle_normal(mesh, t));
        out.triangles.push_back(static_cast<uint32_t>(t));
    }
    if (options.noise > 0)
        add_gaussian_noise(out.positions, options.noise * bbox_diagonal(mesh), seed ^ 0x9e3779b97f4a7c15ULL);
    return out;
}

void add_gaussian_noise(std::vector<Vec3> &points, double sigma, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> gauss(0.0, sigma);
    for (Vec3 &p : points)
        for (int k = 0; k < 3; ++k) p[k] += gauss(rng);
}

}  // namespace gmpu::testing
