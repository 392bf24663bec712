#include "mesh/sharpen.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "core/resize_reporting.hpp"

namespace gmpu {

namespace {

// A vertex is on a feature when some neighbour's normal is this far (degrees) from its own:
// above the turn of one ring on the smooth parts a grid resolves.
constexpr double kFeatureAngle = 35.0;
// Directions of the quadric kept: eigenvalues above this share of the largest. Two faces
// meeting at 30° give a second eigenvalue of about 7 % of the first.
constexpr double kPinnedShare = 0.05;
// A triangle around a moved vertex may turn by at most this much (degrees) and must keep this
// share of its area; a chamfer triangle folded into one of the two faces turns by about half
// the crease angle.
constexpr double kMaxTurn = 75.0;
constexpr double kMinAreaShare = 0.01;

using Vec = Eigen::Vector3d;

Vec at(const std::vector<double> &xyz, uint32_t v) { return Vec(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]); }

}  // namespace

size_t sharpen_features(Mesh &mesh, double reach, Progress &progress) {
    const size_t nv = mesh.vertex_count(), nt = mesh.triangle_count();
    if (nv == 0 || mesh.normals.size() != mesh.vertices.size()) return 0;
    // The 1-ring of every vertex (compressed rows, duplicates removed).
    // Big arrays filled with ticks (tens of megabytes at millions of triangles).
    std::vector<uint32_t> begin, ring;
    assign_reporting(begin, nv + 1, progress, 0u);
    assign_reporting(ring, 6 * nt, progress, 0u);
    // Every loop polls (one clock read per 4096 items): the calling thread runs it alone.
    for (size_t k = 0; k < mesh.triangles.size(); ++k) {
        if (k % 4096 == 0) progress.poll(0.0);
        begin[mesh.triangles[k] + 1] += 2;
    }
    for (size_t v = 0; v < nv; ++v) {
        if (v % 4096 == 0) progress.poll(0.05);
        begin[v + 1] += begin[v];
    }
    {
        std::vector<uint32_t> fill;
        assign_reporting(fill, nv, progress, 0u);
        for (size_t v = 0; v < nv; ++v) {
            if (v % 65536 == 0) progress.poll(0.05);
            fill[v] = begin[v];
        }
        for (size_t t = 0; t < nt; ++t)
            for (int c = 0; c < 3; ++c) {
                if (t % 4096 == 0 && c == 0) progress.poll(0.1);
                const uint32_t v = mesh.triangles[3 * t + size_t(c)];
                ring[fill[v]++] = mesh.triangles[3 * t + size_t((c + 1) % 3)];
                ring[fill[v]++] = mesh.triangles[3 * t + size_t((c + 2) % 3)];
            }
    }
    progress.poll(0.2);

    const double cos_feature = std::cos(kFeatureAngle * M_PI / 180.0);
    std::vector<double> moved;
    assign_reporting(moved, mesh.vertices.size(), progress);
    for (size_t k = 0; k < moved.size(); ++k) {
        if (k % 65536 == 0) progress.poll(0.2);
        moved[k] = mesh.vertices[k];
    }
    std::vector<uint8_t> is_moved(nv, 0);
    std::vector<uint32_t> planes;
    for (uint32_t v = 0; v < nv; ++v) {
        if (v % 256 == 0) progress.poll(0.2 + 0.5 * double(v) / double(nv));  // feature vertices cost microseconds each
        auto first = ring.begin() + begin[v], last = ring.begin() + begin[v + 1];
        std::sort(first, last);
        last = std::unique(first, last);
        const Vec nv_ = at(mesh.normals, v), pv = at(mesh.vertices, v);
        bool feature = false;
        for (auto it = first; it != last && !feature; ++it) feature = at(mesh.normals, *it).dot(nv_) < cos_feature;
        if (!feature) continue;
        // The planes of the 2-ring: the 1-ring alone sits on the rounded part of f along the
        // crease, the next ring reaches the faces' own planes.
        planes.assign(first, last);
        for (auto it = first; it != last; ++it)
            planes.insert(planes.end(), ring.begin() + begin[*it], ring.begin() + begin[*it + 1]);
        std::sort(planes.begin(), planes.end());
        planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
        // Σ n nᵀ (x − p) over the planes; solved around pv along the pinned directions.
        Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
        Vec r = Vec::Zero();  // Σ n nᵀ (p − pv)
        for (uint32_t w : planes) {
            const Vec n = at(mesh.normals, w), p = at(mesh.vertices, w);
            A += n * n.transpose();
            r += n * n.dot(p - pv);
        }
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
        const double largest = es.eigenvalues().maxCoeff();
        Vec step = Vec::Zero();
        for (int k = 0; k < 3; ++k)
            if (es.eigenvalues()[k] > kPinnedShare * largest)
                step += es.eigenvectors().col(k) * (es.eigenvectors().col(k).dot(r) / es.eigenvalues()[k]);
        if (!step.allFinite() || step.norm() > reach || step.norm() == 0.0) continue;
        for (int d = 0; d < 3; ++d) moved[3 * v + uint32_t(d)] = pv[d] + step[d];
        is_moved[v] = 1;
    }
    progress.poll(0.7);

    // Undo the moves that turn or flatten a triangle, until none does (each round undoes
    // at least one move, so this ends).
    const double cos_turn = std::cos(kMaxTurn * M_PI / 180.0);
    for (bool undone = true; undone;) {
        undone = false;
        for (size_t t = 0; t < nt; ++t) {
            if (t % 4096 == 0) progress.poll(0.7);
            const uint32_t *c = &mesh.triangles[3 * t];
            if (!is_moved[c[0]] && !is_moved[c[1]] && !is_moved[c[2]]) continue;
            const Vec before = triangle_cross(mesh.vertices, mesh.triangles, t), after = triangle_cross(moved, mesh.triangles, t);
            const double b = before.norm(), a = after.norm();
            if (a >= kMinAreaShare * b && after.dot(before) > cos_turn * a * b) continue;
            for (int k = 0; k < 3; ++k)
                if (is_moved[c[k]]) {
                    is_moved[c[k]] = 0;
                    for (int d = 0; d < 3; ++d) moved[3 * c[k] + uint32_t(d)] = mesh.vertices[3 * c[k] + uint32_t(d)];
                    undone = true;
                }
        }
    }
    progress.poll(0.9);

    // The moved vertices sit on a crease or corner: their normal is their triangles'.
    std::vector<double> normal_sum(3 * nv, 0.0);
    for (size_t t = 0; t < nt; ++t) {
        if (t % 4096 == 0) progress.poll(0.9);
        const uint32_t *c = &mesh.triangles[3 * t];
        if (!is_moved[c[0]] && !is_moved[c[1]] && !is_moved[c[2]]) continue;
        const Vec n = triangle_cross(moved, mesh.triangles, t);
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) normal_sum[3 * c[k] + uint32_t(d)] += n[d];
    }
    size_t count = 0;
    for (uint32_t v = 0; v < nv; ++v) {
        if (v % 4096 == 0) progress.poll(0.95);
        if (!is_moved[v]) continue;
        ++count;
        const Vec n = at(normal_sum, v).normalized();
        if (n.allFinite())
            for (int d = 0; d < 3; ++d) mesh.normals[3 * v + uint32_t(d)] = n[d];
    }
    mesh.vertices = std::move(moved);
    return count;
}

}  // namespace gmpu
