#include "fit/piecewise_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace gmpu {

namespace {

// Ohtake's thresholds: two normal clusters form an edge when their directions differ by
// more than acos(0.9) ≈ 26°; three form a corner when |(n1 × n2)·n3| ≥ 0.7.
constexpr double kEdgeCos = 0.9;
constexpr double kCornerTriple = 0.7;
constexpr size_t kNormalNeighbours = 10;
constexpr size_t kMaxPoints = 256;  // larger supports are subsampled (cost is quadratic)

// Unoriented normal of each point from its nearest neighbours within the set.
std::vector<Eigen::Vector3d> local_normals(const PointList &pts) {
    std::vector<Eigen::Vector3d> normals(pts.size());
    std::vector<std::pair<double, size_t>> dist(pts.size());
    PointList hood;
    for (size_t i = 0; i < pts.size(); ++i) {
        for (size_t j = 0; j < pts.size(); ++j) dist[j] = {(pts[j] - pts[i]).squaredNorm(), j};
        const size_t k = std::min(kNormalNeighbours, pts.size());
        std::partial_sort(dist.begin(), dist.begin() + long(k), dist.end());
        hood.clear();
        for (size_t j = 0; j < k; ++j) hood.push_back(pts[dist[j].second]);
        normals[i] = compute_pca(hood).normal();
    }
    return normals;
}

// k-means of unoriented directions (n and −n alike): the centre of a cluster is the
// principal axis of Σ n nᵀ. Starts from mutually most different normals.
std::vector<int> cluster_normals(const std::vector<Eigen::Vector3d> &n, int k, std::vector<Eigen::Vector3d> &centre) {
    centre.assign(1, n[0]);
    while (int(centre.size()) < k) {
        size_t far = 0;
        double worst = 2.0;
        for (size_t i = 0; i < n.size(); ++i) {
            double best = 0.0;
            for (const auto &c : centre) best = std::max(best, std::abs(n[i].dot(c)));
            if (best < worst) worst = best, far = i;
        }
        centre.push_back(n[far]);
    }
    std::vector<int> label(n.size(), 0);
    for (int it = 0; it < 10; ++it) {
        for (size_t i = 0; i < n.size(); ++i) {
            double best = -1.0;
            for (int c = 0; c < k; ++c)
                if (std::abs(n[i].dot(centre[size_t(c)])) > best) best = std::abs(n[i].dot(centre[size_t(c)])), label[i] = c;
        }
        for (int c = 0; c < k; ++c) {
            Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
            for (size_t i = 0; i < n.size(); ++i)
                if (label[i] == c) m += n[i] * n[i].transpose();
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
            centre[size_t(c)] = eig.eigenvectors().col(2);
        }
    }
    return label;
}

// Fits one part per cluster, re-assigns points to the nearest part a few times (k-planes),
// signs each part positive towards the other clusters. False when a cluster is too small,
// or (for a corner) the faces do not all lie on each other's positive sides — a saddle
// corner, which a min cannot represent.
bool fit_parts(const PointList &pts, std::vector<int> label, int k, double radius, PiecewiseShape &shape) {
    const size_t min_cluster = std::max<size_t>(6, pts.size() / 10);
    PointList cluster;
    for (int round = 0; round < 3; ++round) {
        for (int c = 0; c < k; ++c) {
            cluster.clear();
            for (size_t i = 0; i < pts.size(); ++i)
                if (label[i] == c) cluster.push_back(pts[i]);
            if (cluster.size() < min_cluster) return false;
            shape.part[c] = fit_bivariate(cluster, compute_pca(cluster), radius);
        }
        for (size_t i = 0; i < pts.size(); ++i) {
            double best = INFINITY;
            for (int c = 0; c < k; ++c) {
                Eigen::Vector3d g = shape.part[c].gradient(pts[i]);
                double d = std::abs(shape.part[c].value(pts[i])) / std::max(1e-12, g.norm());
                if (d < best) best = d, label[i] = c;
            }
        }
    }
    shape.count = k;
    for (int c = 0; c < k; ++c) {
        // Each other cluster must lie on one side of this part; its side is positive.
        int side = 0;
        for (int o = 0; o < k; ++o) {
            if (o == c) continue;
            double sum = 0.0;
            for (size_t i = 0; i < pts.size(); ++i)
                if (label[i] == o) sum += shape.part[c].value(pts[i]);
            int s = sum > 0 ? 1 : -1;
            if (side != 0 && s != side) return false;
            side = s;
        }
        if (side < 0) shape.part[c] *= -1.0;
    }
    return true;
}

}  // namespace

bool fit_piecewise(const PointList &support, double radius, double epsilon, CellFit &out) {
    PointList pts;
    const double step = std::max(1.0, double(support.size()) / double(kMaxPoints));
    for (double k = 0; size_t(k) < support.size(); k += step) pts.push_back(support[size_t(k)]);
    if (pts.size() < 2 * kNormalNeighbours) return false;

    const std::vector<Eigen::Vector3d> normals = local_normals(pts);
    std::vector<Eigen::Vector3d> centre;
    const std::vector<int> two = cluster_normals(normals, 2, centre);
    if (std::abs(centre[0].dot(centre[1])) > kEdgeCos) return false;  // smooth: no feature

    std::vector<Eigen::Vector3d> c3;
    const std::vector<int> three = cluster_normals(normals, 3, c3);
    const bool corner = std::abs(c3[0].cross(c3[1]).dot(c3[2])) >= kCornerTriple;

    static const std::vector<PiecewiseShape> none;
    bool found = false;
    for (int k : {2, 3}) {
        if (k == 3 && !corner) continue;
        PiecewiseShape shape;
        if (!fit_parts(pts, k == 2 ? two : three, k, radius, shape)) continue;
        std::vector<PiecewiseShape> table{shape};
        LocalShape local;
        local.model = k == 2 ? Model::edge : Model::corner;
        local.piece = 0;
        const double error = taubin_error(local, table, support);
        if (error <= epsilon && (!found || error < out.error)) {
            out.shape = local;
            out.shape.q = shape.part[0];  // a smooth stand-in, never used while piece ≥ 0
            out.piece = shape;
            out.error = error;
            found = true;
        }
    }
    (void)none;
    return found;
}

}  // namespace gmpu
