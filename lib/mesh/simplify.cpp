#include "mesh/simplify.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mesh/chunked_decimation.hpp"
#include "mesh/mesh_topology.hpp"

namespace gmpu {

namespace {

// A round that breaks the topology is redone with more vertices locked, this many times in
// a row at most, before simplification stops where it is.
constexpr int kRetries = 12;
// Rings of neighbours locked around a vertex where a round broke the topology: one ring
// leaves the collapses next to it free to break it again a vertex further on, and every
// redone round costs a whole pass over the mesh.
constexpr int kLockRings = 2;
// Chunks of a large mesh may spend this many times the error of the first round over the
// whole mesh: at once, the retries' locks and the seams leave cheap collapses to the pass
// over the whole mesh, which then takes dearer ones to reach the count (the thin plate's
// rim at a tenth: F@0.5 % 0.969); at three times, chunks start to cost the shape of curved
// parts again (the dino at a tenth: 0.988 against 0.999).
constexpr double kChunkErrorPerRound = 2.0;

// Vertices at identical positions become one, so that collapses see the true neighbourhood
// (a duplicate would look like a border and be locked or torn). Degenerate triangles go.
Mesh welded(const Mesh &in) {
    const size_t n = in.vertex_count();
    std::vector<unsigned> remap(n);
    const size_t unique = meshopt_generateVertexRemap(remap.data(), in.triangles.data(), in.triangles.size(),
                                                      in.vertices.data(), n, 3 * sizeof(double));
    Mesh out;
    out.vertices.resize(3 * unique);
    if (!in.confidence.empty()) out.confidence.resize(unique);
    if (!in.colors.empty()) out.colors.resize(3 * unique);
    const bool normals = in.normals.size() == in.vertices.size();
    if (normals) out.normals.resize(3 * unique);
    for (size_t v = 0; v < n; ++v) {
        if (remap[v] == ~0u) continue;
        for (int d = 0; d < 3; ++d) out.vertices[3 * remap[v] + d] = in.vertices[3 * v + d];
        if (normals)
            for (int d = 0; d < 3; ++d) out.normals[3 * remap[v] + d] = in.normals[3 * v + d];
        if (!in.confidence.empty()) out.confidence[remap[v]] = in.confidence[v];
        if (!in.colors.empty())
            for (int d = 0; d < 3; ++d) out.colors[3 * remap[v] + d] = in.colors[3 * v + d];
    }
    out.triangles.reserve(in.triangles.size());
    for (size_t t = 0; t < in.triangles.size(); t += 3) {
        const unsigned a = remap[in.triangles[t]], b = remap[in.triangles[t + 1]], c = remap[in.triangles[t + 2]];
        if (a == b || b == c || c == a) continue;
        out.triangles.insert(out.triangles.end(), {a, b, c});
    }
    return out;
}

// Keeps only the vertices `triangles` uses, in their order.
Mesh compacted(const Mesh &base, const std::vector<uint32_t> &triangles) {
    std::vector<uint32_t> index(base.vertex_count(), UINT32_MAX);
    Mesh out;
    out.triangles.reserve(triangles.size());
    for (uint32_t v : triangles) {
        if (index[v] == UINT32_MAX) {
            index[v] = uint32_t(out.vertices.size() / 3);
            out.vertices.insert(out.vertices.end(), base.vertices.begin() + 3 * v, base.vertices.begin() + 3 * v + 3);
            if (base.normals.size() == base.vertices.size())
                out.normals.insert(out.normals.end(), base.normals.begin() + 3 * v, base.normals.begin() + 3 * v + 3);
            if (!base.confidence.empty()) out.confidence.push_back(base.confidence[v]);
            if (!base.colors.empty())
                out.colors.insert(out.colors.end(), base.colors.begin() + 3 * v, base.colors.begin() + 3 * v + 3);
        }
        out.triangles.push_back(index[v]);
    }
    return out;
}

double bbox_diagonal(const std::vector<double> &xyz) {
    if (xyz.empty()) return 0.0;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (size_t i = 0; i < xyz.size(); i += 3) {
        const Eigen::Vector3d p(xyz[i], xyz[i + 1], xyz[i + 2]);
        lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
    return (hi - lo).norm();
}

}  // namespace

void recompute_normals(Mesh &mesh, const Mesh *fallback) {
    const size_t n = mesh.vertex_count();
    std::vector<Eigen::Vector3d> sum(n, Eigen::Vector3d::Zero());
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        const uint32_t a = mesh.triangles[t], b = mesh.triangles[t + 1], c = mesh.triangles[t + 2];
        // The cross product's length is twice the area: the weight.
        const Eigen::Vector3d w = triangle_cross(mesh.vertices, mesh.triangles, t / 3);
        sum[a] += w, sum[b] += w, sum[c] += w;
    }
    mesh.normals.assign(3 * n, 0.0);
    for (size_t v = 0; v < n; ++v) {
        Eigen::Vector3d u(0, 0, 1);
        const double len = sum[v].norm();
        if (len > 0 && std::isfinite(len)) u = sum[v] / len;
        else if (fallback && fallback->normals.size() == 3 * fallback->vertex_count() && v < fallback->vertex_count())
            u = Eigen::Vector3d(fallback->normals[3 * v], fallback->normals[3 * v + 1], fallback->normals[3 * v + 2]);
        for (int d = 0; d < 3; ++d) mesh.normals[3 * v + d] = u[d];
    }
}

namespace {

// One meshopt_simplify run on `triangles` with the `locked` vertices kept in place.
// meshopt 0.18 locks only border vertices, so each locked vertex is made one: one of its
// corners gets a copy of it whose float position differs in the last bit (meshopt matches
// vertices by exact position), which opens the edges of that corner. The copies map back.
size_t collapse_round(const std::vector<uint32_t> &triangles, const std::vector<float> &positions,
                      const std::vector<char> &locked, size_t target_triangles, double error,
                      std::vector<uint32_t> &out, float &result_error) {
    const size_t n = positions.size() / 3;
    std::vector<uint32_t> in = triangles;
    std::vector<float> pos = positions;
    std::vector<uint32_t> original;  // of each copy
    std::vector<char> done(n, 0);
    for (uint32_t &v : in) {
        if (!locked[v] || done[v]) continue;
        done[v] = 1;
        original.push_back(v);
        const float x = pos[3 * v];
        pos.insert(pos.end(), {std::nextafter(x, std::numeric_limits<float>::infinity()), pos[3 * v + 1], pos[3 * v + 2]});
        v = uint32_t(n + original.size() - 1);
    }
    out.resize(in.size());
    const size_t got = meshopt_simplify(out.data(), in.data(), in.size(), pos.data(), pos.size() / 3,
                                        3 * sizeof(float), 3 * target_triangles, float(error),
                                        meshopt_SimplifyLockBorder, &result_error);
    out.resize(got);
    for (uint32_t &v : out)
        if (v >= n) v = original[v - n];
    return got / 3;
}

}  // namespace

double remove_fins(std::vector<uint32_t> &triangles, const std::vector<float> &positions, double reach) {
    const size_t n = positions.size() / 3;
    std::vector<uint32_t> uses(n, 0);
    for (uint32_t v : triangles) ++uses[v];
    std::vector<uint32_t> first(n, UINT32_MAX);  // a two-triangle vertex's first triangle
    std::vector<char> drop(triangles.size() / 3, 0);
    double highest = -1.0;
    auto at = [&](uint32_t v) { return Eigen::Vector3d(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]); };
    for (uint32_t t = 0; t < uint32_t(triangles.size() / 3); ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = triangles[3 * t + k];
            if (uses[v] != 2) continue;
            if (first[v] == UINT32_MAX) {
                first[v] = t;
                continue;
            }
            // v's two triangles: (v, a, b) and, for a fin, (v, b, a).
            const uint32_t s = first[v];
            int j = 0;
            while (triangles[3 * s + j] != v) ++j;
            const uint32_t a = triangles[3 * s + (j + 1) % 3], b = triangles[3 * s + (j + 2) % 3];
            if (triangles[3 * t + (k + 1) % 3] != b || triangles[3 * t + (k + 2) % 3] != a) continue;
            const Eigen::Vector3d p = at(v), e0 = at(a), e1 = at(b), d = e1 - e0;
            const double along = d.squaredNorm() > 0.0 ? std::clamp((p - e0).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
            const double height = (p - (e0 + along * d)).norm();
            if (!(height <= reach)) return -1.0;
            highest = std::max(highest, height);
            drop[s] = drop[t] = 1;
        }
    if (highest < 0.0) return -1.0;
    size_t kept = 0;
    for (size_t t = 0; t < drop.size(); ++t) {
        if (drop[t]) continue;
        for (int k = 0; k < 3; ++k) triangles[3 * kept + k] = triangles[3 * t + k];
        ++kept;
    }
    triangles.resize(3 * kept);
    return highest;
}

namespace {

// Whether a round's result `next` keeps the topology `before` of the mesh it came from, its
// fins removed (within `reach`) if that is what it takes; `fins` receives their height (0
// if none were removed), `culprits` (may be null) mesh_topology's for the result as given.
bool round_keeps_topology(const MeshTopology &before, std::vector<uint32_t> &next, const std::vector<float> &positions,
                          double reach, std::vector<uint32_t> *culprits, double &fins) {
    fins = 0.0;
    Mesh probe;  // mesh_topology reads the vertex count, not the positions
    probe.vertices.assign(positions.size(), 0.0);
    probe.triangles = next;
    if (keeps_topology(before, mesh_topology(probe, culprits))) return true;
    const double height = remove_fins(probe.triangles, positions, reach);
    if (height < 0.0 || !keeps_topology(before, mesh_topology(probe))) return false;
    next.swap(probe.triangles);
    fins = height;
    return true;
}

}  // namespace

bool keeps_topology(const MeshTopology &before, const MeshTopology &after) {
    return after.same_as(before) && after.nonmanifold_edges <= before.nonmanifold_edges &&
           after.nonmanifold_vertices <= before.nonmanifold_vertices &&
           after.degenerate_triangles <= before.degenerate_triangles &&
           after.duplicate_triangles <= before.duplicate_triangles;
}

PatchDecimation decimate_patch(const std::vector<float> &positions, std::vector<uint32_t> &triangles,
                               size_t target_triangles, double budget, const std::vector<char> *fixed,
                               const BrokenRound *first) {
    PatchDecimation result;
    const size_t n = positions.size() / 3;
    if (triangles.empty() || n == 0) return result;
    // meshopt measures error relative to its own scale (the patch's largest extent).
    const double scale = double(meshopt_simplifyScale(positions.data(), n, 3 * sizeof(float)));
    if (!(scale > 0.0) || !std::isfinite(scale)) return result;
    Mesh probe;  // mesh_topology reads the vertex count, not the positions
    probe.vertices.assign(3 * n, 0.0);
    probe.triangles = triangles;
    const MeshTopology before = mesh_topology(probe);

    std::vector<uint32_t> next, culprits;
    std::vector<char> locked = fixed && fixed->size() == n ? *fixed : std::vector<char>(n, 0);
    int failures = 0;
    size_t ask = target_triangles;  // of this round: more than the target after a failure
    while (triangles.size() / 3 > target_triangles && failures <= kRetries && result.spent <= budget) {
        float round_error = 0.0f;
        const bool known = first && result.rounds == 0;
        ++result.rounds;
        result.work += triangles.size() / 3;
        const size_t got = known ? first->triangles.size() / 3
                                 : collapse_round(triangles, positions, locked, ask, (budget - result.spent) / scale,
                                                  next, round_error);
        if (known) next = first->triangles;
        if (3 * got >= triangles.size()) break;  // the error bound (or the locks) allow no collapse
        culprits.clear();
        if (known) culprits = first->culprits;
        const double round_spent = known ? 0.0 : double(round_error) * scale;
        double fins = 0.0;
        const double reach = budget - result.spent - round_spent;
        if (!known && round_keeps_topology(before, next, positions, reach, &culprits, fins)) {
            triangles.swap(next);
            result.spent += round_spent + fins;
            failures = 0;
            ask = target_triangles;
            continue;
        }
        // Some collapse broke the topology (meshoptimizer does not test the link
        // condition). Lock where it went wrong, with the neighbours that could collapse
        // there, and redo the round from the last good mesh.
        ++failures;
        ++result.retries;
        if (culprits.empty()) {
            // A change with no local sign (a handle closed cleanly): ask for half the
            // reduction, fewer collapses and fewer chances of the bad one.
            const size_t have = triangles.size() / 3;
            ask = have - (have - ask) / 2;
            if (ask >= have) break;
            continue;
        }
        std::vector<char> bad(n, 0);
        for (uint32_t v : culprits) bad[v] = 1;
        for (int ring = 0; ring < kLockRings; ++ring) {
            std::vector<char> grown = bad;
            for (const std::vector<uint32_t> *tris : {&triangles, &next})
                for (size_t t = 0; t < tris->size(); t += 3)
                    if (bad[(*tris)[t]] || bad[(*tris)[t + 1]] || bad[(*tris)[t + 2]])
                        for (int k = 0; k < 3; ++k) grown[(*tris)[t + k]] = 1;
            bad.swap(grown);
        }
        for (size_t v = 0; v < n; ++v) locked[v] = locked[v] || bad[v];
    }
    return result;
}

Mesh simplify_mesh(const Mesh &mesh, size_t target_triangles, double target_error, double *achieved_error,
                   bool keep_normals, Workers *workers, Progress *progress) {
    if (achieved_error) *achieved_error = 0.0;
    if (mesh.triangles.empty()) return Mesh();  // nothing to weld or collapse (and no vertex in use)
    Mesh base = welded(mesh);
    const double diagonal = bbox_diagonal(base.vertices);
    std::vector<uint32_t> current = base.triangles;
    double spent = 0.0;  // absolute error bound used so far (passes add up: triangle inequality)
    if (diagonal > 0.0) {
        const double budget = target_error * diagonal;
        std::vector<float> positions(base.vertices.begin(), base.vertices.end());
        // Large meshes: most of the reduction patch by patch, each with its own retries,
        // then one pass over the whole (smaller) mesh to reach the target across the seams.
        bool chunked = false, trial_broke = false;
        // The first round over the whole mesh: when it breaks the topology, it is also the
        // first round of every pass below that starts from the whole mesh.
        BrokenRound trial;
        if (current.size() / 3 > 2 * kChunkTriangles && target_triangles * 2 < current.size() / 3) {
            // One round over the whole mesh first. When it keeps the topology, or stops at the
            // error bound short of the count (where chunks, each held to its share of the
            // count, would stop shorter still), the rounds go on over the whole mesh; when it
            // reaches the count but breaks the topology, the chunks redo it, each retrying
            // alone.
            const double scale = double(meshopt_simplifyScale(positions.data(), base.vertex_count(), 3 * sizeof(float)));
            float round_error = 0.0f;
            const size_t got = scale > 0 ? collapse_round(current, positions, std::vector<char>(base.vertex_count(), 0),
                                                          target_triangles, budget / scale, trial.triangles,
                                                          round_error)
                                         : current.size() / 3;
            Mesh probe;  // mesh_topology reads the vertex count, not the positions
            probe.vertices.assign(base.vertices.size(), 0.0);
            probe.triangles = current;
            const MeshTopology before = mesh_topology(probe);
            double fins = 0.0;
            if (scale > 0 && round_keeps_topology(before, trial.triangles, positions,
                                                  budget - double(round_error) * scale, &trial.culprits, fins)) {
                current.swap(trial.triangles);
                spent = double(round_error) * scale + fins;
            } else if (scale > 0) {
                trial_broke = true;
            }
            if (trial_broke && got <= target_triangles) {
                // At most half the error bound: the other half is for the pass over the whole
                // mesh, which collapses the seams the chunks had to keep. And about what the
                // first round needed to reach the count: the chunks then make the collapses it
                // made, the cheapest over the whole mesh, rather than whatever reaches each
                // one's share (with its seams held, a chunk's share can cost it its shape).
                const double chunk_budget = std::min(0.5 * budget, kChunkErrorPerRound * double(round_error) * scale);
                const ChunkedDecimation chunks =
                    decimate_in_chunks(positions, current, target_triangles, chunk_budget, kChunkTriangles, workers,
                                       progress, &trial.triangles, &before);
                if (chunks.kept) current = chunks.triangles, spent = chunks.spent, chunked = true;
            }
        }
        spent += decimate_patch(positions, current, target_triangles, budget - spent, nullptr,
                                trial_broke && !chunked ? &trial : nullptr).spent;
        // The chunks stop at about the first round's error and the pass over the whole mesh
        // has the rest of the bound, but its retries' locks can still leave it short of the
        // count the whole mesh reaches alone. Then the whole mesh, from the start.
        if (chunked && target_triangles > 0 && current.size() / 3 > target_triangles) {
            std::vector<uint32_t> whole = base.triangles;
            const double whole_spent =
                decimate_patch(positions, whole, target_triangles, budget, nullptr, &trial).spent;
            if (whole.size() < current.size()) current.swap(whole), spent = whole_spent;
        }
    }
    Mesh out = compacted(base, current);
    if (!keep_normals || out.normals.size() != out.vertices.size()) recompute_normals(out);
    if (achieved_error) *achieved_error = diagonal > 0.0 ? spent / diagonal : 0.0;
    return out;
}

}  // namespace gmpu
