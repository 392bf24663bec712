#include "mesh/block_grid.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {
// Spare blocks beyond the widest trust radius keep the band off the grid's edge, so the
// region touching the edge surrounds everything. Two, not one: mark_band widens its boxes
// a hair, so with one a point at the box's edge can mark block 0, and the band would reach
// the grid's edge, leaving open a surface that crosses it.
double grid_pad(double widest, double h) { return widest + 2 * BlockGrid::B * h; }
// The winding number beyond which a block of the outside region lies within the solid: the
// enclosed regions' test, at its accuracy (across an opening the winding number falls
// through ½ gradually, and a coarser sum left the shark scan's holes as they were). Most
// blocks along the band are plainly outside, and a coarse sum (cells as one dipole from
// kCoarseFarRatio radii on, cheap where the noise-limited fit left large leaves) tells them
// when it reads under kPlainlyOutside.
constexpr double kInsideWinding = 0.5;
constexpr double kCoarseFarRatio = 1.2;
constexpr double kPlainlyOutside = 0.25;
}  // namespace

double BlockGrid::blocks_for(const PointSet &points, int resolution, double widest) {
    const double h = 1.0 / resolution, pad = grid_pad(widest, h);
    double blocks = 1.0;
    for (int d = 0; d < 3; ++d)
        blocks *= std::max(1.0, std::ceil((points.box_max()[d] - points.box_min()[d] + 2.0 * pad) / (h * B)));
    return blocks;
}

BlockGrid::BlockGrid(const PointSet &points, int resolution, const std::vector<float> &trust_radius, double min_trust,
                     const WindingField &winding, Progress &progress) {
    h = 1.0 / resolution;  // the longest side of the normalised box is 1
    double widest = min_trust;
    for (float r : trust_radius) widest = std::max(widest, double(r));
    const double pad = grid_pad(widest, h);
    origin = points.box_min() - Eigen::Vector3d::Constant(pad);
    for (int d = 0; d < 3; ++d) {
        double extent = points.box_max()[d] - points.box_min()[d] + 2.0 * pad;
        blocks[d] = std::max<int64_t>(1, int64_t(std::ceil(extent / (h * B))));
        cubes[d] = blocks[d] * B;
    }
    mark_band(points, trust_radius, min_trust, progress);
    InsideAnswers answers(band.size(), kNotAsked);
    sign_far_regions(winding, answers, progress);
    while (band_sign_seams()) sign_far_regions(winding, answers, progress);
}

Eigen::AlignedBox3d BlockGrid::block_box(int64_t id) const {
    int64_t p[3];
    block_position(id, p);
    Eigen::Vector3d lo = corner(p[0] * B, p[1] * B, p[2] * B);
    return Eigen::AlignedBox3d(lo, lo + Eigen::Vector3d::Constant(B * h));
}

void BlockGrid::mark_band(const PointSet &points, const std::vector<float> &trust_radius, double min_trust,
                          Progress &progress) {
    band.assign(size_t(blocks[0] * blocks[1] * blocks[2]), 0);
    const double block = B * h;
    for (size_t i = 0; i < points.size(); ++i) {
        if (i % 4096 == 0) progress.tick();  // O(n) on the calling thread
        const double r = std::max(double(trust_radius[i]), min_trust);
        const Eigen::Vector3d p = points.point(i) - origin;
        int64_t lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            // Closed boxes, widened a hair: a corner exactly on a block face within reach
            // marks the blocks on both sides, so no trusted corner is ever forced.
            lo[d] = std::clamp<int64_t>(int64_t(std::floor((p[d] - r) / block - 1e-9)), 0, blocks[d] - 1);
            hi[d] = std::clamp<int64_t>(int64_t(std::floor((p[d] + r) / block + 1e-9)), 0, blocks[d] - 1);
        }
        for (int64_t z = lo[2]; z <= hi[2]; ++z)
            for (int64_t y = lo[1]; y <= hi[1]; ++y)
                for (int64_t x = lo[0]; x <= hi[0]; ++x) band[size_t(block_id(x, y, z))] = 1;
    }
}

void BlockGrid::sign_far_regions(const WindingField &winding, InsideAnswers &answers, Progress &progress) {
    const int64_t nb = int64_t(band.size());
    std::vector<int32_t> region(size_t(nb), -1);
    std::vector<int8_t> region_sign;
    std::vector<int64_t> stack;
    for (int64_t s = 0; s < nb; ++s) {
        if (s % 4096 == 0) progress.tick();  // one winding query per region, O(blocks) in all
        if (band[size_t(s)] || region[size_t(s)] >= 0) continue;
        // Block 0 is at the grid's corner, outside the band: region 0 is outside.
        const int32_t id = int32_t(region_sign.size());
        progress.tick();  // a winding query per region
        region_sign.push_back(id > 0 && winding.winding(block_box(s).center()) > 0.5 ? 1 : -1);
        region[size_t(s)] = id;
        stack.push_back(s);
        for (size_t filled = 1; !stack.empty(); ++filled) {
            if (filled % 16384 == 0) progress.tick();  // the outside region spans most blocks
            const int64_t b = stack.back();
            stack.pop_back();
            each_face_neighbour(b, [&](int64_t next) {
                if (band[size_t(next)] || region[size_t(next)] >= 0) return;
                region[size_t(next)] = id;
                stack.push_back(next);
            });
        }
    }
    far_sign.assign(size_t(nb), 0);
    for (int64_t b = 0; b < nb; ++b)
        if (!band[size_t(b)]) far_sign[size_t(b)] = region_sign[size_t(region[size_t(b)])];
    sign_inside_reaches(winding, region, answers, progress);
}

void BlockGrid::sign_inside_reaches(const WindingField &winding, const std::vector<int32_t> &region,
                                    InsideAnswers &answers, Progress &progress) {
    auto inside = [&](int64_t b) {
        if (answers[size_t(b)] == kNotAsked) {
            progress.tick();
            const Eigen::Vector3d centre = block_box(b).center();
            answers[size_t(b)] = winding.winding(centre, kCoarseFarRatio) >= kPlainlyOutside &&
                                 winding.winding(centre) > kInsideWinding;
        }
        return answers[size_t(b)] == 1;
    };
    // An outside block next to block b, if inside, takes the inside sign and is filled from.
    std::vector<int64_t> stack;
    auto claim_neighbours = [&](int64_t b) {
        each_face_neighbour(b, [&](int64_t next) {
            if (region[size_t(next)] == 0 && far_sign[size_t(next)] < 0 && inside(next)) {
                far_sign[size_t(next)] = 1;
                stack.push_back(next);
            }
        });
    };
    // Seeds: the outside region's blocks along the band.
    for (int64_t b = 0; b < int64_t(band.size()); ++b) {
        if (b % 4096 == 0) progress.tick();
        if (band[size_t(b)]) claim_neighbours(b);
    }
    while (!stack.empty()) {
        const int64_t b = stack.back();
        stack.pop_back();
        claim_neighbours(b);
    }
}

bool BlockGrid::band_sign_seams() {
    std::vector<int64_t> seams;
    for (int64_t b = 0; b < int64_t(band.size()); ++b) {
        if (far_sign[size_t(b)] <= 0) continue;
        int64_t p[3];
        block_position(b, p);
        bool meets_outside = false;
        for (int64_t dz = -1; dz <= 1 && !meets_outside; ++dz)
            for (int64_t dy = -1; dy <= 1 && !meets_outside; ++dy)
                for (int64_t dx = -1; dx <= 1 && !meets_outside; ++dx) {
                    const int64_t x = p[0] + dx, y = p[1] + dy, z = p[2] + dz;
                    if (x < 0 || y < 0 || z < 0 || x >= blocks[0] || y >= blocks[1] || z >= blocks[2]) continue;
                    meets_outside = far_sign[size_t(block_id(x, y, z))] < 0;
                }
        if (meets_outside) seams.push_back(b);
    }
    for (int64_t b : seams) band[size_t(b)] = 1;
    return !seams.empty();
}

bool BlockGrid::touches_far(int64_t id) const {
    int64_t p[3];
    block_position(id, p);
    for (int64_t dz = -1; dz <= 1; ++dz)
        for (int64_t dy = -1; dy <= 1; ++dy)
            for (int64_t dx = -1; dx <= 1; ++dx) {
                const int64_t x = p[0] + dx, y = p[1] + dy, z = p[2] + dz;
                if (x < 0 || y < 0 || z < 0 || x >= blocks[0] || y >= blocks[1] || z >= blocks[2]) continue;
                if (!band[size_t(block_id(x, y, z))]) return true;
            }
    return false;
}

int8_t BlockGrid::forced_sign(int64_t x, int64_t y, int64_t z) const {
    int64_t lo[3], hi[3];
    const int64_t c[3] = {x, y, z};
    for (int d = 0; d < 3; ++d) {
        hi[d] = std::min(c[d] / B, blocks[d] - 1);
        lo[d] = (c[d] % B == 0 && c[d] > 0) ? c[d] / B - 1 : hi[d];
    }
    int8_t s = 0;
    for (int64_t bz = lo[2]; bz <= hi[2]; ++bz)
        for (int64_t by = lo[1]; by <= hi[1]; ++by)
            for (int64_t bx = lo[0]; bx <= hi[0]; ++bx) {
                const int8_t v = far_sign[size_t(block_id(bx, by, bz))];
                if (v < 0) return -1;  // outside wins a tie: it is never wrong to close a leak
                if (v > 0) s = 1;
            }
    return s;
}

}  // namespace gmpu
