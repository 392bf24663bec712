// Unit tests of the orient stage's parts, each against an answer known in advance: the
// leaf graph (edges of a hand-built octree, and of a fitted one against a brute-force face
// search), the advancing front (labels of a graph whose true orientation is known, under
// both front orders and both leaf decisions), belief propagation against a plain weighted
// vote on a graph where the vote is wrong, and the outward pass (nested spheres: the outer
// shell faces out, the inner one into the cavity; a component flipped by hand is flipped
// back).
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "core/params.hpp"
#include "core/progress.hpp"
#include "fit/build_octree.hpp"
#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/on_sheet_normal.hpp"
#include "implicit/point_measures.hpp"
#include "orient/advancing_front.hpp"
#include "orient/leaf_graph.hpp"
#include "orient/orient.hpp"
#include "orient/outward.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using Eigen::Vector3d;
using namespace gmpu;

namespace {

using EdgeSet = std::set<std::tuple<uint32_t, uint32_t, int>>;  // (low node, high node, J)

// Every edge of the graph once, after checking that the CSR holds each in both directions
// with the same agreement.
EdgeSet edges_of(const LeafGraph &g) {
    EdgeSet out;
    std::multiset<std::tuple<uint32_t, uint32_t, int>> directed;
    for (uint32_t a = 0; a < g.size(); ++a)
        for (uint32_t e = g.offsets[a]; e < g.offsets[a + 1]; ++e) {
            uint32_t b = g.neighbour[e];
            assert_true(b != a);
            directed.insert({a, b, g.agreement[e]});
            out.insert({std::min(a, b), std::max(a, b), g.agreement[e]});
        }
    for (const auto &[a, b, j] : directed) assert_int_equal(directed.count({b, a, j}), 1);
    assert_int_equal(directed.size(), 2 * out.size());  // no edge twice
    return out;
}

// Leaves whose cubes share a face of positive area, by brute force over all pairs.
std::set<std::pair<uint32_t, uint32_t>> face_neighbours(const Octree &tree, const LeafGraph &g) {
    std::set<std::pair<uint32_t, uint32_t>> out;
    for (uint32_t a = 0; a < g.size(); ++a)
        for (uint32_t b = a + 1; b < g.size(); ++b) {
            const Cell &p = tree.cells[g.cell_of[a]], &q = tree.cells[g.cell_of[b]];
            const double reach = 0.5 * (p.size + q.size), tol = 1e-9;
            int touching = 0, overlapping = 0;
            for (int d = 0; d < 3; ++d) {
                const double gap = std::abs(p.centre[d] - q.centre[d]);
                touching += std::abs(gap - reach) < tol;
                overlapping += gap < reach - tol;
            }
            if (touching == 1 && overlapping == 2) out.insert({a, b});
        }
    return out;
}

// Root, its 8 children, and the 8 children of octant 7: 7 + 8 leaves. Every shape is the
// same global plane x = `plane` (at 0.05 no face corner lies on it; at 0, the root's middle,
// the faces between the two halves lie in it), except `flipped` (a cell index, or -1), whose
// shape is negated.
Octree two_level_octree(int flipped, double plane = 0.05) {
    Octree t;
    auto add = [&](Vector3d centre, double size, int depth, const uint16_t coord[3], int parent) {
        Cell c;
        c.centre = centre;
        c.size = size;
        c.depth = uint8_t(depth);
        for (int d = 0; d < 3; ++d) c.coord[d] = coord[d];
        c.parent = parent;
        c.shape.model = Model::bivariate;
        c.shape.q = Quadric::affine({1, 0, 0}, centre[0] - plane);
        if (int(t.cells.size()) == flipped) c.shape.q *= -1.0;
        t.cells.push_back(c);
    };
    const uint16_t zero[3] = {0, 0, 0};
    add(Vector3d::Zero(), kRootSize, 0, zero, -1);
    auto children = [&](uint32_t parent) {
        const Cell p = t.cells[parent];
        t.cells[parent].first_child = int32_t(t.cells.size());
        t.cells[parent].child_mask = 0xff;
        for (int o = 0; o < 8; ++o) {
            Vector3d centre = p.centre;
            uint16_t coord[3];
            for (int d = 0; d < 3; ++d) {
                int bit = o >> d & 1;
                centre[d] += (bit ? 0.25 : -0.25) * p.size;
                coord[d] = uint16_t(2 * p.coord[d] + bit);
            }
            add(centre, 0.5 * p.size, p.depth + 1, coord, int(parent));
        }
    };
    children(0);
    children(8);  // octant 7 of the root
    return t;
}

// A thin slab, top sheet z = −0.28 (outward +z), bottom sheet z = −0.32 (outward −z). The
// root's four upper children fit the top sheet, the four lower ones the bottom sheet, all
// oriented consistently (positive inside the slab). At a point of the top sheet the lower
// leaves, whose centres are much nearer, dominate the blend, and −∇f points down: the
// normal of the other sheet. Only the leaves whose sheet passes by the point may speak.
// The slab's octree of point_normal_comes_from_the_sheet_through_the_point; `order` and the
// leaves' point ranges are filled for `points` (already in the normalised frame).
Octree slab_octree(double top, double bottom, const PointSet *points) {
    Octree t;
    Cell root;
    root.size = kRootSize;
    root.radius = root.subtree_radius = 2.0;
    root.first_child = 1;
    root.child_mask = 0xff;
    t.cells.push_back(root);
    for (int o = 0; o < 8; ++o) {
        Cell c;
        c.size = 0.5 * kRootSize;
        c.depth = 1;
        c.parent = 0;
        for (int d = 0; d < 3; ++d) {
            c.coord[d] = uint16_t(o >> d & 1);
            c.centre[d] = (o >> d & 1 ? 0.25 : -0.25) * kRootSize;
        }
        c.radius = c.subtree_radius = 0.75 * std::sqrt(3.0) * c.size;
        c.support_count = 10000;  // dense: a sheet 0.04 away is many spacings off
        c.shape.model = Model::bivariate;
        const bool upper = o & 4;
        c.shape.q = upper ? Quadric::affine({0, 0, -1}, top - c.centre[2])       // top − z
                          : Quadric::affine({0, 0, 1}, c.centre[2] - bottom);    // z − bottom
        c.point_begin = uint32_t(t.order.size());
        for (uint32_t i = 0; points && i < points->size(); ++i) {
            const Vector3d q = points->point(i);
            if ((q.x() > 0) == bool(o & 1) && (q.y() > 0) == bool(o & 2) && (q.z() > 0) == bool(o & 4))
                t.order.push_back(i);
        }
        c.point_end = uint32_t(t.order.size());
        t.cells.push_back(c);
    }
    return t;
}

void point_normal_comes_from_the_sheet_through_the_point(void **) {
    const double top = -0.28, bottom = -0.32;
    const Octree t = slab_octree(top, bottom, nullptr);
    const CellSigns as_fitted;
    const MpuFunction f(t, as_fitted, 0);
    std::vector<uint32_t> near;
    for (const double z : {top, bottom}) {
        const Vector3d p(0.1, -0.05, z);
        f.gather(Eigen::AlignedBox3d(p - Vector3d::Constant(0.01), p + Vector3d::Constant(0.01)), near);
        const double outward = z == top ? 1.0 : -1.0;
        Vector3d g;
        f.value_among(near, p, &g);
        if (z == top) assert_true(-g.normalized().z() * outward < 0.0);  // the blend is wrong here...
        assert_true(on_sheet_gradient(f, near, p, g));
        assert_true(-g.normalized().z() * outward > 0.99);  // ...the sheet through p is right
    }
}

// The same slab through point_normals: with from_sheets every point of both sheets gets its
// sheet's outward normal; the blend alone turns some of the top sheet's over.
void point_normals_from_sheets_on_a_thin_slab(void **) {
    const double top = -0.28, bottom = -0.32;
    std::vector<double> xyz;
    for (double z : {top, bottom})
        for (int i = 0; i < 6; ++i)
            for (int j = 0; j < 6; ++j) xyz.insert(xyz.end(), {-0.5 + 0.2 * i, -0.5 + 0.2 * j, z});
    xyz.insert(xyz.end(), {0.5, 0.5, 0.32});  // keeps the slab low in the normalised box
    const size_t n = xyz.size() / 3;
    const PointSet ps = PointSet::from_array(xyz.data(), n, 0, 1);
    const Octree t = slab_octree(ps.point(0).z(), ps.point(36).z(), &ps);  // the sheets, normalised
    assert_int_equal(t.order.size(), n);
    const CellSigns as_fitted;
    const MpuFunction f(t, as_fitted, 0);
    Workers workers(2);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
    for (const bool from_sheets : {false, true}) {
        std::vector<float> blend;
        const std::vector<float> normals = point_normals(f, ps, workers, quiet, from_sheets, &blend);
        size_t right = 0;
        for (size_t i = 0; i + 1 < n; ++i) right += normals[3 * i + 2] * (i < 36 ? 1 : -1) > 0.9;  // top first
        if (from_sheets) assert_int_equal(right, n - 1);
        else assert_true(right < n - 1);
        for (size_t i = 0; !from_sheets && i < 3 * n; ++i) assert_true(blend[i] == normals[i]);
    }
}

void leaf_graph_of_a_known_octree(void **) {
    Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
    Octree t = two_level_octree(-1);
    Workers workers(2);
    LeafGraph g = build_leaf_graph(t, workers, quiet);
    assert_int_equal(g.size(), 15);
    // 7 large leaves: 12 faces of a 2×2×2 block less the 3 of the split octant = 9 edges;
    // 8 small leaves among themselves: 12; the split octant's 3 large neighbours touch 4
    // small leaves each: 12.
    EdgeSet edges = edges_of(g);
    assert_int_equal(edges.size(), 33);
    std::set<std::pair<uint32_t, uint32_t>> expected = face_neighbours(t, g), found;
    for (const auto &[a, b, j] : edges) {
        found.insert({a, b});
        assert_int_equal(j, 4);  // one global plane: every corner agrees
    }
    assert_true(found == expected);
    uint32_t count = 0;
    std::vector<uint32_t> comp = connected_components(g, count);
    assert_int_equal(count, 1);

    // Negate one small leaf's shape: exactly its edges disagree, at all four corners.
    const uint32_t flipped = 9;  // octant 0 of the split octant, at the root's centre
    t = two_level_octree(int(flipped));
    Workers one(1);
    g = build_leaf_graph(t, one, quiet);
    int disagreeing = 0;
    for (const auto &[a, b, j] : edges_of(g)) {
        const bool touches = g.cell_of[a] == flipped || g.cell_of[b] == flipped;
        assert_int_equal(j, touches ? -4 : 4);
        disagreeing += touches;
    }
    assert_int_equal(disagreeing, 6);  // a small corner leaf: 3 small and 3 large neighbours
}

// A flat face on the cells' faces (a CAD part's face at a round coordinate): the corners
// there lie on every leaf's plane, where the sign of the values is that of rounding, so the
// gradients decide. By signs alone the edges across the plane had J = 0 and those along it 2.
void leaf_graph_decides_corners_on_the_surface_by_the_gradients(void **) {
    Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
    Workers workers(1);
    LeafGraph g = build_leaf_graph(two_level_octree(-1, 0.0), workers, quiet);
    EdgeSet edges = edges_of(g);
    assert_int_equal(edges.size(), 33);
    for (const auto &[a, b, j] : edges) assert_int_equal(j, 4);
    const uint32_t flipped = 9;  // a small leaf beside the plane: one of its faces lies in it
    g = build_leaf_graph(two_level_octree(int(flipped), 0.0), workers, quiet);
    int disagreeing = 0;
    for (const auto &[a, b, j] : edges_of(g)) {
        const bool touches = g.cell_of[a] == flipped || g.cell_of[b] == flipped;
        assert_int_equal(j, touches ? -4 : 4);
        disagreeing += touches;
    }
    assert_int_equal(disagreeing, 6);
}

// A Fibonacci sphere (near-uniform, deterministic), its radius modulated by `bump` so that
// no single quadric fits it; appended to *also when given.
PointSet sphere_set(size_t n, double r, const Vector3d &centre, std::vector<double> *also = nullptr,
                    double bump = 0.0) {
    std::vector<double> xyz = also ? *also : std::vector<double>();
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (size_t i = 0; i < n; ++i) {
        double z = 1.0 - 2.0 * (double(i) + 0.5) / double(n), s = std::sqrt(1.0 - z * z);
        Vector3d dir(s * std::cos(golden * double(i)), s * std::sin(golden * double(i)), z);
        Vector3d p = centre + r * (1.0 + bump * std::sin(4.0 * dir[0]) * std::cos(3.0 * dir[1])) * dir;
        xyz.insert(xyz.end(), {p[0], p[1], p[2]});
    }
    if (also) *also = xyz;
    return PointSet::from_array(xyz.data(), xyz.size() / 3, 0, 15);
}

Octree fitted(const PointSet &ps) {
    Progress quiet(nullptr, nullptr, GMPU_STAGE_FIT);
    Params params;
    Workers workers(2);
    return build_octree(ps, params, effective_epsilon(ps, params, 0.0), workers, quiet);
}

void leaf_graph_matches_brute_force_on_a_fitted_octree(void **) {
    // A sphere off-centre in its box, so that leaves of several sizes meet.
    PointSet ps = sphere_set(4000, 1.0, Vector3d(0.3, -0.2, 0.1), nullptr, 0.15);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
    Octree t = fitted(ps);
    Workers workers(2);
    LeafGraph g = build_leaf_graph(t, workers, quiet);
    assert_true(g.size() > 50);
    std::set<std::pair<uint32_t, uint32_t>> found;
    for (const auto &[a, b, j] : edges_of(g)) {
        found.insert({a, b});
        assert_true(j >= -4 && j <= 4);
    }
    assert_true(found == face_neighbours(t, g));
    uint32_t count = 0;
    connected_components(g, count);
    assert_int_equal(count, 1);
}

// ---- advancing front ----------------------------------------------------------------

// A graph from an edge list (a, b, J), with a tree whose cells only carry a model (the
// seed prefers a bivariate leaf).
struct HandGraph {
    Octree tree;
    LeafGraph graph;
    std::vector<uint32_t> component;
    uint32_t components = 0;
    HandGraph(uint32_t n, const std::vector<std::tuple<uint32_t, uint32_t, int>> &edges, uint32_t bivariate) {
        tree.cells.resize(n);
        for (uint32_t v = 0; v < n; ++v) {
            tree.cells[v].shape.model = v == bivariate ? Model::bivariate : Model::quadric;
            graph.cell_of.push_back(v);
        }
        std::vector<std::vector<std::pair<uint32_t, int>>> adj(n);
        for (const auto &[a, b, j] : edges) adj[a].push_back({b, j}), adj[b].push_back({a, j});
        graph.offsets.push_back(0);
        for (uint32_t v = 0; v < n; ++v) {
            for (auto [b, j] : adj[v]) graph.neighbour.push_back(b), graph.agreement.push_back(int8_t(j));
            graph.offsets.push_back(uint32_t(graph.neighbour.size()));
        }
        component = connected_components(graph, components);
    }
    std::vector<int8_t> labels(FrontOrder order, LeafDecision decision) const {
        Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
        FrontOptions o;
        o.order = order;
        o.decision = decision;
        return propagate_orientation(tree, graph, component, components, o, quiet);
    }
};

const FrontOrder kOrders[] = {FrontOrder::most_evidence_first, FrontOrder::fifo};
const LeafDecision kDecisions[] = {LeafDecision::belief_propagation, LeafDecision::weighted_vote};

void front_recovers_a_consistent_orientation(void **) {
    // A 12×12 grid whose leaves were fitted with random signs t: J = 4 t_a t_b. Every option
    // must return t up to one global sign. With a few weak wrong edges (|J| = 1 against the
    // 4s around them) too, except the FIFO front with the plain vote: a leaf reached first
    // through a wrong edge follows it (what belief propagation or the evidence order
    // prevent).
    const uint32_t n = 12;
    std::mt19937_64 rng(5);
    std::vector<int> t(n * n);
    for (int &s : t) s = rng() & 1 ? 1 : -1;
    for (int wrong : {0, 1}) {
        std::vector<std::tuple<uint32_t, uint32_t, int>> edges;
        int k = 0;
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x) {
                uint32_t v = y * n + x;
                for (uint32_t u : {x + 1 < n ? v + 1 : v, y + 1 < n ? v + n : v}) {
                    if (u == v) continue;
                    int j = 4 * t[v] * t[u];
                    if (wrong && ++k % 17 == 0) j = -j / 4;  // weak and wrong
                    edges.push_back({v, u, j});
                }
            }
        HandGraph h(n * n, edges, 0);
        for (FrontOrder order : kOrders)
            for (LeafDecision decision : kDecisions) {
                std::vector<int8_t> l = h.labels(order, decision);
                int agree = 0;
                for (uint32_t v = 0; v < n * n; ++v) agree += l[v] * t[v] == l[0] * t[0];
                fprintf(stderr, "  %s edges, %s front, %s: %d of %u right\n", wrong ? "some wrong" : "consistent",
                        order == FrontOrder::fifo ? "FIFO" : "most-evidence-first",
                        decision == LeafDecision::weighted_vote ? "vote" : "BP", agree, n * n);
                if (wrong && order == FrontOrder::fifo && decision == LeafDecision::weighted_vote)
                    assert_true(agree < int(n * n));
                else
                    assert_int_equal(agree, n * n);
            }
    }
}

void bp_is_right_where_the_vote_is_wrong(void **) {
    // True labels: s = +1, v = u1 = u2 = −1. The edge s–v has a weak, wrong agreement (+1);
    // u1 and u2 each agree strongly with v and disagree strongly with s. Seed s (bivariate,
    // best score). With the FIFO front v is decided first, when s is its only labelled
    // neighbour: the vote follows the wrong edge; belief propagation on v's two-ring graph
    // hears s through u1 and u2 (−4 − 4 against +1) and gets it right. The
    // most-evidence-first front decides u1 and u2 first, so there even the vote is right.
    const uint32_t s = 0, v = 1, u1 = 2, u2 = 3;
    HandGraph h(4, {{s, v, 1}, {s, u1, -4}, {s, u2, -4}, {v, u1, 4}, {v, u2, 4}}, s);
    const std::vector<int8_t> truth = {1, -1, -1, -1};
    assert_true(h.labels(FrontOrder::fifo, LeafDecision::belief_propagation) == truth);
    assert_true(h.labels(FrontOrder::most_evidence_first, LeafDecision::belief_propagation) == truth);
    assert_true(h.labels(FrontOrder::most_evidence_first, LeafDecision::weighted_vote) == truth);
    std::vector<int8_t> vote = h.labels(FrontOrder::fifo, LeafDecision::weighted_vote);
    assert_int_equal(vote[v], 1);  // wrong: what BP adds
    (void)u1, (void)u2;
}

// ---- outward pass -------------------------------------------------------------------

// Share of leaves holding points whose oriented fit has its normal (−∇f) along `outward`
// at the leaf's points, for points with `select`.
template <class Select, class Outward>
double share_facing(const Octree &t, const CellSigns &signs, const PointSet &ps, Select select, Outward outward) {
    int right = 0, total = 0;
    for (const Cell &c : t.cells) {
        if (!c.is_leaf() || c.point_end == c.point_begin) continue;
        const int8_t sign = signs[size_t(&c - t.cells.data())];
        double s = 0.0;
        bool any = false;
        Vector3d g;
        for (uint32_t k = c.point_begin; k < c.point_end; ++k) {
            Vector3d p = ps.point(t.order[k]);
            if (!select(p)) continue;
            any = true;
            oriented_value(c, sign, p, t.pieces, &g);
            s += -g.normalized().dot(outward(p));
        }
        if (!any) continue;
        ++total;
        right += s > 0.0;
    }
    return total ? double(right) / total : 0.0;
}

void outward_pass_orients_nested_shells(void **) {
    // A hollow ball: spheres of radius 1 and 0.5. f is positive in the solid between them,
    // so the outer shell's normals point away from the centre, the inner shell's towards it.
    std::vector<double> xyz;
    sphere_set(12000, 1.0, Vector3d::Zero(), &xyz);
    PointSet ps = sphere_set(6000, 0.5, Vector3d::Zero(), &xyz);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_ORIENT);
    Octree t = fitted(ps);
    Workers workers(2);
    Orientation orientation = orient_octree(t, ps, nullptr, workers, quiet);
    const OrientStats &stats = orientation.stats;
    CellSigns &signs = orientation.signs;
    assert_int_equal(stats.components, 2);
    const double split = 0.75 * 0.5;  // between the shells, in the normalised frame (scale 1/2)
    auto outer = [&](const Vector3d &p) { return p.norm() > split; };
    auto inner = [&](const Vector3d &p) { return p.norm() < split; };
    auto radial = [](const Vector3d &p) { return Vector3d(p.normalized()); };
    auto inward = [](const Vector3d &p) { return Vector3d(-p.normalized()); };
    assert_true(share_facing(t, signs, ps, outer, radial) > 0.99);
    assert_true(share_facing(t, signs, ps, inner, inward) > 0.99);

    // Turn the inner shell inside out by hand: the pass must turn exactly it back.
    LeafGraph g = build_leaf_graph(t, workers, quiet);
    uint32_t count = 0;
    std::vector<uint32_t> comp = connected_components(g, count);
    assert_int_equal(make_components_outward(t, signs, ps, g, comp, count, quiet), 0);  // already right
    uint32_t inner_component = UINT32_MAX;
    for (uint32_t v = 0; v < g.size() && inner_component == UINT32_MAX; ++v) {
        const Cell &c = t.cells[g.cell_of[v]];
        if (c.point_end > c.point_begin && inner(ps.point(t.order[c.point_begin]))) inner_component = comp[v];
    }
    size_t inner_leaves = 0;
    for (uint32_t v = 0; v < g.size(); ++v) {
        int8_t &sign = signs[g.cell_of[v]];
        if (comp[v] == inner_component) sign = int8_t(-sign), ++inner_leaves;
    }
    assert_true(share_facing(t, signs, ps, inner, inward) < 0.01);
    assert_int_equal(make_components_outward(t, signs, ps, g, comp, count, quiet), inner_leaves);
    assert_true(share_facing(t, signs, ps, inner, inward) > 0.99);
    assert_true(share_facing(t, signs, ps, outer, radial) > 0.99);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(leaf_graph_of_a_known_octree),
        cmocka_unit_test(leaf_graph_decides_corners_on_the_surface_by_the_gradients),
        cmocka_unit_test(leaf_graph_matches_brute_force_on_a_fitted_octree),
        cmocka_unit_test(front_recovers_a_consistent_orientation),
        cmocka_unit_test(bp_is_right_where_the_vote_is_wrong),
        cmocka_unit_test(outward_pass_orients_nested_shells),
        cmocka_unit_test(point_normal_comes_from_the_sheet_through_the_point),
        cmocka_unit_test(point_normals_from_sheets_on_a_thin_slab),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
