#include "mesh/confidence.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/parallel.hpp"
#include "core/union_find.hpp"

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
// A cut closer to the supported end of an edge than this share of it is made at that vertex
// (the triangles it would leave are slivers).
constexpr double kMinCut = 0.02;
// Surface over the threshold is cut where it is part of a region that rises to this many
// times the threshold: the caps over holes rise far from the data, while a random gap in
// the sampling or the noise lifts a few vertices just over it inside the scanned surface,
// which cutting would perforate.
constexpr double kSeedFactor = 2.0;

// Per triangle of `triangles` (3 vertex indices each, vertex_count vertices): whether it
// lies in a piece (triangles joined by shared vertices) of at least kMinPieceTriangles.
std::vector<bool> in_real_pieces(const std::vector<uint32_t> &triangles, size_t vertex_count) {
    UnionFind pieces(vertex_count);
    for (size_t t = 0; t < triangles.size(); t += 3)
        for (int k = 1; k < 3; ++k) pieces.join(triangles[t + size_t(k)], triangles[t]);
    auto root = [&](uint32_t v) { return pieces.find(v); };
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

// Per vertex: whether the trim takes it away, i.e. its confidence is over `threshold` in a
// region (vertices over it, joined by edges) that reaches kSeedFactor × threshold somewhere.
std::vector<bool> unsupported_regions(const Mesh &mesh, double threshold) {
    const size_t n = mesh.vertex_count();
    UnionFind regions(n);
    auto root = [&](uint32_t v) { return regions.find(v); };
    auto over = [&](uint32_t v) { return !(mesh.confidence[v] <= threshold); };
    for (size_t t = 0; t < mesh.triangles.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = mesh.triangles[t + size_t(k)], b = mesh.triangles[t + size_t(k + 1) % 3];
            if (over(a) && over(b)) regions.join(a, b);
        }
    std::vector<bool> seeded(n, false), away(n, false);
    for (size_t v = 0; v < n; ++v)
        if (!(mesh.confidence[v] <= kSeedFactor * threshold)) seeded[root(uint32_t(v))] = true;
    for (size_t v = 0; v < n; ++v) away[v] = over(uint32_t(v)) && seeded[root(uint32_t(v))];
    return away;
}

}  // namespace

Mesh trim_unsupported(const Mesh &mesh, double threshold) {
    const bool normals = mesh.normals.size() == mesh.vertices.size();
    const bool colors = mesh.colors.size() == mesh.vertices.size();
    // Every vertex first, then the cuts; unused ones are left out at the end.
    Mesh all;
    all.vertices = mesh.vertices;
    all.confidence = mesh.confidence;
    if (normals) all.normals = mesh.normals;
    if (colors) all.colors = mesh.colors;
    const std::vector<bool> cut_away = unsupported_regions(mesh, threshold);
    auto supported = [&](uint32_t v) { return !cut_away[v]; };
    // The vertex where the confidence, linear along the edge from `in` (supported) to `out`,
    // reaches the threshold: one per edge, so the two triangles sharing it share the cut.
    std::unordered_map<uint64_t, uint32_t> cuts;
    auto cut = [&](uint32_t in, uint32_t out) {
        const uint64_t key = uint64_t(in) << 32 | out;
        const auto found = cuts.find(key);
        if (found != cuts.end()) return found->second;
        const double from = std::min(mesh.confidence[in], threshold), rise = mesh.confidence[out] - from;
        const double t = std::isfinite(rise) && rise > 0.0 ? (threshold - from) / rise : 0.0;
        uint32_t v = in;
        if (t >= kMinCut) {
            v = uint32_t(all.vertex_count());
            for (int d = 0; d < 3; ++d)
                all.vertices.push_back((1 - t) * mesh.vertices[3 * in + d] + t * mesh.vertices[3 * out + d]);
            all.confidence.push_back(threshold);
            if (normals) {
                Eigen::Vector3d n;
                for (int d = 0; d < 3; ++d) n[d] = (1 - t) * mesh.normals[3 * in + d] + t * mesh.normals[3 * out + d];
                if (n.squaredNorm() > 0.0) n.normalize();
                all.normals.insert(all.normals.end(), {n[0], n[1], n[2]});
            }
            if (colors)
                for (int d = 0; d < 3; ++d)
                    all.colors.push_back(uint8_t(std::lround((1 - t) * mesh.colors[3 * in + d] + t * mesh.colors[3 * out + d])));
        }
        cuts.emplace(key, v);
        return v;
    };
    std::vector<uint32_t> kept;
    auto keep = [&](uint32_t a, uint32_t b, uint32_t c) {
        if (a != b && b != c && c != a) kept.insert(kept.end(), {a, b, c});
    };
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        const uint32_t *v = &mesh.triangles[t];
        const int inside = supported(v[0]) + supported(v[1]) + supported(v[2]);
        if (inside == 3) keep(v[0], v[1], v[2]);
        if (inside == 0 || inside == 3) continue;
        // Rotated (keeping the winding) so that v[k] is the lone supported vertex (one inside)
        // or the lone unsupported one (two inside).
        int k = 0;
        while ((supported(v[k]) == 1) != (inside == 1)) ++k;
        const uint32_t a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
        if (inside == 1) {
            keep(a, cut(a, b), cut(a, c));
        } else {
            const uint32_t ab = cut(b, a), ca = cut(c, a);
            keep(b, c, ca);
            keep(ca, ab, b);
        }
    }
    const std::vector<bool> real = in_real_pieces(kept, all.vertex_count());
    Mesh out;
    std::vector<uint32_t> index(all.vertex_count(), UINT32_MAX);
    for (size_t t = 0; t < kept.size(); t += 3) {
        if (!real[t / 3]) continue;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = kept[t + size_t(k)];
            if (index[v] == UINT32_MAX) {
                index[v] = uint32_t(out.vertex_count());
                out.vertices.insert(out.vertices.end(), all.vertices.begin() + 3 * v, all.vertices.begin() + 3 * v + 3);
                if (normals) out.normals.insert(out.normals.end(), all.normals.begin() + 3 * v, all.normals.begin() + 3 * v + 3);
                out.confidence.push_back(all.confidence[v]);
                if (colors) out.colors.insert(out.colors.end(), all.colors.begin() + 3 * v, all.colors.begin() + 3 * v + 3);
            }
            out.triangles.push_back(index[v]);
        }
    }
    return out;
}

}  // namespace gmpu
