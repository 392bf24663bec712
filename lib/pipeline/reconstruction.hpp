// One reconstruction's state and its stages: the point set, the fitted tree, the oriented
// point measures, the winding field, and the worker threads every stage's loops share.
// Each stage computes into locals and commits only once it has completed (its final
// report included), so a cancelled or failed stage leaves the previous stage's result as
// it was. The C ABI (lib/api/surface_api.cpp) checks arguments, converts inputs and keeps
// the stage order; this is where the stages are run.
#pragma once

#include <cstddef>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/parallel.hpp"
#include "core/params.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/smooth_field.hpp"
#include "implicit/surface_field.hpp"
#include "implicit/winding_field.hpp"
#include "mesh/mesh.hpp"
#include "model/octree.hpp"
#include "orient/orient.hpp"
#include "pipeline/smooth_surface.hpp"

namespace gmpu {

struct Reconstruction {
    PointSet points;                       // the input points less the outliers
    size_t input_count = 0;                // points given, outliers included
    std::vector<uint32_t> outliers;        // input indices set aside, increasing
    std::vector<uint32_t> outlier_nearest; // per outlier: the nearest kept point
    std::vector<float> input_normals;      // unit, 3 per kept point; empty when none were given
    Octree tree;                           // fit's result, never changed after
    CellSigns signs;                       // orient's result: one label per cell of the tree
    PointMeasures measures;                // orient's: oriented normals, areas, trust radii per point
    WindingField winding;                  // built from the measures; signs far regions
    // The smooth field (pipeline/smooth_surface.hpp) when GMPU_PARAM_SURFACE asked for it
    // at the last orient or polygonize; null: the MPU blend.
    std::shared_ptr<const SmoothField> smooth;
    // With the smooth field: how far it lets the blend depart (implicit/guided_blend.hpp), or
    // no guide where it replaces the blend.
    Guide guide;
    // The surface the smooth field was solved for (its grid depends on it: smooth_surface.hpp):
    // with `smooth`, the surface evaluate and polygonize use (without it, the blend, or the
    // thin shell's wall when this is shell).
    SurfaceKind smooth_kind = SurfaceKind::blend;
    // Whether the blend was tested for strays (pipeline/blend_strays.hpp; only where the
    // automatic surface depends on it, at orient or polygonize) and found them.
    bool strays_tested = false, strays_found = false;
    // The blend's mesh orient made for that test, where the blend stays the surface, with the
    // grid, parameters and seconds it took: polygonize hands it out when asked for the same
    // mesh (empty: none kept).
    Mesh tested_mesh;
    int tested_resolution = 0;
    Params tested_params;
    double tested_seconds = 0.0;
    // Moves out the kept mesh if it is the one `params` and `resolution` ask for (else an
    // empty mesh); `seconds` gets the time it took to make.
    Mesh take_tested_mesh(const Params &params, int resolution, double &seconds);
    OrientStats orient_stats;
    // The default grids of the last orient, blend's and smooth field's: evaluate asks for one
    // on every call, and each is a pass over every cell and point.
    int blend_grid = 0, smooth_grid = 0, shell_grid = 0;
    double noise = 0.0, epsilon = 0.0;     // of the last fit, normalised units
    bool thin_walls = false;               // whether the last fit found any (polygonizer.hpp: thin_wall_gap)
    // The last fit's reading of the cloud as one thin shell (smooth_surface.hpp:
    // thin_shell_reading); null where it is not one. The surface when smooth_kind is shell.
    std::shared_ptr<const ShellField> shell;

    // Fit: noise estimate, ε, adaptive octree of local fits.
    void fit(const Params &params, Progress &progress);
    // Orient: cell signs, oriented point normals and measures, winding field, and the smooth
    // field when GMPU_PARAM_SURFACE asks for it.
    void orient(const Params &params, Progress &progress);
    // The mesh of the zero set at `resolution` (polygonizer.hpp: default_resolution), the one
    // orient kept if it is that (take_tested_mesh). Tests the blend, solves or drops the
    // smooth field first when GMPU_PARAM_SURFACE changed since orient. `made_at_orient` (may
    // be null) gets the seconds orient spent on the mesh returned (0 when it is made here).
    Mesh polygonize(const Params &params, int resolution, Progress &progress, double *made_at_orient = nullptr);
    // Polygonize's grid when GMPU_PARAM_RESOLUTION is 0: the smooth field's when `params`
    // asks for it alone, else the blend's (blend_resolution).
    int default_resolution(const Params &params) const;
    // The blend's grid: the octree's (polygonizer.hpp: default_resolution), coarsened to the
    // mesh's triangle budget where the points are dense and clean (grid_budget.hpp).
    int blend_resolution() const;
    // Whether the field matches `params`: the smooth field is there, and guides or replaces
    // the blend, as GMPU_PARAM_SURFACE asks (false after the parameter changed since the last
    // orient or polygonize, until one of them solves, drops or re-purposes it).
    bool field_matches(const Params &params) const;
    // f and ∇f (world frame values, unit-free gradients) at `count` world points; either
    // output may be null. Requires an oriented reconstruction whose field matches `params`.
    void evaluate(const Params &params, const double *xyz, size_t count, double *values, double *gradients) const;

    // The surface field of the oriented reconstruction, blended down to `level` (0: the
    // leaves): the one field evaluate and polygonize both ask. A view: valid while this
    // reconstruction is not changed.
    SurfaceField field(int level) const {
        return SurfaceField(MpuFunction(tree, signs, level), points, measures, winding, smooth.get(), guide,
                            smooth_kind == SurfaceKind::shell ? shell.get() : nullptr);
    }

    // Forget fit and orient (the points stay).
    void discard_fit();

    // The surface `params` asks for (smooth_surface.hpp: surface_kind), with what is known of
    // the blend's strays.
    SurfaceKind surface_for(const Params &params) const {
        return surface_kind(params, points, noise, thin_walls, shell != nullptr, strays_found);
    }

    // The worker pool for `threads` (0: one per core): kept across stages, rebuilt only when
    // the count asked for changes.
    Workers &workers(unsigned threads);

private:
    std::unique_ptr<Workers> workers_;
};

}  // namespace gmpu
