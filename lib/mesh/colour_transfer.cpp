#include "mesh/colour_transfer.hpp"

#include <nanoflann.hpp>

namespace gmpu {

namespace {

struct BorrowedCloud {
    const double *xyz;
    size_t count;
    size_t kdtree_get_point_count() const { return count; }
    double kdtree_get_pt(size_t i, size_t d) const { return xyz[3 * i + d]; }
    template <class Box>
    bool kdtree_get_bbox(Box &) const { return false; }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, BorrowedCloud>,
                                                 BorrowedCloud, 3, uint32_t>;

}  // namespace

void transfer_colours(Mesh &mesh, const double *xyz, const uint8_t *colours, size_t count) {
    const BorrowedCloud cloud{xyz, count};
    const Tree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));  // builds the index
    const size_t n = mesh.vertex_count();
    mesh.colors.resize(3 * n);
    for (size_t v = 0; v < n; ++v) {
        uint32_t nearest = 0;
        double squared = 0;
        tree.knnSearch(&mesh.vertices[3 * v], 1, &nearest, &squared);
        for (size_t k = 0; k < 3; ++k) mesh.colors[3 * v + k] = colours[3 * size_t(nearest) + k];
    }
}

}  // namespace gmpu
