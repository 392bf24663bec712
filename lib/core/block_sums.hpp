// Loops and sums over an index range, cut into fixed blocks that run on the workers. A sum
// adds its blocks' partial sums in block order, so the result does not depend on the thread
// count or on which thread took which block: a reconstruction gives the same bits on 1 or
// 64 threads, which a plain parallel reduction would not.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "core/parallel.hpp"

namespace gmpu {

// Indices per block: large enough that handing out a block costs little next to its work,
// small enough that a few hundred thousand indices make blocks for every thread.
constexpr size_t kSumBlock = 4096;

// Calls body(begin, end) for every block of [0, n) on `workers`; `progress` (a zero-width
// slice where the caller reports its own) is only polled for cancellation.
template <class Body>
void block_for(size_t n, Workers &workers, Progress &progress, const Body &body) {
    const size_t blocks = (n + kSumBlock - 1) / kSumBlock;
    parallel_for(0, blocks, workers, progress, [&](size_t b) {
        body(b * kSumBlock, std::min(n, (b + 1) * kSumBlock));
    }, 1);
}

// K sums at once: body(begin, end) returns its block's K partial sums.
template <size_t K, class Body>
std::array<double, K> block_sums(size_t n, Workers &workers, Progress &progress, const Body &body) {
    const size_t blocks = (n + kSumBlock - 1) / kSumBlock;
    std::vector<std::array<double, K>> partial(blocks);
    parallel_for(0, blocks, workers, progress, [&](size_t b) {
        partial[b] = body(b * kSumBlock, std::min(n, (b + 1) * kSumBlock));
    }, 1);
    std::array<double, K> total{};
    for (const std::array<double, K> &p : partial)
        for (size_t k = 0; k < K; ++k) total[k] += p[k];
    return total;
}

}  // namespace gmpu
