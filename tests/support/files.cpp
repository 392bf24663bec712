#include "files.hpp"

#include "io/io.hpp"

namespace gmpu::testing {

namespace {

std::vector<Vec3> to_vectors(const std::vector<double> &flat) {
    std::vector<Vec3> out;
    out.reserve(flat.size() / 3);
    for (size_t i = 0; i + 2 < flat.size(); i += 3) out.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
    return out;
}

std::vector<double> to_flat(const std::vector<Vec3> &vectors) {
    std::vector<double> out;
    out.reserve(3 * vectors.size());
    for (const Vec3 &v : vectors) out.insert(out.end(), {v.x(), v.y(), v.z()});
    return out;
}

}  // namespace

TriangleMesh load_mesh(const std::string &path) {
    const io::MeshData data = io::read_mesh(path);
    return mesh_from_arrays(data.vertices.data(), data.vertices.size() / 3,
                            data.triangles.data(), data.triangles.size() / 3);
}

OrientedPoints load_points(const std::string &path) {
    const io::PointCloud cloud = io::read_points(path);
    return {to_vectors(cloud.positions), to_vectors(cloud.normals)};
}

void save_points(const std::string &path, const OrientedPoints &points, bool with_normals) {
    const std::vector<double> xyz = to_flat(points.positions);
    const bool normals = with_normals && points.normals.size() == points.size();
    const std::vector<double> nxyz = normals ? to_flat(points.normals) : std::vector<double>{};
    io::write_points(path, xyz.data(), normals ? nxyz.data() : nullptr, points.size());
}

}  // namespace gmpu::testing
