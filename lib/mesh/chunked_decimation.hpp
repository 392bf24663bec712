// Decimation of a large mesh in spatial chunks. The triangles are split by their centroids
// into chunks of at most a given count (median cuts across the longest side); each chunk is
// decimated alone, and the vertices it shares with another chunk stay (the cut opens a
// border there, which the collapses lock), so the chunks fit back together exactly, run in
// parallel, and a round that breaks the topology is redone on its chunk only. The whole
// mesh is checked once at the end; the seams are left for a pass over the smaller mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "mesh/mesh_topology.hpp"
#include "mesh/simplify.hpp"

namespace gmpu {

struct ChunkedDecimation {
    std::vector<uint32_t> triangles;      // the chunks' results together, indexing the input's positions
    double spent = 0.0;                   // the largest error bound a chunk used
    bool kept = false;                    // the result keeps the input's topology (else do not use it)
    std::vector<uint32_t> chunk;          // per input triangle, its chunk
    std::vector<PatchDecimation> chunks;  // per chunk, what its decimation did
};

// Decimates the closed or open mesh (`triangles` into `positions`, xyz floats) chunk by
// chunk, each chunk towards its share of `target_triangles` (a little more: the pass over
// the whole mesh chooses the last collapses by error across chunks) within `budget`
// (absolute). On `workers` when given (with `progress`), else on the calling thread.
// `guide` (may be null): the same mesh decimated towards the target without regard to the
// topology; each chunk's share of the target is then the guide's share in the chunk, so the
// triangles go where the error-ordered collapses over the whole mesh left them.
// `topology` (may be null): the input's mesh_topology, when the caller has it already.
ChunkedDecimation decimate_in_chunks(const std::vector<float> &positions, const std::vector<uint32_t> &triangles,
                                     size_t target_triangles, double budget, size_t chunk_triangles,
                                     Workers *workers, Progress *progress, const std::vector<uint32_t> *guide = nullptr,
                                     const MeshTopology *topology = nullptr);

}  // namespace gmpu
