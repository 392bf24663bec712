// Parts of a sparse cloud that orientation turned inside out as a whole (a hand, a leg): the
// leaf graph links such a part to the rest only through a few leaves whose fits span both
// sides of a narrow joint, and the front can cross there with the wrong sign. Each part is
// then consistent in itself, so nothing local shows it; the winding number of all the
// oriented points does. Just beside a correctly oriented point it averages ½ (1 behind, 0
// in front); around a part turned inside out it averages −½ (−1 inside, 0 outside), and
// around a part whose sides disagree, about 0.
#pragma once

#include <cstddef>

#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "geometry/point_set.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/winding_field.hpp"
#include "model/octree.hpp"

namespace gmpu {

// Finds the parts whose points' winding centres (the mean of w a spacing behind and in front
// of each point, along its blend normal) sit far below ½, and turns the leaves of each part
// whose turning brings its centres clearly nearer ½ (the part's own dipoles are taken out
// and put back reversed, so no field is rebuilt to judge it). `winding` must be the field
// of `measures`' blend normals and areas. Inner cells are left to the caller. Returns how
// many leaves were turned; 0 leaves `signs` as they were.
size_t turn_inside_out_parts(const Octree &tree, const PointSet &points, const PointMeasures &measures,
                             const WindingField &winding, CellSigns &signs, Workers &workers, Progress &progress);

}  // namespace gmpu
