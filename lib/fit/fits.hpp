// The local fitting models of MPU without normals (paper §3.2). Points are given relative to
// the cell centre; `scale` is the support radius R, used to keep the normal equations well
// conditioned. Every fit returns a function whose gradient is about unit length near the
// points, so blended functions of different models agree in magnitude.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "model/local_shape.hpp"

namespace gmpu {

using PointList = std::vector<Eigen::Vector3d>;

struct Pca {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns by increasing eigenvalue
    Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
    double variation = 0.0;  // σ = λ0 / (λ0 + λ1 + λ2), eq. (4)
    Eigen::Vector3d normal() const { return axes.col(0); }
};

// Covariance analysis of eq. (3).
Pca compute_pca(const PointList &points);

// Bivariate quadratic w = h(u, v) in the PCA frame (w along the smallest eigenvector),
// as Q = w − h(u, v). Least squares, ridge-regularised so degenerate sets fall back
// towards a plane.
Quadric fit_bivariate(const PointList &points, const Pca &pca, double scale);

// General quadric by Taubin's method: minimises Σ Q(p)² / Σ |∇Q(p)|² (a generalized
// eigenproblem), then normalised to unit mean gradient on the points.
Quadric fit_general_quadric(const PointList &points, double scale);

// Robust Taubin distance error over the points, from d_p = |Q(p)| / |∇Q(p)|:
// max(90th percentile of d_p, max_p d_p / 3). See taubin_error.cpp for why not the max.
double taubin_error(const LocalShape &shape, const std::vector<PiecewiseShape> &pieces,
                    const PointList &points);

}  // namespace gmpu
