// Model selection for one cell (paper §3.2): PCA surface variation σ > 0.25 → general
// quadric, otherwise a bivariate quadratic in the PCA frame; piecewise quadrics when the
// support straddles a sharp edge or corner and no single model meets ε.
#pragma once

#include "core/params.hpp"
#include "fit/fits.hpp"

namespace gmpu {

constexpr double kVariationThreshold = 0.25;

// Where two sheets only a few σ of noise apart are looked for (two_sheet_fit.hpp): nowhere
// (ε is not the noise floor), everywhere the noise estimate saw them cloud-wide (`cloud`),
// or, where it did not, in supports that show them on their own (`local`): the estimate
// reads the quietest neighbourhoods, and on a part that is mostly single-sheeted there (a
// rotor's hub) it misses walls (the blades) that cover much of the rest.
enum class CloseSheets { off, local, cloud };

struct CellFit {
    LocalShape shape;
    PiecewiseShape piece;  // valid when shape.model is edge or corner
    double error = 0.0;    // Taubin distance error on the support points
    double variation = 0.0;
    // Two sheets were seen in the support but no model here fits them: the cell must be
    // split whatever its error (its single fit passes between the sheets).
    bool unresolved_sheets = false;
    // A noise-free two-sheet fit whose sheets end inside the support (two_sheet_fit.hpp):
    // worth splitting even when it meets ε. Under noise the points between close sheets are
    // the noise, not a rim, so noisy fits never ask.
    bool sheets_end = false;
};

// `support` holds the support points relative to the cell centre, `radius` is R.
// `epsilon` is ε in the same (normalised) units, `requested` the caller's ε before the noise
// floor raised it: a fit worse than that is checked for two sheets (two_sheet_fit.hpp),
// whose clean separation shows that the floor, not the data, let the fit pass.
// `close_sheets`: where to also look for sheets only a few σ of noise apart.
CellFit fit_cell(const PointList &support, double radius, double epsilon, double requested, const Params &params,
                 CloseSheets close_sheets = CloseSheets::off);

}  // namespace gmpu
