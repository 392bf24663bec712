#include "mesh/confidence.hpp"

#include <cmath>
#include <vector>

#include "core/parallel.hpp"

namespace gmpu {

void compute_confidence(Mesh &mesh, const PointSet &points, const PointMeasures &measures, Workers &workers,
                        Progress &progress) {
    const size_t n = mesh.vertex_count();
    mesh.confidence.assign(n, 0.0);
    if (points.empty()) return;
    const Normalisation &norm = points.normalisation();
    constexpr size_t kChunk = 256;
    const size_t chunks = (n + kChunk - 1) / kChunk;
    parallel_for(0, chunks, workers, progress, [&](size_t c) {
        std::vector<uint32_t> nearest;
        std::vector<float> squared;
        for (size_t v = c * kChunk; v < std::min(n, (c + 1) * kChunk); ++v) {
            const Eigen::Vector3d q =
                norm.to_unit(Eigen::Vector3d(mesh.vertices[3 * v], mesh.vertices[3 * v + 1], mesh.vertices[3 * v + 2]));
            nearest.clear();
            points.nearest(q, 1, nearest, squared);
            if (nearest.empty()) {
                mesh.confidence[v] = INFINITY;
                continue;
            }
            const double spacing = std::sqrt(double(measures.area[nearest[0]]));
            const double distance = std::sqrt(double(squared[0]));
            mesh.confidence[v] = spacing > 0 ? distance / spacing : (distance > 0 ? INFINITY : 0.0);
        }
    });
}

Mesh trim_unsupported(const Mesh &mesh, double threshold) {
    Mesh out;
    std::vector<uint32_t> index(mesh.vertex_count(), UINT32_MAX);
    const bool normals = mesh.normals.size() == mesh.vertices.size();
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        bool supported = true;
        for (int k = 0; k < 3; ++k) supported = supported && mesh.confidence[mesh.triangles[t + k]] <= threshold;
        if (!supported) continue;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh.triangles[t + k];
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
