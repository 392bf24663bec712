// gmpu_surface_get_stat's answers (see api/statistics.hpp).
#include "api/statistics.hpp"

#include <algorithm>
#include <string>

#include "api/guard.hpp"
#include "core/error.hpp"

namespace gmpu::api {

void check_stat_key(const gmpu_stat &key) {
    const int v = enum_int(key);
    if (v < GMPU_STAT_POINTS || v > GMPU_STAT_OUTLIERS)  // the first and the last key
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown statistic key " + std::to_string(v));
}

double statistic(gmpu_stat key, const StatSources &from) {
    const auto &cells = from.tree.cells;
    auto leaves_where = [&](auto pred) {
        double n = 0;
        for (const auto &c : cells) n += c.is_leaf() && pred(c);
        return n;
    };
    switch (key) {
        case GMPU_STAT_POINTS: return double(from.input_count);
        case GMPU_STAT_CELLS: return double(cells.size());
        case GMPU_STAT_LEAVES: return leaves_where([](const gmpu::Cell &) { return true; });
        case GMPU_STAT_DEPTH: {
            int d = 0;
            for (const auto &c : cells) d = std::max<int>(d, c.depth);
            return d;
        }
        case GMPU_STAT_QUADRIC_CELLS:
            return leaves_where([](const gmpu::Cell &c) { return c.shape.model == gmpu::Model::quadric; });
        case GMPU_STAT_BIVARIATE_CELLS:
            return leaves_where([](const gmpu::Cell &c) { return c.shape.model == gmpu::Model::bivariate; });
        case GMPU_STAT_PIECEWISE_CELLS:
            return leaves_where([](const gmpu::Cell &c) {
                return c.shape.model == gmpu::Model::edge || c.shape.model == gmpu::Model::corner;
            });
        case GMPU_STAT_COMPONENTS: return from.orient.components;
        case GMPU_STAT_FLIPPED_CELLS: return from.orient.flipped_leaves;
        case GMPU_STAT_FIT_SECONDS: return from.seconds[GMPU_STAGE_FIT];
        case GMPU_STAT_ORIENT_SECONDS: return from.seconds[GMPU_STAGE_ORIENT];
        case GMPU_STAT_POLYGONIZE_SECONDS: return from.seconds[GMPU_STAGE_POLYGONIZE];
        case GMPU_STAT_RESOLUTION: return from.last_resolution;
        case GMPU_STAT_OUTLIERS: return double(from.points.outlier_count());
        case GMPU_STAT_BBOX_DIAGONAL: return from.points.empty() ? 0.0 : from.points.world_diagonal();
        case GMPU_STAT_NOISE:
        case GMPU_STAT_EFFECTIVE_ERROR: {
            // Normalised units → fraction of the diagonal.
            double diag = from.points.empty() ? 0.0 : from.points.world_diagonal() * from.points.normalisation().scale;
            double v = key == GMPU_STAT_NOISE ? from.noise : from.epsilon;
            return diag > 0.0 && from.fitted ? v / diag : 0.0;
        }
        default: throw Error(GMPU_ERROR_INVALID_ARGUMENT, "unknown statistic key " + std::to_string(int(key)));
    }
}

}  // namespace gmpu::api
