// A quadratic polynomial in three variables, Q(y) = c + b·y + yᵀAy, where y is measured
// from the owning cell's centre (small numbers, well conditioned). Every local shape
// function of the paper — bivariate quadratic in a PCA frame, general quadric, and each
// piece of a piecewise fit — is stored as one of these.
#pragma once

#include <Eigen/Core>

namespace gmpu {

struct Quadric {
    double c = 0.0;
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    // Symmetric A stored once: xx, yy, zz, xy, yz, xz.
    double a[6] = {0, 0, 0, 0, 0, 0};

    double value(const Eigen::Vector3d &y) const {
        return c + b.dot(y) + a[0] * y[0] * y[0] + a[1] * y[1] * y[1] + a[2] * y[2] * y[2] +
               2.0 * (a[3] * y[0] * y[1] + a[4] * y[1] * y[2] + a[5] * y[0] * y[2]);
    }
    Eigen::Vector3d gradient(const Eigen::Vector3d &y) const {
        return b + 2.0 * Eigen::Vector3d(a[0] * y[0] + a[3] * y[1] + a[5] * y[2],
                                         a[3] * y[0] + a[1] * y[1] + a[4] * y[2],
                                         a[5] * y[0] + a[4] * y[1] + a[2] * y[2]);
    }

    // The affine function g·y + c0.
    static Quadric affine(const Eigen::Vector3d &g, double c0) {
        Quadric q;
        q.b = g;
        q.c = c0;
        return q;
    }
    // Product of two affine functions (their quadratic parts are ignored).
    static Quadric product(const Quadric &p, const Quadric &q);

    Quadric &operator+=(const Quadric &o);
    Quadric &operator*=(double s);
    friend Quadric operator+(Quadric p, const Quadric &q) { return p += q; }
    friend Quadric operator*(double s, Quadric q) { return q *= s; }
    friend Quadric operator-(Quadric p, const Quadric &q) { return p += -1.0 * q; }
};

}  // namespace gmpu
