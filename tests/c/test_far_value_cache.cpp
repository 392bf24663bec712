// The far-sample cache of polygonize (implicit/far_value_cache.hpp): every block of a band
// asks for the samples on its lattice of every 4th corner, as SurfaceField::block_values
// does. Each answer must be the value computed at that very corner (a slot mix-up would give
// a neighbour's value and move the mesh), and a sample shared by several blocks must be
// computed once (else the cache saves nothing).
#include <cstdint>
#include <map>
#include <set>
#include <thread>
#include <tuple>
#include <vector>

#include "implicit/far_value_cache.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu;

namespace {

constexpr int kBlockCubes = 8, kStep = 4;
const int64_t kBlocks[3] = {6, 5, 4};

double sample_at(int64_t x, int64_t y, int64_t z) { return double(x) + 1000.0 * double(y) + 1e6 * double(z) + 0.5; }

// A band: a slab of blocks, one isolated block, and blocks on the grid's + faces.
std::vector<int64_t> band() {
    std::vector<int64_t> ids;
    auto id = [](int64_t x, int64_t y, int64_t z) { return x + kBlocks[0] * (y + kBlocks[1] * z); };
    for (int64_t y = 1; y < 4; ++y)
        for (int64_t x = 1; x < 5; ++x) ids.push_back(id(x, y, 1));
    ids.push_back(id(2, 2, 3));
    ids.push_back(id(5, 4, 3));
    return ids;
}

// Asks for every sample of `block`, as block_values does, and checks each answer.
void ask_block(FarValueCache &cache, int64_t block, std::map<std::tuple<int64_t, int64_t, int64_t>, int> *computed) {
    const int64_t bx = block % kBlocks[0], by = (block / kBlocks[0]) % kBlocks[1], bz = block / (kBlocks[0] * kBlocks[1]);
    for (int k = 0; k <= kBlockCubes; k += kStep)
        for (int j = 0; j <= kBlockCubes; j += kStep)
            for (int i = 0; i <= kBlockCubes; i += kStep) {
                const int64_t x = bx * kBlockCubes + i, y = by * kBlockCubes + j, z = bz * kBlockCubes + k;
                const double v = cache.value(x, y, z, [&] {
                    if (computed) ++(*computed)[{x, y, z}];
                    return sample_at(x, y, z);
                });
                assert_true(v == sample_at(x, y, z));
            }
}

void every_sample_is_its_corners_and_computed_once(void **) {
    const std::vector<int64_t> ids = band();
    FarValueCache cache(kBlocks, kBlockCubes, kStep, ids);
    std::map<std::tuple<int64_t, int64_t, int64_t>, int> computed;
    size_t asked = 0;
    for (int pass = 0; pass < 2; ++pass)  // the second pass reads everything back
        for (int64_t b : ids) ask_block(cache, b, &computed), asked += 27;
    size_t more_than_once = 0, calls = 0;
    for (const auto &c : computed) more_than_once += c.second > 1, calls += size_t(c.second);
    // Only the samples on the grid's + faces (the last block's + side) have no owner.
    const int64_t top[3] = {kBlocks[0] * kBlockCubes, kBlocks[1] * kBlockCubes, kBlocks[2] * kBlockCubes};
    for (const auto &c : computed)
        if (c.second > 1)
            assert_true(std::get<0>(c.first) == top[0] || std::get<1>(c.first) == top[1] || std::get<2>(c.first) == top[2]);
    assert_true(more_than_once > 0);  // the block at the grid's corner has some
    assert_true(calls < asked / 2);  // shared samples once, the second pass all read back
}

void concurrent_blocks_agree(void **) {
    const std::vector<int64_t> ids = band();
    FarValueCache cache(kBlocks, kBlockCubes, kStep, ids);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int pass = 0; pass < 50; ++pass)
                for (size_t b = 0; b < ids.size(); ++b) ask_block(cache, ids[(b + size_t(t) * 3) % ids.size()], nullptr);
        });
    for (std::thread &th : threads) th.join();
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_sample_is_its_corners_and_computed_once),
        cmocka_unit_test(concurrent_blocks_agree),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
