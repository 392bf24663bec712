// Solids with a closed-form signed distance and outward normal, for tests that need the
// exact answer: is f's sign right at this point, does this normal point out, how far is
// the mesh from the true surface. Each can also sample its boundary area-uniformly.
#pragma once

#include "triangle_mesh.hpp"

#include <cstdint>

namespace gmpu::testing {

class AnalyticShape {
public:
    virtual ~AnalyticShape() = default;
    // Exact Euclidean distance to the boundary, negative inside the solid and positive
    // outside (the usual SDF convention; gmpu's f has the opposite sign).
    virtual double signed_distance(const Vec3 &p) const = 0;
    // Unit outward normal of the boundary point nearest to p (the SDF's gradient).
    virtual Vec3 normal(const Vec3 &p) const = 0;
    virtual double area() const = 0;
    virtual double volume() const = 0;
    virtual Eigen::AlignedBox3d bounds() const = 0;
    // count points drawn area-uniformly on the boundary, with outward unit normals;
    // the same seed gives the same points.
    virtual OrientedPoints sample(size_t count, uint64_t seed) const = 0;
};

class Sphere final : public AnalyticShape {
public:
    Sphere(const Vec3 &center, double radius);
    double signed_distance(const Vec3 &p) const override;
    Vec3 normal(const Vec3 &p) const override;
    double area() const override;
    double volume() const override;
    Eigen::AlignedBox3d bounds() const override;
    OrientedPoints sample(size_t count, uint64_t seed) const override;

private:
    Vec3 center_;
    double radius_;
};

// Ring around the z axis through center: tube radius minor < major.
class Torus final : public AnalyticShape {
public:
    Torus(const Vec3 &center, double major, double minor);
    double signed_distance(const Vec3 &p) const override;
    Vec3 normal(const Vec3 &p) const override;
    double area() const override;
    double volume() const override;
    Eigen::AlignedBox3d bounds() const override;
    OrientedPoints sample(size_t count, uint64_t seed) const override;

private:
    Vec3 center_;
    double major_, minor_;
};

// Hollow shell: the solid lies between the two radii. On the inner sphere the outward
// normal points toward the centre (into the cavity) — the nested-shells case of orient.
class NestedSpheres final : public AnalyticShape {
public:
    NestedSpheres(const Vec3 &center, double inner, double outer);
    double signed_distance(const Vec3 &p) const override;
    Vec3 normal(const Vec3 &p) const override;
    double area() const override;
    double volume() const override;
    Eigen::AlignedBox3d bounds() const override;
    OrientedPoints sample(size_t count, uint64_t seed) const override;

private:
    Vec3 center_;
    double inner_, outer_;
};

// Axis-aligned box; with one small half extent it is the thin plate whose two sides
// orientation must tell apart.
class Plate final : public AnalyticShape {
public:
    Plate(const Vec3 &center, const Vec3 &half_extents);
    double signed_distance(const Vec3 &p) const override;
    Vec3 normal(const Vec3 &p) const override;
    double area() const override;
    double volume() const override;
    Eigen::AlignedBox3d bounds() const override;
    OrientedPoints sample(size_t count, uint64_t seed) const override;

private:
    Vec3 center_, half_;
};

}  // namespace gmpu::testing
