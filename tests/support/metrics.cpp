#include "metrics.hpp"

#include "aabb_tree.hpp"
#include "sampling.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gmpu::testing {

namespace {

// Distances (relative) from samples of one surface to the other, and the summed cosine
// between each sample's normal and the normal of the triangle it lands on.
struct Directed {
    std::vector<double> distances;
    double mean = 0, max = 0, cosine_sum = 0;
};

Directed measure(const MeshSamples &from, const TriangleMesh &to, double diagonal,
                 unsigned threads) {
    const AabbTree tree(to);
    const std::vector<AabbTree::Nearest> hits = tree.nearest_all(from.positions, threads);
    Directed d;
    d.distances.reserve(hits.size());
    for (size_t i = 0; i < hits.size(); ++i) {
        const double distance = hits[i].distance / diagonal;
        d.distances.push_back(distance);
        d.mean += distance;
        d.max = std::max(d.max, distance);
        d.cosine_sum += from.normals[i].dot(triangle_normal(to, hits[i].triangle));
    }
    d.mean /= static_cast<double>(hits.size());
    return d;
}

double share_within(const std::vector<double> &distances, double tau) {
    size_t within = 0;
    for (double d : distances) within += d <= tau;
    return static_cast<double>(within) / static_cast<double>(distances.size());
}

}  // namespace

const FScore *SurfaceComparison::fscore_at(double tau) const {
    for (const FScore &f : fscores)
        if (std::abs(f.tau - tau) <= 1e-12) return &f;
    return nullptr;
}

SurfaceComparison compare_surfaces(const TriangleMesh &output, const TriangleMesh &ground_truth,
                                   const ComparisonOptions &options) {
    const auto start = std::chrono::steady_clock::now();
    SurfaceComparison r;
    r.diagonal = bbox_diagonal(ground_truth);
    r.samples = options.samples;
    if (!(surface_area(ground_truth) > 0) || !(r.diagonal > 0) || options.samples == 0)
        throw std::invalid_argument("compare_surfaces: the ground truth has no area or no samples asked");

    if (!(surface_area(output) > 0)) {
        // Nothing reconstructed: nothing is accurate, nothing is complete.
        const double inf = std::numeric_limits<double>::infinity();
        const double nan = std::numeric_limits<double>::quiet_NaN();
        r.accuracy = r.normal_consistency = nan;
        r.completeness = r.chamfer_l1 = r.hausdorff = inf;
        for (double tau : options.thresholds) r.fscores.push_back({tau, 0, 0, 0});
    } else {
        const MeshSamples gt_samples = sample_mesh(ground_truth, options.samples, options.seed);
        const MeshSamples out_samples = sample_mesh(output, options.samples, options.seed + 1);
        const Directed to_gt = measure(out_samples, ground_truth, r.diagonal, options.threads);
        const Directed to_out = measure(gt_samples, output, r.diagonal, options.threads);
        r.accuracy = to_gt.mean;
        r.completeness = to_out.mean;
        r.chamfer_l1 = (r.accuracy + r.completeness) / 2;
        r.hausdorff = std::max(to_gt.max, to_out.max);
        r.normal_consistency =
            (to_gt.cosine_sum + to_out.cosine_sum) / static_cast<double>(2 * options.samples);
        for (double tau : options.thresholds) {
            FScore f{tau, share_within(to_gt.distances, tau), share_within(to_out.distances, tau), 0};
            if (f.precision + f.recall > 0)
                f.fscore = 2 * f.precision * f.recall / (f.precision + f.recall);
            r.fscores.push_back(f);
        }
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

OrientationScore orientation_accuracy(const std::vector<Vec3> &normals,
                                      const std::vector<Vec3> &gt_normals) {
    if (normals.size() != gt_normals.size())
        throw std::invalid_argument("orientation_accuracy: " + std::to_string(normals.size()) +
                                    " normals against " + std::to_string(gt_normals.size()) +
                                    " ground-truth normals");
    OrientationScore s;
    s.points = normals.size();
    for (size_t i = 0; i < normals.size(); ++i)
        s.correct += normals[i].dot(gt_normals[i]) > 0;  // NaN and zero normals fail here
    s.accuracy = s.points ? static_cast<double>(s.correct) / static_cast<double>(s.points) : 0;
    return s;
}

ShapeDeviation compare_to_shape(const TriangleMesh &mesh, const AnalyticShape &shape,
                                size_t samples, uint64_t seed) {
    ShapeDeviation d;
    if (!(surface_area(mesh) > 0) || samples == 0) {
        d.mean_distance = d.max_distance = d.mean_gap = d.max_gap =
            std::numeric_limits<double>::infinity();
        d.normal_agreement = d.inward_share = std::numeric_limits<double>::quiet_NaN();
        return d;
    }
    const MeshSamples on_mesh = sample_mesh(mesh, samples, seed);
    size_t inward = 0;
    for (size_t i = 0; i < on_mesh.size(); ++i) {
        const double distance = std::abs(shape.signed_distance(on_mesh.positions[i]));
        d.mean_distance += distance;
        d.max_distance = std::max(d.max_distance, distance);
        const double cosine = on_mesh.normals[i].dot(shape.normal(on_mesh.positions[i]));
        d.normal_agreement += cosine;
        inward += cosine < 0;
    }
    const auto n = static_cast<double>(on_mesh.size());
    d.mean_distance /= n;
    d.normal_agreement /= n;
    d.inward_share = static_cast<double>(inward) / n;

    const AabbTree tree(mesh);
    const OrientedPoints on_shape = shape.sample(samples, seed + 1);
    for (const AabbTree::Nearest &hit : tree.nearest_all(on_shape.positions)) {
        d.mean_gap += hit.distance;
        d.max_gap = std::max(d.max_gap, hit.distance);
    }
    d.mean_gap /= static_cast<double>(on_shape.size());
    return d;
}

}  // namespace gmpu::testing
