// A nanoflann kd-tree (KDTreeSingleIndexAdaptor, made with SkipInitialBuildIndex) built on
// several threads into exactly the tree its own buildIndex() makes: the same splits, the
// same point order, the same leaf ranges and bounds, so every query answers as before.
// nanoflann 1.4 builds on one thread, and the build is most of set_points' cost.
//
// The top levels are split level by level with nanoflann's own middleSplit_, the nodes of
// one level in parallel (their point ranges are disjoint). Below them each subtree is built
// on one thread by divide_subtree, nanoflann's divideTree step for step (middleSplit_ for
// the splits) but taking its nodes from a pool of its own: the tree's pool is not
// thread-safe. Last, the top nodes take their children's tight bounds, bottom-up, as
// divideTree does. Nothing is copied: every thread reorders its own range of the tree's
// point order in place.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

#include <nanoflann.hpp>

#include "core/huge_pages.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"

namespace gmpu {

// The nodes of points [left, right) of the tree's point order, taken from `pool`: what
// nanoflann's divideTree makes of them (bbox in: the bounds it is handed; out: the tight ones).
template <class Tree>
typename Tree::NodePtr divide_subtree(Tree &tree, nanoflann::PooledAllocator &pool, typename Tree::Offset left,
                                      typename Tree::Offset right, typename Tree::BoundingBox &bbox) {
    using Dimension = typename Tree::Dimension;
    const Dimension dims = Dimension(bbox.size());
    typename Tree::NodePtr node = pool.template allocate<typename Tree::Node>();
    if (right - left <= typename Tree::Offset(tree.m_leaf_max_size)) {
        node->child1 = node->child2 = nullptr;
        node->node_type.lr.left = left;
        node->node_type.lr.right = right;
        for (Dimension i = 0; i < dims; ++i) bbox[i].low = bbox[i].high = tree.dataset_get(tree, tree.vAcc[left], i);
        for (auto k = left + 1; k < right; ++k)
            for (Dimension i = 0; i < dims; ++i) {
                const auto v = tree.dataset_get(tree, tree.vAcc[k], i);
                bbox[i].low = std::min(bbox[i].low, v);
                bbox[i].high = std::max(bbox[i].high, v);
            }
        return node;
    }
    typename Tree::Offset split;
    Dimension cutfeat;
    typename Tree::DistanceType cutval;
    tree.middleSplit_(tree, left, right - left, split, cutfeat, cutval, bbox);
    node->node_type.sub.divfeat = cutfeat;
    typename Tree::BoundingBox low(bbox), high(bbox);
    low[cutfeat].high = cutval;
    high[cutfeat].low = cutval;
    node->child1 = divide_subtree(tree, pool, left, left + split, low);
    node->child2 = divide_subtree(tree, pool, left + split, right, high);
    node->node_type.sub.divlow = low[cutfeat].high;
    node->node_type.sub.divhigh = high[cutfeat].low;
    for (Dimension i = 0; i < dims; ++i) {
        bbox[i].low = std::min(low[i].low, high[i].low);
        bbox[i].high = std::max(low[i].high, high[i].high);
    }
    return node;
}

// Builds `tree` on `workers`. The subtrees' nodes are in `pools`, which must live as long as
// the tree (it is cleared first). Cost: the serial build's, shared among the threads but for
// the root's split (one pass over the points).
template <class Tree>
void build_kdtree_in_parallel(Tree &tree, std::vector<std::unique_ptr<nanoflann::PooledAllocator>> &pools,
                              Workers &workers) {
    using Offset = typename Tree::Offset;
    using BoundingBox = typename Tree::BoundingBox;
    using NodePtr = typename Tree::NodePtr;
    using Dimension = typename Tree::Dimension;
    using DistanceType = typename Tree::DistanceType;

    pools.clear();
    // What buildIndex() does before divideTree.
    tree.m_size = tree.dataset.kdtree_get_point_count();
    tree.vAcc.reserve(tree.m_size);
    advise_huge_pages(tree.vAcc);
    tree.init_vind();
    tree.freeIndex(tree);
    tree.m_size_at_index_build = tree.m_size;
    if (tree.m_size == 0) return;
    tree.computeBoundingBox(tree.root_bbox);

    struct Task {
        Offset left, right;
        BoundingBox bbox;            // as divideTree gets it; its tight bounds once built
        NodePtr node = nullptr;
        size_t child1 = 0, child2 = 0;  // indices of the children's tasks; 0: not split here
        Dimension cutfeat = 0;
        DistanceType cutval = 0;
        Offset split = 0;
    };
    std::vector<Task> tasks{Task{0, Offset(tree.m_size), tree.root_bbox}};
    const size_t leaf = tree.m_leaf_max_size;
    // Enough subtrees for the threads to share them evenly although middle splits are
    // unbalanced; each below-top level costs one pass over the points, split among them.
    const size_t wanted = 8 * size_t(workers.threads());
    constexpr int kMaxTopLevels = 10;
    Progress silent(nullptr, nullptr, GMPU_STAGE_FIT);

    std::vector<size_t> frontier{0};
    for (int level = 0; level < kMaxTopLevels && frontier.size() < wanted; ++level) {
        std::vector<size_t> splittable;
        for (size_t t : frontier)
            if (tasks[t].right - tasks[t].left > leaf) splittable.push_back(t);
        if (splittable.empty()) break;
        parallel_for(0, splittable.size(), workers, silent, [&](size_t k) {
            Task &task = tasks[splittable[k]];
            tree.middleSplit_(tree, task.left, task.right - task.left, task.split, task.cutfeat, task.cutval,
                              task.bbox);
        }, 1);
        std::vector<size_t> next;
        for (size_t t : frontier) {
            if (tasks[t].right - tasks[t].left <= leaf) {
                next.push_back(t);
                continue;
            }
            Task &task = tasks[t];
            task.node = tree.pool.template allocate<typename Tree::Node>();
            task.node->node_type.sub.divfeat = task.cutfeat;
            Task low{task.left, task.left + task.split, task.bbox};
            low.bbox[task.cutfeat].high = task.cutval;
            Task high{task.left + task.split, task.right, task.bbox};
            high.bbox[task.cutfeat].low = task.cutval;
            task.child1 = tasks.size();
            task.child2 = tasks.size() + 1;
            next.push_back(task.child1);
            next.push_back(task.child2);
            tasks.push_back(low);  // may move `task`: not used below
            tasks.push_back(high);
        }
        frontier.swap(next);
    }

    pools.resize(frontier.size());
    parallel_for(0, frontier.size(), workers, silent, [&](size_t k) {
        Task &task = tasks[frontier[k]];
        pools[k] = std::make_unique<nanoflann::PooledAllocator>();
        task.node = divide_subtree(tree, *pools[k], task.left, task.right, task.bbox);
    }, 1);

    for (size_t t = tasks.size(); t-- > 0;) {  // children come after their parent
        Task &task = tasks[t];
        if (!task.child1) continue;
        const Task &low = tasks[task.child1], &high = tasks[task.child2];
        task.node->child1 = low.node;
        task.node->child2 = high.node;
        task.node->node_type.sub.divlow = low.bbox[task.cutfeat].high;
        task.node->node_type.sub.divhigh = high.bbox[task.cutfeat].low;
        for (Dimension i = 0; i < Dimension(task.bbox.size()); ++i) {
            task.bbox[i].low = std::min(low.bbox[i].low, high.bbox[i].low);
            task.bbox[i].high = std::max(low.bbox[i].high, high.bbox[i].high);
        }
    }
    tree.root_node = tasks[0].node;
    tree.root_bbox = tasks[0].bbox;
}

// Fewer points build on one thread: handing out the work would cost more.
constexpr size_t kParallelKdtreePoints = 1u << 15;

// Builds `tree` on `workers` when they have several threads and it has enough points, else
// with its own buildIndex(); the same tree either way. `pools` as for build_kdtree_in_parallel.
// Returns whether it shared the work, so that the tree's users can share theirs alike.
template <class Tree>
bool build_kdtree(Tree &tree, std::vector<std::unique_ptr<nanoflann::PooledAllocator>> &pools, Workers *workers) {
    const bool parallel = workers && workers->threads() > 1 &&
                          size_t(tree.dataset.kdtree_get_point_count()) >= kParallelKdtreePoints;
    if (parallel)
        build_kdtree_in_parallel(tree, pools, *workers);
    else
        tree.buildIndex();
    return parallel;
}

}  // namespace gmpu
