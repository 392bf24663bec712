// Parts of a sparse cloud that orientation turned inside out as a whole (a hand, a leg): the
// leaf graph links such a part to the rest only through a few leaves whose fits span both
// sides of a narrow joint, and the front can cross there with the wrong sign. Each part is
// then consistent in itself, so nothing local shows it; the winding number of all the
// oriented points does. Just beside a correctly oriented point it averages ½ (1 behind, 0
// in front); around a part turned inside out it averages −½ (−1 inside, 0 outside), and
// around a part whose sides disagree, about 0.
// An inner part turned inside out (a spool's core between its flanges) can read about 0
// too; there open space tells: from just in front of a point, rays along its outward normal
// mostly escape the cloud, along the inward one they meet the far side (geometry/open_sky.hpp).
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

// Finds the parts whose points' normals face away from open space (their rays escape clearly
// more often behind than in front), and turns the leaves of each part of at least a few
// points whose winding centres agree that it does not face out (their median well under ½:
// between close blades or in a narrow slot both sides are shut in, but the centres of
// points facing out sit near ½). Same contract as turn_inside_out_parts.
size_t turn_parts_facing_in(const Octree &tree, const PointSet &points, const PointMeasures &measures,
                            const WindingField &winding, CellSigns &signs, Workers &workers, Progress &progress);

}  // namespace gmpu
