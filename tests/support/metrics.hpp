// Ground-truth metrics, the same for gmpu and every peer (DESIGN.md, "How we measure").
// Every distance is exact (point to triangle, through AabbTree) and relative to the
// ground truth's bounding-box diagonal.
#pragma once

#include "analytic_shapes.hpp"
#include "triangle_mesh.hpp"

#include <cstdint>
#include <vector>

namespace gmpu::testing {

struct FScore {
    double tau = 0;        // threshold, relative to the diagonal (0.01 = 1 %)
    double precision = 0;  // share of output samples within tau of the ground truth
    double recall = 0;     // share of ground-truth samples within tau of the output
    double fscore = 0;     // harmonic mean (0 when both are 0)
};

struct SurfaceComparison {
    double diagonal = 0;  // ground truth's bounding-box diagonal: the unit below
    size_t samples = 0;   // per surface
    // Mean distance of output samples to the ground truth (accuracy), of ground-truth
    // samples to the output (completeness), their mean (Chamfer-L1), and the larger
    // of the two maxima (Hausdorff, a lower bound from the samples).
    double accuracy = 0, completeness = 0, chamfer_l1 = 0, hausdorff = 0;
    std::vector<FScore> fscores;  // one per ComparisonOptions::thresholds, same order
    // Mean cosine between each sample's triangle normal and the normal of the nearest
    // triangle on the other surface, both directions pooled: 1 when the normals agree,
    // −1 for an inside-out surface.
    double normal_consistency = 0;
    double seconds = 0;  // wall time of the whole comparison

    const FScore *fscore_at(double tau) const;  // nullptr when tau was not asked for
};

struct ComparisonOptions {
    size_t samples = 100000;  // area-uniform samples on each surface
    uint64_t seed = 1;        // ground truth uses seed, the output seed + 1
    std::vector<double> thresholds{0.005, 0.01};
    unsigned threads = 0;  // 0: every core
};

// Scores output against ground_truth. An output without area (an empty reconstruction)
// gets accuracy NaN, completeness, Chamfer and Hausdorff +inf, F-scores 0 and normal
// consistency NaN. Throws std::invalid_argument when the ground truth has no area.
SurfaceComparison compare_surfaces(const TriangleMesh &output, const TriangleMesh &ground_truth,
                                   const ComparisonOptions &options = {});

struct OrientationScore {
    size_t points = 0;
    size_t correct = 0;  // dot product with the ground-truth normal > 0
    double accuracy = 0; // correct / points (0 for no points)
};

// Orientation accuracy of per-point normals against ground-truth outward normals of the
// same points in the same order. No global flip is allowed: outward is part of the job.
// A zero or non-finite normal counts as wrong. Throws std::invalid_argument when the
// sizes differ.
OrientationScore orientation_accuracy(const std::vector<Vec3> &normals,
                                      const std::vector<Vec3> &gt_normals);

// A mesh against a solid known in closed form (for tests on analytic shapes). Distances
// are absolute (the caller knows the shape's size).
struct ShapeDeviation {
    double mean_distance = 0, max_distance = 0;  // mesh samples → shape boundary (|SDF|)
    double mean_gap = 0, max_gap = 0;            // shape samples → mesh (holes, missing parts)
    // Mean cosine between each mesh sample's triangle normal and the shape's outward
    // normal there: 1 when wound outward, −1 inside-out.
    double normal_agreement = 0;
    double inward_share = 0;  // share of mesh samples whose triangle faces inward
};

// An empty mesh gets infinite distances and gaps and NaN agreement.
ShapeDeviation compare_to_shape(const TriangleMesh &mesh, const AnalyticShape &shape,
                                size_t samples = 20000, uint64_t seed = 1);

}  // namespace gmpu::testing
