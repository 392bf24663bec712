#include "pipeline/inside_out_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/median.hpp"
#include "geometry/open_sky.hpp"

namespace gmpu {

namespace {

// Winding centres. A part starts at points whose centre is below this: well past 0, where a
// part whose two sides disagree (a thin blade, a wall) sits, towards the −½ of one turned
// inside out.
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

// Open space. Rays are stopped within this many median spacings of a point (the random gaps
// of a sampled surface closed) and start this many in front of or behind it (past its own
// and its neighbours' blocking balls).
constexpr double kBlockSpacings = 0.75;
constexpr double kStartSpacings = 1.5;
// A part starts at points whose rays escape this much less often in front than behind,
// and takes in neighbours of like normal under kGrowOpenness (its rim, where both sides
// see some sky).
constexpr double kSeedOpenness = -0.3;
constexpr double kGrowOpenness = 0.15;
// A part is turned when its mean openness is under this, it holds at least kMinPart points,
// and the winding number agrees that it is not facing out: its points' median centre is
// under kMaxCentre. In a narrow slot or between close blades both sides are shut in and a
// few points read closed in front, but their centres sit near ½ (or between 0.15 and 0.2
// beside blades thinner than a spacing); a part turned inside out reads about 0 or less.
constexpr double kTurnOpenness = -0.2;
constexpr size_t kMinPart = 16;
constexpr double kMaxCentre = 0.1;

Eigen::Vector3d normal_of(const std::vector<float> &normals, size_t i) {
    return Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
}

// A spacing at point i: its k-th neighbour distance over √k, from the area it stands for.
double spacing(const PointMeasures &measures, size_t i) { return std::sqrt(double(measures.area[i]) / M_PI); }

// The winding centre at point i: the mean winding number a spacing behind and in front.
double winding_centre(const PointSet &points, const PointMeasures &measures, const WindingField &winding, size_t i) {
    const Eigen::Vector3d step = spacing(measures, i) * normal_of(measures.blend_normals, i);
    return 0.5 * (winding.winding(points.point(i) - step) + winding.winding(points.point(i) + step));
}

// Grows the part of `seed` (not yet seen) over the nearest neighbours of like normal whose
// score(j) is under `grow`, marking them seen.
template <class Score>
void grow_part(const PointSet &points, const std::vector<float> &normals, const Score &score, uint32_t seed,
               double grow, std::vector<uint8_t> &seen, std::vector<uint32_t> &part) {
    thread_local std::vector<uint32_t> stack, near;
    thread_local std::vector<float> d2;
    part.assign(1, seed);
    stack.assign(1, seed);
    seen[seed] = 1;
    while (!stack.empty()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        const Eigen::Vector3d ni = normal_of(normals, i);
        // Only the parts' points ask for their neighbours: most clouds have few parts or none.
        points.nearest(points.point(i), kNeighbours + 1, near, d2);
        for (uint32_t j : near) {
            if (seen[j] || !(ni.dot(normal_of(normals, j)) > 0.0) || !(score(j) < grow)) continue;
            seen[j] = 1;
            part.push_back(j);
            stack.push_back(j);
        }
    }
}

// Turns each leaf the majority of whose points are marked (a leaf holding none, with its
// nearest points); returns how many.
size_t turn_marked_leaves(const Octree &tree, const PointSet &points, const std::vector<uint8_t> &turn,
                          CellSigns &signs) {
    std::vector<uint32_t> near;
    std::vector<float> d2;
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

bool measured(const PointSet &points, const PointMeasures &measures, const WindingField &winding) {
    const size_t n = points.size();
    return n > 0 && !winding.empty() && measures.blend_normals.size() == 3 * n && measures.area.size() == n;
}

}  // namespace

size_t turn_inside_out_parts(const Octree &tree, const PointSet &points, const PointMeasures &measures,
                             const WindingField &winding, CellSigns &signs, Workers &workers, Progress &progress) {
    if (!measured(points, measures, winding)) return 0;
    const size_t n = points.size();
    Progress centre_progress = progress.slice(0.0, 0.8);
    std::vector<double> centre(n);
    parallel_for(0, n, workers, centre_progress,
                 [&](size_t i) { centre[i] = winding_centre(points, measures, winding, i); });
    // Grow the parts from their seeds, then judge each with its own dipoles reversed: turned,
    // a point's behind and ahead swap, so its centre moves only by what the part adds there.
    std::vector<uint8_t> turn(n, 0), seen(n, 0);
    std::vector<uint32_t> part;
    for (size_t s = 0; s < n; ++s) {
        progress.poll(0.8 + 0.2 * double(s) / double(n));
        if (seen[s] || !(centre[s] < kSeedCentre)) continue;
        grow_part(points, measures.blend_normals, [&](uint32_t j) { return centre[j]; }, uint32_t(s), kGrowCentre,
                  seen, part);
        // Judged at up to kMaxJudged of its points, evenly strided: every point of the part
        // adds its dipole at each, so a large part costs kMaxJudged × its size, not its square.
        const size_t stride = std::max<size_t>(1, part.size() / kMaxJudged);
        double before = 0.0, after = 0.0;
        size_t judged = 0;
        for (size_t k = 0; k < part.size(); k += stride, ++judged) {
            progress.tick();
            const uint32_t i = part[k];
            const Eigen::Vector3d step = spacing(measures, i) * normal_of(measures.blend_normals, i);
            const Eigen::Vector3d behind = points.point(i) - step, ahead = points.point(i) + step;
            double own = 0.0;
            for (uint32_t j : part) own += winding.point_winding(j, behind) + winding.point_winding(j, ahead);
            before += centre[i];
            after += centre[i] - own;  // ½ (w − 2·own) at both
        }
        before /= double(judged), after /= double(judged);
        if (std::fabs(after - 0.5) < std::fabs(before - 0.5) - kMinGain && after > kTurnedBand &&
            after < 1.0 - kTurnedBand)
            for (uint32_t i : part) turn[i] = 1;
    }
    progress.throw_if_cancelled();
    return turn_marked_leaves(tree, points, turn, signs);
}

size_t turn_parts_facing_in(const Octree &tree, const PointSet &points, const PointMeasures &measures,
                            const WindingField &winding, CellSigns &signs, Workers &workers, Progress &progress) {
    if (!measured(points, measures, winding)) return 0;
    const size_t n = points.size();
    std::vector<float> areas(measures.area);
    const double typical = std::sqrt(double(median_in_place(areas)) / M_PI);
    if (!(typical > 0.0)) return 0;
    const OpenSky sky(points, kBlockSpacings * typical);
    // Openness: the share of rays that escape in front less the share behind, in [−1, 1].
    // The rays in front are cast at every point; those behind (which cross the solid, the
    // longer walk) only where a seed or a part's growth asks for the openness: a point whose
    // front alone keeps it above kSeedOpenness (front − 1 ≥ it) cannot seed.
    // (A Vector3d: an Eigen expression would outlive the normal it refers to.)
    auto start = [&](size_t i) -> Eigen::Vector3d {
        return kStartSpacings * typical * normal_of(measures.blend_normals, i);
    };
    Progress front_progress = progress.slice(0.0, 0.9);
    std::vector<double> front(n), openness(n);
    std::vector<uint8_t> cast(n, 0);
    parallel_for(0, n, workers, front_progress, [&](size_t i) {
        front[i] = sky.escaping(points.point(i) + start(i), normal_of(measures.blend_normals, i));
    });
    auto open = [&](uint32_t i) {
        if (!cast[i]) {
            openness[i] = front[i] - sky.escaping(points.point(i) - start(i), -normal_of(measures.blend_normals, i));
            cast[i] = 1;
        }
        return openness[i];
    };
    std::vector<uint8_t> turn(n, 0), seen(n, 0);
    std::vector<uint32_t> part;
    std::vector<double> centres;
    for (size_t s = 0; s < n; ++s) {
        progress.poll(0.9 + 0.1 * double(s) / double(n));
        if (seen[s] || !(front[s] - 1.0 < kSeedOpenness) || !(open(uint32_t(s)) < kSeedOpenness)) continue;
        grow_part(points, measures.blend_normals, open, uint32_t(s), kGrowOpenness, seen, part);
        if (part.size() < kMinPart) continue;
        double mean = 0.0;
        for (uint32_t i : part) mean += openness[i];
        if (!(mean / double(part.size()) < kTurnOpenness)) continue;
        centres.clear();
        for (uint32_t i : part) {
            progress.tick();
            centres.push_back(winding_centre(points, measures, winding, i));
        }
        if (median_in_place(centres) < kMaxCentre)
            for (uint32_t i : part) turn[i] = 1;
    }
    progress.throw_if_cancelled();
    return turn_marked_leaves(tree, points, turn, signs);
}

}  // namespace gmpu
