// Two sheets in one support: a thin wall, or the two sides of a narrow gap, closer together
// than the support is wide. A single smooth model can only pass between them, and the blend
// of such fits makes one sheet in the middle of the wall. The two sheets show as a bimodal
// distribution of the single fit's signed distances; they are then fitted as
// min(w − h0(u, v), h1(u, v) − w) in one frame (h0 below h1): positive between the sheets,
// zero on each, unit gradient, stored like a piecewise edge with two parts. Sheets only a
// few σ of noise apart are looked for too (flat, interleaved distances) where the noise
// estimate saw them.
#pragma once

#include "fit/cell_fit.hpp"

namespace gmpu {

struct SheetSplit {
    bool found = false;  // the single fit's distances form two well-separated groups
    double gap = 0.0;    // distance between the groups' means
    // The fitted sheets end inside the support: enough points lie deep between them (a
    // plate's rim face). The two-sheet model has no end, so its slab runs on past the rim
    // and the blend leaves a fin there unless the cell is split towards the rim.
    bool ends = false;
};

// Looks for two sheets in `support` around the fitted `single` shape. Fills `out` with the
// two-sheet model when one fits (its error below the single fit's); the split tells
// whether two sheets were seen at all, fitted or not. `close`: also look for sheets only a
// few σ of noise apart (on a cloud without them, a flat support is more often a coarse
// cell's shape misfit, so without the cloud-wide evidence the support must show more).
// `epsilon`: the noise floor ε, which the local evidence is measured against.
SheetSplit fit_two_sheets(const PointList &support, const LocalShape &single, double single_error, double radius,
                          CloseSheets close, double epsilon, CellFit &out);

}  // namespace gmpu
