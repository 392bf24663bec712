#include "mesh/chunked_decimation.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "mesh/mesh_topology.hpp"

namespace gmpu {

namespace {

// A chunk is asked for this much more than its share of the target: the last collapses
// are left to the pass over the whole mesh, which orders them by error across chunks (a
// curved chunk then keeps more triangles than a flat one).
constexpr double kChunkSlack = 1.15;

// Splits order[begin, end) (triangle ids) at the median centroid across the longest side of
// their centroids' box, until each part holds at most `most`; appends the parts' ends.
void split(std::vector<uint32_t> &order, size_t begin, size_t end, const std::vector<Eigen::Vector3f> &centroid,
           size_t most, std::vector<size_t> &ends) {
    if (end - begin <= most) {
        ends.push_back(end);
        return;
    }
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
    for (size_t i = begin; i < end; ++i) lo = lo.cwiseMin(centroid[order[i]]), hi = hi.cwiseMax(centroid[order[i]]);
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const size_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + long(begin), order.begin() + long(mid), order.begin() + long(end),
                     [&](uint32_t a, uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
    split(order, begin, mid, centroid, most, ends);
    split(order, mid, end, centroid, most, ends);
}

}  // namespace

ChunkedDecimation decimate_in_chunks(const std::vector<float> &positions, const std::vector<uint32_t> &triangles,
                                     size_t target_triangles, double budget, size_t chunk_triangles,
                                     Workers *workers, Progress *progress, const std::vector<uint32_t> *guide,
                                     const MeshTopology *topology) {
    ChunkedDecimation result;
    const size_t count = triangles.size() / 3, n = positions.size() / 3;
    if (count == 0) return result;
    std::vector<Eigen::Vector3f> centroid(count);
    for (size_t t = 0; t < count; ++t) {
        Eigen::Vector3f c = Eigen::Vector3f::Zero();
        for (int k = 0; k < 3; ++k) c += Eigen::Vector3f::Map(&positions[3 * size_t(triangles[3 * t + k])]);
        centroid[t] = c / 3.0f;
    }
    std::vector<uint32_t> order(count);
    for (size_t t = 0; t < count; ++t) order[t] = uint32_t(t);
    std::vector<size_t> ends;
    split(order, 0, count, centroid, std::max<size_t>(chunk_triangles, 1), ends);
    const size_t chunks = ends.size();
    result.chunk.resize(count);
    result.chunks.resize(chunks);
    std::vector<std::vector<uint32_t>> out(chunks);  // each chunk's triangles, input vertex ids
    for (size_t c = 0; c < chunks; ++c)
        for (size_t i = c == 0 ? 0 : ends[c - 1]; i < ends[c]; ++i) result.chunk[order[i]] = uint32_t(c);
    // The vertices two chunks share: their seam.
    std::vector<uint32_t> first_chunk(n, UINT32_MAX);
    std::vector<char> seam(n, 0);
    for (size_t t = 0; t < count; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = triangles[3 * t + k];
            if (first_chunk[v] == UINT32_MAX) first_chunk[v] = result.chunk[t];
            else if (first_chunk[v] != result.chunk[t]) seam[v] = 1;
        }

    // Each chunk's share of the target: from the guide's triangles in the chunk (by their
    // first vertex's chunk) when there is one, else from the chunk's share of the input.
    std::vector<double> guided(chunks, 0.0);
    if (guide && !guide->empty())
        for (size_t t = 0; t < guide->size(); t += 3) guided[first_chunk[(*guide)[t]]] += 1.0;

    auto decimate_chunk = [&](size_t c) {
        const size_t begin = c == 0 ? 0 : ends[c - 1], end = ends[c];
        // The chunk as a mesh of its own: its vertices renumbered, so meshopt's work and
        // memory follow the chunk, not the whole mesh.
        std::vector<uint32_t> global;
        global.reserve(3 * (end - begin));
        for (size_t i = begin; i < end; ++i)
            for (int k = 0; k < 3; ++k) global.push_back(triangles[3 * size_t(order[i]) + k]);
        std::vector<uint32_t> ids = global;
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        std::vector<float> local_positions(3 * ids.size());
        for (size_t v = 0; v < ids.size(); ++v)
            for (int d = 0; d < 3; ++d) local_positions[3 * v + d] = positions[3 * size_t(ids[v]) + d];
        std::vector<uint32_t> local(global.size());
        for (size_t i = 0; i < global.size(); ++i)
            local[i] = uint32_t(std::lower_bound(ids.begin(), ids.end(), global[i]) - ids.begin());
        const double share = guide && !guide->empty() ? guided[c] / double(guide->size() / 3)
                                                      : double(end - begin) / double(count);
        const size_t target = target_triangles == 0 ? 0 : size_t(std::ceil(kChunkSlack * share * double(target_triangles)));
        // Where the cut passed, the chunk's edges have one triangle: a border, which the
        // collapses leave in place, so the neighbouring chunk finds the same vertices. Their
        // neighbours stay too: a vertex next to two seam vertices, collapsed, would join them
        // by an edge the other chunk may also have (four triangles on one edge).
        std::vector<char> fixed(ids.size(), 0);
        for (size_t t = 0; t < local.size(); t += 3)
            if (seam[ids[local[t]]] || seam[ids[local[t + 1]]] || seam[ids[local[t + 2]]])
                fixed[local[t]] = fixed[local[t + 1]] = fixed[local[t + 2]] = 1;
        result.chunks[c] = decimate_patch(local_positions, local, target, budget, &fixed);
        out[c].resize(local.size());
        for (size_t i = 0; i < local.size(); ++i) out[c][i] = ids[local[i]];
    };
    if (workers && progress)
        parallel_for(0, chunks, *workers, *progress, decimate_chunk, 1);
    else
        for (size_t c = 0; c < chunks; ++c) decimate_chunk(c);

    for (size_t c = 0; c < chunks; ++c) {
        result.triangles.insert(result.triangles.end(), out[c].begin(), out[c].end());
        result.spent = std::max(result.spent, result.chunks[c].spent);
    }
    // Each chunk kept its own topology with its border fixed, which bounds but does not
    // prove the whole's (two chunks could trade a component): one check of the result.
    Mesh probe;  // mesh_topology reads the vertex count, not the positions
    probe.vertices.assign(3 * n, 0.0);
    auto topology_of = [&](const std::vector<uint32_t> &tris) {
        probe.triangles = tris;
        return mesh_topology(probe);
    };
    const MeshTopology before = topology ? *topology : topology_of(triangles);
    result.kept = keeps_topology(before, topology_of(result.triangles));
    return result;
}

}  // namespace gmpu
