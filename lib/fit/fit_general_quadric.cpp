#include <cmath>

#include <Eigen/Eigenvalues>

#include "fit/fits.hpp"

namespace gmpu {

namespace {
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

// Monomials without the constant term: x y z x² y² z² xy yz xz.
Vec9 monomials(const Eigen::Vector3d &z) {
    Vec9 v;
    v << z[0], z[1], z[2], z[0] * z[0], z[1] * z[1], z[2] * z[2], z[0] * z[1], z[1] * z[2],
        z[0] * z[2];
    return v;
}

// Jacobian of the monomials (3 × 9).
Eigen::Matrix<double, 3, 9> jacobian(const Eigen::Vector3d &z) {
    Eigen::Matrix<double, 3, 9> j = Eigen::Matrix<double, 3, 9>::Zero();
    j(0, 0) = 1; j(1, 1) = 1; j(2, 2) = 1;
    j(0, 3) = 2 * z[0]; j(1, 4) = 2 * z[1]; j(2, 5) = 2 * z[2];
    j(0, 6) = z[1]; j(1, 6) = z[0];
    j(1, 7) = z[2]; j(2, 7) = z[1];
    j(0, 8) = z[2]; j(2, 8) = z[0];
    return j;
}
}  // namespace

Quadric fit_general_quadric(const PointList &points, double scale) {
    const double inv = 1.0 / scale;
    const double n = double(points.size());
    Vec9 mean = Vec9::Zero();
    for (const auto &p : points) mean += monomials(p * inv);
    mean /= n;
    // The constant term is eliminated analytically (a0 = −mean·a), leaving the 9 × 9
    // generalized eigenproblem M a = λ N a of Taubin's fit.
    Mat9 m = Mat9::Zero(), g = Mat9::Zero();
    for (const auto &p : points) {
        Eigen::Vector3d z = p * inv;
        Vec9 d = monomials(z) - mean;
        m.noalias() += d * d.transpose();
        auto j = jacobian(z);
        g.noalias() += j.transpose() * j;
    }
    g.diagonal().array() += 1e-9 * (1.0 + g.trace() / 9.0);
    Eigen::GeneralizedSelfAdjointEigenSolver<Mat9> solver(m, g);
    Vec9 a = solver.eigenvectors().col(0);
    if (solver.info() != Eigen::Success || !a.allFinite()) {
        a.setZero();
        a[2] = 1.0;  // a plane through the centroid: only reached on numerically broken sets
    }

    // Q(y) = a0 + monomials(y / R)·a, expanded in y.
    Quadric q;
    q.c = -mean.dot(a);
    q.b = a.head<3>() * inv;
    const double i2 = inv * inv;
    q.a[0] = a[3] * i2;
    q.a[1] = a[4] * i2;
    q.a[2] = a[5] * i2;
    q.a[3] = 0.5 * a[6] * i2;
    q.a[4] = 0.5 * a[7] * i2;
    q.a[5] = 0.5 * a[8] * i2;

    // Unit mean gradient on the points makes Q a first-order distance.
    double grad = 0.0;
    for (const auto &p : points) grad += q.gradient(p).norm();
    grad /= n;
    if (grad > 0.0 && std::isfinite(grad)) q *= 1.0 / grad;
    return q;
}

}  // namespace gmpu
