// The polygonizer's sparse grid: cubes of size h grouped in blocks of 8³. Only the band —
// the blocks within reach of some point's trust radius — is ever evaluated. The other
// blocks form connected far regions, each wholly inside or outside: the one touching the
// grid's edge is outside; enclosed ones (cavities, the inside of thick parts) ask the
// winding number once. A corner touching a far block takes its region's sign, so the
// band's border never changes sign within a region and every surface closes inside it;
// where regions of opposite signs meet across an edge or a corner, the inside blocks there
// join the band.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/winding_field.hpp"

namespace gmpu {

struct BlockGrid {
    static constexpr int B = 8;  // cubes per block side

    Eigen::Vector3d origin;
    double h = 0.0;
    int64_t cubes[3] = {0, 0, 0};   // per axis, a multiple of B
    int64_t blocks[3] = {0, 0, 0};  // per axis
    std::vector<uint8_t> band;      // per block
    std::vector<int8_t> far_sign;   // per block: 0 in the band, else its region's sign

    // `trust_radius[i]`: how far from point i the band must extend (at least min_trust).
    BlockGrid(const PointSet &points, int resolution, const std::vector<float> &trust_radius, double min_trust,
              const WindingField &winding, Progress &progress);

    // Blocks of the grid the constructor would make, with `widest` the largest trust radius: known
    // before the grid is allocated, for the memory estimate.
    static double blocks_for(const PointSet &points, int resolution, double widest);

    Eigen::Vector3d corner(int64_t x, int64_t y, int64_t z) const {
        return origin + h * Eigen::Vector3d(double(x), double(y), double(z));
    }
    uint64_t corner_id(int64_t x, int64_t y, int64_t z) const {
        return uint64_t(x + (cubes[0] + 1) * (y + (cubes[1] + 1) * z));
    }
    int64_t block_id(int64_t x, int64_t y, int64_t z) const { return x + blocks[0] * (y + blocks[1] * z); }
    void block_position(int64_t id, int64_t pos[3]) const {
        pos[0] = id % blocks[0];
        pos[1] = (id / blocks[0]) % blocks[1];
        pos[2] = id / (blocks[0] * blocks[1]);
    }
    Eigen::AlignedBox3d block_box(int64_t id) const;

    // Sign imposed on grid corner (x, y, z) by the far blocks touching it, 0 if none. A
    // function of the corner alone, so every block sharing it agrees.
    int8_t forced_sign(int64_t x, int64_t y, int64_t z) const;
    // Whether any of the 26 blocks around a band block is far (else no corner is forced).
    bool touches_far(int64_t id) const;

    size_t block_count() const { return band.size(); }

private:
    void mark_band(const PointSet &points, const std::vector<float> &trust_radius, double min_trust, Progress &progress);
    // Per block, what sign_inside_reaches asked the winding number: kNotAsked, or whether
    // the block lies inside. A block's answer stays the same as the regions are made anew.
    static constexpr uint8_t kNotAsked = 2;
    using InsideAnswers = std::vector<uint8_t>;
    void sign_far_regions(const WindingField &winding, InsideAnswers &answers, Progress &progress);
    // The outside region can reach into the solid through an opening the band leaves (the
    // bore of an open-ended tube whose two faces the noise merged into one sheet, a scan's
    // hole): its blocks reached from the band across blocks whose winding number says
    // inside take the inside sign, so the surface closes across the opening (the seams
    // between them join the band) instead of around the band's edge inside the solid.
    void sign_inside_reaches(const WindingField &winding, const std::vector<int32_t> &region, InsideAnswers &answers,
                             Progress &progress);
    // Calls visit(next) for each block sharing a face with block b.
    template <class Visit>
    void each_face_neighbour(int64_t b, Visit &&visit) const {
        const int64_t step[3] = {1, blocks[0], blocks[0] * blocks[1]};
        int64_t pos[3];
        block_position(b, pos);
        for (int d = 0; d < 3; ++d)
            for (int side = -1; side <= 1; side += 2)
                if (pos[d] + side >= 0 && pos[d] + side < blocks[d]) visit(b + side * step[d]);
    }
    // Adds to the band every inside far block that meets an outside one across an edge or a
    // corner only (the regions are face-connected, so two of opposite signs can touch so):
    // the corners they share take the outside's sign, so the surface passes through the
    // inside block, which must then be marched. Returns whether it added any.
    bool band_sign_seams();
};

}  // namespace gmpu
