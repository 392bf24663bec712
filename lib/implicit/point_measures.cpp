#include "implicit/point_measures.hpp"

#include <algorithm>
#include <cmath>

#include "core/median.hpp"
#include "core/resize_reporting.hpp"
#include "implicit/on_sheet_normal.hpp"

namespace gmpu {

namespace {

constexpr size_t kNeighbours = 8;
// Trust extends this many k-th-neighbour distances from a point: enough to bridge the
// gaps between samples so the trusted shell around the surface has no holes.
constexpr double kTrustSpacings = 1.5;
// On sparse clouds a leaf's fit holds few points and the blend extrapolates them: a few
// spacings out its quadrics bulge or close into sheets the data never showed (blobs and
// handles beside legs and horns). There the trust reaches only kSparseTrustSpacings, and the
// far field (signed by the winding number) decides beyond. Sparsity is the median k-th
// neighbour distance as a fraction of the bounding-box diagonal; the trust shrinks linearly
// from kDenseSpacing to kSparseSpacing, so denser clouds keep their trust exactly.
constexpr double kSparseTrustSpacings = 0.75;
constexpr double kDenseSpacing = 0.0125, kSparseSpacing = 0.015;
// Where another sheet faces a point (normals opposed past kOpposedNormals) the far field's
// sign is unreliable (the winding number of two close sparse sheets is not decisive, the
// nearest normals disagree): the point keeps its full trust and the blend, which fits both
// sheets, decides. The other sheet is one that a point faces within kOpposedNear of the full
// trust in any direction, or a parallel sheet across a gap under kOpposedGap of it (the
// facing point lies further along the normal than across it): the far side of a curved
// organic part a few spacings away is neither, and there the trust shrinks.
constexpr double kOpposedNormals = -0.5, kOpposedNear = 0.375, kOpposedGap = 0.5;
// Up to this many points, the areas come from every point's own neighbours.
constexpr size_t kExactMeasureLimit = 1u << 17;

void shrink_sparse_trust(const PointSet &points, const std::vector<float> &normals, Workers &workers,
                         Progress &progress, std::vector<float> &trust_radius) {
    if (trust_radius.empty() || normals.size() != 3 * trust_radius.size()) return;
    std::vector<float> radii(trust_radius);
    const double median_trust = median_in_place(radii);
    const double diagonal = points.world_diagonal() * points.normalisation().scale;
    if (!(diagonal > 0.0)) return;
    const double sparsity = median_trust / kTrustSpacings / diagonal;
    if (!(sparsity > kDenseSpacing)) return;
    const double t = std::min(1.0, (sparsity - kDenseSpacing) / (kSparseSpacing - kDenseSpacing));
    const float scale = float(1.0 - t * (1.0 - kSparseTrustSpacings / kTrustSpacings));
    const std::vector<float> full(trust_radius);
    auto normal = [&](uint32_t i) { return Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]); };
    parallel_for(0, trust_radius.size(), workers, progress, [&](size_t i) {
        thread_local std::vector<uint32_t> idx;
        idx.clear();
        const Eigen::Vector3d p = points.point(i);
        points.within(p, double(full[i]), idx);
        const Eigen::Vector3d n = normal(uint32_t(i));
        for (uint32_t j : idx) {
            if (!(n.dot(normal(j)) < kOpposedNormals)) continue;
            const Eigen::Vector3d d = points.point(j) - p;
            const double along = std::fabs(n.dot(d)), across = (d - n.dot(d) * n).norm();
            const bool near = d.norm() < kOpposedNear * double(full[i]);
            const bool parallel_sheet = along > across && along < kOpposedGap * double(full[i]);
            if (near || parallel_sheet) return;  // a second sheet near: keep the blend
        }
        trust_radius[i] = full[i] * scale;
    }, 512);
    progress.throw_if_cancelled();
}

// Area and trust radius of every point, from its k-th neighbour distance. Noise-limited fits
// keep their full trust: there the neighbour distances measure the noise as much as the
// spacing, and the smooth field, not the blend's extrapolation, is the surface.
void measure_areas(const Octree &tree, const PointSet &points, Workers &workers, Progress &progress,
                   bool noisy_fits, PointMeasures &out) {
    const size_t n = points.size();
    assign_reporting(out.area, n, progress);
    assign_reporting(out.trust_radius, n, progress);
    auto set = [&](uint32_t i, double rk) {
        out.area[i] = float(M_PI * rk * rk / double(kNeighbours));
        out.trust_radius[i] = float(kTrustSpacings * rk);
    };
    if (n <= kExactMeasureLimit) {
        // The k-th neighbour distance of every point: exact, and what sparse or nonuniform
        // clouds need.
        parallel_for(0, n, workers, progress, [&](size_t i) {
            thread_local std::vector<uint32_t> idx;
            thread_local std::vector<float> d2;
            points.nearest(points.point(i), kNeighbours + 1, idx, d2);  // includes the point itself
            set(uint32_t(i), std::sqrt(double(d2.back())));
        }, 512);
        progress.throw_if_cancelled();
    } else {
        // Dense clouds: the density of each leaf's support, as if the surface crossed its ball
        // through the centre (π R² of area for its points), gives the k-th neighbour distance
        // sqrt(k · area per point / π) without a million neighbour searches.
        for (const Cell &c : tree.cells) {
            progress.tick();
            if (!c.is_leaf() || c.point_end == c.point_begin) continue;
            const double area = M_PI * c.radius * c.radius / double(std::max<uint32_t>(1, c.support_count));
            const double rk = std::sqrt(double(kNeighbours) * area / M_PI);
            for (uint32_t k = c.point_begin; k < c.point_end; ++k) set(tree.order[k], rk);
        }
    }
    if (!noisy_fits) shrink_sparse_trust(points, out.normals, workers, progress, out.trust_radius);
    out.widest_trust = 0.0;
    for (float r : out.trust_radius) out.widest_trust = std::max(out.widest_trust, double(r));
}

}  // namespace

void restore_full_trust(PointMeasures &measures) {
    measures.widest_trust = 0.0;
    for (size_t i = 0; i < measures.area.size(); ++i) {
        const double rk = std::sqrt(double(kNeighbours) * double(measures.area[i]) / M_PI);
        measures.trust_radius[i] = float(kTrustSpacings * rk);
        measures.widest_trust = std::max(measures.widest_trust, double(measures.trust_radius[i]));
    }
}

std::vector<float> point_normals(const MpuFunction &mpu, const PointSet &points, Workers &workers,
                                 Progress &progress, bool from_sheets, std::vector<float> *blend_normals) {
    const Octree &tree = mpu.tree();
    std::vector<float> out;
    assign_reporting(out, 3 * points.size(), progress);
    if (blend_normals) assign_reporting(*blend_normals, 3 * points.size(), progress);
    std::vector<uint32_t> leaves;
    for (uint32_t i = 0; i < tree.cells.size(); ++i)
        if (tree.cells[i].is_leaf() && tree.cells[i].point_end > tree.cells[i].point_begin) leaves.push_back(i);
    parallel_for(0, leaves.size(), workers, progress, [&](size_t l) {
        const uint32_t cell = leaves[l];
        const Cell &c = tree.cells[cell];
        // The leaves blending inside this cell, gathered once for all its points.
        thread_local std::vector<uint32_t> near;
        const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.5 * c.size);
        mpu.gather(Eigen::AlignedBox3d(c.centre - half, c.centre + half), near);
        Eigen::Vector3d g;
        for (uint32_t k = c.point_begin; k < c.point_end; ++k) {
            // A coarse leaf can hold thousands of points: report within it too.
            if ((k - c.point_begin) % 16 == 15) progress.tick();
            uint32_t i = tree.order[k];
            Eigen::Vector3d p = points.point(i);
            mpu.value_among(near, p, &g);
            double gn = g.norm();
            if (!(gn > 1e-12) || !g.allFinite()) {
                mpu.cell_value(cell, p, &g);  // ∇f vanishes: the oriented local fit
                gn = g.norm();
            }
            Eigen::Vector3d n = gn > 0.0 ? Eigen::Vector3d(-g / gn) : Eigen::Vector3d::UnitZ();
            if (blend_normals)
                for (int d = 0; d < 3; ++d) (*blend_normals)[3 * i + d] = float(n[d]);
            Eigen::Vector3d s;
            if (from_sheets && on_sheet_gradient(mpu, near, p, s)) n = -s.normalized();
            for (int d = 0; d < 3; ++d) out[3 * i + d] = float(n[d]);
        }
    }, 1);  // leaves come coarsest first: one per chunk
    progress.throw_if_cancelled();
    return out;
}


PointMeasures measure_points(const MpuFunction &mpu, const PointSet &points, Workers &workers, Progress &progress,
                             bool noisy_fits) {
    PointMeasures out;
    out.normals = point_normals(mpu, points, workers, progress, noisy_fits, &out.blend_normals);
    // Areas and trust radii take no share of the bar: they cost little next to the normals.
    Progress areas_progress = progress.slice(1.0, 1.0);
    measure_areas(mpu.tree(), points, workers, areas_progress, noisy_fits, out);
    return out;
}

}  // namespace gmpu
