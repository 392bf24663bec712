#include "geometry/clusters.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <numeric>

#include "core/union_find.hpp"

namespace gmpu {

namespace {

// Cells of the grid along the longest side: about 4·√n, so a surface sampled by n points
// puts some sixteen of them in an occupied cell (a hole in the sampling does not split it).
constexpr double kCellsPerSqrtPoint = 0.25;
constexpr int kMaxCells = 64;
// More separate pieces than this on the coarse grid is a sparse or noisy sampling of one
// scene, not a few objects: left whole.
constexpr size_t kMaxPieces = 512;
// A group whose box is thinner than this share of its size (points on a line or in a plane)
// bounds no volume: it is not a cluster of its own.
constexpr double kFlat = 1e-6;


struct Box {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t points = 0;
    void add(const double p[3]) {
        for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
        ++points;
    }
    void add(const Box &b) {
        for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], b.lo[d]), hi[d] = std::max(hi[d], b.hi[d]);
        points += b.points;
    }
    double side() const { return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}); }
    double thinnest() const { return std::min({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}); }
    // Largest per-axis gap to b (0 when the boxes overlap on every axis).
    double gap(const Box &b) const {
        double g = 0.0;
        for (int d = 0; d < 3; ++d) g = std::max({g, b.lo[d] - hi[d], lo[d] - b.hi[d]});
        return g;
    }
    double distance(const double p[3]) const {
        double s = 0.0;
        for (int d = 0; d < 3; ++d) {
            const double e = std::max({lo[d] - p[d], 0.0, p[d] - hi[d]});
            s += e * e;
        }
        return s;
    }
};

// Walks the increasing outlier indices alongside a pass over the points.
struct Skip {
    const std::vector<uint32_t> *outliers;
    size_t next = 0;
    explicit Skip(const std::vector<uint32_t> &o) : outliers(&o) {}
    bool operator()(size_t i) {
        if (next < outliers->size() && (*outliers)[next] == i) return ++next, true;
        return false;
    }
};

template <class T>
void read_point(const unsigned char *bytes, size_t stride, size_t i, double p[3]) {
    T v[3];
    std::memcpy(v, bytes + i * stride, sizeof v);
    for (int d = 0; d < 3; ++d) p[d] = double(v[d]);
}

}  // namespace

template <class T>
Clusters find_clusters(const T *xyz, size_t count, size_t stride, const std::vector<uint32_t> &outliers,
                       size_t min_points) {
    Clusters result;
    if (stride == 0) stride = 3 * sizeof(T);
    const auto *bytes = reinterpret_cast<const unsigned char *>(xyz);
    const size_t kept = count - std::min(count, outliers.size());
    const size_t need = std::max(kMinClusterPoints, min_points);
    if (kept < 2 * need) return result;
    Skip is_outlier{outliers};

    Box all;
    double p[3];
    for (size_t i = 0; i < count; ++i) {
        if (is_outlier(i)) continue;
        read_point<T>(bytes, stride, i, p);
        for (int d = 0; d < 3; ++d)
            if (!(std::fabs(p[d]) <= 1e300)) return result;  // PointSet says what is wrong
        all.add(p);
    }
    const int cells = std::min(kMaxCells, int(kCellsPerSqrtPoint * std::sqrt(double(kept))));
    const double side = all.side();
    if (cells < 2 || !(side > 0.0)) return result;
    const double cell = side / cells;
    auto key = [&](const double q[3]) {
        uint64_t k = 0;
        for (int d = 0; d < 3; ++d) k = k * uint64_t(cells + 3) + uint64_t(std::min(cells, int((q[d] - all.lo[d]) / cell)) + 1);
        return k;
    };

    // Occupied cells (a dense grid: at most 67³ entries), each joined with its occupied
    // neighbours. The border of empty cells around the grid keeps neighbours in range.
    constexpr uint32_t kEmpty = UINT32_MAX;
    const uint64_t row = uint64_t(cells + 3);
    std::vector<uint32_t> grid(row * row * row, kEmpty);
    uint32_t occupied = 0;
    std::vector<uint32_t> cell_of(count, 0);
    is_outlier = Skip{outliers};
    for (size_t i = 0; i < count; ++i) {
        if (is_outlier(i)) continue;
        read_point<T>(bytes, stride, i, p);
        uint32_t &cell = grid[key(p)];
        if (cell == kEmpty) cell = occupied++;
        cell_of[i] = cell;
    }
    UnionFind pieces(occupied);
    for (uint64_t k = 0; k < grid.size(); ++k) {
        if (grid[k] == kEmpty) continue;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const uint64_t n = k + uint64_t(int64_t(dx) * int64_t(row * row) + dy * int64_t(row) + dz);
                    if (n < grid.size() && grid[n] != kEmpty) pieces.join(grid[k], grid[n]);
                }
    }

    // One box per piece, then groups merged until every two are apart and large enough.
    std::vector<uint32_t> piece_of(occupied);
    std::vector<Box> groups;
    for (uint32_t c = 0; c < piece_of.size(); ++c)
        if (pieces.find(c) == c) piece_of[c] = uint32_t(groups.size()), groups.emplace_back();
    if (groups.size() < 2 || groups.size() > kMaxPieces) return result;
    for (uint32_t c = 0; c < piece_of.size(); ++c) piece_of[c] = piece_of[pieces.find(c)];
    is_outlier = Skip{outliers};
    for (size_t i = 0; i < count; ++i) {
        if (is_outlier(i)) continue;
        read_point<T>(bytes, stride, i, p);
        groups[piece_of[cell_of[i]]].add(p);
    }
    UnionFind merged(groups.size());
    std::vector<bool> alive(groups.size(), true);
    auto merge = [&](size_t a, size_t b) {
        groups[a].add(groups[b]);
        alive[b] = false;
        merged.join(uint32_t(a), uint32_t(b));
    };
    for (bool changed = true; changed;) {
        changed = false;
        for (size_t a = 0; a < groups.size(); ++a)
            for (size_t b = a + 1; alive[a] && b < groups.size(); ++b)
                if (alive[b] && groups[a].gap(groups[b]) <= kClusterGap * std::max(groups[a].side(), groups[b].side()))
                    merge(a, b), changed = true;
    }
    // Every two groups are apart now. One that cannot stand alone (too few points, or flat:
    // no solid) is a stray, like an outlier: its points go to the nearest cluster (whose own
    // outlier scan sees them) but do not widen its box, which would join it to its neighbour.
    std::vector<bool> stray(groups.size(), false);
    for (size_t a = 0; a < groups.size(); ++a)
        if (alive[a] && !(groups[a].points >= need && groups[a].thinnest() > kFlat * groups[a].side()))
            alive[a] = false, stray[a] = true;
    std::vector<uint32_t> label_of(groups.size(), 0);
    for (size_t a = 0; a < groups.size(); ++a)
        if (alive[a]) {
            label_of[a] = uint32_t(result.boxes.size());
            const Box &g = groups[a];
            result.boxes.push_back({g.lo[0], g.lo[1], g.lo[2], g.hi[0], g.hi[1], g.hi[2]});
        }
    if (result.boxes.size() < 2) {
        result.boxes.clear();
        return result;
    }
    result.count = result.boxes.size();
    result.labels.resize(count);
    is_outlier = Skip{outliers};
    for (size_t i = 0; i < count; ++i) {
        if (!is_outlier(i) && !stray[merged.find(piece_of[cell_of[i]])]) {
            result.labels[i] = label_of[merged.find(piece_of[cell_of[i]])];
            continue;
        }
        read_point<T>(bytes, stride, i, p);  // an outlier or a stray: the nearest cluster
        double best = INFINITY;
        for (size_t a = 0, c = 0; a < groups.size(); ++a)
            if (alive[a]) {
                const double dist = groups[a].distance(p);
                if (dist < best) best = dist, result.labels[i] = uint32_t(c);
                ++c;
            }
    }
    return result;
}

template Clusters find_clusters<double>(const double *, size_t, size_t, const std::vector<uint32_t> &, size_t);
template Clusters find_clusters<float>(const float *, size_t, size_t, const std::vector<uint32_t> &, size_t);

}  // namespace gmpu
