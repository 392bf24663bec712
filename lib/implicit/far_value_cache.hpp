// Far-field samples shared between the blocks of one polygonize call. Each block samples the
// far field (SurfaceField::far_value: a winding number and a neighbour search) on the
// lattice of every `step`-th grid corner; a sample on a block's face or edge is wanted by
// up to 8 blocks. The value is a function of the corner's position alone, so it is computed
// once, stored, and every later block reads the same bits it would have computed.
//
// Storage is sparse: each block that may ask owns the (block_cubes / step)³ samples on its
// − faces and inside it; the band blocks' neighbours on the + sides own those on the band's
// + faces. A sample no block owns (on the grid's own + faces) is computed and not kept. Safe for concurrent use: two threads may
// both compute a missing sample, and both store the same value.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace gmpu {

class FarValueCache {
public:
    FarValueCache() = default;
    // `blocks`: the grid's blocks per axis, each `block_cubes` cubes a side (a multiple of
    // `step`); `in_use`: the ids x + blocks[0] (y + blocks[1] z) of the blocks that ask.
    FarValueCache(const int64_t blocks[3], int block_cubes, int step, const std::vector<int64_t> &in_use);

    // The sample at grid corner (x, y, z) (each a multiple of the step): the stored one, else
    // compute() — stored when the corner has a slot.
    template <class Compute>
    double value(int64_t x, int64_t y, int64_t z, Compute &&compute) {
        std::atomic<double> *s = slot(x, y, z);
        if (!s) return compute();
        double v = s->load(std::memory_order_relaxed);
        if (std::isnan(v)) {
            v = compute();
            s->store(v, std::memory_order_relaxed);
        }
        return v;
    }

    // Memory, for the polygonizer's budget: per block of the grid (its slot index) and, at
    // most, per block in use (its samples and those of up to 7 neighbours it adds).
    static constexpr double kBytesPerGridBlock = sizeof(int32_t);
    static constexpr double bytes_per_block_in_use(int block_cubes, int step) {
        return 8.0 * double(block_cubes / step) * double(block_cubes / step) * double(block_cubes / step) * sizeof(double);
    }

private:
    std::atomic<double> *slot(int64_t x, int64_t y, int64_t z);

    int64_t blocks_[3] = {0, 0, 0};
    int block_cubes_ = 0, step_ = 1, side_ = 0;  // side_: samples per block side
    size_t per_block_ = 0;
    std::vector<int32_t> block_slot_;  // per grid block: first sample's index / per_block_, or -1
    std::unique_ptr<std::atomic<double>[]> samples_;
};

}  // namespace gmpu
