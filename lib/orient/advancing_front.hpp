// Algorithm 1 of the paper: orientation propagated as an advancing front. Each connected
// component starts from a seed leaf (kept as fitted). The front holds the unlabelled leaves
// next to labelled ones; the most strongly constrained one is taken first (the paper's
// FIFO front, ordered by evidence so that ambiguous cells wait for more labelled
// neighbours). For the active leaf a local graph is grown over unlabelled leaves, with
// every labelled leaf it touches clamped, belief propagation is run on it, and the active
// leaf takes its MAP label.
//
// The paper's FIFO order and a plain weighted vote of the labelled neighbours (instead of
// belief propagation) are kept as options so that tests and tests/bench/orient_ablation
// can measure what each part contributes (README, "What belief propagation adds"); the
// library always uses the defaults.
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "model/octree.hpp"
#include "orient/leaf_graph.hpp"

namespace gmpu {

enum class FrontOrder : uint8_t {
    most_evidence_first,  // the default: the leaf with the largest |Σ J ℓ| goes next
    fifo,                 // the paper's queue: leaves in the order they joined the front
};
enum class LeafDecision : uint8_t {
    belief_propagation,  // the default: MAP label of BP on the local graph
    weighted_vote,       // sign of Σ J ℓ over labelled neighbours only (ties keep the fit)
};

struct FrontOptions {
    FrontOrder order = FrontOrder::most_evidence_first;
    LeafDecision decision = LeafDecision::belief_propagation;
    int rings = 2;              // hops of unlabelled leaves in each local graph
    // λ of E_d(ℓ) = −λ ℓ. The paper uses 1, on graphs grown only until they reach one
    // labelled leaf; on our two-ring graphs, dozens of free leaves would each add a vote
    // for keeping their arbitrary fitted sign and outweigh the labelled evidence, so the
    // prior here only breaks ties.
    double data_weight = 0.01;
    int bp_iterations = 12;
};

// Returns ±1 per graph node: +1 keeps the fitted sign, −1 flips it. Labels are consistent
// within each component; the global sign of a component is decided later (outward.hpp).
std::vector<int8_t> propagate_orientation(const Octree &tree, const LeafGraph &graph,
                                          const std::vector<uint32_t> &component,
                                          uint32_t component_count, const FrontOptions &options,
                                          Progress &progress);

}  // namespace gmpu
