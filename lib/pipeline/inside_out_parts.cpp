#include "pipeline/inside_out_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace gmpu {

namespace {

// A part starts at points whose centre is below this: well past 0, where a part whose two
// sides disagree (a thin blade, a wall) sits, towards the −½ of one turned inside out.
constexpr double kSeedCentre = -0.3;
// and takes in the neighbours (of like normal) whose centre is below this: a part turned
// inside out reads less than ½ throughout, its joint to the rest about 0.
constexpr double kGrowCentre = 0.15;
constexpr size_t kNeighbours = 8;
// A part is turned when that brings its mean centre this much nearer ½ and within
// [kTurnedBand, 1 − kTurnedBand]. Beside a blade thinner than a spacing the centres read
// about 0 whichever way its sides face, and a lone point's own dipole cancels out of its
// centre (it adds as much behind as it takes in front): neither passes.
constexpr double kMinGain = 0.3;
constexpr double kTurnedBand = 0.2;
// A part is judged at no more than this many of its points.
constexpr size_t kMaxJudged = 1024;

Eigen::Vector3d normal_of(const std::vector<float> &normals, size_t i) {
    return Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
}

// A spacing at point i: its k-th neighbour distance over √k, from the area it stands for.
double spacing(const PointMeasures &measures, size_t i) { return std::sqrt(double(measures.area[i]) / M_PI); }

}  // namespace

size_t turn_inside_out_parts(const Octree &tree, const PointSet &points, const PointMeasures &measures,
                             const WindingField &winding, CellSigns &signs, Workers &workers, Progress &progress) {
    const size_t n = points.size();
    if (n == 0 || winding.empty() || measures.blend_normals.size() != 3 * n || measures.area.size() != n) return 0;
    Progress centre_progress = progress.slice(0.0, 0.8);

    // Each point's centre: the mean winding number a spacing behind and in front of it.
    std::vector<Eigen::Vector3d> behind(n), ahead(n);
    std::vector<double> centre(n);
    parallel_for(0, n, workers, centre_progress, [&](size_t i) {
        const Eigen::Vector3d step = spacing(measures, i) * normal_of(measures.blend_normals, i);
        behind[i] = points.point(i) - step;
        ahead[i] = points.point(i) + step;
        centre[i] = 0.5 * (winding.winding(behind[i]) + winding.winding(ahead[i]));
    });
    // Grow the parts from their seeds, then judge each with its own dipoles reversed: turned,
    // a point's behind and ahead swap, so its centre moves only by what the part adds there.
    std::vector<uint8_t> turn(n, 0), seen(n, 0);
    std::vector<uint32_t> part, stack, near;
    std::vector<float> d2;
    for (size_t s = 0; s < n; ++s) {
        progress.poll(0.8 + 0.2 * double(s) / double(n));
        if (seen[s] || !(centre[s] < kSeedCentre)) continue;
        part.assign(1, uint32_t(s));
        stack.assign(1, uint32_t(s));
        seen[s] = 1;
        while (!stack.empty()) {
            const uint32_t i = stack.back();
            stack.pop_back();
            const Eigen::Vector3d ni = normal_of(measures.blend_normals, i);
            // Only the parts' points ask for their neighbours: most clouds have few or none.
            points.nearest(points.point(i), kNeighbours + 1, near, d2);
            for (uint32_t j : near) {
                if (seen[j] || !(centre[j] < kGrowCentre) || !(ni.dot(normal_of(measures.blend_normals, j)) > 0.0))
                    continue;
                seen[j] = 1;
                part.push_back(j);
                stack.push_back(j);
            }
        }
        // Judged at up to kMaxJudged of its points, evenly strided: every point of the part
        // adds its dipole at each, so a large part costs kMaxJudged × its size, not its square.
        const size_t stride = std::max<size_t>(1, part.size() / kMaxJudged);
        double before = 0.0, after = 0.0;
        size_t judged = 0;
        for (size_t k = 0; k < part.size(); k += stride, ++judged) {
            progress.tick();
            const uint32_t i = part[k];
            double own = 0.0;
            for (uint32_t j : part) own += winding.point_winding(j, behind[i]) + winding.point_winding(j, ahead[i]);
            before += centre[i];
            after += centre[i] - own;  // ½ (w − 2·own) at both
        }
        before /= double(judged), after /= double(judged);
        if (std::fabs(after - 0.5) < std::fabs(before - 0.5) - kMinGain && after > kTurnedBand &&
            after < 1.0 - kTurnedBand)
            for (uint32_t i : part) turn[i] = 1;
    }
    progress.throw_if_cancelled();

    // A leaf turns with the majority of its points (a leaf holding none, with its nearest).
    size_t turned = 0;
    for (size_t c = 0; c < tree.cells.size(); ++c) {
        const Cell &cell = tree.cells[c];
        if (!cell.is_leaf()) continue;
        near.assign(tree.order.begin() + cell.point_begin, tree.order.begin() + cell.point_end);
        if (near.empty()) points.nearest(cell.centre, kNeighbours, near, d2);
        size_t votes = 0;
        for (uint32_t i : near) votes += turn[i];
        if (!near.empty() && 2 * votes > near.size()) {
            signs[c] = int8_t(-signs[c]);
            ++turned;
        }
    }
    return turned;
}

}  // namespace gmpu
