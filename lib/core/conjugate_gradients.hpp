// Jacobi-preconditioned conjugate gradients for a symmetric positive definite system given
// as a product (apply(v, out) writes A v), on the workers. Every vector operation runs in
// fixed blocks and every dot product sums them in block order (block_sums.hpp), so the
// solution's bits do not depend on the thread count.
#pragma once

#include <array>
#include <cstddef>

#include <Eigen/Core>

#include "core/block_sums.hpp"
#include "core/huge_pages.hpp"
#include "core/progress.hpp"

namespace gmpu {

// Solves A x = rhs from `x` (the start, overwritten with the solution), with A's diagonal
// as the preconditioner. Stops once the residual's norm falls below `tolerance` × rhs's, or
// after `iterations`; polls `progress` (reported from `from` to 1 over the iterations) for a
// cancel between them, and throws CANCELLED once cancelled. Returns the iterations taken.
template <class Apply>
int conjugate_gradients(const Apply &apply, const Eigen::VectorXd &rhs, const Eigen::VectorXd &diagonal,
                        Eigen::VectorXd &x, double tolerance, int iterations, Workers &workers, Progress &progress,
                        double from) {
    Progress quiet = progress.slice(from, from);  // the loops only check for a cancel
    const Eigen::Index unknowns = rhs.size();
    const size_t rows = size_t(unknowns);
    const Eigen::VectorXd inverse_diagonal = diagonal.cwiseInverse();
    Eigen::VectorXd r(unknowns), Ap(unknowns), z(unknowns), p(unknowns);
    for (const Eigen::VectorXd *v : {&r, &Ap, &z, &p}) advise_huge_pages(*v);
    apply(x, Ap);
    std::array<double, 2> rz_rr = block_sums<2>(rows, workers, quiet, [&](size_t lo, size_t hi) {
        std::array<double, 2> sum{};
        for (Eigen::Index u = Eigen::Index(lo); u < Eigen::Index(hi); ++u) {
            r[u] = rhs[u] - Ap[u];
            p[u] = z[u] = inverse_diagonal[u] * r[u];
            sum[0] += r[u] * z[u], sum[1] += r[u] * r[u];
        }
        return sum;
    });
    const double rhs_norm2 = block_sums<1>(rows, workers, quiet, [&](size_t lo, size_t hi) {
        return std::array<double, 1>{rhs.segment(Eigen::Index(lo), Eigen::Index(hi - lo)).squaredNorm()};
    })[0];
    const double target = tolerance * tolerance * std::max(rhs_norm2, 1e-300);
    int it = 0;
    for (; it < iterations && rz_rr[1] > target; ++it) {
        progress.poll(from + (1.0 - from) * double(it) / iterations);
        apply(p, Ap);
        const double pAp = block_sums<1>(rows, workers, quiet, [&](size_t lo, size_t hi) {
            return std::array<double, 1>{p.segment(Eigen::Index(lo), Eigen::Index(hi - lo))
                                             .dot(Ap.segment(Eigen::Index(lo), Eigen::Index(hi - lo)))};
        })[0];
        const double step = rz_rr[0] / pAp;
        const std::array<double, 2> next = block_sums<2>(rows, workers, quiet, [&](size_t lo, size_t hi) {
            std::array<double, 2> sum{};
            for (Eigen::Index u = Eigen::Index(lo); u < Eigen::Index(hi); ++u) {
                x[u] += step * p[u];
                r[u] -= step * Ap[u];
                z[u] = inverse_diagonal[u] * r[u];
                sum[0] += r[u] * z[u], sum[1] += r[u] * r[u];
            }
            return sum;
        });
        const double beta = next[0] / rz_rr[0];
        block_for(rows, workers, quiet, [&](size_t lo, size_t hi) {
            for (Eigen::Index u = Eigen::Index(lo); u < Eigen::Index(hi); ++u) p[u] = z[u] + beta * p[u];
        });
        rz_rr = next;
    }
    // A cancel seen inside a loop leaves that loop's sums unfinished: they must not pass for
    // a solution.
    progress.throw_if_cancelled();
    return it;
}

}  // namespace gmpu
