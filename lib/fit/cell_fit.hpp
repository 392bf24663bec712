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
    // Two sheets were seen in the support but no model here fits them: the cell must be
    // split whatever its error (its single fit passes between the sheets).
    bool unresolved_sheets = false;
};

// `support` holds the support points relative to the cell centre, `radius` is R.
// `epsilon` is ε in the same (normalised) units, `requested` the caller's ε before the noise
// floor raised it: a fit worse than that is checked for two sheets (two_sheet_fit.hpp),
// whose clean separation shows that the floor, not the data, let the fit pass.
// `close_sheets`: also look for sheets only a few σ of noise apart.
CellFit fit_cell(const PointList &support, double radius, double epsilon, double requested, const Params &params,
                 bool close_sheets = false);

}  // namespace gmpu
