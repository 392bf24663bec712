// A smooth global implicit solved from the oriented points (GMPU_PARAM_SURFACE = 1, and the
// automatic choice 2 where the estimated noise says so).
//
// The MPU blend fits each leaf's points on their own, so at noise of a fraction of a
// percent of the diagonal its zero set follows the noise (bumps, handles, small closed
// pieces), and on sparse clouds the local fits have too few points to agree. Here one
// least-squares problem spans the whole cloud, in the spirit of screened Poisson (Kazhdan &
// Hoppe 2013): on a regular grid restricted to a band around the points, f minimises
//     ∫ |∇f − V|²  +  α Σᵢ Aᵢ f(pᵢ)²
// where V is the splatted field of the inward normals (unit where they agree; within a few
// grid steps of the points, 0 farther, fading where the points lie to one side of a node
// rather than under it: past a thin part's edge) and the
// screening term pulls the zero set through the points, all weighted alike (Aᵢ: their mean
// area), with α falling as the estimated noise grows past a knee (at least 0.4 of the finest
// grid step: noise under it is finer than the grid resolves); f is then shifted so that its median
// over the samples is 0 (its mean, beside thin walls: ZeroLevel), and then, cell by cell
// of a few grid steps, by what is left of the samples' median there beyond the noise
// (follow_local_level), and on parts thinner than the noise, corrected for the outward bias
// noise gives a curved surface's samples (thin_part_bias). The gradient term
// couples every sample to its neighbours, so a point's noise is averaged over its
// neighbourhood instead of bending the surface; the normals, which
// belief propagation made consistent, set the shape. f is about a signed distance,
// positive inside like the MPU blend. Values between grid nodes are trilinear; gradients
// are central differences at the nodes, interpolated the same way.
//
// The band reaches every point's trust radius (widened to `min_trust`, and at most a fixed
// number of grid steps, so the band's size is bounded by the points and the grid) plus a
// cell diagonal, so wherever the surface field trusts the data a smooth value exists (the
// outer field's, past a band cut short by that cap). Around it,
// an outer field solves the same problem on a coarser grid over the whole box (no normals
// away from the points: f settles flat there, as in screened Poisson), and the band's edge
// takes its values (Dirichlet): a misoriented patch's error then relaxes into the space
// around it instead of rising to the band's edge, and the surface field uses the outer
// field instead of its far sign wherever the band ends. The solve is cascadic: the same
// problem on a grid twice as coarse gives the fine solve its start, so conjugate gradients
// only have the fine detail left to converge (they converge slowly on the smooth,
// long-range part). `resolved` solves the problem again from other normals (the field's own
// at the points, pipeline/smooth_surface.cpp), outer field and band both, each started from
// the previous solution.
//
// smooth_field.cpp holds the grid, the cascade and the solve; smooth_field_band.cpp the
// splats and the edges' equations; smooth_field_samples.cpp the screening term;
// smooth_field_levels.cpp the zero levels' corrections and the thin parts' bias.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/huge_page_allocator.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"

namespace gmpu {

struct PointMeasures;

// How f's offset is set once the normals' integral is solved: the zero set through the
// samples' median value or through their mean. At noise, on a part thinner than a few σ, a
// sample pushed outward has f the more negative the farther it lies, while one pushed
// inward past the part's middle has f fall again: the samples' values have a long negative
// tail. Through their mean the zero set moves outward to balance that tail, and every thin
// part comes out too thick; the median is not moved by it. Where the fit found thin walls
// (two sheets in one support) the median let the sheets approach until they touched, and
// the mean keeps them apart (pipeline/smooth_surface.cpp chooses).
enum class ZeroLevel { median, mean };

// Whether f then follows the samples' level cell by cell (follow_local_level below); off
// only to observe the global level alone.
enum class LocalLevel { follow, off };

// Whether f is then corrected for the noise's bias on parts thinner than about 1.5 σ
// (thin_part_bias below); off only to observe the levels alone.
enum class ThinPartBias { correct, off };

// How much sparser than a dense cloud the samples are, as a factor of at least 1
// (pipeline/smooth_surface.cpp sets it for a sparse cloud's smooth surface; 1 elsewhere).
// On a sparse cloud the normals are the weaker half of the data: the orientation leaves a
// few percent of them wrong in patches, and a thin part (a leg, a tail, a blade), one or two
// grid steps thick, has its faces' normals cancel in V, so that f, only smooth there, lets
// the part thin out or vanish. The samples still mark where the part is: the screening
// weight (and its noise-free ceiling) grows by the factor, and the noise floor of V's
// narrowing across a sheet (kAcrossSigmas) shrinks by it.
struct Sparseness {
    double factor = 1.0;
};

// The outer field's grid step, in the band's steps: coarse enough to cover the whole box at a
// small cost, fine enough to keep a thin wall's two sides apart where it hands over. Where
// the band covers the surface's neighbourhood everywhere (a dense cloud) the outer field
// only holds the band's edge and the far sign, and a coarser grid does that as well for an
// eighth of the unknowns; where samples lie farther apart than the band reaches (a sparse
// cloud) the outer field carries the surface between them (pipeline/smooth_surface.cpp
// chooses).
struct OuterGrid {
    double steps = 2.0;
};

class SmoothField {
public:
    SmoothField() = default;
    // `spacing`: the grid step (normalised frame); `min_trust` widens every point's trust
    // radius for the band; `noise`: the fit's estimated noise deviation as a fraction of the
    // bounding-box diagonal (0 if none), which sets how hard the surface is pulled through
    // each sample; `level`: where the zero set lies among the samples. Checks its memory
    // estimate against `max_memory` (LIMIT_EXCEEDED) and polls `progress`, which it reports
    // to 1.
    SmoothField(const PointSet &points, const PointMeasures &measures, double spacing, double min_trust, double noise,
                ZeroLevel level, double max_memory, Workers &workers, Progress &progress,
                LocalLevel local = LocalLevel::follow, ThinPartBias thin = ThinPartBias::correct,
                Sparseness sparseness = {}, OuterGrid outer_grid = {});

    // f and optionally ∇f at x: the band's where it is defined, else the outer field's;
    // false outside the outer field's box (f is then undefined).
    bool value(const Eigen::Vector3d &x, double &f, Eigen::Vector3d *gradient) const;

    // The same problem solved again with `normals` (outward, 3 per point) in place of the
    // blend's, on the same grid and band edge, started from this field.
    SmoothField resolved(const PointSet &points, const PointMeasures &measures, const std::vector<float> &normals,
                         double noise, double max_memory, Workers &workers, Progress &progress) const;

    bool empty() const { return values_.empty(); }
    size_t unknowns() const { return values_.size(); }
    size_t outer_unknowns() const { return outer_ ? outer_->unknowns() : 0; }
    double spacing() const { return h_; }

private:
    static constexpr int B = 8;  // nodes per block side of the sparse storage
    // An empty field on a grid of step `step` with this one's splat reach and zero levels:
    // the outer field and the cascade's levels.
    SmoothField with_step(double step) const;
    // Returns the shift that made f's median (or mean, level_) over the samples 0. `boundary`
    // (may be null) gives the band's edge its values; `whole_box` solves on every node of
    // the box, not a band.
    double solve(const PointSet &points, const PointMeasures &measures, const std::vector<float> &normals,
                 double min_trust, double noise, double max_memory, const SmoothField *coarse,
                 const SmoothField *boundary, bool whole_box, int iterations, Workers &workers, Progress &progress);
    // What the points' splats leave at a node of the laid-out blocks: their weights' sum and
    // weighted point-to-plane distances, and, over V's shorter reach, the normals' weights,
    // weighted normals and weighted offsets from the node to the points.
    struct NodeSums {
        double wsum = 0.0, distance = 0.0, normal_wsum = 0.0;
        Eigen::Vector3d normal = Eigen::Vector3d::Zero(), offset = Eigen::Vector3d::Zero();
    };
    // The band's equations but the samples': per unknown its six neighbours (−x, +x, −y, +y,
    // −z, +z; −1 where the band ends), the edges' part of the diagonal, every edge's weight,
    // the right-hand side and the start.
    struct BandEquations {
        HugePageVector<int32_t> neighbours;
        Eigen::VectorXd edge_diagonal, rhs, start;
        double edge_weight = 0.0;
    };
    // The samples' screening term: per sample its cube's 8 corner unknowns, their trilinear
    // weights and its pull α·A (0: it does not pull); per unknown the (sample, corner) pairs
    // that land on it, in sample order: row_pairs[row_start[u] .. row_start[u + 1]).
    struct SampleRows {
        HugePageVector<int32_t> node;
        HugePageVector<double> weight;
        std::vector<double> scale;
        std::vector<uint32_t> row_start;
        HugePageVector<uint32_t> row_pairs;
        // f (the solution `x`) at sample i: its cube's corners blended trilinearly.
        double value(size_t i, const Eigen::VectorXd &x) const;
    };
    // The splats of the points (with `normals`) on the `slots` laid-out blocks
    // (smooth_field_band.cpp); `sigma`: the noise's deviation in normalised units.
    HugePageVector<NodeSums> splat(const PointSet &points, const PointMeasures &measures, const std::vector<float> &normals,
                                double min_trust, double sigma, int32_t slots, Workers &workers,
                                Progress &progress) const;
    // Numbers the band's unknowns (the nodes some splat reached, every node when
    // `whole_box`), and from the splats V and the start (`coarse`'s values where it has
    // them) and the edges' equations, with `boundary`'s values at the band's edge.
    BandEquations band_equations(HugePageVector<NodeSums> &&sums, const SmoothField *coarse,
                                 const SmoothField *boundary, bool whole_box, Workers &workers, Progress &progress);
    // The samples' rows for the screening weight that `noise` sets (smooth_field_samples.cpp);
    // adds their part of the matrix's diagonal to `diagonal`.
    SampleRows sample_rows(const PointSet &points, const PointMeasures &measures, double noise, int32_t unknowns,
                           Eigen::VectorXd &diagonal, Workers &workers, Progress &progress) const;
    // The index of node (x, y, z) of a laid-out block among the blocks' nodes.
    size_t slot_node(int64_t x, int64_t y, int64_t z) const;
    // The local zero level: where the samples of a cell of a few grid steps lie on one side
    // of f's zero set by more than the noise explains (their median past one standard error
    // of it), f there is shifted by the rest, at most a grid step, blended trilinearly
    // between the cells' centres. The smoothness term rounds what is sharp or thin at the
    // grid's scale (a gear's teeth and their roots, a tail's tip) the same way at every
    // noise; one global level cannot undo that, a stronger pull through every sample follows
    // the noise everywhere. `sigma`: the noise's deviation on this grid (normalised units).
    void follow_local_level(const PointSet &points, const SampleRows &samples, double sigma, Eigen::VectorXd &x,
                            Workers &workers, Progress &progress);
    // The noise's bias on thin parts, to be added to f (the solution `x`) once its levels
    // are set. Noise in every direction moves a sample off a curved surface outward on
    // average: f's expected value at the samples is f + σ²/2 Δf on the surface, so a zero
    // set through the samples' median lies outward by about σ² times the mean curvature.
    // On thick parts the smoothness term's own rounding, which moves convex parts inward,
    // roughly cancels that (a gear's edges lean on it); on parts thinner than about 1.5 σ
    // (legs, tails, fingers at 1 % noise) the bias stays, and there f takes a share of
    // σ²/2 Δf, at most a fraction of σ. A part is thin where f, probed inward from a node,
    // stops rising before it has risen as deep as a thick part's.
    Eigen::VectorXd thin_part_bias(const Eigen::VectorXd &x, double sigma, Workers &workers, Progress &progress) const;
    // The grid over the points' box and its blocks within a splat's reach of a point (every
    // block when `whole_box`); checks the memory this level will take against `max_memory`
    // (LIMIT_EXCEEDED). Returns the number of blocks laid out.
    int32_t lay_out(const PointSet &points, const PointMeasures &measures, double min_trust, bool whole_box,
                    double max_memory, Progress &progress);
    double splat_radius(const PointMeasures &measures, size_t i, double min_trust) const;
    // The grid nodes within `r` of `point`, as a box of node coordinates.
    void box_of(const Eigen::Vector3d &point, double r, int64_t lo[3], int64_t hi[3]) const;
    // The band's own value (the fine grid only).
    bool band_value(const Eigen::Vector3d &x, double &f, Eigen::Vector3d *gradient) const;
    int32_t node(int64_t x, int64_t y, int64_t z) const;  // unknown index, -1 outside the band
    // The grid cube holding grid coordinates t: its lowest corner, its 8 corners' unknowns
    // (corner k at base + (k & 1, k >> 1 & 1, k >> 2 & 1); −1 off the band) and trilinear
    // weights, and whether all 8 lie on the band.
    struct Corners {
        int64_t base[3];
        int32_t node[8];
        double weight[8];
        bool complete;
    };
    Corners corners(const Eigen::Vector3d &t) const;
    // visit(x, y, z, u) for every node u of the band, the grid's planes in parallel (each
    // node visited once, so a visit may write its own node's entries).
    template <class Visit>
    void for_each_node(Workers &workers, Progress &progress, const Visit &visit) const {
        parallel_for(0, size_t(nodes_[2]), workers, progress, [&](size_t plane) {
            const int64_t z = int64_t(plane);
            for (int64_t y = 0; y < nodes_[1]; ++y)
                for (int64_t x = 0; x < nodes_[0]; ++x) {
                    const int32_t u = node(x, y, z);
                    if (u >= 0) visit(x, y, z, u);
                }
        }, 1);
    }
    Eigen::Vector3d node_gradient(int64_t x, int64_t y, int64_t z) const;

    Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
    double h_ = 0.0;
    double min_trust_ = 0.0;
    double max_reach_ = 0.0;          // the longest splat radius, before the cell diagonal
    double fine_step_ = 0.0;          // the finest level's grid step, which the screening's knee reads
    ZeroLevel level_ = ZeroLevel::median;
    LocalLevel local_ = LocalLevel::follow;
    ThinPartBias thin_ = ThinPartBias::correct;
    Sparseness sparseness_;
    int64_t nodes_[3] = {0, 0, 0};     // per axis
    int64_t blocks_[3] = {0, 0, 0};    // per axis
    std::vector<int32_t> block_slot_;  // per block: its slot in node_index_ (÷ B³), or -1
    HugePageVector<int32_t> node_index_;  // per slot node: unknown index or -1
    std::vector<double> values_;       // per unknown
    std::shared_ptr<const SmoothField> outer_;  // the coarse field over the whole box, or null
};

}  // namespace gmpu
