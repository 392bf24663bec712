// A closed thin shell sampled too sparsely for its two sheets: a hollow box, a pipe, a ring,
// a plate, walls one or two sample spacings thick or less.
//
// There every support of the octree holds points of both sheets, interleaved; the local fits
// wander between them, orientation has no side to give a point, and the blend closes the
// merged sheet into a blob. Yet each point's neighbourhood says plainly what it is: one smooth middle
// surface with every point a fixed distance a to one side of it or the other. Fitted so,
//     z = q(x, y) ± a         (q a quadratic height over the neighbourhood's plane)
// a noise-free wall leaves residuals far below the gap, where on a solid's surface the two
// "sheets" the split finds are its own shape's misfit, a few residuals apart. The reading
// needs no orientation: a point's outward normal points away from the middle, to its side.
//
// The field is then the wall itself, the blend of every nearby patch's slab,
//     f(x) = (Σ wᵢ(x) aᵢ − |Σ wᵢ(x) sᵢ hᵢ(x)|) / Σ wᵢ(x)
// hᵢ the height of x over patch i's middle surface and sᵢ = ±1 the patch's orientation,
// passed from patch to patch along the wall so the heights agree in sign: f is positive
// inside the wall, negative out. Round a fold or a corner (a box's edges) no patch reads two
// sheets; those patches blend in at a tenth of the weight, which closes the wall there.
// The patches reach a couple of spacings past the last points, and so would the wall, past
// every rim of a plate or a pipe's end. So inside the wall f is also held under
//     e(x) = τ R − |Pₜ(c(x) − x)|
// c(x) the centroid of the points around x (weights (1 − r²/R²)², R a few spacings) and Pₜ
// the projection on the wall's plane: within the sampled sheet c(x) is about x, and past a
// straight rim it falls behind x by 0.29 R at the rim and by more beyond it. e varies over
// R, not over the wall's thickness: it is read at the nodes of a lattice half a spacing
// apart (each once, kept) and interpolated, which spares a wide neighbour search per query.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

// One point's neighbourhood fitted as a middle surface and two sheets ± half_gap off it.
struct ShellPatch {
    Eigen::Vector3d origin;       // the point
    Eigen::Vector3d u, v, n;      // the neighbourhood's frame (n: across the sheets)
    double q[6] = {0, 0, 0, 0, 0, 0};  // middle height q(x, y) = q0 x² + q1 xy + q2 y² + q3 x + q4 y + q5
    double half_gap = 0.0;
    double separation = 0.0;      // the gap over the residuals' deviation
    double reach = 0.0;           // weight radius
    double spacing = 0.0;         // the neighbourhood's sample spacing, both sheets counted
    Eigen::Vector3d side_normal;  // unit, away from the middle, to the point's side
    bool two_sheets = false;      // separation reads a wall
    // +1 or -1: turns n (and the heights along it) to agree with the neighbouring patches',
    // so that heights blend with one sign across a whole connected wall.
    double orientation = 1.0;

    // Signed height of x over the middle surface, along its normal (first order).
    double height(const Eigen::Vector3d &x) const;
};

class ShellField {
public:
    ShellField() = default;
    // Fits every point's neighbourhood (its kNeighbours nearest).
    ShellField(const PointSet &points, Workers &workers, Progress &progress);

    // Whether an even sample of the points may read as a shell: a cheap look first, since
    // most clouds are solids and reading every point costs a sixth of a sparse cloud's run.
    static bool may_be_shell(const PointSet &points);

    bool empty() const { return patches_.empty(); }
    // The share of points whose neighbourhood reads as two sheets.
    double two_sheet_share() const { return two_sheet_share_; }
    // The median gap between the sheets where they were read (normalised units).
    double median_gap() const { return median_gap_; }
    // The grid (cubes along the normalised box's side) that draws the wall kCubesAcrossWall
    // cubes thick, at most kMaxGrid: a wall thinner than kMinCubesAcrossWall cubes of that
    // grid is drawn that thick (its faces a fraction of a cube off), not lost between corners
    // nor paid for with a grid whose cost grows as the cube of its resolution.
    int grid() const;
    // The median sample spacing of the neighbourhoods, both sheets counted.
    double median_spacing() const { return median_spacing_; }
    // Whether the whole cloud reads as a thin shell: two sheets in enough of its
    // neighbourhoods, under a sample spacing apart (in fewer of them where far thinner).
    bool whole_shell() const;

    // f at x (positive inside the wall); false where no patch reaches x. The gradient, if
    // asked, by central differences. `points`: the set the field was fitted to.
    bool value(const PointSet &points, const Eigen::Vector3d &x, double &f, Eigen::Vector3d *gradient) const;

    // The patches that may reach into the ball (centre, radius), in index order: gathered
    // once for a block of queries, they spare each query its own neighbour searches.
    void gather(const PointSet &points, const Eigen::Vector3d &centre, double radius,
                std::vector<uint32_t> &patches) const;
    // f at x as value() gives it (without the gradient), from `patches` (gather()'s for a
    // ball that holds x): the same patches take part, in the same order.
    bool value_among(const PointSet &points, const std::vector<uint32_t> &patches, const Eigen::Vector3d &x,
                     double &f) const;

    // Point i's outward normal: −∇f there, the wall's own (on a rim face it points past the
    // rim, where every patch's middle surface only knows the two faces), turned over where
    // the two-sheet patches reaching the point read it on the other sheet (near a fold); its
    // patch's side normal where f is flat.
    Eigen::Vector3d outward_normal(const PointSet &points, size_t i) const;

private:
    // value() from gather()'s patches for a ball that holds x and, with a gradient, the
    // central-difference samples kGradientStep round it.
    bool value_among(const PointSet &points, const std::vector<uint32_t> &patches, const Eigen::Vector3d &x,
                     double &f, Eigen::Vector3d *gradient) const;
    // Which sheet x lies on, as the two-sheet patches reaching it read it: the sum of their
    // normals turned to x's side of each middle surface, weighted as in the blend (patches
    // that put x within a fraction of a half gap of their middle abstain).
    Eigen::Vector3d side_vote(const std::vector<uint32_t> &patches, const Eigen::Vector3d &x) const;
    // e(x): positive within the sampled sheets, negative past their rims; at a lattice node,
    // and interpolated between them.
    double rim_at_node(const PointSet &points, const Eigen::Vector3d &x) const;
    double within_rims(const PointSet &points, const Eigen::Vector3d &x) const;

    std::vector<ShellPatch> patches_;
    // Each patch's origin and squared reach, packed for the scans over candidates.
    std::vector<Eigen::Vector4d> balls_;
    double widest_reach_ = 0.0;
    double two_sheet_share_ = 0.0, median_gap_ = 0.0, median_spacing_ = 0.0;
    double rim_step_ = 0.0;
    // e at the lattice nodes read so far, sharded by node so threads rarely wait.
    struct RimShard {
        std::mutex lock;
        std::unordered_map<int64_t, float> values;
    };
    std::unique_ptr<std::array<RimShard, 64>> rim_nodes_ = std::make_unique<std::array<RimShard, 64>>();
};

}  // namespace gmpu
