// Unit tests of the C++ modules, one group per concept, each against an answer known in
// advance: quadric algebra, the three fits, the robust Taubin error, the noise estimate,
// belief propagation, the marching-cubes table (closed surfaces for any sign field),
// the winding number, point-set validation, mesh clean-up and the parallel loop.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <map>
#include <functional>
#include <mutex>
#include <set>

#include <pthread.h>
#include <signal.h>
#include <thread>
#include <random>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <stdexcept>
#include <vector>

#include "core/cancellable_sort.hpp"
#include "core/conjugate_gradients.hpp"
#include "core/resize_reporting.hpp"
#include "core/error.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "fit/build_octree.hpp"
#include "fit/cell_fit.hpp"
#include "fit/fits.hpp"
#include "fit/noise_estimate.hpp"
#include "geometry/clusters.hpp"
#include "io/io.hpp"
#include "geometry/outliers.hpp"
#include "geometry/point_set.hpp"
#include "implicit/mpu_function.hpp"
#include "implicit/winding_field.hpp"
#include "mesh/marching_cubes.hpp"
#include "mesh/mesh_cleanup.hpp"
#include "orient/belief_propagation.hpp"
#include "random_vectors.hpp"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using gmpu_test::draw_vector;

using Eigen::Vector3d;
using namespace gmpu;

namespace {

#define assert_near(a, b, tol) assert_true(std::abs((a) - (b)) <= (tol))

std::vector<double> flat(const PointList &pts) {
    std::vector<double> out;
    for (const auto &p : pts) out.insert(out.end(), {p[0], p[1], p[2]});
    return out;
}

PointList sphere_points(size_t n, double r, double noise, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0, 1);
    PointList pts;
    for (size_t i = 0; i < n; ++i) {
        Vector3d d = draw_vector(g, rng);
        pts.push_back(r * d.normalized() + noise * draw_vector(g, rng));
    }
    return pts;
}

// ---- quadrics and fits ---------------------------------------------------------------

void quadric_algebra(void **) {
    // (x + 2y − 1)(3z + 1) expanded and evaluated against the product of the factors.
    Quadric a = Quadric::affine({1, 2, 0}, -1), b = Quadric::affine({0, 0, 3}, 1);
    Quadric p = Quadric::product(a, b) + 2.0 * a - b;
    for (Vector3d y : {Vector3d(0.3, -1, 2), Vector3d(-2, 0.5, 0.1), Vector3d(0, 0, 0)}) {
        double expect = (y[0] + 2 * y[1] - 1) * (3 * y[2] + 1) + 2 * (y[0] + 2 * y[1] - 1) - (3 * y[2] + 1);
        assert_near(p.value(y), expect, 1e-12);
        // The analytic gradient against central differences.
        for (int d = 0; d < 3; ++d) {
            Vector3d e = Vector3d::Zero();
            e[d] = 1e-6;
            assert_near(p.gradient(y)[d], (p.value(y + e) - p.value(y - e)) / 2e-6, 1e-6);
        }
    }
}

void bivariate_fit_is_exact_on_a_paraboloid(void **) {
    // z = 0.4x² + 0.2y² + 0.02 on a symmetric grid, so the PCA frame is the xyz frame: the
    // fit must reproduce it (Taubin error ~ 0), with ∇Q about unit length.
    PointList pts;
    for (int i = -10; i <= 10; ++i)
        for (int j = -10; j <= 10; ++j) {
            double x = 0.1 * i, y = 0.1 * j;
            pts.emplace_back(x, y, 0.4 * x * x + 0.2 * y * y + 0.02);
        }
    Pca pca = compute_pca(pts);
    assert_true(pca.variation < 0.25);
    LocalShape s;
    s.q = fit_bivariate(pts, pca, 1.0);
    assert_true(taubin_error(s, {}, pts) < 1e-4);
    for (const auto &p : pts) assert_true(s.q.gradient(p).norm() > 0.9 && s.q.gradient(p).norm() < 2.0);
}

void general_quadric_fits_a_sphere(void **) {
    PointList pts = sphere_points(500, 0.7, 0, 5);
    Pca pca = compute_pca(pts);
    assert_true(pca.variation > 0.25);  // about isotropic: the general-quadric branch
    LocalShape s;
    s.model = Model::quadric;
    s.q = fit_general_quadric(pts, 1.0);
    assert_true(taubin_error(s, {}, pts) < 1e-6);
    // One consistent sign on each side, unit mean gradient on the data.
    assert_true(s.q.value({0, 0, 0}) * s.q.value({2, 0, 0}) < 0);
    double mean = 0;
    for (const auto &p : pts) mean += s.q.gradient(p).norm();
    assert_near(mean / double(pts.size()), 1.0, 1e-9);
}

void pca_surface_variation(void **) {
    PointList plane;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j) plane.emplace_back(i * 0.1, j * 0.1, 0.5);
    Pca p = compute_pca(plane);
    assert_near(p.variation, 0.0, 1e-12);
    assert_near(std::abs(p.normal().dot(Vector3d::UnitZ())), 1.0, 1e-9);
}

void robust_taubin_error(void **) {
    // A plane fit with 1 of 100 points off by 0.3: the error is max/3 (0.1), not 0.3; with 20
    // of 100 points off by 0.03, the 90th percentile (0.03) decides.
    PointList pts;
    for (int i = 0; i < 100; ++i) pts.emplace_back(0.01 * i, 0.02 * (i % 7), 0.0);
    LocalShape plane;
    plane.q = Quadric::affine({0, 0, 1}, 0);
    pts[10][2] = 0.3;
    assert_near(taubin_error(plane, {}, pts), 0.1, 1e-12);
    pts[10][2] = 0;
    for (int i = 0; i < 20; ++i) pts[size_t(i)][2] = 0.03;
    assert_near(taubin_error(plane, {}, pts), 0.03, 1e-12);
}

// The estimate as a fraction of the bounding-box diagonal (the statistic GMPU_STAT_NOISE).
double noise_share(const PointList &pts) {
    std::vector<double> xyz = flat(pts);
    PointSet ps = PointSet::from_array(xyz.data(), pts.size(), 0, 15);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_FIT);
    return estimate_noise(ps, quiet) / (ps.world_diagonal() * ps.normalisation().scale);
}

bool sees_close_sheets(const PointList &pts) {
    std::vector<double> xyz = flat(pts);
    PointSet ps = PointSet::from_array(xyz.data(), pts.size(), 0, 15);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_FIT);
    return estimate_noise_model(ps, quiet).close_sheets;
}

void noise_estimate_tracks_the_noise(void **) {
    // σ as a share of the diagonal (2√3 for the unit sphere's box). At 1 % the noise is
    // twice the spacing of 30,000 points: neighbours picked by 3D distance would see it cut.
    const double diagonal = 2.0 * std::sqrt(3.0);
    for (double share : {0.0, 0.0025, 0.005, 0.01}) {
        double est = noise_share(sphere_points(30000, 1.0, share * diagonal, 17));
        fprintf(stderr, "  sigma %.4f estimated %.5f\n", share, est);
        if (share == 0) assert_true(est < 0.0001);
        else assert_true(est > 0.8 * share && est < 1.25 * share);
        if (share > 0) assert_false(sees_close_sheets(sphere_points(30000, 1.0, share * diagonal, 17)));
    }
}

void noise_estimate_ignores_a_second_sheet(void **) {
    // A clean hollow sphere, its wall 1.2 % of the diagonal thick and sampled twice as
    // sparsely: every neighbourhood holds both sheets, which is no noise.
    PointList pts = sphere_points(2000, 1.0, 0, 3), inner = sphere_points(2000, 0.96, 0, 4);
    pts.insert(pts.end(), inner.begin(), inner.end());
    double est = noise_share(pts);
    fprintf(stderr, "  two sheets: estimated %.5f\n", est);
    assert_true(est <= 0.0005);
}

void noise_estimate_sees_through_a_noisy_wall(void **) {
    // A hollow sphere whose wall (1.2 % of the diagonal) is only 2.4 σ thick: the sheets
    // do not split into two groups, and their offset added to the noise would read 1.5 σ.
    const double diagonal = 2.0 * std::sqrt(3.0);
    for (double share : {0.005, 0.01}) {
        PointList pts = sphere_points(18000, 1.0, share * diagonal, 31),
                  inner = sphere_points(17000, 1.0 - 0.012 * diagonal, share * diagonal, 32);
        pts.insert(pts.end(), inner.begin(), inner.end());
        double est = noise_share(pts);
        fprintf(stderr, "  noisy wall: sigma %.4f estimated %.5f\n", share, est);
        assert_true(est > 0.7 * share && est < 1.3 * share);
        if (share == 0.005) assert_true(sees_close_sheets(pts));
    }
}

// Point sets on the plane z = 0 in [-1, 1]²: two noisy sheets half_gap either side of it
// (a wall), one noisy sheet, one sheet as spread as the wall, and a clean wave.
struct SheetClouds {
    PointList wall, single, spread, wave;
};

SheetClouds sheet_clouds(int n, double sigma, double half_gap, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0, 1);
    std::uniform_real_distribution<double> u(-1, 1);
    SheetClouds c;
    for (int i = 0; i < n; ++i) {
        const double x = u(rng), y = u(rng);
        c.wall.emplace_back(x, y, (i % 2 ? half_gap : -half_gap) + sigma * g(rng));
        c.single.emplace_back(x, y, sigma * g(rng));
        c.spread.emplace_back(x, y, std::sqrt(sigma * sigma + half_gap * half_gap) * g(rng));
        c.wave.emplace_back(x, y, 0.1 * std::sin(4.0 * x));
    }
    return c;
}

void two_noisy_sheets_in_one_support(void **) {
    // Two parallel sheets only 2.4 σ apart: their residuals do not split into two groups,
    // but form a flat two-peaked mixture spread over the whole support. A single sheet with
    // the same spread of Gaussian noise, or a clean wave one quadric cannot follow, must
    // not be read as two.
    const double sigma = 0.02, half_gap = 1.2 * sigma;
    const SheetClouds c = sheet_clouds(1500, sigma, half_gap, 41);
    Params params;
    const double tight = 1e-4;
    const CloseSheets cloud = CloseSheets::cloud;
    assert_true(fit_cell(c.wall, 1.5, tight, tight, params, cloud).shape.model == Model::two_sheets);
    assert_true(fit_cell(c.spread, 1.5, tight, tight, params, cloud).shape.model != Model::two_sheets);
    assert_true(fit_cell(c.wave, 1.5, tight, tight, params, cloud).shape.model != Model::two_sheets);
    // Only where ε is the noise floor.
    assert_true(fit_cell(c.wall, 1.5, tight, tight, params, CloseSheets::off).shape.model != Model::two_sheets);
}

void two_noisy_sheets_without_cloud_evidence(void **) {
    // A blade 3 σ thick in a small support (300 points, under the 384 the cloud-wide
    // evidence asks for), on a cloud whose noise estimate did not see close sheets (it reads
    // the quietest neighbourhoods: a rotor's hub, not its blades, and reads the blades'
    // offset as 1.2 σ). ε is the noise floor, 1.75 σ̂: one sheet through the blade misses
    // it, two sheets stay well inside it, so the support shows the two sheets on its own.
    // A single noisy sheet passes ε; a single sheet as spread as the blade, or a wave, are
    // not two sheets either.
    const double sigma = 0.02, half_gap = 1.5 * sigma, floor = 1.75 * 1.2 * sigma, tight = 1e-4;
    const SheetClouds c = sheet_clouds(300, sigma, half_gap, 43);
    Params params;
    const CloseSheets local = CloseSheets::local;
    assert_true(fit_cell(c.wall, 1.5, floor, tight, params, local).shape.model == Model::two_sheets);
    assert_true(fit_cell(c.single, 1.5, floor, tight, params, local).shape.model != Model::two_sheets);
    assert_true(fit_cell(c.spread, 1.5, floor, tight, params, local).shape.model != Model::two_sheets);
    assert_true(fit_cell(c.wave, 1.5, floor, tight, params, local).shape.model != Model::two_sheets);
    // Without the local evidence rule these supports are below the cloud-wide size.
    assert_true(fit_cell(c.wall, 1.5, floor, tight, params, CloseSheets::off).shape.model != Model::two_sheets);
}

// A plate's end in one support: two clean sheets z = ±gap/2 for x < 0.5 (`sheet_points`
// over them), the rim face at x = 0.5 joining them (`rim_points`), in the ball of radius
// 1.5 around the origin.
PointList plate_end(int sheet_points, int rim_points, double gap, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.5, 1.5), unit(0, 1);
    PointList pts;
    for (int i = 0; i < sheet_points; ++i)
        pts.emplace_back(unit(rng) * 2.0 - 1.5, u(rng), unit(rng) < 0.5 ? -gap / 2 : gap / 2);
    for (int i = 0; i < rim_points; ++i) pts.emplace_back(0.5, u(rng), gap * (unit(rng) - 0.5));
    return pts;
}

void two_sheets_that_end_ask_for_a_split(void **) {
    // Sheets fitted past their rim run on and meet beyond it (a fin around a plate's
    // outline); the fit says so, on noise-free fits whose sampling resolves the gap.
    Params params;
    const double tight = 1e-4;
    // 3,000 sheet points and the rim face's share of the area (about 2 %).
    const PointList rim = plate_end(3000, 60, 0.1, 51);
    const CellFit end = fit_cell(rim, 1.5, tight, tight, params);
    assert_true(end.shape.model == Model::two_sheets);
    assert_true(end.sheets_end);
    // The same sheets without the rim face: they run through the support.
    const CellFit wall = fit_cell(plate_end(3000, 0, 0.1, 51), 1.5, tight, tight, params);
    assert_true(wall.shape.model == Model::two_sheets);
    assert_false(wall.sheets_end);
    // Where ε is the noise floor the points between close sheets are noise, not a rim.
    const CellFit noisy = fit_cell(rim, 1.5, 10 * tight, tight, params);
    assert_true(noisy.shape.model == Model::two_sheets);
    assert_false(noisy.sheets_end);
    // Sheets sampled more coarsely than twice their gap: there, points between them are
    // more often the sheets' own, straddled by fits through too few points, than a rim face,
    // however many there are.
    const CellFit sparse = fit_cell(plate_end(150, 20, 0.1, 51), 1.5, tight, tight, params);
    assert_true(sparse.shape.model == Model::two_sheets);
    assert_false(sparse.sheets_end);
}

void noise_estimate_ignores_sparse_detail(void **) {
    // 1,500 clean points on a sphere with 30 ridges around it, each about two sample spacings
    // wide at the equator and narrower towards the poles: what a local quadric cannot follow
    // there is shape, not noise (the quiet tenth of the neighbourhoods says so).
    std::mt19937_64 rng(9);
    std::normal_distribution<double> g(0, 1);
    PointList pts;
    for (int i = 0; i < 1500; ++i) {
        Vector3d d = draw_vector(g, rng).normalized();
        double ridge = 0.08 * std::sin(30.0 * std::atan2(d[1], d[0]));
        pts.push_back((1.0 + ridge) * d);
    }
    double est = noise_share(pts);
    fprintf(stderr, "  sparse ridges: estimated %.5f\n", est);
    assert_true(est <= 0.0005);
}

// ---- point set ---------------------------------------------------------------------

template <class Fn>
gmpu_status status_of(Fn &&fn, std::string *message = nullptr) {
    try {
        fn();
    } catch (const Error &e) {
        if (message) *message = e.what();
        return e.status();
    }
    return GMPU_OK;
}

// Outliers are points far from all others against the cloud's own spacing: single strays
// and a small far group are found at any distance, in float and double input; dense
// clusters, a sparse but evenly sampled region, and clouds too small to judge are not.
void outliers_are_far_from_everything(void **) {
    std::vector<double> xyz = flat(sphere_points(2000, 1, 0, 1));
    OutlierScan none = find_outliers(xyz.data(), 2000, 0, false);
    assert_true(none.outliers.empty());
    assert_true(none.spacing > 0.0 && std::fabs(none.extent - 2.0) < 0.01);
    // Every 10th point of a second sphere 10 radii away: ten times sparser, still no outlier.
    std::vector<double> sparse = flat(sphere_points(200, 1, 0, 2));
    for (size_t i = 0; i < sparse.size(); i += 3) sparse[i] += 10.0;
    std::vector<double> both = xyz;
    both.insert(both.end(), sparse.begin(), sparse.end());
    assert_true(find_outliers(both.data(), both.size() / 3, 0, false).outliers.empty());
    for (double far : {30.0, 1e3, 1e8}) {
        std::vector<double> with = xyz;
        with.insert(with.end(), {far, 0.0, 0.0, -far, far, 0.5});                  // two strays
        for (int k = 0; k < 3; ++k) with.insert(with.end(), {0.0, far + 0.01 * k, 0.0});  // a group of 3
        OutlierScan scan = find_outliers(with.data(), with.size() / 3, 0);
        assert_int_equal(scan.outliers.size(), 5);
        for (size_t k = 0; k < 5; ++k) assert_int_equal(scan.outliers[k], 2000 + k);
        assert_true(std::fabs(scan.extent - 2.0) < 0.01);  // the kept points' extent
        std::vector<float> f(with.begin(), with.end());
        assert_int_equal(find_outliers(f.data(), f.size() / 3, 0).outliers.size(), 5);
    }
    // Strided records, and too few points to judge.
    std::vector<double> rec;
    for (size_t i = 0; i < 2000; ++i) rec.insert(rec.end(), {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], NAN});
    rec.insert(rec.end(), {1e4, 0, 0, NAN});
    assert_int_equal(find_outliers(rec.data(), 2001, 4 * sizeof(double)).outliers.size(), 1);
    // Without a box wider than the bulk of the points, the scan is skipped (spacing 0).
    assert_true(find_outliers(xyz.data(), 2000, 0).spacing == 0.0);
    std::vector<double> few = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1e6, 1e6, 1e6};
    assert_true(find_outliers(few.data(), 5, 0).outliers.empty());
}

// Clusters: groups whose boxes are farther apart than their own sizes; one object (whole,
// nested, or beside a clump too small to stand alone) stays one cluster.
void clusters_are_groups_far_apart(void **) {
    auto shifted = [](PointList pts, Vector3d by) {
        for (auto &p : pts) p += by;
        return flat(pts);
    };
    const std::vector<uint32_t> none;
    std::vector<double> big = shifted(sphere_points(3000, 1000, 0, 1), Vector3d::Zero());
    assert_int_equal(find_clusters(big.data(), 3000, 0, none, 15).count, 1);
    // A small sphere a thousand of its radii away: two clusters, labelled by input order.
    std::vector<double> both = shifted(sphere_points(500, 1, 0, 2), Vector3d(1e6, 5, -3));
    both.insert(both.begin(), big.begin(), big.end());
    Clusters two = find_clusters(both.data(), 3500, 0, none, 15);
    assert_int_equal(two.count, 2);
    for (size_t i = 0; i < 3500; ++i) assert_int_equal(two.labels[i], i < 3000 ? 0 : 1);
    // Each box is its own sphere's (random points on it: the extremes lie within its radius).
    assert_true(two.boxes[1][0] >= 1e6 - 1 - 1e-9 && two.boxes[1][0] < 1e6 - 0.8);
    assert_true(two.boxes[0][3] <= 1000 + 1e-9 && two.boxes[0][3] > 800);
    std::vector<float> f(both.begin(), both.end());
    assert_int_equal(find_clusters(f.data(), 3500, 0, none, 15).count, 2);
    // The same far sphere as outliers (set aside): one cluster; one far outlier among
    // two clusters is labelled with the nearer.
    std::vector<uint32_t> tail(500);
    for (uint32_t k = 0; k < 500; ++k) tail[k] = 3000 + k;
    assert_int_equal(find_clusters(both.data(), 3500, 0, tail, 15).count, 1);
    std::vector<double> stray = both;
    stray.insert(stray.end(), {2e6, 0, 0});
    Clusters three = find_clusters(stray.data(), 3501, 0, std::vector<uint32_t>{3500}, 15);
    assert_int_equal(three.count, 2);
    assert_int_equal(three.labels[3500], 1);
    // A stray the outlier scan left (the box is not wider than the bulk: half the points are at
    // each end) does not join the clusters: it goes to the nearer, whose box it does not widen.
    Clusters strayed = find_clusters(stray.data(), 3501, 0, none, 15);
    assert_int_equal(strayed.count, 2);
    assert_int_equal(strayed.labels[3500], 1);
    assert_true(strayed.boxes[1][3] < 1e6 + 2);
    stray[3 * 3500] = 5e5;  // halfway: still no bridge
    assert_int_equal(find_clusters(stray.data(), 3501, 0, none, 15).count, 2);
    // Nearer than their size, nested, or too few points to stand alone: one cluster.
    std::vector<double> near = shifted(sphere_points(500, 1000, 0, 2), Vector3d(2900, 0, 0));
    near.insert(near.begin(), big.begin(), big.end());
    assert_int_equal(find_clusters(near.data(), 3500, 0, none, 15).count, 1);
    std::vector<double> nested = shifted(sphere_points(500, 300, 0, 2), Vector3d::Zero());
    nested.insert(nested.begin(), big.begin(), big.end());
    assert_int_equal(find_clusters(nested.data(), 3500, 0, none, 15).count, 1);
    std::vector<double> clump = shifted(sphere_points(40, 1, 0, 2), Vector3d(1e6, 0, 0));
    clump.insert(clump.begin(), big.begin(), big.end());
    assert_int_equal(find_clusters(clump.data(), 3040, 0, none, 15).count, 1);
    // A cluster needs min_points too.
    assert_int_equal(find_clusters(both.data(), 3500, 0, none, 600).count, 1);
    // Every cloud of tests/data is one object: one cluster, so its reconstruction takes the
    // single-surface path, unchanged.
    const char *root = std::getenv("GMPU_TEST_DATA");
    assert_non_null(root);
    size_t clouds = 0;
    for (const auto &entry : std::filesystem::directory_iterator(std::string(root) + "/clouds")) {
        const std::string path = entry.path().string();
        if (entry.path().extension() != ".ply" || path.find("_gt.ply") != std::string::npos) continue;
        const gmpu::io::PointCloud cloud = gmpu::io::read_points(path);
        const OutlierScan scan = find_outliers(cloud.positions.data(), cloud.size(), 0);
        if (find_clusters(cloud.positions.data(), cloud.size(), 0, scan.outliers, 15).count != 1)
            fail_msg("%s: more than one cluster", path.c_str());
        ++clouds;
    }
    assert_true(clouds >= 10);
}

void point_set_validation(void **) {
    std::vector<double> xyz = flat(sphere_points(100, 1, 0, 1));
    std::string msg;
    xyz[3 * 42 + 1] = NAN;
    assert_int_equal(status_of([&] { PointSet::from_array(xyz.data(), 100, 0, 15); }, &msg), GMPU_ERROR_INVALID_INPUT);
    assert_non_null(strstr(msg.c_str(), "point 42"));
    xyz = flat(sphere_points(100, 1, 0, 1));
    assert_int_equal(status_of([&] { PointSet::from_array(xyz.data(), 10, 0, 15); }), GMPU_ERROR_INVALID_INPUT);

    std::vector<double> line, plane, same(300, 2.5);
    for (int i = 0; i < 100; ++i) {
        line.insert(line.end(), {double(i), 2.0 * i, -1.0 * i});
        plane.insert(plane.end(), {double(i % 10), double(i / 10), 3.0});
    }
    assert_int_equal(status_of([&] { PointSet::from_array(line.data(), 100, 0, 15); }, &msg), GMPU_ERROR_DEGENERATE_INPUT);
    assert_non_null(strstr(msg.c_str(), "collinear"));
    assert_int_equal(status_of([&] { PointSet::from_array(plane.data(), 100, 0, 15); }, &msg), GMPU_ERROR_DEGENERATE_INPUT);
    assert_non_null(strstr(msg.c_str(), "coplanar"));
    assert_int_equal(status_of([&] { PointSet::from_array(same.data(), 100, 0, 15); }, &msg), GMPU_ERROR_DEGENERATE_INPUT);
    assert_non_null(strstr(msg.c_str(), "identical"));
}

void point_set_normalises_and_searches(void **) {
    // A strided float array; the box's longest side becomes 1 and its centre the origin.
    std::vector<float> data;
    PointList pts = sphere_points(2000, 3.0, 0, 2);
    for (const auto &p : pts) data.insert(data.end(), {float(p[0] + 10), float(p[1]), float(p[2]), 99.0f});
    PointSet ps = PointSet::from_array(data.data(), 2000, 4 * sizeof(float), 15);
    assert_near((ps.box_max() - ps.box_min()).maxCoeff(), 1.0, 1e-9);
    assert_near(ps.normalisation().to_world(ps.point(7))[0], data[4 * 7], 1e-5);
    // Bounded nearest: nothing beyond the radius, and the same answer as unbounded within it.
    std::vector<uint32_t> a, b;
    std::vector<float> da, db;
    ps.nearest(Vector3d(3, 0, 0), 4, a, da, 0.1);
    assert_int_equal(a.size(), 0);
    ps.nearest(ps.point(5), 4, a, da, 0.2);
    ps.nearest(ps.point(5), 4, b, db);
    assert_true(a == b);
}

// ---- the MPU blend ---------------------------------------------------------------------

void blend_finds_every_covering_leaf(void **) {
    // A sparse, noisy sphere: many cells grow their support past their parent's ball. The
    // walk and the gathered lists must still find every leaf whose ball holds x (checked
    // against all leaves), and both paths must give bit-identical values — the polygonizer's
    // watertightness rests on it.
    std::vector<double> xyz = flat(sphere_points(3000, 1.0, 0.02, 23));
    PointSet ps = PointSet::from_array(xyz.data(), 3000, 0, 15);
    Params params;
    Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    Workers workers(2);
    Octree tree = build_octree(ps, params, 0.001, workers, progress);
    size_t grown = 0;
    for (const Cell &c : tree.cells)
        if (c.parent >= 0 && (c.centre - tree.cells[size_t(c.parent)].centre).norm() + c.radius >
                                 tree.cells[size_t(c.parent)].radius)
            ++grown;
    assert_true(grown > 0);  // the case this test is about
    const CellSigns as_fitted;
    MpuFunction f(tree, as_fitted, 0);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-0.6, 0.6);
    std::vector<uint32_t> near;
    for (int q = 0; q < 2000; ++q) {
        Vector3d x = draw_vector(u, rng);
        std::vector<uint32_t> covering;
        for (uint32_t i = 0; i < tree.cells.size(); ++i) {
            const Cell &c = tree.cells[i];
            if (c.is_leaf() && (x - c.centre).squaredNorm() < c.radius * c.radius) covering.push_back(i);
        }
        f.gather(Eigen::AlignedBox3d(x - Vector3d::Constant(0.01), x + Vector3d::Constant(0.01)), near);
        for (uint32_t i : covering) assert_true(std::binary_search(near.begin(), near.end(), i));
        Vector3d g1, g2;
        const double a = f.value(x, &g1), b = f.value_among(near, x, &g2);
        assert_true(a == b && g1 == g2);
    }
}

// ---- the winding number ----------------------------------------------------------------

void winding_number_of_a_sampled_sphere(void **) {
    // A Fibonacci sphere (near-uniform) with its radial outward normals, each point standing
    // for an equal share of the area: about 1 inside, 0 outside, and 1/2 on the surface
    // (at a sample, whose own term is left out, the rest of the sphere sees half the solid
    // angle). The octree makes far cells one dipole each; near the sphere and at the centre
    // the answer must still be right. A 0.05 % radial jitter keeps one quadric from fitting
    // the whole sphere, so the octree is deep.
    const size_t n = 20000;
    std::vector<double> xyz;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (size_t i = 0; i < n; ++i) {
        double z = 1.0 - 2.0 * (double(i) + 0.5) / double(n), s = std::sqrt(1.0 - z * z);
        const double jitter = 1.0 + 0.0005 * std::sin(1.7 * double(i));
        xyz.insert(xyz.end(), {jitter * s * std::cos(golden * double(i)), jitter * s * std::sin(golden * double(i)),
                               jitter * z});
    }
    PointSet ps = PointSet::from_array(xyz.data(), n, 0, 15);
    const double r = ps.normalisation().scale;  // the unit sphere in the normalised frame
    std::vector<float> normals(3 * n), area(n, float(4.0 * M_PI * r * r / double(n)));
    for (size_t i = 0; i < n; ++i) {
        Vector3d u = ps.point(i).normalized();
        for (int d = 0; d < 3; ++d) normals[3 * i + d] = float(u[d]);
    }
    Params params;
    Progress progress(nullptr, nullptr, GMPU_STAGE_ORIENT);
    Workers workers(2);
    Octree tree = build_octree(ps, params, 1e-5, workers, progress);  // below the jitter: a deep octree
    assert_true(tree.cells.size() > 100);
    WindingField w(tree, ps, normals, area, &progress);
    std::mt19937_64 rng(3);
    std::normal_distribution<double> g(0, 1);
    // Summed exactly (every cell opened: a huge far ratio), then with the default far
    // ratio, whose dipoles are a few percent off: enough to tell 0 from 1.
    assert_near(w.winding(Vector3d::Zero(), 1e6), 1.0, 0.005);
    assert_near(w.winding(Vector3d(0, 0, 2 * r), 1e6), 0.0, 0.005);
    for (int q = 0; q < 200; ++q) {
        Vector3d dir = draw_vector(g, rng).normalized();
        assert_near(w.winding(0.0 * dir), 1.0, 0.05);
        assert_near(w.winding(0.5 * r * dir), 1.0, 0.05);
        assert_near(w.winding(0.9 * r * dir), 1.0, 0.05);
        assert_near(w.winding(1.1 * r * dir), 0.0, 0.05);
        assert_near(w.winding(3.0 * r * dir), 0.0, 0.01);
        assert_near(w.winding(ps.point(size_t(q) * 97)), 0.5, 0.05);
    }
    // Normals turned inward: the solid is the outside, so −1 inside.
    for (float &c : normals) c = -c;
    WindingField inverted(tree, ps, normals, area, &progress);
    assert_near(inverted.winding(Vector3d::Zero(), 1e6), -1.0, 0.005);
    assert_true(WindingField().winding(Vector3d::Zero()) == 0.0);  // empty: no opinion
}

// Each cell's radius is found by a search that skips children whose ball cannot hold a
// farther point: it must equal the largest distance of the cell's points from their
// area-weighted centroid, counted point by point (areas uneven, some zero).
void winding_radii_hold_their_points(void **) {
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g(0, 1);
    const size_t n = 6000;
    std::vector<double> xyz;
    for (size_t i = 0; i < n; ++i) {
        const Vector3d u = draw_vector(g, rng).normalized();
        const Vector3d p(1.5 * u[0], u[1], 0.6 * u[2]);  // an ellipsoid: cells of many shapes
        xyz.insert(xyz.end(), {p[0], p[1], p[2]});
    }
    PointSet ps = PointSet::from_array(xyz.data(), n, 0, 15);
    std::vector<float> normals(3 * n, 0.0f), area(n);
    for (size_t i = 0; i < n; ++i) {
        normals[3 * i + 2] = 1.0f;
        area[i] = i % 7 == 0 ? 0.0f : float(1e-4 * (1 + i % 5));
    }
    Params params;
    Progress progress(nullptr, nullptr, GMPU_STAGE_ORIENT);
    Workers workers(2);
    const Octree tree = build_octree(ps, params, 1e-4, workers, progress);
    assert_true(tree.cells.size() > 100);
    const WindingField w(tree, ps, normals, area, &progress);
    for (uint32_t c = 0; c < tree.cells.size(); ++c) {
        const Cell &cell = tree.cells[c];
        Vector3d centroid = Vector3d::Zero();
        double total = 0.0;
        for (uint32_t k = cell.point_begin; k < cell.point_end; ++k) {
            centroid += double(area[tree.order[k]]) * ps.point(tree.order[k]);
            total += double(area[tree.order[k]]);
        }
        double radius = 0.0;
        if (total > 0.0) {
            centroid /= total;
            for (uint32_t k = cell.point_begin; k < cell.point_end; ++k)
                radius = std::max(radius, (ps.point(tree.order[k]) - centroid).norm());
        }
        assert_near(w.radius(c), radius, 1e-9);
    }
}

// ---- belief propagation ---------------------------------------------------------------

void bp_follows_clamped_evidence(void **) {
    // A chain 0 – 1 – 2 – 3 with node 0 clamped to −1; edges agree (+4), disagree (−4),
    // agree (+2): labels −1, −1, +1, +1.
    BpGraph g;
    g.clamp = {-1, 0, 0, 0};
    g.edges = {{0, 1, 4}, {1, 2, -4}, {2, 3, 2}};
    BpResult r = solve_bp(g, 0.01, 20);
    assert_true(r.label == std::vector<int8_t>({-1, -1, 1, 1}));
    // A loop with one inconsistent edge: the weaker edge gives way.
    g.clamp = {1, 0, 0};
    g.edges = {{0, 1, 4}, {1, 2, 4}, {2, 0, -2}};
    r = solve_bp(g, 0.01, 30);
    assert_true(r.label[1] == 1 && r.label[2] == 1);
}

void bp_data_term_breaks_ties_only(void **) {
    // No evidence at all: the data term keeps the fitted sign (+1); a single agreement of
    // 2 outweighs it.
    BpGraph g;
    g.clamp = {0};
    assert_int_equal(solve_bp(g, 0.01, 5).label[0], 1);
    g.clamp = {-1, 0};
    g.edges = {{0, 1, 2}};
    assert_int_equal(solve_bp(g, 0.01, 5).label[1], -1);
}

// ---- marching cubes ---------------------------------------------------------------------

// Marches an n³-corner field with marching cubes, welding vertices by grid edge; returns
// the triangles (vertex ids) and the vertices' positions (linear interpolation).
std::vector<uint32_t> march_cubes(const std::vector<double> &v, int n, std::vector<Eigen::Vector3d> *positions = nullptr) {
    auto id = [&](int i, int j, int k) { return i + n * (j + n * k); };
    std::map<uint64_t, uint32_t> vertex;
    std::vector<uint32_t> tris;
    std::mt19937 coin{7};  // quads split either way: the surface closes whatever the choice
    mc::march_block(
        n - 1, [&](int i, int j, int k) { return v[size_t(id(i, j, k))]; },
        [&](int i, int j, int k, const mc::Edge &e) {
            const Eigen::Vector3i a(i + (e.from & 1), j + (e.from >> 1 & 1), k + (e.from >> 2 & 1));
            const Eigen::Vector3i b(i + (e.to & 1), j + (e.to >> 1 & 1), k + (e.to >> 2 & 1));
            const uint64_t key = uint64_t(id(a[0], a[1], a[2])) * 8 + uint64_t(mc::edge_direction(e));
            auto [it, added] = vertex.emplace(key, uint32_t(vertex.size()));
            if (added && positions) {
                const double va = v[size_t(id(a[0], a[1], a[2]))], vb = v[size_t(id(b[0], b[1], b[2]))];
                positions->push_back(a.cast<double>() + va / (va - vb) * (b - a).cast<double>());
            }
            tris.push_back(it->second);
        },
        [&](int, int, int, const mc::Edge *) { return coin() & 1; });
    return tris;
}

// Closed (every edge has its twin), edge-manifold and consistently wound (no directed edge
// twice), every vertex's triangles one fan (no two cones touching at a vertex).
void assert_closed_manifold(const std::vector<uint32_t> &tris) {
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (size_t t = 0; t < tris.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            assert_true(tris[t + size_t(e)] != tris[t + size_t((e + 1) % 3)]);
            ++directed[{tris[t + size_t(e)], tris[t + size_t((e + 1) % 3)]}];
        }
    std::map<uint32_t, std::map<uint32_t, uint32_t>> next_around;  // vertex → (a → b) per triangle
    for (size_t t = 0; t < tris.size(); t += 3)
        for (int e = 0; e < 3; ++e) next_around[tris[t + size_t(e)]][tris[t + size_t((e + 1) % 3)]] = tris[t + size_t((e + 2) % 3)];
    for (const auto &[edge, count] : directed) {
        assert_int_equal(count, 1);
        assert_true(directed.count({edge.second, edge.first}) == 1);
    }
    for (const auto &[v, ring] : next_around) {  // walking the fan once visits every triangle
        size_t steps = 0;
        uint32_t at = ring.begin()->first;
        do at = ring.at(at), ++steps;
        while (at != ring.begin()->first && steps <= ring.size());
        assert_int_equal(steps, ring.size());
    }
}

void cube_cases_cut_sign_changes_outward(void **) {
    // Every vertex lies on an edge joining an inside and an outside corner; a lone inside
    // corner gets one triangle facing away from it.
    for (int mask = 0; mask < 256; ++mask) {
        const mc::CubeCase &c = mc::cube_case(mask);
        const int inside = __builtin_popcount(unsigned(mask));
        if (inside == 0 || inside == 8) assert_int_equal(c.triangle_count + c.quad_count, 0);
        else assert_true(c.triangle_count + c.quad_count > 0);
        for (int t = 0; t < c.triangle_count; ++t)
            for (const mc::Edge &e : c.triangles[t]) assert_true(((mask >> e.from) & 1) != ((mask >> e.to) & 1));
        for (int q = 0; q < c.quad_count; ++q)
            for (int v = 0; v < 4; ++v) assert_true(((mask >> c.quads[q][v].from) & 1) != ((mask >> c.quads[q][v].to) & 1));
    }
    for (int corner = 0; corner < 8; ++corner) {
        const mc::CubeCase &c = mc::cube_case(1 << corner);
        assert_int_equal(c.triangle_count, 1);
        auto mid = [](const mc::Edge &e) -> Eigen::Vector3d {
            return 0.5 * Eigen::Vector3d((e.from & 1) + (e.to & 1), (e.from >> 1 & 1) + (e.to >> 1 & 1),
                                         (e.from >> 2 & 1) + (e.to >> 2 & 1));
        };
        const Eigen::Vector3d a = mid(c.triangles[0][0]), b = mid(c.triangles[0][1]), d = mid(c.triangles[0][2]);
        const Eigen::Vector3d at(corner & 1, corner >> 1 & 1, corner >> 2 & 1);
        assert_true((b - a).cross(d - a).dot(a - at) > 0);
    }
}

void marching_cubes_closes_any_sign_field(void **) {
    // Random values and near-saddles (a checkerboard of signs, so nearly every face is
    // ambiguous) on 9³ grids with a negative border: closed, edge-manifold, one fan per
    // vertex, outward (positive enclosed volume).
    const int n = 9;
    auto id = [&](int i, int j, int k) { return i + n * (j + n * k); };
    for (int seed = 0; seed < 40; ++seed) {
        std::mt19937_64 rng{uint64_t(seed)};
        std::uniform_real_distribution<double> u(-1, 1);
        std::vector<double> v(n * n * n);
        for (int k = 0; k < n; ++k)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const bool border = i == 0 || j == 0 || k == 0 || i == n - 1 || j == n - 1 || k == n - 1;
                    const double checker = (i + j + k) % 2 ? 1.0 : -1.0;
                    v[size_t(id(i, j, k))] = border ? -1 : seed % 2 ? checker + 0.9 * u(rng) : u(rng);
                }
        std::vector<Eigen::Vector3d> p;
        const std::vector<uint32_t> tris = march_cubes(v, n, &p);
        assert_true(tris.size() > 30);
        assert_closed_manifold(tris);
        double volume = 0.0;
        for (size_t t = 0; t < tris.size(); t += 3) volume += p[tris[t]].dot(p[tris[t + 1]].cross(p[tris[t + 2]])) / 6.0;
        assert_true(volume > 0);
    }
}

void marching_cubes_keep_a_thin_solid_whole(void **) {
    // A solid one corner thick running diagonally (inside corners (i, i, k) only): each
    // column touches the next across faces' diagonals alone. Joining inside corners on such
    // faces makes it one closed piece; keeping them apart would cut it into its 4 columns.
    const int n = 8;
    auto id = [&](int i, int j, int k) { return i + n * (j + n * k); };
    std::vector<double> v(size_t(n) * n * n, -1.0);
    for (int i = 2; i <= 5; ++i)
        for (int k = 2; k <= 5; ++k) v[size_t(id(i, i, k))] = 1.0;
    const std::vector<uint32_t> tris = march_cubes(v, n);
    assert_closed_manifold(tris);
    std::vector<uint32_t> parent(tris.size());
    for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
    std::function<uint32_t(uint32_t)> root = [&](uint32_t a) { return parent[a] == a ? a : parent[a] = root(parent[a]); };
    for (size_t t = 0; t < tris.size(); t += 3)
        for (int e = 1; e < 3; ++e) parent[root(tris[t + size_t(e)])] = root(tris[t]);
    std::set<uint32_t> pieces;
    for (uint32_t vtx : tris) pieces.insert(root(vtx));
    assert_int_equal(pieces.size(), 1);
}

void marching_cubes_sphere_needs_few_triangles(void **) {
    // About 2 triangles per cube the surface crosses: at most 4 per h² of area on a sphere
    // (a split of each cube into tetrahedra makes about 9).
    const int n = 41;
    const double r = 15.3, c = 20.1;
    std::vector<double> v(size_t(n) * n * n);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) v[size_t(i + n * (j + n * k))] = r - Eigen::Vector3d(i - c, j - c, k - c).norm();
    const std::vector<uint32_t> tris = march_cubes(v, n);
    assert_closed_manifold(tris);
    const double per_area = double(tris.size() / 3) / (4 * M_PI * r * r);
    fprintf(stderr, "  sphere: %.2f triangles per cube area\n", per_area);
    assert_true(per_area < 4.0);
}

// ---- mesh clean-up ----------------------------------------------------------------------

void unsupported_components_are_dropped(void **) {
    // Two tetrahedra; only the second is voted for.
    Mesh m;
    for (int s = 0; s < 2; ++s) {
        double o = 5.0 * s;
        m.vertices.insert(m.vertices.end(), {o, 0, 0, o + 1, 0, 0, o, 1, 0, o, 0, 1});
        uint32_t b = uint32_t(4 * s);
        m.triangles.insert(m.triangles.end(), {b, b + 2, b + 1, b, b + 1, b + 3, b, b + 3, b + 2, b + 1, b + 2, b + 3});
    }
    std::vector<uint32_t> comp;
    Progress quiet(nullptr, nullptr, GMPU_STAGE_POLYGONIZE);
    assert_int_equal(vertex_components(m, comp, quiet), 2);
    remove_unsupported_components(m, {0, 0, 0, 0, 1, 2, 0, 0}, 3, quiet);
    assert_int_equal(m.vertex_count(), 4);
    assert_int_equal(m.triangle_count(), 4);
    assert_near(m.vertices[0], 5.0, 0);
    for (uint32_t t : m.triangles) assert_true(t < 4);
}

void pieces_smaller_than_a_side_are_dropped(void **) {
    // Tetrahedra of sides 3, 0.5 and 1.5: with a minimum side of 1 the small one goes.
    auto add_tetrahedron = [](Mesh &m, double x, double side) {
        const uint32_t b = uint32_t(m.vertex_count());
        m.vertices.insert(m.vertices.end(), {x, 0, 0, x + side, 0, 0, x, side, 0, x, 0, side});
        m.triangles.insert(m.triangles.end(), {b, b + 2, b + 1, b, b + 1, b + 3, b, b + 3, b + 2, b + 1, b + 2, b + 3});
    };
    Mesh m;
    add_tetrahedron(m, 0, 3);
    add_tetrahedron(m, 10, 0.5);
    add_tetrahedron(m, 20, 1.5);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_POLYGONIZE);
    remove_components_smaller_than(m, 1.0, quiet);
    assert_int_equal(m.vertex_count(), 8);
    assert_int_equal(m.triangle_count(), 8);
    assert_near(m.vertices[12], 20.0, 0);
    for (uint32_t t : m.triangles) assert_true(t < 8);
    // Every piece under the side: the largest (most vertices) stays, the mesh is never emptied.
    Mesh tiny;
    add_tetrahedron(tiny, 0, 0.2);
    add_tetrahedron(tiny, 5, 0.1);
    tiny.vertices.insert(tiny.vertices.end(), {5.05, 0.05, 0.05});  // an extra vertex in the second
    tiny.triangles.insert(tiny.triangles.end(), {4, 5, 8});
    remove_components_smaller_than(tiny, 1.0, quiet);
    assert_int_equal(tiny.vertex_count(), 5);
    assert_near(tiny.vertices[0], 5.0, 0);
}

// ---- conjugate gradients ------------------------------------------------------------------

// A 1-D Laplacian with a screening term, tridiagonal and symmetric positive definite, larger
// than one block of the sums: the solution satisfies the system, the same bits come out on
// 1 and 3 threads, and the iteration cap and the cancel are kept.
void conjugate_gradients_solve_and_keep_their_bits(void **) {
    const Eigen::Index n = 20000;
    auto apply = [&](const Eigen::VectorXd &v, Eigen::VectorXd &out) {
        for (Eigen::Index i = 0; i < n; ++i)
            out[i] = 2.1 * v[i] - (i > 0 ? v[i - 1] : 0.0) - (i + 1 < n ? v[i + 1] : 0.0);
    };
    Eigen::VectorXd rhs(n), diagonal = Eigen::VectorXd::Constant(n, 2.1);
    for (Eigen::Index i = 0; i < n; ++i) rhs[i] = std::sin(0.01 * double(i)) + (i % 7 == 0 ? 1.0 : 0.0);
    auto solve = [&](unsigned threads, int iterations, Progress &progress, int &taken) {
        Workers workers(threads);
        Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
        taken = conjugate_gradients(apply, rhs, diagonal, x, 1e-10, iterations, workers, progress, 0.5);
        return x;
    };
    Progress progress(nullptr, nullptr, GMPU_STAGE_ORIENT);
    int taken_one = 0, taken_three = 0, capped = 0;
    const Eigen::VectorXd one = solve(1, 1000, progress, taken_one), three = solve(3, 1000, progress, taken_three);
    Eigen::VectorXd residual(n);
    apply(one, residual);
    residual -= rhs;
    print_message("conjugate gradients: %d iterations, residual %.3g of the right-hand side\n", taken_one,
                  residual.norm() / rhs.norm());
    assert_true(residual.norm() <= 1e-9 * rhs.norm());
    assert_true(taken_one > 5 && taken_one < 1000);
    assert_int_equal(taken_one, taken_three);
    assert_memory_equal(one.data(), three.data(), size_t(n) * sizeof(double));
    solve(2, 3, progress, capped);
    assert_int_equal(capped, 3);
    Progress cancelled(nullptr, nullptr, GMPU_STAGE_ORIENT);
    cancelled.cancel();
    int never = 0;
    assert_int_equal(status_of([&] { solve(2, 1000, cancelled, never); }), GMPU_ERROR_CANCELLED);
}

// ---- parallel loop ------------------------------------------------------------------------

void parallel_for_runs_each_index_once(void **) {
    Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    std::vector<std::atomic<int>> hits(10007);
    Workers workers(4);
    parallel_for(0, hits.size(), workers, progress, [&](size_t i) { hits[i]++; });
    // The same pool again: its threads are reused, every index still runs once.
    parallel_for(0, hits.size(), workers, progress, [&](size_t i) { hits[i]++; });
    for (auto &h : hits) assert_int_equal(h.load(), 2);
}

void parallel_for_rethrows_and_cancels(void **) {
    Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    std::atomic<size_t> ran{0};
    gmpu_status s = status_of([&] {
        Workers workers(2);
        parallel_for(0, 100000, workers, progress, [&](size_t i) {
            ++ran;
            if (i == 50) throw Error(GMPU_ERROR_INTERNAL, "boom");
            // Every other index takes a little while: bodies that cost nothing let the other
            // thread run out the range while the throwing one unwinds (slow under the
            // sanitizers) or waits for a core on a busy machine, and it would not stop early.
            std::this_thread::sleep_for(std::chrono::microseconds(20));
        }, 1);
    });
    assert_int_equal(s, GMPU_ERROR_INTERNAL);
    assert_true(ran.load() < 100000);  // the others stopped early
    // A callback returning non-zero cancels: the loop stops and the stage throws CANCELLED.
    int calls = 0;
    Progress cancelling([](void *user, gmpu_stage, double) -> int { return ++*static_cast<int *>(user) >= 1; }, &calls,
                        GMPU_STAGE_ORIENT);
    cancelling.report(0.1, true);
    assert_true(cancelling.cancelled());
    assert_int_equal(status_of([&] { cancelling.throw_if_cancelled(); }), GMPU_ERROR_CANCELLED);
}

void only_the_final_report_says_done(void **) {
    // A step ending on the stage's last slice reports its own end (not forced, with no
    // report in the throttle interval before it); the stage's final report follows.
    // Callers see fraction 1 once.
    int done = 0;
    Progress progress([](void *user, gmpu_stage, double f) -> int { *static_cast<int *>(user) += f >= 1.0; return 0; },
                      &done, GMPU_STAGE_POLYGONIZE);
    Progress last_step = progress.slice(0.95, 1.0);
    last_step.report(1.0);  // the stage's first report: no throttle holds it back
    progress.report(1.0, true);
    assert_int_equal(done, 1);
}

void workers_are_reused_across_loops(void **) {
    // Every thread that runs a body gets a token the first time (thread_local: a new thread
    // starts without one). Helpers kept by the pool show the same tokens in the second loop;
    // threads started per loop would bring new ones.
    Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    Workers workers(3);
    static std::atomic<int> tokens{0};
    static thread_local int token = 0;
    const auto caller = std::this_thread::get_id();
    std::mutex m;
    std::set<int> helper_tokens;
    for (int loop = 0; loop < 2; ++loop)
        parallel_for(0, 64, workers, progress, [&](size_t) {
            if (token == 0) token = ++tokens;
            if (std::this_thread::get_id() != caller) {
                std::lock_guard<std::mutex> lock(m);
                helper_tokens.insert(token);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(2));  // time for the helpers to join in
        }, 1);
    assert_true(!helper_tokens.empty());
    assert_true(helper_tokens.size() <= workers.threads() - 1);
}

void workers_take_none_of_the_hosts_signals(void **) {
    // The caller's mask is left as it was; every helper blocks SIGINT and SIGTERM, so a
    // host's handler never runs on a pool thread while the host's own thread writes on.
    Progress progress(nullptr, nullptr, GMPU_STAGE_FIT);
    sigset_t before;
    pthread_sigmask(SIG_SETMASK, nullptr, &before);
    Workers workers(3);
    sigset_t after;
    pthread_sigmask(SIG_SETMASK, nullptr, &after);
    assert_int_equal(sigismember(&after, SIGINT), sigismember(&before, SIGINT));
    assert_int_equal(sigismember(&after, SIGTERM), sigismember(&before, SIGTERM));
    const auto caller = std::this_thread::get_id();
    std::atomic<int> helpers_seen{0}, helpers_open{0};
    parallel_for(0, 64, workers, progress, [&](size_t) {
        if (std::this_thread::get_id() != caller) {
            sigset_t mask;
            pthread_sigmask(SIG_SETMASK, nullptr, &mask);
            ++helpers_seen;
            if (!sigismember(&mask, SIGINT) || !sigismember(&mask, SIGTERM)) ++helpers_open;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(2));  // time for the helpers to join in
    }, 1);
    assert_true(helpers_seen > 0);
    assert_int_equal(helpers_open.load(), 0);
}

void progress_slices_map_onto_the_stage(void **) {
    std::vector<double> seen;
    Progress progress([](void *user, gmpu_stage, double f) -> int {
        static_cast<std::vector<double> *>(user)->push_back(f);
        return 0;
    }, &seen, GMPU_STAGE_ORIENT);
    Progress step = progress.slice(0.2, 0.6);
    Progress inner = step.slice(0.5, 1.0);  // 0.4 .. 0.6 of the stage
    step.report(0.5, true);
    inner.report(0.5, true);
    inner.report(1.0, true);
    progress.report(0.1, true);  // never backwards
    assert_int_equal(seen.size(), 4);
    assert_true(std::fabs(seen[0] - 0.4) < 1e-12);
    assert_true(std::fabs(seen[1] - 0.5) < 1e-12);
    assert_true(std::fabs(seen[2] - 0.6) < 1e-12);
    assert_true(std::fabs(seen[3] - 0.6) < 1e-12);
    // One cancel flag for the stage and all its slices.
    inner.cancel();
    assert_true(progress.cancelled());
}

void cancellable_sort_sorts_and_cancels(void **) {
    // Not a multiple of the 32k slice, with duplicates: the last partial slice and merges of
    // unequal runs are exercised.
    std::mt19937_64 rng(3);
    std::vector<std::pair<uint64_t, uint32_t>> v(100003), expected;
    for (size_t i = 0; i < v.size(); ++i) v[i] = {rng() % 5000, uint32_t(i)};
    expected = v;
    std::sort(expected.begin(), expected.end());
    Progress quiet(nullptr, nullptr, GMPU_STAGE_POLYGONIZE);
    cancellable_sort(v, quiet, 0.5);
    assert_true(v == expected);
    // A callback that cancels: the sort stops with CANCELLED at its first poll.
    int calls = 0;
    Progress cancelling([](void *user, gmpu_stage, double) -> int { return ++*static_cast<int *>(user) >= 1; }, &calls,
                        GMPU_STAGE_POLYGONIZE);
    std::vector<int> w(70000, 1);
    assert_int_equal(status_of([&] { cancellable_sort(w, cancelling, 0.5); }), GMPU_ERROR_CANCELLED);
    assert_int_equal(calls, 1);
}

void assign_reporting_fills_and_cancels(void **) {
    // Several megabyte slices and a partial last one, over a vector that held other values.
    std::vector<uint32_t> v(10, 7);
    Progress quiet(nullptr, nullptr, GMPU_STAGE_POLYGONIZE);
    assign_reporting(v, 1000003, quiet, 42u);
    assert_int_equal(v.size(), 1000003);
    assert_true(std::all_of(v.begin(), v.end(), [](uint32_t x) { return x == 42u; }));
    int calls = 0;
    Progress cancelling([](void *user, gmpu_stage, double) -> int { return ++*static_cast<int *>(user) >= 1; }, &calls,
                        GMPU_STAGE_POLYGONIZE);
    cancelling.report(0.1, true);
    std::vector<double> w;
    assert_int_equal(status_of([&] { assign_reporting(w, 1u << 22, cancelling); }), GMPU_ERROR_CANCELLED);
    assert_true(w.size() < size_t(1) << 22);
}

// The tests' random clouds (support/random_vectors.hpp): a "distribution" that counts its
// calls shows the order of the draws, which must be the same on every compiler.
void random_vectors_draw_z_first(void **) {
    int calls = 0;
    auto counting = [&calls](int &) { return double(++calls); };
    int rng = 0;
    assert_true(draw_vector(counting, rng) == Vector3d(3, 2, 1));
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(quadric_algebra),
        cmocka_unit_test(bivariate_fit_is_exact_on_a_paraboloid),
        cmocka_unit_test(general_quadric_fits_a_sphere),
        cmocka_unit_test(pca_surface_variation),
        cmocka_unit_test(robust_taubin_error),
        cmocka_unit_test(noise_estimate_tracks_the_noise),
        cmocka_unit_test(noise_estimate_ignores_a_second_sheet),
        cmocka_unit_test(noise_estimate_ignores_sparse_detail),
        cmocka_unit_test(noise_estimate_sees_through_a_noisy_wall),
        cmocka_unit_test(two_noisy_sheets_in_one_support),
        cmocka_unit_test(two_noisy_sheets_without_cloud_evidence),
        cmocka_unit_test(two_sheets_that_end_ask_for_a_split),
        cmocka_unit_test(point_set_validation),
        cmocka_unit_test(outliers_are_far_from_everything),
        cmocka_unit_test(clusters_are_groups_far_apart),
        cmocka_unit_test(point_set_normalises_and_searches),
        cmocka_unit_test(blend_finds_every_covering_leaf),
        cmocka_unit_test(winding_number_of_a_sampled_sphere),
        cmocka_unit_test(winding_radii_hold_their_points),
        cmocka_unit_test(bp_follows_clamped_evidence),
        cmocka_unit_test(bp_data_term_breaks_ties_only),
        cmocka_unit_test(cube_cases_cut_sign_changes_outward),
        cmocka_unit_test(marching_cubes_closes_any_sign_field),
        cmocka_unit_test(marching_cubes_keep_a_thin_solid_whole),
        cmocka_unit_test(marching_cubes_sphere_needs_few_triangles),
        cmocka_unit_test(unsupported_components_are_dropped),
        cmocka_unit_test(pieces_smaller_than_a_side_are_dropped),
        cmocka_unit_test(conjugate_gradients_solve_and_keep_their_bits),
        cmocka_unit_test(parallel_for_runs_each_index_once),
        cmocka_unit_test(parallel_for_rethrows_and_cancels),
        cmocka_unit_test(only_the_final_report_says_done),
        cmocka_unit_test(workers_are_reused_across_loops),
        cmocka_unit_test(workers_take_none_of_the_hosts_signals),
        cmocka_unit_test(progress_slices_map_onto_the_stage),
        cmocka_unit_test(cancellable_sort_sorts_and_cancels),
        cmocka_unit_test(assign_reporting_fills_and_cancels),
        cmocka_unit_test(random_vectors_draw_z_first),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
