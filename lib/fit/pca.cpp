#include <Eigen/Eigenvalues>

#include "fit/fits.hpp"

namespace gmpu {

Pca compute_pca(const PointList &points) {
    Pca pca;
    if (points.empty()) return pca;
    for (const auto &p : points) pca.centroid += p;
    pca.centroid /= double(points.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto &p : points) {
        Eigen::Vector3d d = p - pca.centroid;
        cov.noalias() += d * d.transpose();
    }
    cov /= double(points.size());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    pca.eigenvalues = eig.eigenvalues().cwiseMax(0.0);
    pca.axes = eig.eigenvectors();
    double sum = pca.eigenvalues.sum();
    pca.variation = sum > 0.0 ? pca.eigenvalues[0] / sum : 1.0 / 3.0;
    return pca;
}

}  // namespace gmpu
