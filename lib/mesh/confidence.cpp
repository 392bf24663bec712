#include "mesh/confidence.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/parallel.hpp"

namespace gmpu {

namespace {

// Neighbours that tell whether a vertex has points all around it.
constexpr size_t kAroundNeighbours = 12;
// Past the edge of the data, the distance counts up to this many times: interior vertices
// keep their slack for the gaps of random sampling, while the surface past a scan's rim,
// where the data has ended, is cut about a third as far out.
constexpr double kPastEdgeFactor = 3.0;
// The factor ramps up as the widest gap between the nearby points grows from a half-turn
// (a vertex on the rim) to three quarters of a turn, so that a gap a little over a
// half-turn, which twelve random samples leave around about one interior vertex in 170,
// hardly counts. (More neighbours make such gaps rarer but reach across small holes, whose
// caps then look surrounded.)
constexpr double kPastEdgeGap = 1.5 * M_PI;

// The widest angular gap between the points `nearest` to q, seen in the plane through q
// normal to n: a half-turn or more when q lies beyond the edge of the sampled surface (past
// a hole's rim), less among the points. 0 when it cannot tell.
double widest_gap(const Eigen::Vector3d &q, const Eigen::Vector3d &n, const PointSet &points,
                   const std::vector<uint32_t> &nearest) {
    if (nearest.size() < 3 || !(n.squaredNorm() > 0.0)) return 0.0;
    const Eigen::Vector3d normal = n.normalized();
    const Eigen::Vector3d helper = std::fabs(normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d e1 = normal.cross(helper).normalized(), e2 = normal.cross(e1);
    thread_local std::vector<double> angles;
    angles.clear();
    for (uint32_t i : nearest) {
        const Eigen::Vector3d d = points.point(i) - q;
        const double x = d.dot(e1), y = d.dot(e2);
        if (x != 0.0 || y != 0.0) angles.push_back(std::atan2(y, x));
    }
    if (angles.size() < 3) return 0.0;
    std::sort(angles.begin(), angles.end());
    double widest = angles.front() + 2.0 * M_PI - angles.back();
    for (size_t k = 1; k < angles.size(); ++k) widest = std::max(widest, angles[k] - angles[k - 1]);
    return widest;
}

// How many times the distance counts at a vertex with that widest gap.
double past_edge_factor(double gap) {
    const double t = std::clamp((gap - M_PI) / (kPastEdgeGap - M_PI), 0.0, 1.0);
    return 1.0 + (kPastEdgeFactor - 1.0) * t;
}

}  // namespace

void compute_confidence(Mesh &mesh, const PointSet &points, const PointMeasures &measures, Workers &workers,
                        Progress &progress) {
    const size_t n = mesh.vertex_count();
    mesh.confidence.assign(n, 0.0);
    if (points.empty()) return;
    const Normalisation &norm = points.normalisation();
    const bool mesh_normals = mesh.normals.size() == mesh.vertices.size();
    constexpr size_t kChunk = 256;
    const size_t chunks = (n + kChunk - 1) / kChunk;
    parallel_for(0, chunks, workers, progress, [&](size_t c) {
        std::vector<uint32_t> nearest;
        std::vector<float> squared;
        for (size_t v = c * kChunk; v < std::min(n, (c + 1) * kChunk); ++v) {
            const Eigen::Vector3d q =
                norm.to_unit(Eigen::Vector3d(mesh.vertices[3 * v], mesh.vertices[3 * v + 1], mesh.vertices[3 * v + 2]));
            nearest.clear();
            points.nearest(q, kAroundNeighbours, nearest, squared);
            if (nearest.empty()) {
                mesh.confidence[v] = INFINITY;
                continue;
            }
            const double spacing = std::sqrt(double(measures.area[nearest[0]]));
            const double distance = std::sqrt(double(squared[0]));
            double confidence = spacing > 0 ? distance / spacing : (distance > 0 ? INFINITY : 0.0);
            // The surface's own normal there; the nearest point's when the mesh has none.
            Eigen::Vector3d n = Eigen::Vector3d::Zero();
            if (mesh_normals)
                n = Eigen::Vector3d(mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]);
            else if (measures.normals.size() == 3 * points.size())
                for (int d = 0; d < 3; ++d) n[d] = measures.normals[3 * nearest[0] + d];
            confidence *= past_edge_factor(widest_gap(q, n, points, nearest));
            mesh.confidence[v] = confidence;
        }
    });
}

namespace {

// Trimmed pieces of fewer triangles than this (and under half the trimmed mesh) are slivers
// of invented surface that came within the threshold of the data, not scanned surface.
constexpr size_t kMinPieceTriangles = 8;

// Per triangle of `triangles` (3 vertex indices each, vertex_count vertices): whether it
// lies in a piece (triangles joined by shared vertices) of at least kMinPieceTriangles.
std::vector<bool> in_real_pieces(const std::vector<uint32_t> &triangles, size_t vertex_count) {
    std::vector<uint32_t> parent(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) parent[v] = uint32_t(v);
    auto root = [&](uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (size_t t = 0; t < triangles.size(); t += 3)
        for (int k = 1; k < 3; ++k) parent[root(triangles[t + size_t(k)])] = root(triangles[t]);
    std::vector<size_t> piece_triangles(vertex_count, 0);
    for (size_t t = 0; t < triangles.size(); t += 3) ++piece_triangles[root(triangles[t])];
    const size_t count = triangles.size() / 3;
    std::vector<bool> real(count);
    for (size_t t = 0; t < count; ++t) {
        const size_t size = piece_triangles[root(triangles[3 * t])];
        real[t] = size >= kMinPieceTriangles || 2 * size >= count;
    }
    return real;
}

}  // namespace

Mesh trim_unsupported(const Mesh &mesh, double threshold) {
    std::vector<uint32_t> kept;
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        bool supported = true;
        for (int k = 0; k < 3; ++k) supported = supported && mesh.confidence[mesh.triangles[t + k]] <= threshold;
        if (supported) kept.insert(kept.end(), mesh.triangles.begin() + long(t), mesh.triangles.begin() + long(t) + 3);
    }
    const std::vector<bool> real = in_real_pieces(kept, mesh.vertex_count());
    Mesh out;
    std::vector<uint32_t> index(mesh.vertex_count(), UINT32_MAX);
    const bool normals = mesh.normals.size() == mesh.vertices.size();
    for (size_t t = 0; t < kept.size(); t += 3) {
        if (!real[t / 3]) continue;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = kept[t + size_t(k)];
            if (index[v] == UINT32_MAX) {
                index[v] = uint32_t(out.vertex_count());
                out.vertices.insert(out.vertices.end(), mesh.vertices.begin() + 3 * v, mesh.vertices.begin() + 3 * v + 3);
                if (normals) out.normals.insert(out.normals.end(), mesh.normals.begin() + 3 * v, mesh.normals.begin() + 3 * v + 3);
                out.confidence.push_back(mesh.confidence[v]);
                if (!mesh.colors.empty())
                    out.colors.insert(out.colors.end(), mesh.colors.begin() + 3 * v, mesh.colors.begin() + 3 * v + 3);
            }
            out.triangles.push_back(index[v]);
        }
    }
    return out;
}

}  // namespace gmpu
