// C ABI of tiles on a shared grid: the field at the grid corners a tile owns, and marching
// tetrahedra over a tile's blocks with corner values the caller assembled from the tiles
// that own them (see gmpu.h, "tiles").
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "api/guard.hpp"
#include "api/handles.hpp"
#include "gmpu/gmpu.h"
#include "mesh/grid_march.hpp"

namespace {

using gmpu::Error;
constexpr int B = gmpu::GlobalGrid::kGridBlock;
constexpr size_t kOwned = B * B * B, kCorners = (B + 1) * (B + 1) * (B + 1);

void check_frame(const double *origin, double cell_size) {
    gmpu::api::require_arg(origin, "grid_origin");
    for (int d = 0; d < 3; ++d)
        if (!std::isfinite(origin[d])) throw Error(GMPU_ERROR_INVALID_ARGUMENT, "grid_origin is not finite");
    if (!std::isfinite(cell_size) || cell_size <= 0)
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "cell_size must be finite and positive");
}

void check_count(size_t block_count, size_t per_block) {
    if (block_count > std::numeric_limits<size_t>::max() / (per_block * sizeof(double)))
        throw Error(GMPU_ERROR_INVALID_ARGUMENT, "block_count " + std::to_string(block_count) + " is too large");
}

}  // namespace

extern "C" {

GMPU_API gmpu_status gmpu_surface_evaluate_grid(const gmpu_surface *surface, const double *grid_origin,
                                                double cell_size, const int64_t *blocks, size_t block_count,
                                                double *values) {
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(surface, "surface");
        check_frame(grid_origin, cell_size);
        check_count(block_count, kOwned);
        if (block_count == 0) return;
        gmpu::api::require_arg(blocks, "blocks");
        gmpu::api::require_arg(values, "values");
        double threads_param = 0;
        gmpu_surface_get_param(surface, GMPU_PARAM_THREADS, &threads_param);
        unsigned threads = threads_param > 0 ? unsigned(threads_param) : std::max(1u, std::thread::hardware_concurrency());
        threads = unsigned(std::min<size_t>(threads, block_count));
        // Each thread evaluates a run of whole blocks through the public (thread-safe, const)
        // evaluate, which checks the stage and the surface's clusters as for any query.
        std::vector<gmpu_status> status(threads, GMPU_OK);
        std::vector<std::string> message(threads);
        auto run = [&](unsigned t) {
            const size_t begin = block_count * t / threads, end = block_count * (t + 1) / threads;
            std::vector<double> xyz(3 * kOwned);
            for (size_t b = begin; b < end && status[t] == GMPU_OK; ++b) {
                for (int k = 0; k < B; ++k)
                    for (int j = 0; j < B; ++j)
                        for (int i = 0; i < B; ++i) {
                            const int64_t c[3] = {blocks[3 * b] * B + i, blocks[3 * b + 1] * B + j,
                                                  blocks[3 * b + 2] * B + k};
                            double *p = &xyz[3 * size_t(i + B * (j + B * k))];
                            for (int d = 0; d < 3; ++d) p[d] = grid_origin[d] + cell_size * double(c[d]);
                        }
                status[t] = gmpu_surface_evaluate(surface, xyz.data(), kOwned, values + kOwned * b, nullptr);
                if (status[t] != GMPU_OK) {
                    // The thread's message starts with the status name, which Error adds again.
                    const std::string text = gmpu_last_error(), prefix = std::string(gmpu_status_name(status[t])) + ": ";
                    message[t] = text.compare(0, prefix.size(), prefix) == 0 ? text.substr(prefix.size()) : text;
                }
            }
        };
        std::vector<std::thread> pool;
        for (unsigned t = 1; t < threads; ++t) pool.emplace_back(run, t);
        run(0);
        for (std::thread &t : pool) t.join();
        for (unsigned t = 0; t < threads; ++t)
            if (status[t] != GMPU_OK) throw Error(status[t], message[t]);
    });
}

GMPU_API gmpu_status gmpu_grid_polygonize(const double *grid_origin, double cell_size, const int64_t *grid_cells,
                                          const int64_t *blocks, size_t block_count, const double *corner_values,
                                          gmpu_mesh **out) {
    return gmpu::api::guarded(nullptr, [&] {
        gmpu::api::require_arg(out, "out");
        *out = nullptr;
        check_frame(grid_origin, cell_size);
        gmpu::api::require_arg(grid_cells, "grid_cells");
        check_count(block_count, kCorners);
        gmpu::GlobalGrid grid;
        grid.cell = cell_size;
        for (int d = 0; d < 3; ++d) {
            grid.origin[d] = grid_origin[d];
            grid.cells[d] = grid_cells[d];
            // Keys must fit 64 bits: (cells + 1)³ · 8 < 2⁶⁴ holds up to 2²⁰ cells a side.
            if (grid_cells[d] <= 0 || grid_cells[d] % B != 0 || grid_cells[d] > (int64_t(1) << 20))
                throw Error(GMPU_ERROR_INVALID_ARGUMENT,
                            "grid_cells must be positive multiples of 8 up to 2^20, not " +
                                std::to_string(grid_cells[d]));
        }
        if (block_count > 0) {
            gmpu::api::require_arg(blocks, "blocks");
            gmpu::api::require_arg(corner_values, "corner_values");
        }
        for (size_t b = 0; b < block_count; ++b)
            for (int d = 0; d < 3; ++d)
                if (blocks[3 * b + d] < 0 || blocks[3 * b + d] >= grid_cells[d] / B)
                    throw Error(GMPU_ERROR_INVALID_ARGUMENT, "block " + std::to_string(b) + " is outside the grid");
        for (size_t i = 0; i < block_count * kCorners; ++i)
            if (std::isnan(corner_values[i]))
                throw Error(GMPU_ERROR_INVALID_INPUT, "corner value " + std::to_string(i % kCorners) + " of block " +
                                                          std::to_string(i / kCorners) + " is NaN");
        auto mesh = std::make_unique<gmpu_mesh>();
        mesh->mesh = gmpu::march_grid_blocks(grid, blocks, block_count, corner_values, mesh->grid_keys);
        *out = mesh.release();
    });
}

GMPU_API const uint64_t *gmpu_mesh_grid_keys(const gmpu_mesh *mesh) {
    const uint64_t *keys = nullptr;
    gmpu::api::guarded(nullptr, [&] {
        if (mesh && !mesh->grid_keys.empty()) keys = mesh->grid_keys.data();
    });
    return keys;
}

}  // extern "C"
