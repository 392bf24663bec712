// A cell's local shape function Q_i: one quadric (general quadric or bivariate quadratic,
// both expanded to the same polynomial form), or piecewise quadrics at a sharp edge or
// corner: min of two or three parts, each signed positive towards the others, so the
// zero set is exactly the faces meeting at the feature; or two sheets of a thin wall (or a
// narrow gap), the min of two parts in the same way (two_sheet_fit.hpp). The sign of the whole function is
// arbitrary after fitting; orientation multiplies it by the cell's label ℓ_i.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "model/quadric.hpp"

namespace gmpu {

enum class Model : uint8_t { quadric = 0, bivariate = 1, edge = 2, corner = 3, two_sheets = 4 };

// Models stored as parts in the octree's PiecewiseShape table.
inline bool is_piecewise(Model m) { return m == Model::edge || m == Model::corner || m == Model::two_sheets; }

struct PiecewiseShape {
    Quadric part[3];
    int count = 0;

    // For two sheets: their distance through the cell centre (each part is about a unit
    // signed distance, positive towards the other sheet, so the two values add up to it).
    double sheet_gap() const {
        double gap = 0.0;
        for (int k = 0; k < 2; ++k) gap += part[k].value(Eigen::Vector3d::Zero()) / std::max(1e-12, part[k].b.norm());
        return gap;
    }
};

struct LocalShape {
    Model model = Model::bivariate;
    int32_t piece = -1;  // index into the octree's PiecewiseShape table (is_piecewise models)
    Quadric q;           // the smooth model (also used when piece < 0)

    // Value at y (relative to the cell centre); writes the gradient if asked.
    double value(const Eigen::Vector3d &y, const std::vector<PiecewiseShape> &pieces,
                 Eigen::Vector3d *gradient) const {
        if (piece < 0) {
            if (gradient) *gradient = q.gradient(y);
            return q.value(y);
        }
        const PiecewiseShape &p = pieces[size_t(piece)];
        int best = 0;
        double v = p.part[0].value(y);
        for (int k = 1; k < p.count; ++k) {
            double vk = p.part[k].value(y);
            if (vk < v) v = vk, best = k;
        }
        if (gradient) *gradient = p.part[best].gradient(y);
        return v;
    }
};

}  // namespace gmpu
