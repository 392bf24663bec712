// The implicit that gmpu hands out: the MPU blend where it is trustworthy, and a
// sign from the winding number elsewhere.
//
// Local quadrics are only valid near the points they were fitted to; extended into empty
// space they cross zero in spurious sheets (a known MPU pitfall). So a query x is
// "trusted" when it lies within the trust radius of some input point (a few local
// spacings, never less than two polygonizer cubes); there f is the MPU blend. Farther out
// f = ±d(x), the distance to the nearest point, signed by which side of the nearby points'
// oriented normals x lies on (Hoppe's test, voted over the 8 nearest points), unless the
// winding number is clearly 0 or 1 there (it sees every point, and the
// nearest ones can all face away from x beyond a concave part): continuous
// enough at the border (the blend is about a signed distance too) and never zero, so no
// surface can appear away from the data. With a smooth field (smooth_field.hpp), trusted
// queries take its value instead of the blend's wherever it is defined, and untrusted ones
// inside its box take its outer field instead of the far field (the two meet at the band's
// edge with the same values, where the far sign could disagree).
// Guided by the smooth field (guided_blend.hpp), trusted queries take the blend held to
// the smooth field, and untrusted ones the far field, as for the blend alone.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "geometry/point_set.hpp"
#include "implicit/far_value_cache.hpp"
#include "implicit/guided_blend.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/shell_field.hpp"
#include "implicit/smooth_field.hpp"
#include "implicit/winding_field.hpp"

namespace gmpu {

// A cubic block of lattice corners for one batch of queries: corner (i, j, k), 0 <= i, j, k
// <= n, sits at grid_origin + h · (start + (i, j, k)) (the same arithmetic for every block,
// so blocks sharing a corner agree bit for bit). `leaves` are the MPU leaves gathered for
// each octant sub-block of n/2 cubes a side (MpuFunction::gather), octant bit 0: +x.
struct LatticeBlock {
    Eigen::Vector3d grid_origin;
    double h = 0.0;
    int64_t start[3] = {0, 0, 0};
    int n = 0;
    const std::vector<uint32_t> *leaves[8] = {};

    Eigen::Vector3d corner(int i, int j, int k) const {
        return grid_origin + h * Eigen::Vector3d(double(start[0] + i), double(start[1] + j), double(start[2] + k));
    }
    // The leaves for a corner (0..n per axis) or a cube (0..n-1): a sub-block whose box holds it.
    const std::vector<uint32_t> &leaves_at(int i, int j, int k) const {
        const int half = n / 2;
        return *leaves[std::min(i / half, 1) | std::min(j / half, 1) << 1 | std::min(k / half, 1) << 2];
    }
};

class SurfaceField {
public:
    // `winding` (built from the same measures) signs the far field where it is decisive
    // (see far_value); an empty one leaves it to the side test. All are kept by reference
    // except the blend, a small view.
    // `smooth` (may be null or empty) replaces the blend where it is defined, or with a
    // finite limit in `guide` guides it (guided_blend.hpp). `shell` (may be null or empty)
    // replaces both: trusted queries take the thin shell's wall (shell_field.hpp), or the far
    // value where no patch of it reaches.
    SurfaceField(const MpuFunction &mpu, const PointSet &points, const PointMeasures &measures,
                 const WindingField &winding, const SmoothField *smooth = nullptr, const Guide &guide = Guide(),
                 const ShellField *shell = nullptr)
        : mpu_(mpu), points_(points), measures_(measures), winding_(winding),
          smooth_(smooth && !smooth->empty() ? smooth : nullptr), guide_(guide),
          shell_(shell && !shell->empty() ? shell : nullptr) {}

    // The same field for a polygonizer's grid: `min_trust` widens every trust radius to at
    // least that (two cube sizes, so every cube the surface crosses has its corners
    // trusted); `search_bound` bounds the neighbour searches of untrusted queries (the polygonizer
    // knows every query it makes has a point within that distance, and bounded searches
    // are much cheaper far from the data).
    SurfaceField bounded(double min_trust, double search_bound) const {
        SurfaceField f = *this;
        f.min_trust_ = min_trust;
        f.search_bound_ = search_bound;
        return f;
    }

    // f and optionally ∇f at x (normalised frame).
    double value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const;

    // f at every corner of `block` whose skip flag is 0 (skip may be null), into
    // values[i + (n+1)(j + (n+1) k)]. Trust comes from the `near` points only: every point
    // whose (widened) trust ball may reach the block. Untrusted corners take the far field
    // sampled on the coarse lattice of every kFarStep-th corner and interpolated: its sign
    // only matters away from the data, where it varies slowly, and this costs 1/64 of the
    // neighbour searches. `far_cache` (may be null) keeps those samples for the blocks that
    // share them (a lattice of kFarStep over the grid the blocks' `start`s index).
    static constexpr int kFarStep = 4;
    void block_values(const LatticeBlock &block, const uint32_t *near, size_t near_count, const uint8_t *skip,
                      double *values, FarValueCache *far_cache = nullptr) const;

    // The trusted value at x (the caller knows x is trusted): the smooth field's where it
    // is defined (guiding the MPU blend's, if so made), else the MPU blend's among `leaves`.
    double trusted_value(const std::vector<uint32_t> &leaves, const Eigen::Vector3d &x,
                         Eigen::Vector3d *gradient) const {
        return compose([&](Eigen::Vector3d *g) { return mpu_.value_among(leaves, x, g); }, x, gradient);
    }

    // Whether x lies within some point's trust radius (widened to min_trust).
    bool trusted(const Eigen::Vector3d &x) const;
    // The far field: ±(distance to the nearest point), signed by the nearby points' normals.
    double far_value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const;
    // Trust radius of point i, widened to min_trust.
    double trust_radius(uint32_t i) const { return std::max(double(measures_.trust_radius[i]), min_trust_); }
    double widest_trust() const { return std::max(measures_.widest_trust, min_trust_); }

    // Whether the smooth field guides the blend rather than replacing it.
    bool guided() const { return smooth_ && guide_.active(); }
    // Whether untrusted queries take the smooth field's (outer) value, not the far field.
    bool smooth_beyond_trust() const { return smooth_ && !guided(); }

    const MpuFunction &mpu() const { return mpu_; }
    const PointSet &points() const { return points_; }
    const PointMeasures &measures() const { return measures_; }
    const WindingField &winding() const { return winding_; }

private:
    // The trusted value from `blend(gradient)`, the blend's value at x.
    template <class Blend>
    double compose(const Blend &blend, const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
        double s;
        if (shell_) return shell_->value(points_, x, s, gradient) ? s : far_value(x, gradient);
        if (!smooth_) return blend(gradient);
        if (!guided()) return smooth_->value(x, s, gradient) ? s : blend(gradient);
        Eigen::Vector3d gs, gb;
        const double b = blend(gradient ? &gb : nullptr);
        if (!smooth_->value(x, s, gradient || guide_.widens() ? &gs : nullptr)) {
            if (gradient) *gradient = gb;
            return b;
        }
        return guided_value(b, s, guide_.widens() ? guide_.limit_at(gs) : guide_.limit, &gb, &gs, gradient);
    }

    MpuFunction mpu_;
    const PointSet &points_;
    const PointMeasures &measures_;
    const WindingField &winding_;
    const SmoothField *smooth_ = nullptr;
    Guide guide_;
    const ShellField *shell_ = nullptr;
    double min_trust_ = 0.0, search_bound_ = INFINITY;
};

}  // namespace gmpu
