// The kd-tree built on several threads (geometry/parallel_kdtree.hpp) is nanoflann's own
// serial tree, node for node: same splits and bounds, same point order, same leaf ranges;
// and a point set built with workers answers every query as one built without, and the
// outlier scan finds the same outliers.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <nanoflann.hpp>

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include "core/parallel.hpp"
#include "geometry/outliers.hpp"
#include "geometry/parallel_kdtree.hpp"
#include "geometry/point_set.hpp"

namespace {

using namespace gmpu;

struct Cloud {
    std::vector<float> xyz;
    size_t kdtree_get_point_count() const { return xyz.size() / 3; }
    float kdtree_get_pt(size_t i, size_t d) const { return xyz[3 * i + d]; }
    template <class Box>
    bool kdtree_get_bbox(Box &) const { return false; }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, uint32_t>;
const auto kSkip = nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex;

// A surface-like cloud with what makes splits uneven or ties: a dense sphere, a sparse far
// blob, and runs of identical points and of points sharing one coordinate.
Cloud awkward_cloud(size_t n) {
    std::mt19937 rng(5);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    Cloud c;
    for (size_t i = 0; i < n; ++i) {
        float p[3] = {gauss(rng), gauss(rng), gauss(rng)};
        const float r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + 1e-6f;
        for (float &v : p) v /= r;
        if (i % 10 == 0) p[0] = 5.0f + uni(rng), p[1] = uni(rng) * 0.1f;  // far blob
        if (i % 13 == 0) p[0] = p[1] = p[2] = 0.25f;                       // duplicates
        if (i % 7 == 0) p[2] = 0.5f;                                      // one shared coordinate
        c.xyz.insert(c.xyz.end(), p, p + 3);
    }
    return c;
}

void assert_same_nodes(const Tree::Node *a, const Tree::Node *b) {
    assert_true((a->child1 == nullptr) == (b->child1 == nullptr));
    assert_true((a->child2 == nullptr) == (b->child2 == nullptr));
    if (!a->child1 && !a->child2) {
        assert_int_equal(a->node_type.lr.left, b->node_type.lr.left);
        assert_int_equal(a->node_type.lr.right, b->node_type.lr.right);
        return;
    }
    assert_int_equal(a->node_type.sub.divfeat, b->node_type.sub.divfeat);
    assert_true(a->node_type.sub.divlow == b->node_type.sub.divlow);
    assert_true(a->node_type.sub.divhigh == b->node_type.sub.divhigh);
    assert_same_nodes(a->child1, b->child1);
    assert_same_nodes(a->child2, b->child2);
}

void parallel_build_is_the_serial_tree(void **) {
    for (size_t n : {size_t(1), size_t(17), size_t(1000), size_t(60000)}) {
        const Cloud cloud = awkward_cloud(n);
        Tree serial(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16, kSkip));
        serial.buildIndex();
        for (unsigned threads : {1u, 2u, 5u}) {
            Workers workers(threads);
            Tree parallel(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16, kSkip));
            std::vector<std::unique_ptr<nanoflann::PooledAllocator>> pools;
            build_kdtree_in_parallel(parallel, pools, workers);
            assert_true(parallel.vAcc == serial.vAcc);
            for (int d = 0; d < 3; ++d) {
                assert_true(parallel.root_bbox[d].low == serial.root_bbox[d].low);
                assert_true(parallel.root_bbox[d].high == serial.root_bbox[d].high);
            }
            assert_same_nodes(parallel.root_node, serial.root_node);
        }
    }
}

void point_set_answers_alike_with_workers(void **) {
    const Cloud cloud = awkward_cloud(1 << 17);  // above the parallel build's threshold
    const size_t n = cloud.xyz.size() / 3;
    Workers workers(3);
    const PointSet alone = PointSet::from_array(cloud.xyz.data(), n, 0, 15);
    const PointSet shared = PointSet::from_array(cloud.xyz.data(), n, 0, 15, &workers);
    std::vector<uint32_t> a, b;
    std::vector<float> da, db;
    for (size_t i = 0; i < n; i += 997) {
        const Eigen::Vector3d q = alone.point(i) + Eigen::Vector3d(1e-3, -2e-3, 0.0);
        a.clear(), b.clear();
        alone.within(q, 0.02, a);
        shared.within(q, 0.02, b);
        assert_true(a == b);  // same order too: the trees are the same
        alone.nearest(q, 8, a, da);
        shared.nearest(q, 8, b, db);
        assert_true(a == b && da == db);
    }
}

void outlier_scan_alike_with_workers(void **) {
    Cloud cloud = awkward_cloud(1 << 16);  // above the parallel scan's threshold
    for (int k = 0; k < 40; ++k) {         // strays far from everything and each other
        const float p[3] = {30.0f + 7.0f * float(k % 8), -20.0f * float(k % 3), 11.0f * float(k / 8)};
        cloud.xyz.insert(cloud.xyz.end(), p, p + 3);
    }
    const size_t n = cloud.xyz.size() / 3;
    Workers workers(3);
    const OutlierScan alone = find_outliers(cloud.xyz.data(), n, 0);
    const OutlierScan shared = find_outliers(cloud.xyz.data(), n, 0, true, &workers);
    assert_int_equal(alone.outliers.size(), 40);
    assert_true(shared.outliers == alone.outliers);
    assert_true(shared.spacing == alone.spacing && shared.extent == alone.extent);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(parallel_build_is_the_serial_tree),
        cmocka_unit_test(point_set_answers_alike_with_workers),
        cmocka_unit_test(outlier_scan_alike_with_workers),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
