#include "pipeline/smooth_surface.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/median.hpp"
#include "mesh/polygonizer.hpp"
#include "pipeline/smooth_normals.hpp"

namespace gmpu {

namespace {
// GMPU_PARAM_SURFACE = 2 solves the smooth field from this estimated noise on, as a fraction
// of the bounding-box diagonal. Noise-free clouds estimate (near) 0 and keep the blend.
constexpr double kSmoothFromNoise = 0.003;
// The smooth grid is never finer than this many cubes along the longest side (the default
// polygonize grid's own cap).
constexpr int kMaxResolution = 1024;
// From this estimated noise on (a fraction of the diagonal) the smooth field is solved a
// second time from its own normals: there the blend's normals are noisy enough that their
// smoothed version moves the surface; below it, on a dense cloud, the second solve changes
// little and costs as much (sparse clouds: solve_smooth_surface).
constexpr double kResolveFromNoise = 0.0075;
// From this estimated noise on a dense cloud's field is corrected for the noise's outward
// bias on thin parts (SmoothField's ThinPartBias). The bias goes with σ²; at half this noise
// it is a quarter as large, and the parts the correction takes for thin there are more
// often a CAD part's fins and webs, whose rounding the bias offsets, than tubes made too
// thick. A sparse cloud's field is not corrected: there a thin part comes out too thin
// rather than too thick (its faces' normals cancel in V, few samples hold it), and the
// correction would take away what the samples kept.
constexpr double kThinBiasFromNoise = 0.0075;
// GMPU_PARAM_SURFACE = 2 guides the blend on noise-free clouds of fewer points than this:
// there leaves hold few points and the blend strays past thin parts' ends. On denser clouds the blend alone is mostly as close, and the smooth
// solve would cost several times the rest of the run: it is guided only where it strays
// (blend_strays.hpp).
constexpr size_t kGuideBelowPoints = 20000;
// The guided blend's limit, in median sample spacings: enough for the blend's detail
// (sharp edges, thin walls) to stand, short of its strays.
constexpr double kGuideSpacings = 0.25;
// On dense clouds the smooth field that guides is solved on a grid this many times coarser
// (a third of the time), and the limit widens to a spacing: the strays it must catch lie
// several spacings out, and the coarser field is a fraction of a spacing off the finer one.
constexpr int kDenseGuideCoarsening = 2;
constexpr double kDenseGuideSpacings = 1.0;
// Where the fit found thin walls, the guide's limit widens where the smooth field is flatter
// than a signed distance, at most by 1 / this (Guide, guided_blend.hpp): there the field has
// merged a wall's two sheets, which the blend keeps. A higher floor (less widening) lets
// the guide punch holes through walls the field has only half merged; a lower one leaves
// more of the blend's strays past a thin part's end.
constexpr double kThinWallGuideMinSlope = 0.5;


// Clouds of more points are not tested for strays: the guiding solve's grid follows the
// point spacing, and from a few hundred thousand points on it would take several times the
// rest of the run.
constexpr size_t kStrayTestBelowPoints = 200000;

bool dense(const PointSet &points) { return points.size() >= kGuideBelowPoints; }

// A sparse cloud's smooth surface leans on its samples more than a dense one's
// (Sparseness, implicit/smooth_field.hpp), by √(kGuideBelowPoints / points): continuous
// where a cloud turns dense. Where the smooth field only guides the blend, the blend holds
// the samples already.
Sparseness sparseness(SurfaceKind kind, const PointSet &points) {
    if (kind != SurfaceKind::smooth || dense(points) || points.size() == 0) return {};
    return {std::sqrt(double(kGuideBelowPoints) / double(points.size()))};
}

// A dense cloud's outer field is solved on a grid this many band steps apart (OuterGrid,
// implicit/smooth_field.hpp), a sparse cloud's on the default: there a thin plate's outer
// field, coarser, let the plate come apart.
constexpr double kDenseOuterSteps = 4.0;

OuterGrid outer_grid(const PointSet &points) { return dense(points) ? OuterGrid{kDenseOuterSteps} : OuterGrid{}; }

double noise_fraction(const PointSet &points, double noise) {
    const double diagonal = points.world_diagonal() * points.normalisation().scale;  // normalised
    return diagonal > 0.0 ? noise / diagonal : 0.0;
}

// The points' typical spacing: the square root of the median area a point stands for (0
// without areas).
double median_spacing(const PointMeasures &measures) {
    std::vector<float> area(measures.area);
    return area.empty() ? 0.0 : std::sqrt(double(median_in_place(area)));
}
}  // namespace

int smooth_resolution(const Octree &tree, const PointMeasures &measures) {
    // The octree's detail sets the blend's grid, but at high noise ε is inflated and the
    // octree stops early: its cube can be several point spacings, coarser than the detail the
    // noise-averaged surface still has. The smooth grid is at least as fine as the points'
    // typical spacing (the square root of the median area a point stands for).
    const double spacing = median_spacing(measures);
    const int from_spacing = spacing > 0.0 ? int(std::ceil(1.0 / spacing)) : 0;
    return std::clamp(std::max(default_resolution(tree, measures), from_spacing), 8, kMaxResolution);
}

SurfaceKind surface_kind(const Params &params, const PointSet &points, double noise, bool thin_walls,
                         bool thin_shell, bool blend_strays) {
    switch (params.surface) {
    case 0: return SurfaceKind::blend;
    case 1: return SurfaceKind::smooth;
    case 3: return SurfaceKind::guided_blend;
    default:
        if (noise_fraction(points, noise) >= kSmoothFromNoise) return SurfaceKind::smooth;
        if (thin_shell) return SurfaceKind::shell;
        return !dense(points) || (!thin_walls && blend_strays) ? SurfaceKind::guided_blend : SurfaceKind::blend;
    }
}

bool strays_decide(const Params &params, const PointSet &points, double noise, bool thin_walls, bool thin_shell) {
    return points.size() < kStrayTestBelowPoints && surface_kind(params, points, noise, thin_walls, thin_shell, false) !=
           surface_kind(params, points, noise, thin_walls, thin_shell, true);
}

std::shared_ptr<const ShellField> thin_shell_reading(const PointSet &points, double noise, Workers &workers,
                                                     Progress &progress) {
    if (dense(points) || noise_fraction(points, noise) >= kSmoothFromNoise || !ShellField::may_be_shell(points)) {
        progress.report(1.0);
        return nullptr;
    }
    auto shell = std::make_shared<const ShellField>(points, workers, progress);
    return shell->whole_shell() ? shell : nullptr;
}

int shell_resolution(const ShellField &shell, int default_grid) {
    return std::clamp(std::max(default_grid, shell.grid()), 8, kMaxResolution);
}

Guide guide_for(const PointSet &points, const PointMeasures &measures, bool thin_walls) {
    Guide guide;
    guide.limit = (dense(points) ? kDenseGuideSpacings : kGuideSpacings) * median_spacing(measures);
    if (thin_walls) guide.min_slope = kThinWallGuideMinSlope;
    return guide;
}

bool normals_follow_smooth_field(SurfaceKind kind, const PointSet &points) {
    return kind == SurfaceKind::smooth || (kind == SurfaceKind::guided_blend && !dense(points));
}

int smooth_coarsening(SurfaceKind kind, const PointSet &points) {
    return kind == SurfaceKind::guided_blend && dense(points) ? kDenseGuideCoarsening : 1;
}

std::shared_ptr<const SmoothField> solve_smooth_surface(const Params &params, SurfaceKind kind, const Octree &tree,
                                                        const PointSet &points, const PointMeasures &measures,
                                                        double noise, bool thin_walls, Workers &workers,
                                                        Progress &progress) {
    const double h = double(smooth_coarsening(kind, points)) / smooth_resolution(tree, measures);
    const ZeroLevel level = thin_walls ? ZeroLevel::mean : ZeroLevel::median;
    const double noise_share = noise_fraction(points, noise);
    Progress first_progress = progress.slice(0.0, 0.7), normals_progress = progress.slice(0.7, 0.75),
             second_progress = progress.slice(0.75, 1.0);
    const bool sparse = !dense(points);
    const ThinPartBias thin = !sparse && noise_share >= kThinBiasFromNoise ? ThinPartBias::correct : ThinPartBias::off;
    SmoothField first(points, measures, h, 2.0 * h, noise_share, level, params.max_memory, workers, first_progress,
                      LocalLevel::follow, thin, sparseness(kind, points), outer_grid(points));
    // Solved again from its own normals at the points (where the neighbours agree): they
    // are the blend's normals averaged over the field's neighbourhood, far less noisy than
    // the blend's own at noise, and scattered flips are corrected.
    // A sparse cloud (under kGuideBelowPoints) is solved again wherever it has a smooth
    // surface at all (kSmoothFromNoise): there the orientation leaves a few percent of the
    // normals wrong in patches, and the first field, pulled by them, fills the space between
    // nearby parts (legs, a tail) where no point lies; the field's own normals outvote the
    // patches. A sparse cloud's solve takes a fraction of a second.
    const bool resolve = noise_share >= kResolveFromNoise || (sparse && noise_share >= kSmoothFromNoise);
    if (!resolve) {
        progress.report(1.0);
        return std::make_shared<const SmoothField>(std::move(first));
    }
    const std::vector<float> normals = field_point_normals(first, points, measures, normals_progress);
    return std::make_shared<const SmoothField>(
        first.resolved(points, measures, normals, noise_share, params.max_memory, workers, second_progress));
}

}  // namespace gmpu
