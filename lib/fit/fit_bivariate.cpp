#include <Eigen/Cholesky>

#include "fit/fits.hpp"

namespace gmpu {

Quadric fit_bivariate(const PointList &points, const Pca &pca, double scale) {
    const Eigen::Vector3d t1 = pca.axes.col(2), t2 = pca.axes.col(1), n = pca.axes.col(0);
    const Eigen::Vector3d &o = pca.centroid;
    const double inv = 1.0 / scale;

    // Normal equations for w' = a u'² + b u'v' + c v'² + d u' + e v' + f in units of R.
    Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto &p : points) {
        Eigen::Vector3d d = (p - o) * inv;
        double u = d.dot(t1), v = d.dot(t2), w = d.dot(n);
        Eigen::Matrix<double, 6, 1> r;
        r << u * u, u * v, v * v, u, v, 1.0;
        m.noalias() += r * r.transpose();
        rhs += r * w;
    }
    // A small ridge keeps collinear or tiny sets solvable; it pulls towards a flat fit.
    m.diagonal().array() += 1e-6 * (1.0 + m.trace() / 6.0);
    Eigen::Matrix<double, 6, 1> k = m.ldlt().solve(rhs);
    if (!k.allFinite()) k.setZero();

    // Q(y) = w(y) − R·h(u(y)/R, v(y)/R) with u, v, w affine in y.
    Quadric U = Quadric::affine(t1 * inv, -t1.dot(o) * inv);
    Quadric V = Quadric::affine(t2 * inv, -t2.dot(o) * inv);
    Quadric W = Quadric::affine(n, -n.dot(o));
    Quadric h = k[0] * Quadric::product(U, U) + k[1] * Quadric::product(U, V) +
                k[2] * Quadric::product(V, V) + k[3] * U + k[4] * V;
    h.c += k[5];
    return W - scale * h;
}

}  // namespace gmpu
