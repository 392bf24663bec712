#include "implicit/far_value_cache.hpp"

namespace gmpu {

FarValueCache::FarValueCache(const int64_t blocks[3], int block_cubes, int step, const std::vector<int64_t> &in_use)
    : block_cubes_(block_cubes), step_(step), side_(block_cubes / step) {
    for (int d = 0; d < 3; ++d) blocks_[d] = blocks[d];
    per_block_ = size_t(side_) * side_ * side_;
    block_slot_.assign(size_t(blocks_[0] * blocks_[1] * blocks_[2]), -1);
    // A block's samples lie on its − faces and inside it; those on its + faces belong to the
    // neighbours there, which get slots too.
    int32_t slots = 0;
    for (int64_t id : in_use) {
        const int64_t x = id % blocks_[0], y = (id / blocks_[0]) % blocks_[1], z = id / (blocks_[0] * blocks_[1]);
        for (int64_t dz = 0; dz <= 1; ++dz)
            for (int64_t dy = 0; dy <= 1; ++dy)
                for (int64_t dx = 0; dx <= 1; ++dx) {
                    if (x + dx >= blocks_[0] || y + dy >= blocks_[1] || z + dz >= blocks_[2]) continue;
                    int32_t &s = block_slot_[size_t(x + dx + blocks_[0] * (y + dy + blocks_[1] * (z + dz)))];
                    if (s < 0) s = slots++;
                }
    }
    const size_t count = size_t(slots) * per_block_;
    samples_.reset(new std::atomic<double>[count]);
    for (size_t i = 0; i < count; ++i) samples_[i].store(std::numeric_limits<double>::quiet_NaN(), std::memory_order_relaxed);
}

std::atomic<double> *FarValueCache::slot(int64_t x, int64_t y, int64_t z) {
    if (per_block_ == 0) return nullptr;
    const int64_t c[3] = {x, y, z};
    int64_t block[3], local[3];
    for (int d = 0; d < 3; ++d) {
        if (c[d] < 0 || c[d] % step_ != 0) return nullptr;
        block[d] = c[d] / block_cubes_;
        if (block[d] >= blocks_[d]) return nullptr;  // the grid's far + faces: no owner
        local[d] = (c[d] - block[d] * block_cubes_) / step_;
    }
    const int32_t s = block_slot_[size_t(block[0] + blocks_[0] * (block[1] + blocks_[1] * block[2]))];
    if (s < 0) return nullptr;
    return &samples_[size_t(s) * per_block_ + size_t(local[0] + side_ * (local[1] + side_ * local[2]))];
}

}  // namespace gmpu
