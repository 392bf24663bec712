// Parts turned inside out as a whole (pipeline/inside_out_parts.hpp). A body with a limb,
// oriented by the orient stage, is left as it is; with the limb's leaves turned by hand, the
// limb is turned back and the body is not touched; with the body's, the body is turned back. Through the whole pipeline, a 1,000-point
// hub's blades that the front turned inside out are turned back, and blades thinner than a
// spacing, beside which the winding number cannot tell, are left as orientation made them.
// Open space: a spool whose core's leaves are turned by hand, which the winding number does
// not see, is turned back, as is the limb.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/params.hpp"
#include "core/progress.hpp"
#include "fit/build_octree.hpp"
#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/point_measures.hpp"
#include "implicit/winding_field.hpp"
#include "orient/orient.hpp"
#include "pipeline/inside_out_parts.hpp"
#include "reconstruct.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using Eigen::Vector3d;
using namespace gmpu;
using namespace gmpu::testing;

namespace {

// A ball of radius 1 with a limb: a ball of radius 0.4 whose centre is 1.2 off, joined to it
// along the circle at x = 0.95. Near-uniform samples of the union's surface.
const Vector3d kLimbCentre(1.2, 0.0, 0.0);
constexpr double kLimbRadius = 0.4, kJoint = 0.95;

struct Samples {
    std::vector<double> xyz;
    std::vector<Vector3d> outward;
    std::vector<bool> on_limb;
};

void add_sphere(Samples &s, size_t n, double r, const Vector3d &centre, bool limb) {
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (size_t i = 0; i < n; ++i) {
        const double z = 1.0 - 2.0 * (double(i) + 0.5) / double(n), t = std::sqrt(1.0 - z * z);
        const Vector3d dir(t * std::cos(golden * double(i)), t * std::sin(golden * double(i)), z);
        const Vector3d p = centre + r * dir;
        const bool inside_other = limb ? p.norm() < 1.0 : (p - kLimbCentre).norm() < kLimbRadius;
        if (inside_other) continue;
        s.xyz.insert(s.xyz.end(), {p[0], p[1], p[2]});
        s.outward.push_back(dir);
        s.on_limb.push_back(limb);
    }
}

// At about the corpus's 1k-point density: where the front can cross a joint wrongly.
Samples body_with_limb() {
    Samples s;
    add_sphere(s, 1400, 1.0, Vector3d::Zero(), false);
    add_sphere(s, 260, kLimbRadius, kLimbCentre, true);
    return s;
}

// A spool: a core of radius 0.4 along z from −0.6 to 0.6 between two flanges of radius 1,
// 0.1 thick. Uniform random samples of the union's surface, 200 per unit area (about 3,200
// in all: leaves small enough that those on the core hold no flange points); `on_limb`
// marks the core's.
Samples spool(unsigned seed) {
    constexpr double kCore = 0.4, kHalf = 0.6, kFlange = 1.0, kThick = 0.1, kDensity = 200.0;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Samples s;
    auto add = [&](const Vector3d &p, const Vector3d &n, bool core) {
        s.xyz.insert(s.xyz.end(), {p[0], p[1], p[2]});
        s.outward.push_back(n);
        s.on_limb.push_back(core);
    };
    auto count = [&](double area) { return size_t(kDensity * area); };
    // Lateral surfaces: the core's, and each flange's rim.
    auto side = [&](double r, double z0, double z1, bool core) {
        for (size_t i = 0, n = count(2 * M_PI * r * (z1 - z0)); i < n; ++i) {
            const double a = 2 * M_PI * unit(rng), z = z0 + (z1 - z0) * unit(rng);
            add(Vector3d(r * std::cos(a), r * std::sin(a), z), Vector3d(std::cos(a), std::sin(a), 0), core);
        }
    };
    // Flat annuli between radii r0 and r1 at height z, facing `up` (±1).
    auto annulus = [&](double r0, double r1, double z, double up) {
        for (size_t i = 0, n = count(M_PI * (r1 * r1 - r0 * r0)); i < n; ++i) {
            const double a = 2 * M_PI * unit(rng), r = std::sqrt(r0 * r0 + (r1 * r1 - r0 * r0) * unit(rng));
            add(Vector3d(r * std::cos(a), r * std::sin(a), z), Vector3d(0, 0, up), false);
        }
    };
    side(kCore, -kHalf, kHalf, true);
    for (double up : {-1.0, 1.0}) {
        side(kFlange, up > 0 ? kHalf : -kHalf - kThick, up > 0 ? kHalf + kThick : -kHalf, false);
        annulus(0.0, kFlange, up * (kHalf + kThick), up);
        annulus(kCore, kFlange, up * kHalf, -up);
    }
    return s;
}

struct Fixture {
    Samples samples;
    PointSet points;
    Workers workers{2};
    Progress quiet{nullptr, nullptr, GMPU_STAGE_ORIENT};
    Octree tree;
    CellSigns signs;
    PointMeasures measures;
    WindingField winding;

    explicit Fixture(Samples s = body_with_limb())
        : samples(std::move(s)), points(PointSet::from_array(samples.xyz.data(), samples.outward.size(), 0, 15)) {
        Params params;
        tree = build_octree(points, params, effective_epsilon(points, params, 0.0), workers, quiet);
        signs = orient_octree(tree, points, nullptr, workers, quiet).signs;
        measure();
    }
    void measure() {
        sign_inner_cells(tree, points, signs, quiet);
        const MpuFunction mpu(tree, signs, 0);
        measures = measure_points(mpu, points, workers, quiet);
        winding = WindingField(tree, points, measures.blend_normals, measures.area);
    }
    // The share of the limb's (or the body's) points whose normal faces out.
    double facing_out(bool limb) const {
        size_t right = 0, total = 0;
        for (size_t i = 0; i < samples.outward.size(); ++i) {
            if (samples.on_limb[i] != limb) continue;
            const Vector3d n(measures.normals[3 * i], measures.normals[3 * i + 1], measures.normals[3 * i + 2]);
            right += n.dot(samples.outward[i]) > 0.0;
            ++total;
        }
        return double(right) / double(total);
    }
    // Turns every leaf whose points pass `select` (the majority of them); returns how many.
    template <class Select> size_t turn_leaves(Select select) {
        size_t turned = 0;
        for (size_t c = 0; c < tree.cells.size(); ++c) {
            const Cell &cell = tree.cells[c];
            if (!cell.is_leaf() || cell.point_end == cell.point_begin) continue;
            size_t chosen = 0;
            for (uint32_t k = cell.point_begin; k < cell.point_end; ++k) chosen += select(tree.order[k]);
            if (2 * chosen > cell.point_end - cell.point_begin) signs[c] = int8_t(-signs[c]), ++turned;
        }
        return turned;
    }
    // Turns the leaves of the marked part (the limb, the core) by hand and measures again.
    size_t turn_part_by_hand() {
        const size_t turned = turn_leaves([&](uint32_t i) { return bool(samples.on_limb[i]); });
        measure();
        return turned;
    }
    size_t repair() { return turn_inside_out_parts(tree, points, measures, winding, signs, workers, quiet); }
    size_t repair_facing_in() { return turn_parts_facing_in(tree, points, measures, winding, signs, workers, quiet); }
};

void a_body_and_its_limb_facing_out_are_left_alone(void **) {
    Fixture f;
    assert_true(f.facing_out(false) > 0.99);
    assert_true(f.facing_out(true) > 0.99);
    assert_int_equal(f.repair(), 0);
}

void a_limb_turned_inside_out_is_turned_back(void **) {
    Fixture f;
    const CellSigns oriented = f.signs;
    const size_t turned_by_hand = f.turn_part_by_hand();
    print_message("limb turned by hand: %zu leaves, %.3f of its points facing out\n", turned_by_hand,
                  f.facing_out(true));
    assert_true(turned_by_hand > 20);
    assert_true(f.facing_out(true) < 0.2);
    assert_true(f.repair() > 0);
    f.measure();
    print_message("turned back: limb %.3f, body %.3f facing out\n", f.facing_out(true), f.facing_out(false));
    assert_true(f.facing_out(true) > 0.97);
    assert_true(f.facing_out(false) > 0.99);
    // Every leaf holding only the body's points, away from the joint (where a leaf of one
    // point may go either way), keeps the sign orientation gave it.
    size_t body_leaves = 0;
    for (size_t c = 0; c < f.tree.cells.size(); ++c) {
        const Cell &cell = f.tree.cells[c];
        if (!cell.is_leaf() || cell.point_end == cell.point_begin) continue;
        bool off_joint = true;
        for (uint32_t k = cell.point_begin; k < cell.point_end; ++k)
            off_joint = off_joint && f.samples.xyz[3 * f.tree.order[k]] < kJoint - 0.1;
        if (!off_joint) continue;
        assert_int_equal(f.signs[c], oriented[c]);
        ++body_leaves;
    }
    assert_true(body_leaves > 100);
}

void a_spool_whose_core_was_turned_inside_out_is_turned_back_by_open_space(void **) {
    // Turned by hand, the core between the flanges reads winding centres about 0, not −½:
    // the winding number's look leaves it. Its rays, shut in by the flanges towards the axis,
    // escape along its true outward normal: the open-space look turns it back.
    Fixture f(spool(3));
    print_message("spool: core %.3f, flanges %.3f facing out\n", f.facing_out(true), f.facing_out(false));
    assert_true(f.facing_out(true) > 0.97);
    assert_true(f.facing_out(false) > 0.97);
    assert_int_equal(f.repair_facing_in(), 0);
    f.turn_part_by_hand();
    assert_true(f.facing_out(true) < 0.2);
    const size_t by_winding = f.repair();
    if (by_winding > 0) f.measure();
    print_message("core turned by hand: %.3f facing out after the winding look (%zu leaves)\n", f.facing_out(true),
                  by_winding);
    assert_true(f.facing_out(true) < 0.5);
    assert_true(f.repair_facing_in() > 0);
    f.measure();
    print_message("turned back by open space: core %.3f, flanges %.3f facing out\n", f.facing_out(true),
                  f.facing_out(false));
    assert_true(f.facing_out(true) > 0.9);
    assert_true(f.facing_out(false) > 0.97);
}

void a_limb_turned_inside_out_is_turned_back_by_open_space(void **) {
    Fixture f;
    assert_int_equal(f.repair_facing_in(), 0);
    f.turn_part_by_hand();
    assert_true(f.repair_facing_in() > 0);
    f.measure();
    print_message("limb turned back by open space: limb %.3f, body %.3f facing out\n", f.facing_out(true),
                  f.facing_out(false));
    assert_true(f.facing_out(true) > 0.97);
    assert_true(f.facing_out(false) > 0.99);
}

void a_body_turned_inside_out_beside_its_limb_is_turned_back(void **) {
    // The part turned is most of the cloud: the winding number, not the share, decides.
    Fixture f;
    f.turn_leaves([&](uint32_t i) { return !f.samples.on_limb[i]; });
    f.measure();
    assert_true(f.facing_out(false) < 0.2);
    assert_true(f.repair() > 0);
    f.measure();
    print_message("body turned by hand, then back: body %.3f, limb %.3f facing out\n", f.facing_out(false),
                  f.facing_out(true));
    assert_true(f.facing_out(false) > 0.95);
    // The limb's points at the joint read low centres beside the turned body; some grow into
    // its part and are turned with it.
    assert_true(f.facing_out(true) > 0.75);
}

// A hub with six blades at 1,000 points (a box 0.5 × 0.5 × 0.3; blades 0.7 long, 0.26 tall,
// pitched 23°): samples of the union's surface with their true normals.
struct Blades {
    std::vector<Vec3> points, outward;
};

Blades hub_with_blades(double blade_thickness, unsigned seed) {
    struct Box {
        Vec3 centre, half;
        Eigen::Matrix3d frame;
    };
    std::vector<Box> boxes{{Vec3::Zero(), Vec3(0.25, 0.25, 0.15), Eigen::Matrix3d::Identity()}};
    for (int k = 0; k < 6; ++k) {
        const Eigen::Matrix3d frame = (Eigen::AngleAxisd(M_PI / 3.0 * k, Vec3::UnitZ()) *
                                       Eigen::AngleAxisd(0.4, Vec3::UnitX())).toRotationMatrix();
        boxes.push_back({frame * Vec3(0.55, 0, 0), Vec3(0.35, 0.5 * blade_thickness, 0.13), frame});
    }
    auto inside = [](const Box &b, const Vec3 &p) {
        return ((b.frame.transpose() * (p - b.centre)).cwiseAbs() - b.half).maxCoeff() < -1e-9;
    };
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    Blades all;
    for (size_t i = 0; i < boxes.size(); ++i)
        for (int axis = 0; axis < 3; ++axis)
            for (int side = -1; side <= 1; side += 2) {
                const int u = (axis + 1) % 3, v = (axis + 2) % 3;
                const Box &b = boxes[i];
                const size_t count = size_t(4000.0 * 4.0 * b.half[u] * b.half[v]);
                for (size_t m = 0; m < count; ++m) {
                    Vec3 local;
                    local[axis] = side * b.half[axis], local[u] = unit(rng) * b.half[u], local[v] = unit(rng) * b.half[v];
                    const Vec3 p = b.centre + b.frame * local;
                    bool covered = false;
                    for (size_t j = 0; j < boxes.size(); ++j) covered = covered || (j != i && inside(boxes[j], p));
                    if (covered) continue;
                    all.points.push_back(p);
                    all.outward.push_back(b.frame.col(axis) * side);
                }
            }
    std::vector<size_t> order(all.points.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    Blades out;
    for (size_t i = 0; i < 1000 && i < order.size(); ++i) {
        out.points.push_back(all.points[order[i]]);
        out.outward.push_back(all.outward[order[i]]);
    }
    return out;
}

double oriented_share(const Blades &b, unsigned seed, double thickness) {
    Reconstruction r = reconstruct(b.points);
    assert_int_equal(r.status, GMPU_OK);
    size_t right = 0;
    for (size_t i = 0; i < b.points.size(); ++i) right += r.normals[i].dot(b.outward[i]) > 0.0;
    const double share = double(right) / double(b.points.size());
    print_message("hub with blades %.2f thick, seed %u: %.3f oriented\n", thickness, seed, share);
    return share;
}

void blades_turned_inside_out_are_turned_back(void **) {
    // Blades 0.05 thick: the front turns two of them inside out (0.86 oriented without the
    // turn); their winding centres read −0.1 to −0.3.
    assert_true(oriented_share(hub_with_blades(0.05, 2), 2, 0.05) > 0.94);
}

void thin_blades_whose_sides_disagree_are_left(void **) {
    // Blades 0.03 thick, under a spacing: a spacing off either side is past the blade, the
    // centres read about 0 whichever way a side faces, and turning a side brings them no
    // nearer ½ than the bar. Turned all the same, 0.75 of the normals would be right.
    assert_true(oriented_share(hub_with_blades(0.03, 1), 1, 0.03) > 0.8);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_body_and_its_limb_facing_out_are_left_alone),
        cmocka_unit_test(a_limb_turned_inside_out_is_turned_back),
        cmocka_unit_test(a_body_turned_inside_out_beside_its_limb_is_turned_back),
        cmocka_unit_test(a_spool_whose_core_was_turned_inside_out_is_turned_back_by_open_space),
        cmocka_unit_test(a_limb_turned_inside_out_is_turned_back_by_open_space),
        cmocka_unit_test(blades_turned_inside_out_are_turned_back),
        cmocka_unit_test(thin_blades_whose_sides_disagree_are_left),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
