#include "orient/belief_propagation.hpp"

#include <algorithm>
#include <cmath>

namespace gmpu {

namespace {
constexpr double kClamped = 1e6;  // an energy no agreement sum can outweigh

// Message difference m(+1) − m(−1) sent across an edge with agreement J by a node whose
// own cost difference (data + other incoming messages) is h = cost(+1) − cost(−1).
inline double message(double h, double j) {
    // m(ℓ_j) = min over ℓ_i of cost(ℓ_i) − ℓ_i ℓ_j J, with cost(+1) = h, cost(−1) = 0.
    double plus = std::min(h - j, j);
    double minus = std::min(h + j, -j);
    return plus - minus;
}
}  // namespace

BpResult solve_bp(const BpGraph &g, double data_weight, int max_iterations) {
    const size_t n = g.clamp.size();
    std::vector<double> data(n);
    for (size_t i = 0; i < n; ++i)
        data[i] = g.clamp[i] == 0 ? -2.0 * data_weight : (g.clamp[i] > 0 ? -kClamped : kClamped);

    // Directed messages: 2e is a→b, 2e+1 is b→a.
    const size_t m = g.edges.size();
    std::vector<double> msg(2 * m, 0.0), next(2 * m, 0.0), incoming(n);
    for (int it = 0; it < max_iterations; ++it) {
        std::copy(data.begin(), data.end(), incoming.begin());
        for (size_t e = 0; e < m; ++e) {
            incoming[g.edges[e].b] += msg[2 * e];
            incoming[g.edges[e].a] += msg[2 * e + 1];
        }
        double change = 0.0;
        for (size_t e = 0; e < m; ++e) {
            const auto &edge = g.edges[e];
            next[2 * e] = message(incoming[edge.a] - msg[2 * e + 1], edge.agreement);
            next[2 * e + 1] = message(incoming[edge.b] - msg[2 * e], edge.agreement);
            change = std::max({change, std::abs(next[2 * e] - msg[2 * e]),
                               std::abs(next[2 * e + 1] - msg[2 * e + 1])});
        }
        msg.swap(next);
        if (change < 1e-9) break;
    }

    BpResult r;
    r.label.resize(n);
    r.margin.resize(n);
    std::copy(data.begin(), data.end(), incoming.begin());
    for (size_t e = 0; e < m; ++e) {
        incoming[g.edges[e].b] += msg[2 * e];
        incoming[g.edges[e].a] += msg[2 * e + 1];
    }
    for (size_t i = 0; i < n; ++i) {
        r.label[i] = incoming[i] <= 0.0 ? 1 : -1;  // lower cost wins; a tie keeps the fit's sign
        r.margin[i] = std::abs(incoming[i]);
    }
    return r;
}

}  // namespace gmpu
