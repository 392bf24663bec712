#include "fit/build_octree.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <string>
#include <thread>

#include "core/huge_pages.hpp"
#include "core/memory_budget.hpp"
#include "core/parallel.hpp"
#include "fit/cell_fit.hpp"

namespace gmpu {

namespace {

// Supports larger than this (estimated) are taken from the coarse subsample.
constexpr double kFullSupport = 16384;
// A leaf that misses ε but has no child near the data is "stranded" (typically a coarse
// cell beside a sharp corner, whose cube holds no point). Its blending weight is scaled by
// (ε / error)^kStrandedPower: where finer leaves reach, they decide; where none does, it
// still stands in.
constexpr double kStrandedPower = 2.0;
// Two-sheet cells whose sheets end inside the support (a plate's rim) are split this many
// levels below the first such cell: past the rim their slab runs on until other leaves take
// over, and smaller cells there leave less of it. One level left most of a tube's fin; more
// than two add cells without closing what two leave.
constexpr uint8_t kMaxRimSplits = 2;

// Memory model of fit, for GMPU_PARAM_MAX_MEMORY (upper estimates of the peak): per point,
// the points and their kd-trees and the octree's order; per cell, the cell, its copy among
// a level's children while they are made, and the cells vector's growth slack.
constexpr double kFitBytesPerPoint = 48;
constexpr double kFitBytesPerCell = 3 * sizeof(Cell);

void check_fit_memory(size_t points, double cells, double budget) {
    const double estimate = double(points) * kFitBytesPerPoint + cells * kFitBytesPerCell;
    if (estimate <= budget) return;  // the message only when it fails: this runs per cell
    const std::string what = "fit (" + std::to_string(points) + " points, " + std::to_string(uint64_t(cells)) + " cells)";
    check_memory(estimate, budget, what.c_str());
}

struct Builder {
    const PointSet &points;
    const Params &params;
    double epsilon;  // ε in normalised units
    double requested;  // the caller's ε, before the noise floor
    CloseSheets close_sheets;  // where to look for sheets a few σ apart (two_sheet_fit.hpp)
    Workers &workers;
    Progress &progress;
    Octree tree;
    // Progress inside a level, counted in points: near the root a level has a few cells that
    // each take long, so the bar also moves as their children are fitted, by the share of
    // the level's points whose child is done. Reported from the calling thread only.
    std::thread::id caller = std::this_thread::get_id();
    Progress *level_progress = nullptr;
    double level_points = 1.0;
    mutable std::atomic<uint64_t> level_fitted{0};

    void report_work() const {
        if (level_progress && std::this_thread::get_id() == caller)
            level_progress->report(double(level_fitted.load(std::memory_order_relaxed)) / level_points);
        progress.tick();
    }

    double support_radius(double size) const { return params.support_scale * std::sqrt(3.0) * size; }

    bool should_subdivide(const Cell &c) const {
        return (c.error > epsilon || c.unresolved_sheets || c.split_at_rim) && c.depth < params.max_depth &&
               c.initial_count >= uint32_t(params.min_points);
    }

    // Gathers the support and fits it; returns false when the ball holds no point and the
    // cube is empty (the cell is not created).
    bool fit(Cell &c, bool cube_has_points, PiecewiseShape &piece) const {
        // Near the root one cell's children take tens of milliseconds: report between fits.
        report_work();
        thread_local std::vector<uint32_t> idx;
        thread_local std::vector<float> d2;
        thread_local PointList support;
        // A cell exists only near the data: a point in its cube, or within one cell size of
        // its centre (so cells whose corner the surface merely clips still join the face
        // graph). Cells farther out would extrapolate their fits into empty space.
        if (!cube_has_points && points.count_within(c.centre, c.size, 1) == 0) return false;
        idx.clear();
        c.radius = support_radius(c.size);
        // Coarse cells of a big cloud: their support holds a large share of all points, and
        // a uniform subsample of it fits as well (the fit uses 2048 points at most anyway).
        double estimate = 0.0;
        if (points.coarse_ratio() > 1.0) {
            points.coarse_within(c.centre, c.radius, idx);
            estimate = double(idx.size()) * points.coarse_ratio();
        }
        if (estimate <= kFullSupport) {
            idx.clear();
            points.within(c.centre, c.radius, idx);
        }
        const size_t nmin = size_t(params.min_points);
        c.initial_count = uint32_t(std::min(idx.size(), nmin));
        if (idx.size() < nmin) {
            // Grow R to the N_min-th nearest point: the continuous limit of Ohtake's
            // 10 % steps, found with one k-nearest query instead of repeated searches.
            points.nearest(c.centre, nmin, idx, d2);
            c.radius = std::max(c.radius, std::sqrt(double(d2.back())) * (1.0 + 1e-6));
        }
        support.resize(idx.size());
        for (size_t k = 0; k < idx.size(); ++k) support[k] = points.point(idx[k]) - c.centre;
        CellFit f = fit_cell(support, c.radius, epsilon, requested, params, close_sheets);
        c.unresolved_sheets = f.unresolved_sheets;
        c.split_at_rim = f.sheets_end && f.error <= epsilon && c.rim_splits_above < kMaxRimSplits;
        c.support_count = uint32_t(std::max(double(idx.size()), estimate));
        c.error = float(f.error);
        c.variation = float(f.variation);
        c.shape = f.shape;
        if (is_piecewise(f.shape.model)) {
            c.shape.piece = -2;  // resolved to a table index when appended (single-threaded)
            piece = f.piece;
        }
        level_fitted.fetch_add(c.point_end - c.point_begin, std::memory_order_relaxed);
        return true;
    }

    struct Child {
        Cell cell;
        PiecewiseShape piece;
    };

    // Partitions the parent's points by octant and fits every non-empty child.
    std::vector<Child> make_children(const Cell &parent) {
        std::vector<Child> kids;
        uint32_t *ord = tree.order.data();
        uint32_t b = parent.point_begin, e = parent.point_end;
        auto octant_of = [&](uint32_t i) {
            Eigen::Vector3d p = points.point(i);
            return int(p[0] >= parent.centre[0]) | int(p[1] >= parent.centre[1]) << 1 |
                   int(p[2] >= parent.centre[2]) << 2;
        };
        uint32_t count[8] = {0};
        for (uint32_t k = b; k < e; ++k) ++count[octant_of(ord[k])];
        uint32_t start[9] = {b};
        for (int o = 0; o < 8; ++o) start[o + 1] = start[o] + count[o];
        {
            thread_local std::vector<uint32_t> tmp;
            tmp.assign(ord + b, ord + e);
            uint32_t fill[8];
            std::copy(start, start + 8, fill);
            for (uint32_t i : tmp) ord[fill[octant_of(i)]++] = i;
        }
        const double half = parent.size * 0.5;
        for (int o = 0; o < 8; ++o) {
            Child child;
            Cell &c = child.cell;
            c.size = half;
            c.depth = uint8_t(parent.depth + 1);
            for (int d = 0; d < 3; ++d) {
                int bit = (o >> d) & 1;
                c.coord[d] = uint16_t(parent.coord[d] * 2 + bit);
                c.centre[d] = parent.centre[d] + (bit ? 0.5 : -0.5) * half;
            }
            c.point_begin = start[o];
            c.point_end = start[o + 1];
            c.rim_splits_above = uint8_t(parent.rim_splits_above + (parent.split_at_rim ? 1 : 0));
            if (!fit(c, count[o] > 0, child.piece)) continue;
            kids.push_back(child);
            kids.back().cell.child_mask = 0;
            // Remember the octant in first_child until the parent is linked (see append).
            kids.back().cell.first_child = o;
        }
        return kids;
    }

    void append(Cell &&c, const PiecewiseShape &piece) {
        if (c.shape.piece == -2) {
            c.shape.piece = int32_t(tree.pieces.size());
            tree.pieces.push_back(piece);
        }
        tree.cells.push_back(std::move(c));
    }

    // Levels still to make, this one included: a level's work is about the same at every depth
    // (each unsettled point is in a support or two per level), so the bar is shared among
    // them. Splitting a surface's cell spreads its points over about 4 children, and cells
    // stop splitting near GMPU_PARAM_MIN_POINTS points.
    double expected_levels(const std::vector<uint32_t> &level, double settled) const {
        const double unsettled = std::max(1.0, (1.0 - settled) * double(points.size()));
        const double per_cell = unsettled / double(level.size());
        const double by_points = std::max(1.0, std::ceil(std::log(per_cell / params.min_points) / std::log(4.0)));
        const double by_depth = std::max(1.0, double(params.max_depth) - double(tree.cells[level[0]].depth));
        return std::min(by_points, by_depth);
    }

    [[noreturn]] void too_many_cells() const {
        throw Error(GMPU_ERROR_LIMIT_EXCEEDED, "the octree needs more than GMPU_PARAM_MAX_CELLS = " +
                                                   std::to_string(uint64_t(params.max_cells)) +
                                                   " cells; raise the cap, raise GMPU_PARAM_ERROR or lower "
                                                   "GMPU_PARAM_MAX_DEPTH");
    }

    Octree run() {
        const size_t n = points.size();
        check_fit_memory(n, 1, params.max_memory);
        tree.order.reserve(n);
        advise_huge_pages(tree.order);
        tree.order.resize(n);
        std::iota(tree.order.begin(), tree.order.end(), 0u);
        // Room for the cells up front (address space only until used): growing the array by
        // doubling would copy all the cells made so far in one go, with no report between.
        tree.cells.reserve(size_t(std::min(params.max_cells, 8.0 * double(n) / params.min_points + 64.0)));

        Cell root;
        root.centre.setZero();
        root.size = kRootSize;
        root.point_begin = 0;
        root.point_end = uint32_t(n);
        PiecewiseShape root_piece;
        fit(root, true, root_piece);
        append(std::move(root), root_piece);

        std::vector<uint32_t> level;
        if (should_subdivide(tree.cells[0])) level.push_back(0);
        double settled = level.empty() ? 1.0 : 0.0;  // share of points already in leaves
        double done = 0.0;                             // the progress bar's top so far

        while (!level.empty()) {
            std::vector<std::vector<Child>> kids(level.size());
            // Each level continues the bar where the previous one stopped, and takes the
            // share of what is left that one of the levels still expected gets, with one
            // share kept back: 1 means done, and more levels than expected may follow.
            const double span = (1.0 - done) / (expected_levels(level, settled) + 1.0);
            Progress this_level = progress.slice(done, done + span);
            done += span;
            level_points = 0.0;
            for (uint32_t parent : level) level_points += tree.cells[parent].point_end - tree.cells[parent].point_begin;
            level_points = std::max(1.0, level_points);
            level_fitted = 0;
            level_progress = &this_level;
            // The cap is checked as children are made, not once the level is done: a level can
            // hold most of the octree, and would otherwise overshoot the cap up to 8-fold.
            std::atomic<size_t> made{tree.cells.size()};
            // One cell per chunk: near the root a cell's fit takes tens of milliseconds, and
            // the caller reports progress (and sees a cancel) only between chunks.
            parallel_for(0, level.size(), workers, this_level, [&](size_t i) {
                kids[i] = make_children(tree.cells[level[i]]);
                const double cells = double(made += kids[i].size());
                if (cells > params.max_cells) too_many_cells();
                check_fit_memory(n, cells, params.max_memory);
            }, 1);
            level_progress = nullptr;
            progress.throw_if_cancelled();

            std::vector<uint32_t> next;
            for (size_t i = 0; i < level.size(); ++i) {
                progress.tick();
                uint32_t parent = level[i];
                if (kids[i].empty()) {  // stays a leaf, although its fit misses ε
                    Cell &stranded = tree.cells[parent];
                    stranded.blend_factor =
                        float(std::min(1.0, std::pow(epsilon / double(stranded.error), kStrandedPower)));
                    continue;
                }
                tree.cells[parent].first_child = int32_t(tree.cells.size());
                for (auto &k : kids[i]) {
                    tree.cells[parent].child_mask |= uint8_t(1u << k.cell.first_child);
                    k.cell.first_child = -1;
                    k.cell.parent = int32_t(parent);
                    bool split = should_subdivide(k.cell);
                    if (split) next.push_back(uint32_t(tree.cells.size()));
                    else settled += double(k.cell.point_end - k.cell.point_begin) / double(n);
                    append(std::move(k.cell), k.piece);
                }
            }
            if (double(tree.cells.size()) > params.max_cells) too_many_cells();
            level.swap(next);
            progress.report(done);
        }
        // Subtree radius, children before parents (they come later in the array).
        for (size_t i = tree.cells.size(); i-- > 0;) {
            Cell &c = tree.cells[i];
            c.subtree_radius = std::max(c.subtree_radius, c.radius);
            if (c.parent >= 0) {
                Cell &p = tree.cells[size_t(c.parent)];
                p.subtree_radius = std::max(p.subtree_radius, (c.centre - p.centre).norm() + c.subtree_radius);
            }
        }
        return std::move(tree);  // the caller makes the final report
    }
};

}  // namespace

namespace {
double requested_epsilon(const PointSet &points, const Params &params) {
    return params.error * points.world_diagonal() * points.normalisation().scale;
}
}  // namespace

double effective_epsilon(const PointSet &points, const Params &params, double noise) {
    return std::max(requested_epsilon(points, params), params.noise_scale * noise);
}

Octree build_octree(const PointSet &points, const Params &params, double epsilon, Workers &workers,
                    Progress &progress, bool close_sheets) {
    // Sheets a few σ apart matter only where the noise, not the caller, sets ε.
    const double requested = requested_epsilon(points, params);
    const CloseSheets close = !(epsilon > requested) ? CloseSheets::off
                              : close_sheets         ? CloseSheets::cloud
                                                     : CloseSheets::local;
    Builder b{points, params, epsilon, std::min(epsilon, requested), close, workers, progress, {}};
    return b.run();
}

}  // namespace gmpu
