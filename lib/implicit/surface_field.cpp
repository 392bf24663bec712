#include "implicit/surface_field.hpp"

#include <cmath>


namespace gmpu {

namespace {
constexpr size_t kSideVotes = 8;
// The winding number overrules the side test when it is within this of 0 or 1. Telling
// 0 from 1 needs less accuracy than the far regions' sign (block_grid.cpp), so cells count
// as one dipole from kWindingFarRatio radii on (the far regions wait until 2).
constexpr double kDecisiveWinding = 0.25;
constexpr double kWindingFarRatio = 1.2;
constexpr double kFarAway = 1e6;  // normalised units: the data spans 1
}  // namespace

bool SurfaceField::trusted(const Eigen::Vector3d &x) const {
    thread_local std::vector<uint32_t> idx;
    idx.clear();
    // A little wider than needed: the kd-tree compares float distances.
    points_.within(x, widest_trust() * (1.0 + 1e-5) + 1e-7, idx);
    for (uint32_t i : idx)
        if ((x - points_.point(i)).norm() <= trust_radius(i)) return true;
    return false;
}

double SurfaceField::far_value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
    // Very far away (where the kd-tree's float distances would overflow), the data is a
    // point at the origin of the normalised frame: outside, at distance |x|.
    if (x.norm() > kFarAway) {
        if (gradient) *gradient = -x.normalized();
        return -x.norm();
    }
    // The sign: the winding number of all the oriented points where it is clearly 0 or 1;
    // else Hoppe's side test, voted over the k nearest points (weighted by closeness) so
    // that one poorly estimated normal (at the tip of a thin part, say) cannot flip a
    // region. The side test alone only sees the nearest points: far beyond a concave part
    // (above a back between two humps, say) their normals can all face away from x.
    double sign = 0.0;
    if (!winding_.empty()) {
        const double w = winding_.winding(x, kWindingFarRatio);
        if (w > 1.0 - kDecisiveWinding) sign = 1.0;
        else if (w < kDecisiveWinding) sign = -1.0;
    }
    thread_local std::vector<uint32_t> idx;
    thread_local std::vector<float> d2;
    points_.nearest(x, sign != 0.0 ? 1 : kSideVotes, idx, d2, search_bound_);
    if (idx.empty()) {
        if (gradient) gradient->setZero();
        return -search_bound_;  // no point within the search bound: outside
    }
    if (sign == 0.0) {
        double vote = 0.0;
        for (size_t k = 0; k < idx.size(); ++k) {
            const uint32_t i = idx[k];
            Eigen::Vector3d n(measures_.blend_normals[3 * i], measures_.blend_normals[3 * i + 1], measures_.blend_normals[3 * i + 2]);
            double side = (x - points_.point(i)).dot(n);
            vote += (side < 0.0 ? 1.0 : -1.0) / (std::sqrt(double(d2[k])) + 1e-12);
        }
        sign = vote > 0.0 ? 1.0 : -1.0;  // behind the outward normals: inside
    }
    const double distance = std::sqrt(double(d2[0]));
    if (gradient) {
        Eigen::Vector3d away = x - points_.point(idx[0]);
        // f = sign · distance grows away from the point inside and falls outside.
        *gradient = distance > 0.0 ? Eigen::Vector3d(sign * away / distance) : Eigen::Vector3d::Zero();
    }
    return sign * distance;
}

double SurfaceField::value(const Eigen::Vector3d &x, Eigen::Vector3d *gradient) const {
    double v;
    if (!trusted(x)) {
        // The smooth field covers the box (its outer part): it, not the far field, meets
        // its own band's edge.
        if (smooth_beyond_trust() && smooth_->value(x, v, gradient)) return v;
        return far_value(x, gradient);
    }
    return compose([&](Eigen::Vector3d *g) { return mpu_.value(x, g); }, x, gradient);
}

void SurfaceField::block_values(const LatticeBlock &block, const uint32_t *near, size_t near_count,
                                const uint8_t *skip, double *values, FarValueCache *far_cache) const {
    const int n = block.n, C = n + 1, S = kFarStep, CC = n / S + 1;  // coarse lattice step and size
    auto local = [C](int i, int j, int k) { return size_t(i + C * (j + C * k)); };

    // Trust by splatting every nearby point's ball onto the corners. Ranges are a corner
    // wider than the ball's box so rounding never decides; the squared-distance test does,
    // on corner coordinates computed exactly as block.corner() does, the same in every block.
    thread_local std::vector<uint8_t> trusted;
    trusted.assign(size_t(C) * C * C, 0);
    thread_local std::vector<double> axis[3];
    for (int d = 0; d < 3; ++d) {
        axis[d].resize(size_t(C));
        for (int i = 0; i < C; ++i) axis[d][size_t(i)] = block.grid_origin[d] + block.h * double(block.start[d] + i);
    }
    for (size_t m = 0; m < near_count; ++m) {
        const uint32_t p = near[m];
        const Eigen::Vector3d q = points_.point(p);
        const double r = trust_radius(p), r2 = r * r;
        int a[3], b[3];
        for (int d = 0; d < 3; ++d) {
            a[d] = std::max(0, int(std::floor((q[d] - r - axis[d][0]) / block.h)));
            b[d] = std::min(n, int(std::ceil((q[d] + r - axis[d][0]) / block.h)));
        }
        for (int k = a[2]; k <= b[2]; ++k) {
            const double dz = axis[2][size_t(k)] - q[2];
            for (int j = a[1]; j <= b[1]; ++j) {
                const double dy = axis[1][size_t(j)] - q[1], dyz = dy * dy + dz * dz;
                if (dyz > r2) continue;
                for (int i = a[0]; i <= b[0]; ++i) {
                    const double dx = axis[0][size_t(i)] - q[0];
                    if (dx * dx + dyz <= r2) trusted[local(i, j, k)] = 1;
                }
            }
        }
    }

    thread_local std::vector<double> coarse;
    thread_local std::vector<uint8_t> coarse_done;
    coarse.assign(size_t(CC) * CC * CC, 0.0);
    coarse_done.assign(size_t(CC) * CC * CC, 0);
    auto far = [&](int i, int j, int k) {
        const size_t c = size_t(i / S + CC * (j / S + CC * (k / S)));
        if (!coarse_done[c]) {
            auto sample = [&] { return far_value(block.corner(i, j, k), nullptr); };
            coarse[c] = far_cache ? far_cache->value(block.start[0] + i, block.start[1] + j, block.start[2] + k, sample)
                                  : sample();
            coarse_done[c] = 1;
        }
        return coarse[c];
    };
    // The thin shell's patches for the whole block, gathered once: every corner's query
    // would search nearly the same neighbourhood again.
    thread_local std::vector<uint32_t> shell_patches;
    if (shell_) {
        const Eigen::Vector3d centre = block.corner(0, 0, 0) + 0.5 * block.h * Eigen::Vector3d::Constant(n);
        shell_->gather(points_, centre, 0.5 * std::sqrt(3.0) * block.h * n * (1.0 + 1e-9), shell_patches);
    }
    for (int k = 0; k < C; ++k)
        for (int j = 0; j < C; ++j)
            for (int i = 0; i < C; ++i) {
                const size_t at = local(i, j, k);
                if (skip && skip[at]) continue;
                double v;
                if (trusted[at] && shell_) {
                    const Eigen::Vector3d x = block.corner(i, j, k);
                    if (!shell_->value_among(points_, shell_patches, x, v)) v = far_value(x, nullptr);
                } else if (trusted[at]) {
                    v = trusted_value(block.leaves_at(i, j, k), block.corner(i, j, k), nullptr);
                } else if (smooth_beyond_trust() && smooth_->value(block.corner(i, j, k), v, nullptr)) {
                    // Untrusted, but inside the smooth field's box: its value, as in value().
                } else {
                    // Trilinear in the coarse cell holding the corner.
                    const int ci = std::min(i / S, CC - 2) * S, cj = std::min(j / S, CC - 2) * S,
                              ck = std::min(k / S, CC - 2) * S;
                    const double u = double(i - ci) / S, w = double(j - cj) / S, t = double(k - ck) / S;
                    v = 0.0;
                    for (int c = 0; c < 8; ++c) {
                        const int di = c & 1, dj = c >> 1 & 1, dk = c >> 2 & 1;
                        const double weight = (di ? u : 1 - u) * (dj ? w : 1 - w) * (dk ? t : 1 - t);
                        if (weight > 0.0) v += weight * far(ci + S * di, cj + S * dj, ck + S * dk);
                    }
                    if (v == 0.0) v = -block.h;  // exactly between: outside, like every tie
                }
                if (!std::isfinite(v)) v = -block.h;
                values[at] = v;
            }
}

}  // namespace gmpu
