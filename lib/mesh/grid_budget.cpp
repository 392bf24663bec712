#include "mesh/grid_budget.hpp"

#include <algorithm>
#include <cmath>

#include "mesh/size_cap.hpp"

namespace gmpu {

namespace {
// Triangles marching cubes makes per cube² of surface: 2 on a surface along a grid plane,
// more on oblique and curved ones. Clean clouds give 2.6–3.3: at 3.0 most meshes land a
// little under the budget (a coarser grid costs normal accuracy on curved parts), the
// others a little over it, which the size cap's decimation then trims.
constexpr double kTrianglesPerCubeArea = 3.0;
// The smallest budget a uniform grid is used for. Under it (clouds of a few thousand points)
// the coarse grid loses thin parts and curvature that the decimation of a fine grid keeps.
constexpr double kUniformBudget = 40000;
// Noise estimate, as a share of the mean sample spacing, under which the points' areas
// (from neighbour distances) measure the surface: noise spreads the neighbours off it and
// inflates them.
constexpr double kAreaNoise = 0.1;
// The coarsest cube across a thin wall's gap: at a whole gap both sheets can fall between two
// corners of the same sign.
constexpr double kCubesPerWallGap = 0.9;
// Never coarser than the octree's default grid may be (polygonizer.cpp).
constexpr int kCoarsestGrid = 32;
}  // namespace

int resolution_within_budget(int resolution, const PointMeasures &measures, double noise, double leaf,
                             double wall_gap) {
    const double points = double(measures.area.size());
    const double budget = kTrianglesPerPoint * points;
    if (budget < kUniformBudget || resolution <= 0) return resolution;
    double area = 0.0;
    for (float a : measures.area) area += double(a);
    if (!(area > 0.0) || !std::isfinite(area)) return resolution;
    if (!(noise < kAreaNoise * std::sqrt(area / points))) return resolution;
    double h = std::sqrt(kTrianglesPerCubeArea * area / budget);
    h = std::min({h, leaf, kCubesPerWallGap * wall_gap});
    return std::min(resolution, std::max(kCoarsestGrid, int(1.0 / h)));
}

}  // namespace gmpu
