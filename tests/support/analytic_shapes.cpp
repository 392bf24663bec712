#include "analytic_shapes.hpp"
#include "random_vectors.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

using gmpu_test::draw_vector;

namespace gmpu::testing {

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 random_direction(std::mt19937_64 &rng) {
    std::normal_distribution<double> gauss;
    for (;;) {  // an isotropic Gaussian, normalised, is uniform on the sphere
        const Vec3 v = draw_vector(gauss, rng);
        const double n = v.norm();
        if (n > 1e-12) return v / n;
    }
}

Vec3 radial(const Vec3 &p, const Vec3 &center) {
    const Vec3 d = p - center;
    const double n = d.norm();
    return n > 0 ? Vec3(d / n) : Vec3::UnitZ();  // any direction is right at the centre
}

void require(bool ok, const char *what) {
    if (!ok) throw std::invalid_argument(what);
}

}  // namespace

// ---- sphere ----

Sphere::Sphere(const Vec3 &center, double radius) : center_(center), radius_(radius) {
    require(radius > 0, "Sphere: radius must be positive");
}
double Sphere::signed_distance(const Vec3 &p) const { return (p - center_).norm() - radius_; }
Vec3 Sphere::normal(const Vec3 &p) const { return radial(p, center_); }
double Sphere::area() const { return 4 * kPi * radius_ * radius_; }
double Sphere::volume() const { return 4.0 / 3 * kPi * radius_ * radius_ * radius_; }
Eigen::AlignedBox3d Sphere::bounds() const {
    return {center_ - Vec3::Constant(radius_), center_ + Vec3::Constant(radius_)};
}
OrientedPoints Sphere::sample(size_t count, uint64_t seed) const {
    std::mt19937_64 rng(seed);
    OrientedPoints out;
    for (size_t i = 0; i < count; ++i) {
        const Vec3 n = random_direction(rng);
        out.positions.push_back(center_ + radius_ * n);
        out.normals.push_back(n);
    }
    return out;
}

// ---- torus ----

Torus::Torus(const Vec3 &center, double major, double minor)
    : center_(center), major_(major), minor_(minor) {
    require(minor > 0 && major > minor, "Torus: need 0 < minor < major");
}
double Torus::signed_distance(const Vec3 &p) const {
    const Vec3 d = p - center_;
    return std::hypot(std::hypot(d.x(), d.y()) - major_, d.z()) - minor_;
}
Vec3 Torus::normal(const Vec3 &p) const {
    const Vec3 d = p - center_;
    const double rho = std::hypot(d.x(), d.y());
    const Vec3 e = rho > 0 ? Vec3(d.x() / rho, d.y() / rho, 0) : Vec3::UnitX();
    return radial(p, center_ + major_ * e);  // away from the tube's centre line
}
double Torus::area() const { return 4 * kPi * kPi * major_ * minor_; }
double Torus::volume() const { return 2 * kPi * kPi * major_ * minor_ * minor_; }
Eigen::AlignedBox3d Torus::bounds() const {
    const Vec3 half(major_ + minor_, major_ + minor_, minor_);
    return {center_ - half, center_ + half};
}
OrientedPoints Torus::sample(size_t count, uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    OrientedPoints out;
    while (out.size() < count) {
        const double phi = 2 * kPi * uniform(rng), theta = 2 * kPi * uniform(rng);
        // The area element is ∝ (R + r cos θ): accept θ with that weight.
        if (uniform(rng) * (major_ + minor_) > major_ + minor_ * std::cos(theta)) continue;
        const Vec3 e(std::cos(phi), std::sin(phi), 0);
        const Vec3 n = std::cos(theta) * e + std::sin(theta) * Vec3::UnitZ();
        out.positions.push_back(center_ + major_ * e + minor_ * n);
        out.normals.push_back(n);
    }
    return out;
}

// ---- hollow shell ----

NestedSpheres::NestedSpheres(const Vec3 &center, double inner, double outer)
    : center_(center), inner_(inner), outer_(outer) {
    require(inner > 0 && outer > inner, "NestedSpheres: need 0 < inner < outer");
}
double NestedSpheres::signed_distance(const Vec3 &p) const {
    const double d = (p - center_).norm();
    return std::max(inner_ - d, d - outer_);
}
Vec3 NestedSpheres::normal(const Vec3 &p) const {
    const bool nearer_outer = (p - center_).norm() >= (inner_ + outer_) / 2;
    return nearer_outer ? radial(p, center_) : Vec3(-radial(p, center_));
}
double NestedSpheres::area() const { return 4 * kPi * (inner_ * inner_ + outer_ * outer_); }
double NestedSpheres::volume() const {
    return 4.0 / 3 * kPi * (outer_ * outer_ * outer_ - inner_ * inner_ * inner_);
}
Eigen::AlignedBox3d NestedSpheres::bounds() const {
    return {center_ - Vec3::Constant(outer_), center_ + Vec3::Constant(outer_)};
}
OrientedPoints NestedSpheres::sample(size_t count, uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const double p_outer = outer_ * outer_ / (outer_ * outer_ + inner_ * inner_);
    OrientedPoints out;
    for (size_t i = 0; i < count; ++i) {
        const Vec3 d = random_direction(rng);
        const bool outer = uniform(rng) < p_outer;
        out.positions.push_back(center_ + (outer ? outer_ : inner_) * d);
        out.normals.push_back(outer ? d : Vec3(-d));
    }
    return out;
}

// ---- box / thin plate ----

Plate::Plate(const Vec3 &center, const Vec3 &half_extents) : center_(center), half_(half_extents) {
    require(half_extents.minCoeff() > 0, "Plate: half extents must be positive");
}
double Plate::signed_distance(const Vec3 &p) const {
    const Vec3 q = (p - center_).cwiseAbs() - half_;
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}
Vec3 Plate::normal(const Vec3 &p) const {
    const Vec3 d = p - center_;
    const Vec3 q = d.cwiseAbs() - half_;
    const Vec3 sign = d.unaryExpr([](double x) { return x < 0 ? -1.0 : 1.0; });
    if (q.maxCoeff() > 0) return sign.cwiseProduct(q.cwiseMax(0.0)).normalized();
    int axis = 0;  // inside or on: the nearest face is the one with the largest q
    q.maxCoeff(&axis);
    return sign[axis] * Vec3::Unit(axis);
}
double Plate::area() const {
    return 8 * (half_.x() * half_.y() + half_.y() * half_.z() + half_.x() * half_.z());
}
double Plate::volume() const { return 8 * half_.prod(); }
Eigen::AlignedBox3d Plate::bounds() const { return {center_ - half_, center_ + half_}; }
OrientedPoints Plate::sample(size_t count, uint64_t seed) const {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    // A face pair normal to axis k has area ∝ the product of the other two half extents.
    const Vec3 face_area(half_.y() * half_.z(), half_.x() * half_.z(), half_.x() * half_.y());
    const double total = face_area.sum();
    OrientedPoints out;
    for (size_t i = 0; i < count; ++i) {
        const double pick = uniform(rng) * total;
        const int axis = pick < face_area[0] ? 0 : pick < face_area[0] + face_area[1] ? 1 : 2;
        const double side = uniform(rng) < 0.5 ? -1.0 : 1.0;
        Vec3 local;
        for (int k = 0; k < 3; ++k) local[k] = (2 * uniform(rng) - 1) * half_[k];
        local[axis] = side * half_[axis];
        out.positions.push_back(center_ + local);
        out.normals.push_back(side * Vec3::Unit(axis));
    }
    return out;
}

}  // namespace gmpu::testing
