// What belief propagation contributes under each front order: for every cloud given (with
// its *_gt.ply of true normals beside it), orient is run four ways — the front taken most
// evidence first (the library's) or first-in-first-out (the paper's), each leaf decided by
// belief propagation (the library's) or by a plain weighted vote of its labelled
// neighbours — and the share of points whose oriented normal agrees with the true one is
// printed. Same fit for all four. README, "What belief propagation adds".
//
//   orient-ablation CLOUD.ply [CLOUD.ply ...]
#include <cstdio>
#include <string>
#include <vector>

#include "core/parallel.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "fit/build_octree.hpp"
#include "fit/noise_estimate.hpp"
#include "geometry/point_set.hpp"
#include "gmpu/gmpu.h"
#include "implicit/mpu_function.hpp"
#include "implicit/point_measures.hpp"
#include "orient/orient.hpp"

using namespace gmpu;

namespace {

struct Variant {
    const char *name;
    FrontOrder order;
    LeafDecision decision;
};
const Variant kVariants[] = {
    {"evidence+BP", FrontOrder::most_evidence_first, LeafDecision::belief_propagation},
    {"evidence+vote", FrontOrder::most_evidence_first, LeafDecision::weighted_vote},
    {"FIFO+BP", FrontOrder::fifo, LeafDecision::belief_propagation},
    {"FIFO+vote", FrontOrder::fifo, LeafDecision::weighted_vote},
};

gmpu_points *read(const std::string &path) {
    gmpu_points *p = nullptr;
    if (gmpu_points_read(path.c_str(), &p) != GMPU_OK) {
        std::fprintf(stderr, "%s: %s\n", path.c_str(), gmpu_last_error());
        return nullptr;
    }
    return p;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s CLOUD.ply [CLOUD.ply ...] (each with CLOUD_gt.ply beside it)\n", argv[0]);
        return 2;
    }
    std::printf("cloud\tpoints\tleaves");
    for (const Variant &v : kVariants) std::printf("\t%s", v.name);
    std::printf("\n");
    int failures = 0;
    for (int a = 1; a < argc; ++a) {
        const std::string path = argv[a], gt_path = path.substr(0, path.size() - 4) + "_gt.ply";
        gmpu_points *cloud = read(path), *gt = read(gt_path);
        if (!cloud || !gt || !gmpu_points_normals(gt) || gmpu_points_count(gt) != gmpu_points_count(cloud)) {
            std::fprintf(stderr, "%s: needs %s with one true normal per point\n", path.c_str(), gt_path.c_str());
            ++failures;
            gmpu_points_destroy(cloud);
            gmpu_points_destroy(gt);
            continue;
        }
        const size_t n = gmpu_points_count(cloud);
        const double *truth = gmpu_points_normals(gt);
        try {
            const PointSet points = PointSet::from_array(gmpu_points_positions(cloud), n, 0, 15);
            const Params params;
            Progress quiet(nullptr, nullptr, GMPU_STAGE_FIT);
            const double eps = effective_epsilon(points, params, estimate_noise(points, quiet));
            Workers workers(0);
            const Octree fitted = build_octree(points, params, eps, workers, quiet);
            size_t leaves = 0;
            for (const Cell &c : fitted.cells) leaves += c.is_leaf();
            std::printf("%s\t%zu\t%zu", path.substr(path.rfind('/') + 1).c_str(), n, leaves);
            for (const Variant &v : kVariants) {
                const Octree &tree = fitted;  // orient leaves the fit as it is
                FrontOptions front;
                front.order = v.order;
                front.decision = v.decision;
                const Orientation orientation = orient_octree(tree, points, nullptr, workers, quiet, front);
                const MpuFunction f(tree, orientation.signs, 0);
                const std::vector<float> normals = point_normals(f, points, workers, quiet);
                size_t right = 0;
                for (size_t i = 0; i < n; ++i) {
                    double dot = 0.0;
                    for (int d = 0; d < 3; ++d) dot += double(normals[3 * i + d]) * truth[3 * i + d];
                    right += dot > 0.0;
                }
                std::printf("\t%.3f%%", 100.0 * double(right) / double(n));
            }
            std::printf("\n");
            std::fflush(stdout);
        } catch (const std::exception &e) {
            std::fprintf(stderr, "%s: %s\n", path.c_str(), e.what());
            ++failures;
        }
        gmpu_points_destroy(cloud);
        gmpu_points_destroy(gt);
    }
    return failures ? 1 : 0;
}
