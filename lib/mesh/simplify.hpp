// Decimation: fewer triangles for the same surface, by meshoptimizer's quadric-error edge
// collapses, with the topology (manifold, closed, components, genus) checked after every
// round since the collapses themselves do not guarantee it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_topology.hpp"

namespace gmpu {

// Welds vertices at identical positions, then collapses edges until at most
// `target_triangles` remain (0: no count target) or the next collapse would move the
// surface by more than `target_error` × the bounding-box diagonal. A round whose result
// changes the topology is mended by dropping its fins (remove_fins) when that suffices,
// else retried with a smaller reduction, and simplification stops at the last mesh that
// kept it. Meshes over 2 × kChunkTriangles to be more than halved, whose first round over
// the whole mesh reaches the count but breaks the topology, are decimated chunk by chunk
// (chunked_decimation.hpp; on `workers` when given, reporting to `progress`), so a retry
// redoes one chunk rather than the whole mesh. Vertices are a subset of the input's
// (positions exact, the confidence carried); normals are recomputed from the triangles, or
// with `keep_normals` carried from the input when it has them (polygonize's normals are
// −∇f, exact at each vertex). `achieved_error` (may be null) receives the accumulated error
// bound, as a fraction of the diagonal. A mesh without triangles gives an empty mesh.
Mesh simplify_mesh(const Mesh &mesh, size_t target_triangles, double target_error, double *achieved_error,
                   bool keep_normals = false, Workers *workers = nullptr, Progress *progress = nullptr);

// Triangles per chunk of a large mesh's decimation: enough that the locked chunk borders
// are a small share of the surface, few enough that a retried round is cheap.
constexpr size_t kChunkTriangles = 16384;

// What one patch's decimation did.
struct PatchDecimation {
    double spent = 0.0;  // error bound used, in the positions' units
    size_t rounds = 0;   // meshopt calls, the retried ones and a given first round included
    size_t retries = 0;  // rounds whose result broke the topology and were redone
    size_t work = 0;     // triangles handed to meshopt over all rounds
};

// A round of collapses already run on a patch, exactly as decimate_patch's first round
// would run it, whose result broke the topology at `culprits` (mesh_topology's) even with
// its fins dropped.
struct BrokenRound {
    std::vector<uint32_t> triangles;
    std::vector<uint32_t> culprits;
};

// The rounds of collapses on one patch (`triangles` indexes `positions`, xyz floats), in
// place: towards `target_triangles`, within `budget` (absolute), border vertices and those
// `fixed` marks (per vertex, may be null) locked, every round checked by keeps_topology
// against the patch as given. `first` (may be null): the first round's result, known
// already, so it is not run again.
PatchDecimation decimate_patch(const std::vector<float> &positions, std::vector<uint32_t> &triangles,
                               size_t target_triangles, double budget, const std::vector<char> *fixed = nullptr,
                               const BrokenRound *first = nullptr);

// meshoptimizer can crush a thin tube's tip to a fin: a vertex left with only two
// triangles, on the same three vertices in opposite order (two faces glued back to back
// along the edge they hang from), so that the edge has four triangles and the round
// changes the topology. Removes every fin of `triangles` (into `positions`, xyz floats)
// whose vertex lies within `reach` of its edge (the surface moves by that much) and returns
// the highest one's height; returns −1 and removes nothing when there is none or some fin
// is higher (the tip of a real thin part, which a retry keeps).
double remove_fins(std::vector<uint32_t> &triangles, const std::vector<float> &positions, double reach);

// `after` is the same surface type as `before` (MeshTopology::same_as) and has no more
// defects of any kind: a patch cut out of a manifold mesh may be pinched at a border
// vertex, and must not gain another pinch or a non-manifold edge elsewhere.
bool keeps_topology(const MeshTopology &before, const MeshTopology &after);

// Unit area-weighted vertex normals of the triangles (a vertex no triangle uses keeps
// `fallback`'s normal when given, else +z).
void recompute_normals(Mesh &mesh, const Mesh *fallback = nullptr);

}  // namespace gmpu
