// Decimation of large meshes chunk by chunk (mesh/chunked_decimation.hpp): the vertices two
// chunks share stay, so the chunks fit back together into the same closed surface, and a
// chunk whose collapses break the topology is redone alone while the others keep their
// single round. A whole mesh's first round, run already by simplify_mesh to choose between
// chunks and the whole, is not run again by decimate_patch. A round whose only break is a
// fin low enough to drop is mended instead of redone.
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh/chunked_decimation.hpp"
#include "mesh/mesh_topology.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using namespace gmpu;

namespace {

// Appends a closed torus (outward-wound, `around` × `tube` quads) centred at x = `cx`.
void add_torus(std::vector<float> &positions, std::vector<uint32_t> &triangles, float cx, float major, float minor,
               uint32_t around, uint32_t tube) {
    const uint32_t first = uint32_t(positions.size() / 3);
    for (uint32_t i = 0; i < around; ++i)
        for (uint32_t j = 0; j < tube; ++j) {
            const double u = 2 * M_PI * i / around, v = 2 * M_PI * j / tube;
            positions.push_back(float(cx + (major + minor * std::cos(v)) * std::cos(u)));
            positions.push_back(float((major + minor * std::cos(v)) * std::sin(u)));
            positions.push_back(float(minor * std::sin(v)));
        }
    auto at = [&](uint32_t i, uint32_t j) { return first + (i % around) * tube + j % tube; };
    for (uint32_t i = 0; i < around; ++i)
        for (uint32_t j = 0; j < tube; ++j) {
            const uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            triangles.insert(triangles.end(), {a, b, c, a, c, d});
        }
}

MeshTopology topology(size_t vertices, const std::vector<uint32_t> &triangles) {
    Mesh m;
    m.vertices.assign(3 * vertices, 0.0);
    m.triangles = triangles;
    return mesh_topology(m);
}

void chunk_borders_stay(void **) {
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    add_torus(positions, triangles, 0.0f, 1.0f, 0.4f, 200, 100);  // 40 000 triangles
    const size_t n = positions.size() / 3, count = triangles.size() / 3;
    assert_true(topology(n, triangles).closed_manifold());
    const ChunkedDecimation d = decimate_in_chunks(positions, triangles, count / 10, 1.0, 8192, nullptr, nullptr);
    assert_int_equal(d.chunks.size(), 8);
    assert_true(d.kept);
    // The seams and the ring beside them stay whole: a third, not the tenth asked for.
    assert_true(d.triangles.size() / 3 < count / 3);
    // Every vertex the triangles of two chunks share is still in the result.
    std::vector<int64_t> first_chunk(n, -1);
    std::vector<char> shared(n, 0), used(n, 0);
    for (size_t t = 0; t < count; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = triangles[3 * t + k];
            if (first_chunk[v] < 0) first_chunk[v] = d.chunk[t];
            else if (first_chunk[v] != d.chunk[t]) shared[v] = 1;
        }
    for (uint32_t v : d.triangles) used[v] = 1;
    size_t shared_count = 0;
    for (size_t v = 0; v < n; ++v) {
        shared_count += shared[v];
        if (shared[v]) assert_true(used[v]);
    }
    assert_true(shared_count > 0);
    const MeshTopology after = topology(n, d.triangles);
    assert_true(after.closed_manifold());
    assert_int_equal(after.components, 1);
    assert_int_equal(after.euler_characteristic, 0);  // genus 1
}

void failing_chunk_alone_is_retried(void **) {
    // A fat torus that decimates in one round, and far off a thin one whose tube, cut down
    // to a few triangles, pinches: its rounds break the topology and are redone.
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    add_torus(positions, triangles, 0.0f, 1.0f, 0.4f, 200, 100);
    const size_t fat = triangles.size() / 3;
    add_torus(positions, triangles, 10.0f, 1.0f, 0.01f, 400, 8);
    const size_t n = positions.size() / 3, count = triangles.size() / 3;
    const ChunkedDecimation d = decimate_in_chunks(positions, triangles, count / 50, 100.0, 4096, nullptr, nullptr);
    assert_true(d.kept);
    std::vector<char> has_thin(d.chunks.size(), 0);
    for (size_t t = fat; t < count; ++t) has_thin[d.chunk[t]] = 1;
    size_t retried = 0, fat_only = 0;
    for (size_t c = 0; c < d.chunks.size(); ++c) {
        if (d.chunks[c].retries > 0) ++retried;
        fat_only += !has_thin[c];
        // A chunk of the fat torus alone is never redone for the thin one's failures.
        if (!has_thin[c]) assert_int_equal(d.chunks[c].retries, 0);
    }
    assert_true(retried > 0);
    assert_true(fat_only >= 8);  // most of the fat torus was spared the thin one's retries
    const MeshTopology after = topology(n, d.triangles);
    assert_true(after.closed_manifold());
    assert_int_equal(after.components, 2);
    assert_int_equal(after.euler_characteristic, 0);
}

void given_first_round_is_not_rerun(void **) {
    // A torus that decimates in one round that keeps the topology. Told that its first round
    // already ran and broke the topology at one vertex, decimate_patch takes that round as
    // its first (it does not run it again: run, it would have kept the topology), locks the
    // vertex with its neighbours and redoes the round: the vertex stays.
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    add_torus(positions, triangles, 0.0f, 1.0f, 0.4f, 200, 100);
    const size_t count = triangles.size() / 3;
    std::vector<uint32_t> plain = triangles;
    const PatchDecimation alone = decimate_patch(positions, plain, count / 10, 1.0);
    assert_int_equal(alone.rounds, 1);
    assert_int_equal(alone.retries, 0);

    const uint32_t culprit = 5050;
    bool collapsed = true;
    for (uint32_t v : plain) collapsed = collapsed && v != culprit;
    assert_true(collapsed);  // without the lock, the round collapses it away
    BrokenRound first;
    first.triangles.assign(triangles.begin(), triangles.begin() + 3 * long(count / 2));
    first.culprits = {culprit};
    const PatchDecimation redone = decimate_patch(positions, triangles, count / 10, 1.0, nullptr, &first);
    assert_int_equal(redone.rounds, 2);
    assert_int_equal(redone.retries, 1);
    bool kept = false;
    for (uint32_t v : triangles) kept = kept || v == culprit;
    assert_true(kept);
    assert_true(triangles.size() / 3 <= count / 10 + count / 100);
    const MeshTopology after = topology(positions.size() / 3, triangles);
    assert_true(after.closed_manifold());
    assert_int_equal(after.euler_characteristic, 0);
}

// A closed octahedron (6 vertices, 8 outward triangles) with a fin on its edge (0, 2): a
// seventh vertex `height` above the edge's midpoint, in two triangles back to back.
void octahedron_with_fin(std::vector<float> &positions, std::vector<uint32_t> &triangles, float height) {
    positions = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    triangles = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    const float out = 0.5f + height / std::sqrt(2.0f);  // along the edge's outward bisector
    positions.insert(positions.end(), {out, out, 0});
    triangles.insert(triangles.end(), {6, 0, 2, 6, 2, 0});
}

void fins_within_reach_are_removed(void **) {
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    octahedron_with_fin(positions, triangles, 0.1f);
    const MeshTopology broken = topology(7, triangles);
    assert_false(broken.manifold());  // the fin's edge has four triangles
    std::vector<uint32_t> low = triangles;
    assert_true(remove_fins(low, positions, 0.05) < 0.0);  // higher than the reach: kept
    assert_true(low == triangles);
    const double height = remove_fins(low, positions, 0.2);
    assert_true(std::fabs(height - 0.1) < 1e-6);
    assert_int_equal(low.size(), 24);
    const MeshTopology mended = topology(7, low);
    assert_true(mended.closed_manifold());
    assert_int_equal(mended.euler_characteristic, 2);
    // Two triangles at a vertex wound the same way are not a fin.
    std::vector<uint32_t> twice = triangles;
    twice[twice.size() - 2] = 0, twice[twice.size() - 1] = 2;
    assert_true(remove_fins(twice, positions, 1.0) < 0.0);
}

// A unit sphere (64 × 32 quads) with a thin spike on every 31st triangle: its centre raised
// `height` off the sphere, the triangle split into three around it.
void spiky_sphere(std::vector<float> &positions, std::vector<uint32_t> &triangles, float height) {
    constexpr int kAround = 64, kRings = 32;
    positions = {0, 0, 1};
    for (int i = 1; i < kRings; ++i)
        for (int j = 0; j < kAround; ++j) {
            const double theta = M_PI * i / kRings, phi = 2 * M_PI * j / kAround;
            positions.insert(positions.end(), {float(std::sin(theta) * std::cos(phi)),
                                               float(std::sin(theta) * std::sin(phi)), float(std::cos(theta))});
        }
    positions.insert(positions.end(), {0, 0, -1});
    const uint32_t south = uint32_t(positions.size() / 3 - 1);
    auto at = [](int i, int j) { return uint32_t(1 + (i - 1) * kAround + j % kAround); };
    std::vector<uint32_t> sphere;
    for (int j = 0; j < kAround; ++j) sphere.insert(sphere.end(), {0, at(1, j), at(1, j + 1)});
    for (int i = 1; i < kRings - 1; ++i)
        for (int j = 0; j < kAround; ++j)
            sphere.insert(sphere.end(),
                          {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    for (int j = 0; j < kAround; ++j) sphere.insert(sphere.end(), {at(kRings - 1, j), south, at(kRings - 1, j + 1)});
    triangles.clear();
    for (size_t t = 0; t < sphere.size() / 3; ++t) {
        const uint32_t a = sphere[3 * t], b = sphere[3 * t + 1], c = sphere[3 * t + 2];
        if (t % 31 != 1) {
            triangles.insert(triangles.end(), {a, b, c});
            continue;
        }
        float centre[3], length = 0;
        for (int d = 0; d < 3; ++d) {
            centre[d] = (positions[3 * a + d] + positions[3 * b + d] + positions[3 * c + d]) / 3;
            length += centre[d] * centre[d];
        }
        const uint32_t tip = uint32_t(positions.size() / 3);
        for (int d = 0; d < 3; ++d) positions.push_back(centre[d] / std::sqrt(length) * (1 + height));
        triangles.insert(triangles.end(), {a, b, tip, b, c, tip, c, a, tip});
    }
}

void crushed_spikes_are_dropped_not_redone(void **) {
    // The spikes stand 0.05 off the sphere, half the error bound of 0.1: the first round
    // crushes them into fins, which are dropped, and the round is kept. Redone instead (with
    // the fins' neighbourhoods locked), it took 5 rounds and stopped at 2420 triangles.
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
    spiky_sphere(positions, triangles, 0.05f);
    const size_t n = positions.size() / 3, count = triangles.size() / 3;
    assert_true(topology(n, triangles).closed_manifold());
    const PatchDecimation d = decimate_patch(positions, triangles, count / 10, 0.1);
    assert_int_equal(d.rounds, 1);
    assert_int_equal(d.retries, 0);
    assert_true(triangles.size() / 3 <= count / 10);
    assert_true(d.spent <= 0.1);
    const MeshTopology after = topology(n, triangles);
    assert_true(after.closed_manifold());
    assert_int_equal(after.euler_characteristic, 2);
}

}  // namespace

int main() {
    const struct CMUnitTest tests[] = {cmocka_unit_test(chunk_borders_stay),
                                       cmocka_unit_test(failing_chunk_alone_is_retried),
                                       cmocka_unit_test(given_first_round_is_not_rerun),
                                       cmocka_unit_test(fins_within_reach_are_removed),
                                       cmocka_unit_test(crushed_spikes_are_dropped_not_redone)};
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
