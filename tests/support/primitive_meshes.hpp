// Closed triangle meshes of simple solids, wound outward, for tests that need a known
// mesh: an icosphere is within a known distance of its sphere, a torus has genus 1.
#pragma once

#include "triangle_mesh.hpp"

namespace gmpu::testing {

// Icosahedron subdivided `subdivisions` times (20·4^s triangles), vertices on the sphere.
TriangleMesh icosphere(int subdivisions, double radius = 1, const Vec3 &center = Vec3::Zero());

// Ring around the z axis: `around` segments along the ring, `tube` around the tube.
TriangleMesh torus_mesh(double major, double minor, int around, int tube,
                        const Vec3 &center = Vec3::Zero());

// Axis-aligned box, two triangles per face.
TriangleMesh box_mesh(const Vec3 &center, const Vec3 &half_extents);

}  // namespace gmpu::testing
