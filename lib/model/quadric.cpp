#include "model/quadric.hpp"

namespace gmpu {

Quadric Quadric::product(const Quadric &p, const Quadric &q) {
    Quadric r;
    r.c = p.c * q.c;
    r.b = p.c * q.b + q.c * p.b;
    // (p.b·y)(q.b·y) = yᵀ (p.b q.bᵀ) y, symmetrised.
    r.a[0] = p.b[0] * q.b[0];
    r.a[1] = p.b[1] * q.b[1];
    r.a[2] = p.b[2] * q.b[2];
    r.a[3] = 0.5 * (p.b[0] * q.b[1] + p.b[1] * q.b[0]);
    r.a[4] = 0.5 * (p.b[1] * q.b[2] + p.b[2] * q.b[1]);
    r.a[5] = 0.5 * (p.b[0] * q.b[2] + p.b[2] * q.b[0]);
    return r;
}

Quadric &Quadric::operator+=(const Quadric &o) {
    c += o.c;
    b += o.b;
    for (int i = 0; i < 6; ++i) a[i] += o.a[i];
    return *this;
}

Quadric &Quadric::operator*=(double s) {
    c *= s;
    b *= s;
    for (double &v : a) v *= s;
    return *this;
}

}  // namespace gmpu
