// CGAL peer pipeline for the benchmark: jet normals → MST orientation → Poisson surface
// reconstruction, CGAL's own recipe (its Poisson example), with its example parameters.
// Built by run_bench.py with g++ against Debian's libcgal-dev; never part of libgmpu.
//
//   cgal_peer INPUT.ply OUTPUT_MESH.ply ORIENTED_POINTS.ply
//
// Prints one JSON object: seconds per stage, and under "info" how many points MST left
// unoriented (it orients only the neighbour graph's component holding its seed point).
// The oriented points are written in the input's order (MST reorders its range), so
// they can be scored against the *_gt.ply normals point by point.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/read_points.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/compute_average_spacing.h>
#include <CGAL/jet_estimate_normals.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/poisson_surface_reconstruction.h>
#include <CGAL/property_map.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <tuple>
#include <vector>

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Entry = std::tuple<Point, Vector, std::size_t>;  // position, normal, input index
using PointMap = CGAL::Nth_of_tuple_property_map<0, Entry>;
using NormalMap = CGAL::Nth_of_tuple_property_map<1, Entry>;

namespace {

constexpr unsigned kNeighbours = 18;       // jet fitting and MST graph (CGAL's examples)
constexpr unsigned kSpacingNeighbours = 6;  // average spacing for Poisson (CGAL's example)

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Binary little-endian PLY: float32 vertices (with normals when given), int32 faces.
bool write_ply(const char *path, const std::vector<float> &xyz, const std::vector<float> &normals,
               const std::vector<int> &faces) {
    std::ofstream out(path, std::ios::binary);
    const size_t n = xyz.size() / 3;
    out << "ply\nformat binary_little_endian 1.0\ncomment written by gmpu's cgal_peer\n"
        << "element vertex " << n << "\nproperty float x\nproperty float y\nproperty float z\n";
    if (!normals.empty()) out << "property float nx\nproperty float ny\nproperty float nz\n";
    out << "element face " << faces.size() / 3 << "\nproperty list uchar int vertex_indices\n"
        << "end_header\n";
    for (size_t i = 0; i < n; ++i) {
        out.write(reinterpret_cast<const char *>(&xyz[3 * i]), 12);
        if (!normals.empty()) out.write(reinterpret_cast<const char *>(&normals[3 * i]), 12);
    }
    for (size_t f = 0; f < faces.size(); f += 3) {
        const unsigned char three = 3;
        out.write(reinterpret_cast<const char *>(&three), 1);
        out.write(reinterpret_cast<const char *>(&faces[f]), 12);
    }
    return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char **argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: cgal_peer INPUT.ply OUTPUT_MESH.ply ORIENTED_POINTS.ply\n");
        return 2;
    }
    auto start = std::chrono::steady_clock::now();
    std::vector<Point> read;
    if (!CGAL::IO::read_points(argv[1], std::back_inserter(read))) {
        std::fprintf(stderr, "cgal_peer: cannot read %s\n", argv[1]);
        return 1;
    }
    std::vector<Entry> points;
    points.reserve(read.size());
    for (std::size_t i = 0; i < read.size(); ++i) points.emplace_back(read[i], Vector(0, 0, 0), i);
    const double t_read = seconds_since(start);

    const auto maps = CGAL::parameters::point_map(PointMap()).normal_map(NormalMap());
    start = std::chrono::steady_clock::now();
    CGAL::jet_estimate_normals<CGAL::Sequential_tag>(points, kNeighbours, maps);
    const double t_normals = seconds_since(start);

    start = std::chrono::steady_clock::now();
    const auto unoriented = CGAL::mst_orient_normals(points, kNeighbours, maps);
    const auto unoriented_count = std::distance(unoriented, points.end());
    const double t_orient = seconds_since(start);

    // Poisson on every point, as the pipeline is measured on all of them; the points MST
    // could not reach keep their jet normal's arbitrary sign.
    start = std::chrono::steady_clock::now();
    const double spacing =
        CGAL::compute_average_spacing<CGAL::Sequential_tag>(points, kSpacingNeighbours, maps);
    Mesh mesh;
    const bool ok = CGAL::poisson_surface_reconstruction_delaunay(
        points.begin(), points.end(), PointMap(), NormalMap(), mesh, spacing);
    const double t_reconstruct = seconds_since(start);
    if (!ok) {
        std::fprintf(stderr, "cgal_peer: Poisson reconstruction failed\n");
        return 1;
    }

    start = std::chrono::steady_clock::now();
    std::vector<float> xyz, nxyz(3 * points.size());
    std::vector<int> faces;
    std::vector<float> pxyz(3 * points.size());
    for (const Entry &e : points) {
        const std::size_t i = std::get<2>(e);
        for (int k = 0; k < 3; ++k) {
            pxyz[3 * i + k] = static_cast<float>(std::get<0>(e)[k]);
            nxyz[3 * i + k] = static_cast<float>(std::get<1>(e)[k]);
        }
    }
    std::vector<int> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), -1);
    int next = 0;
    for (Mesh::Vertex_index v : mesh.vertices()) {
        index[v] = next++;
        for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(mesh.point(v)[k]));
    }
    for (Mesh::Face_index f : mesh.faces()) {
        int corners = 0;
        for (Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            faces.push_back(index[v]);
            ++corners;
        }
        if (corners != 3) {
            std::fprintf(stderr, "cgal_peer: a face with %d corners\n", corners);
            return 1;
        }
    }
    if (!write_ply(argv[2], xyz, {}, faces) || !write_ply(argv[3], pxyz, nxyz, {})) {
        std::fprintf(stderr, "cgal_peer: cannot write the outputs\n");
        return 1;
    }
    const double t_write = seconds_since(start);
    std::printf("{\"read\": %.6f, \"normals\": %.6f, \"orient\": %.6f, \"reconstruct\": %.6f, "
                "\"write\": %.6f, \"info\": {\"points\": %zu, \"mst_unoriented\": %ld, "
                "\"spacing\": %.9g}}\n",
                t_read, t_normals, t_orient, t_reconstruct, t_write, points.size(),
                static_cast<long>(unoriented_count), spacing);
    return 0;
}
