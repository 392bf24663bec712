#include "orient/advancing_front.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <queue>

#include "orient/belief_propagation.hpp"

namespace gmpu {

namespace {

// A seed should sit in a well-determined neighbourhood: a smooth fit whose face corners
// decisively agree or disagree with every neighbour.
double seed_score(const Octree &tree, const LeafGraph &g, uint32_t v) {
    double s = 0.0;
    for (uint32_t e = g.offsets[v]; e < g.offsets[v + 1]; ++e) s += std::abs(g.agreement[e]);
    if (tree.cells[g.cell_of[v]].shape.model == Model::bivariate) s += 8.0;
    return s;
}

class Front {
public:
    Front(const LeafGraph &g, std::vector<int8_t> &label, FrontOrder order)
        : g_(g), label_(label), order_(order), queued_(order == FrontOrder::fifo ? g.size() : 0, 0) {}

    // Evidence from labelled neighbours: positive favours keeping the fitted sign.
    double evidence(uint32_t v) const {
        double s = 0.0;
        for (uint32_t e = g_.offsets[v]; e < g_.offsets[v + 1]; ++e) {
            int8_t l = label_[g_.neighbour[e]];
            if (l != 0) s += double(g_.agreement[e]) * l;
        }
        return s;
    }
    void push_neighbours(uint32_t v) {
        for (uint32_t e = g_.offsets[v]; e < g_.offsets[v + 1]; ++e) {
            uint32_t u = g_.neighbour[e];
            if (label_[u] != 0) continue;
            if (order_ == FrontOrder::most_evidence_first) heap_.push({std::abs(evidence(u)), u});
            else if (!queued_[u]) queued_[u] = 1, queue_.push_back(u);
        }
    }
    bool pop(uint32_t &v) {
        while (!queue_.empty()) {
            v = queue_.front();
            queue_.pop_front();
            if (label_[v] == 0) return true;
        }
        while (!heap_.empty()) {
            v = heap_.top().second;
            heap_.pop();
            if (label_[v] == 0) return true;  // stale entries of labelled leaves are skipped
        }
        return false;
    }

private:
    const LeafGraph &g_;
    std::vector<int8_t> &label_;
    FrontOrder order_;
    std::vector<uint8_t> queued_;  // FIFO: each leaf joins the queue once
    std::deque<uint32_t> queue_;
    // Max-heap on evidence; ties go to the lower node id (deterministic).
    struct Order {
        bool operator()(const std::pair<double, uint32_t> &a, const std::pair<double, uint32_t> &b) const {
            return a.first < b.first || (a.first == b.first && a.second > b.second);
        }
    };
    std::priority_queue<std::pair<double, uint32_t>, std::vector<std::pair<double, uint32_t>>, Order> heap_;
};

// Grows the local graph of the active leaf v and returns v's MAP label.
class LocalSolver {
public:
    LocalSolver(const LeafGraph &g, const std::vector<int8_t> &label, const FrontOptions &o)
        : g_(g), label_(label), opt_(o), local_(g.size(), UINT32_MAX) {}

    int8_t solve(uint32_t v) {
        if (opt_.decision == LeafDecision::weighted_vote) return vote(v);
        nodes_.clear();
        bp_.clamp.clear();
        bp_.edges.clear();
        add(v);
        // Breadth-first over unlabelled leaves; labelled ones join clamped, unexpanded.
        size_t ring_begin = 0;
        for (int ring = 0; ring < opt_.rings; ++ring) {
            size_t ring_end = nodes_.size();
            for (size_t k = ring_begin; k < ring_end; ++k) {
                uint32_t a = nodes_[k];
                if (label_[a] != 0) continue;
                for (uint32_t e = g_.offsets[a]; e < g_.offsets[a + 1]; ++e) add(g_.neighbour[e]);
            }
            ring_begin = ring_end;
        }
        // Edges among the collected nodes (each once).
        for (size_t k = 0; k < nodes_.size(); ++k) {
            uint32_t a = nodes_[k];
            for (uint32_t e = g_.offsets[a]; e < g_.offsets[a + 1]; ++e) {
                uint32_t b = g_.neighbour[e];
                uint32_t lb = local_[b];
                if (lb == UINT32_MAX || lb <= k) continue;
                if (label_[a] != 0 && label_[b] != 0) continue;  // both fixed: no information
                bp_.edges.push_back({uint32_t(k), lb, double(g_.agreement[e])});
            }
        }
        BpResult r = solve_bp(bp_, opt_.data_weight, opt_.bp_iterations);
        for (uint32_t a : nodes_) local_[a] = UINT32_MAX;
        return r.label[0];
    }

private:
    int8_t vote(uint32_t v) const {
        double s = 0.0;
        for (uint32_t e = g_.offsets[v]; e < g_.offsets[v + 1]; ++e) s += double(g_.agreement[e]) * label_[g_.neighbour[e]];
        return s < 0.0 ? -1 : 1;
    }
    void add(uint32_t a) {
        if (local_[a] != UINT32_MAX) return;
        local_[a] = uint32_t(nodes_.size());
        nodes_.push_back(a);
        bp_.clamp.push_back(label_[a]);
    }
    const LeafGraph &g_;
    const std::vector<int8_t> &label_;
    const FrontOptions &opt_;
    std::vector<uint32_t> local_;  // graph node → local index, UINT32_MAX when absent
    std::vector<uint32_t> nodes_;
    BpGraph bp_;
};

}  // namespace

std::vector<int8_t> propagate_orientation(const Octree &tree, const LeafGraph &g,
                                          const std::vector<uint32_t> &component,
                                          uint32_t component_count, const FrontOptions &options,
                                          Progress &progress) {
    std::vector<int8_t> label(g.size(), 0);
    // One seed per component: the best-scoring leaf.
    std::vector<uint32_t> seed(component_count, UINT32_MAX);
    std::vector<double> best(component_count, -1.0);
    for (uint32_t v = 0; v < g.size(); ++v) {
        double s = seed_score(tree, g, v);
        if (s > best[component[v]]) best[component[v]] = s, seed[component[v]] = v;
    }

    Front front(g, label, options.order);
    LocalSolver solver(g, label, options);
    size_t done = 0;
    for (uint32_t c = 0; c < component_count; ++c) {
        label[seed[c]] = 1;
        ++done;
        front.push_neighbours(seed[c]);
        uint32_t v;
        while (front.pop(v)) {
            label[v] = solver.solve(v);
            front.push_neighbours(v);
            if ((++done & 255) == 0) {
                progress.report(double(done) / double(g.size()));
                progress.throw_if_cancelled();
            }
        }
    }
    return label;
}

}  // namespace gmpu
