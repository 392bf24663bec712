// Max-product belief propagation in the log domain (min-sum) for binary labels
// ℓ ∈ {+1, −1} on a small graph (paper eqs. 5–7):
//   E(L) = Σ_i E_d(ℓ_i) + Σ_ij E_s(ℓ_i, ℓ_j),  E_d(ℓ) = −λ ℓ,  E_s = −ℓ_i ℓ_j J_ij.
// Nodes whose label is already known are clamped. Because labels are binary, each message
// is stored as the single difference m(+1) − m(−1).
#pragma once

#include <cstdint>
#include <vector>

namespace gmpu {

struct BpGraph {
    // Per node: 0 = free, +1 / −1 = clamped to that label.
    std::vector<int8_t> clamp;
    // Undirected edges (local node indices) with their agreement J.
    struct Edge {
        uint32_t a, b;
        double agreement;
    };
    std::vector<Edge> edges;
};

struct BpResult {
    std::vector<int8_t> label;   // ±1 per node
    std::vector<double> margin;  // |belief(+1) − belief(−1)|: how decided each label is
};

// Loopy min-sum with synchronous updates until messages settle or `max_iterations`.
BpResult solve_bp(const BpGraph &graph, double data_weight, int max_iterations);

}  // namespace gmpu
