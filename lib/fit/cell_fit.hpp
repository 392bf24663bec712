// Model selection for one cell (paper §3.2): PCA surface variation σ > 0.25 → general
// quadric, otherwise a bivariate quadratic in the PCA frame; piecewise quadrics when the
// support straddles a sharp edge or corner and no single model meets ε.
#pragma once

#include "core/params.hpp"
#include "fit/fits.hpp"

namespace gmpu {

constexpr double kVariationThreshold = 0.25;

struct CellFit {
    LocalShape shape;
    PiecewiseShape piece;  // valid when shape.model is edge or corner
    double error = 0.0;    // Taubin distance error on the support points
    double variation = 0.0;
};

// `support` holds the support points relative to the cell centre, `radius` is R.
// `epsilon` is ε in the same (normalised) units.
CellFit fit_cell(const PointList &support, double radius, double epsilon, const Params &params);

}  // namespace gmpu
