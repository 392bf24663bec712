#include "primitive_meshes.hpp"

#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace gmpu::testing {

namespace {

constexpr double kPi = 3.14159265358979323846;

// For a convex solid containing `inside`: wind every triangle so its normal points away.
void wind_outward(TriangleMesh &mesh, const Vec3 &inside) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        if (triangle_cross(mesh, t).dot(mesh.vertices[mesh.triangles[t][0]] - inside) < 0)
            std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
}

}  // namespace

TriangleMesh icosphere(int subdivisions, double radius, const Vec3 &center) {
    if (subdivisions < 0 || subdivisions > 10 || !(radius > 0))
        throw std::invalid_argument("icosphere: subdivisions 0..10, radius > 0");
    const double g = (1 + std::sqrt(5.0)) / 2;
    TriangleMesh m;
    m.vertices = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                  {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (Vec3 &v : m.vertices) v.normalize();
    wind_outward(m, Vec3::Zero());
    for (int s = 0; s < subdivisions; ++s) {
        // Each edge's midpoint, pushed onto the sphere, is made once and shared.
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            auto [it, fresh] = midpoints.try_emplace(key, static_cast<uint32_t>(m.vertices.size()));
            if (fresh) m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
            return it->second;
        };
        std::vector<Triangle> finer;
        for (const Triangle &t : m.triangles) {
            const uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]),
                           ca = midpoint(t[2], t[0]);
            finer.insert(finer.end(), {{t[0], ab, ca}, {t[1], bc, ab}, {t[2], ca, bc}, {ab, bc, ca}});
        }
        m.triangles = std::move(finer);
    }
    for (Vec3 &v : m.vertices) v = center + radius * v;
    return m;
}

TriangleMesh torus_mesh(double major, double minor, int around, int tube, const Vec3 &center) {
    if (around < 3 || tube < 3 || !(minor > 0 && major > minor))
        throw std::invalid_argument("torus_mesh: need 3+ segments and 0 < minor < major");
    TriangleMesh m;
    auto index = [&](int i, int j) { return static_cast<uint32_t>((i % around) * tube + j % tube); };
    for (int i = 0; i < around; ++i)
        for (int j = 0; j < tube; ++j) {
            const double phi = 2 * kPi * i / around, theta = 2 * kPi * j / tube;
            const Vec3 e(std::cos(phi), std::sin(phi), 0);
            m.vertices.push_back(center + (major + minor * std::cos(theta)) * e +
                                 minor * std::sin(theta) * Vec3::UnitZ());
        }
    // ∂/∂φ × ∂/∂θ points out of the tube, so (i,j) → (i+1,j) → (i+1,j+1) is outward.
    for (int i = 0; i < around; ++i)
        for (int j = 0; j < tube; ++j) {
            const uint32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1),
                           d = index(i, j + 1);
            m.triangles.push_back({a, b, c});
            m.triangles.push_back({a, c, d});
        }
    return m;
}

TriangleMesh box_mesh(const Vec3 &center, const Vec3 &half_extents) {
    TriangleMesh m;
    for (int k = 0; k < 8; ++k)  // corner k: bit 0 → +x, bit 1 → +y, bit 2 → +z
        m.vertices.push_back(center + Vec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1)
                                          .cwiseProduct(half_extents));
    m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                   {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    wind_outward(m, center);
    return m;
}

}  // namespace gmpu::testing
