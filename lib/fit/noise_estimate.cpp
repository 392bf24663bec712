#include "fit/noise_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>

#include "core/two_groups.hpp"
#include "fit/fits.hpp"

namespace gmpu {

namespace {

constexpr size_t kCentres = 1024;
constexpr size_t kMinCentres = 256;
// The two neighbourhood sizes compared (nearest in the tangent plane). Twice the points is
// twice the area, so a residual that comes from the shape grows at least √2-fold (a crease:
// linearly in the radius; smooth curvature: with its cube) while noise stays the same.
constexpr size_t kNear = 12;
constexpr size_t kFar = 24;
// The ball the frame and the tangent-plane neighbours are taken from. Neighbours chosen by
// 3D distance from a noisy centre are biased towards points close to it in height (the
// residual then under-reads the noise); chosen by tangential distance from a ball several σ
// high, they are not.
constexpr size_t kBall = 36;
constexpr size_t kMaxBall = 1024;
constexpr double kBallPerNoise = 5.0;  // ball radius wanted, in estimated σ
// A neighbourhood's residuals split into two groups this many (pooled) standard deviations
// apart are two sheets (a thin wall), not noise: a Gaussian sample of 24 splits by less.
constexpr double kSheetSeparation = 5.5;
constexpr size_t kSheetMinSide = 4;
// A split this many pooled deviations apart is a noise-free wall's (noise of a few σ between
// sheets splits, if at all, just past kSheetSeparation): only then is a ball whose centre's
// sheet came out short taken again twice as large. At noise the larger ball lets the other
// sheet's tail in, and the centres that split are few and a biased share of the noise.
constexpr double kCleanSplit = 12.0;
// The residuals are read at this quantile over the centres (z its standard normal score):
// noise is everywhere, while the residual of a shape too sparsely sampled for its detail
// (gear teeth, creases) is where that detail is, so a low quantile reads the noise alone.
constexpr double kQuantile = 0.1;
constexpr double kQuantileZ = -1.2816;
// Two sheets closer than a few σ do not split into two groups, but their residuals are a
// two-peaked mixture, flatter than Gaussian noise: its excess kurtosis is −2a⁴/(σ² + a²)²
// for sheets ±a off the fit. The kurtosis is read on the centres whose residual is at or
// below this quantile (for Gaussian noise the kurtosis of a sample is independent of its
// size, so the choice does not bias it; on a cloud with walls in some parts only, these are
// the single-sheet centres and nothing is corrected) and compared with that of Gaussian
// residuals drawn on the same neighbourhoods. A deficit within kFlatnessSignificance
// standard errors of zero (measured from the centres' own spread: a tall ball is measured
// at fewer centres) is sampling, or a surface's shape, not a second sheet.
constexpr double kFlatnessQuantile = 0.25;
constexpr double kFlatnessSignificance = 3.0;

struct Local {
    double u, v, w;  // tangential coordinates and height in the ball's PCA frame
    double t2;       // squared tangential distance
};

double quantile(std::vector<double> &v, double q) {
    if (v.empty()) return 0.0;
    const size_t i = size_t(q * double(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + long(i), v.end());
    return v[i];
}

// The kQuantile-quantile of √(χ²_ν / ν) (Wilson–Hilferty): what that quantile of unbiased
// RMS residuals with ν degrees of freedom reads for unit noise.
double chi_quantile(double dof) {
    const double a = 2.0 / (9.0 * dof);
    return std::pow(std::max(0.0, 1.0 - a + kQuantileZ * std::sqrt(a)), 1.5);
}

// Least-squares height w = a u² + b uv + c v² + d u + e v + f (or only its affine part when
// `terms` is 3) over fit; returns the residuals of all of pts. `scale` balances the normal
// equations.
void fit_height(const std::vector<Local> &fit, int terms, double scale, const std::vector<Local> &pts,
                std::vector<double> &residuals) {
    const double inv = 1.0 / scale;
    using Vec = Eigen::Matrix<double, 6, 1>;
    auto row = [&](const Local &p) {
        double u = p.u * inv, v = p.v * inv;
        Vec r;
        if (terms == 6) r << u * u, u * v, v * v, u, v, 1.0;
        else r << 0.0, 0.0, 0.0, u, v, 1.0;
        return r;
    };
    Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Zero();
    Vec rhs = Vec::Zero();
    for (const Local &p : fit) {
        Vec r = row(p);
        m.noalias() += r * r.transpose();
        rhs += r * p.w;
    }
    m.diagonal().array() += 1e-9 * (1.0 + m.trace() / 6.0);
    Vec k = m.ldlt().solve(rhs);
    if (!k.allFinite()) k.setZero();
    residuals.resize(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) residuals[i] = pts[i].w - row(pts[i]).dot(k);
}

// Sample kurtosis m4 / m2² of residuals[0, count).
double kurtosis(const std::vector<double> &residuals, size_t count) {
    double m2 = 0.0, m4 = 0.0;
    for (size_t i = 0; i < count; ++i) {
        const double r2 = residuals[i] * residuals[i];
        m2 += r2, m4 += r2 * r2;
    }
    return m2 > 0.0 ? double(count) * m4 / (m2 * m2) : 0.0;
}

// Standard normal draws from a small deterministic generator (the estimate is reproducible
// everywhere), by Box–Muller.
struct Gaussian {
    uint64_t state;
    double uniform() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return (double(state >> 11) + 0.5) * (1.0 / 9007199254740992.0);
    }
    double operator()() { return std::sqrt(-2.0 * std::log(uniform())) * std::cos(6.283185307179586 * uniform()); }
};

double unbiased_rms(const std::vector<double> &residuals, size_t count) {
    double sum = 0.0;
    for (size_t i = 0; i < count; ++i) sum += residuals[i] * residuals[i];
    return std::sqrt(sum / double(count - 6));
}

// The best split of residuals[0, count) into two groups: the threshold between them and
// how many pooled standard deviations apart their means are.
double two_means(const std::vector<double> &residuals, size_t count, double &separation) {
    std::vector<double> s(residuals.begin(), residuals.begin() + long(count));
    std::sort(s.begin(), s.end());
    const TwoGroups t = split_two_groups(s, kSheetMinSide);
    separation = 0.0;
    if (t.low == 0) return 0.0;
    const double pooled = std::sqrt(t.squared_deviations / double(count - 2));
    separation = pooled > 0.0 ? (t.high_mean - t.low_mean) / pooled : INFINITY;
    return t.threshold;
}

// Keeps the points of pts on the centre's sheet (pts[0] is the centre) when the nearest
// kFar hold two. A fit through both sheets lies between them and is tilted by whichever
// holds more points, which blurs the two groups of residuals; refitted to the centre's
// group alone, the other sheet stands a full wall thickness off, while a noisy single sheet
// still reads as one group. Returns the split's separation (0 when nothing was cut).
double keep_centre_sheet(std::vector<Local> &pts, double scale) {
    thread_local std::vector<double> residuals;
    thread_local std::vector<Local> side;
    fit_height(std::vector<Local>(pts.begin(), pts.begin() + long(kFar)), 6, scale, pts, residuals);
    double separation;
    double split = two_means(residuals, kFar, separation);
    side.clear();
    for (size_t k = 0; k < kFar; ++k)
        if ((residuals[k] > split) == (residuals[0] > split)) side.push_back(pts[k]);
    fit_height(side, side.size() >= 12 ? 6 : 3, scale, pts, residuals);
    split = two_means(residuals, kFar, separation);
    if (!(separation > kSheetSeparation)) return 0.0;
    size_t kept = 0;
    const bool above = residuals[0] > split;
    for (size_t k = 0; k < pts.size(); ++k)
        if ((residuals[k] > split) == above) pts[kept++] = pts[k];
    pts.resize(kept);
    return separation;
}

struct Scales {
    double near = 0.0, far = 0.0;  // median unbiased RMS residual at kNear and kFar
    double ball = 0.0;             // median ball radius
    double flatness = 0.0;         // Gaussian residuals' kurtosis less the data's (≥ 0)
};

// Mean kurtosis of the Gaussian residuals less the data's over the centres whose RMS
// residual is at or below kFlatnessQuantile: how much flatter the data's are (0 unless
// significant).
double flatness(const std::vector<double> &far, const std::vector<double> &data, const std::vector<double> &gauss) {
    if (far.size() < 2) return 0.0;
    std::vector<double> sorted = far;
    const double limit = quantile(sorted, kFlatnessQuantile);
    double sum = 0.0, squares = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < far.size(); ++i)
        if (far[i] <= limit) {
            const double deficit = gauss[i] - data[i];
            sum += deficit, squares += deficit * deficit, ++count;
        }
    if (count < 2) return 0.0;
    const double mean = sum / double(count);
    const double error = std::sqrt(std::max(0.0, squares / double(count) - mean * mean) / double(count - 1));
    return mean > kFlatnessSignificance * error ? mean : 0.0;
}

Scales measure(const PointSet &points, size_t ball, size_t centres, Progress &progress) {
    const size_t n = points.size();
    const size_t step = std::max<size_t>(1, n / centres);
    std::vector<double> near, far, radii, residuals, data_kurtosis, gauss_kurtosis;
    Gaussian draw{0x9e3779b97f4a7c15ull};
    std::vector<Local> gauss(kFar);
    std::vector<uint32_t> idx;
    std::vector<float> d2;
    PointList local;
    std::vector<Local> pts;
    for (size_t i = 0; i < n; i += step) {
        progress.tick();
        const Eigen::Vector3d centre = points.point(i);
        double r = 0.0;
        // A ball on a wall holds both sheets, the centre's only about half of it: where that
        // half is short of kFar after a clean split, the ball is taken twice as large once.
        // Skipped instead, a sparse thin-walled cloud would be read only where its sheets do
        // not split (folds, rims) and its shape there taken for noise.
        for (size_t wanted = ball; wanted <= 2 * ball; wanted *= 2) {
            points.nearest(centre, std::min(wanted, n), idx, d2);
            pts.clear();
            if (idx.size() < kFar) break;
            r = std::sqrt(double(d2.back()));
            if (!(r > 0.0)) break;
            local.clear();
            for (uint32_t j : idx) local.push_back(points.point(j) - centre);
            const Pca pca = compute_pca(local);
            const Eigen::Vector3d t1 = pca.axes.col(2), t2 = pca.axes.col(1), nrm = pca.axes.col(0);
            for (const auto &p : local) {
                double u = p.dot(t1), v = p.dot(t2);
                pts.push_back({u, v, p.dot(nrm), u * u + v * v});
            }
            auto by_tangential = [](const Local &a, const Local &b) { return a.t2 < b.t2; };
            std::sort(pts.begin(), pts.end(), by_tangential);
            const double separation = keep_centre_sheet(pts, r);
            if (pts.size() >= kFar || separation < kCleanSplit) break;
        }
        if (pts.size() < kFar) continue;
        fit_height(std::vector<Local>(pts.begin(), pts.begin() + long(kNear)), 6, r, pts, residuals);
        near.push_back(unbiased_rms(residuals, kNear));
        fit_height(std::vector<Local>(pts.begin(), pts.begin() + long(kFar)), 6, r, pts, residuals);
        far.push_back(unbiased_rms(residuals, kFar));
        data_kurtosis.push_back(kurtosis(residuals, kFar));
        for (size_t k = 0; k < kFar; ++k) gauss[k] = {pts[k].u, pts[k].v, draw(), pts[k].t2};
        fit_height(gauss, 6, r, gauss, residuals);
        gauss_kurtosis.push_back(kurtosis(residuals, kFar));
        radii.push_back(r);
    }
    Scales s;
    s.near = quantile(near, kQuantile) / chi_quantile(double(kNear - 6));
    s.far = quantile(far, kQuantile) / chi_quantile(double(kFar - 6));
    s.flatness = flatness(far, data_kurtosis, gauss_kurtosis);
    s.ball = quantile(radii, 0.5);
    return s;
}

// Noise is what the two scales share: σ² = 2 near² − far² cancels a residual that grows
// at least in proportion to the neighbourhood's area (shape, sampling), and leaves noise,
// which is the same at both.
// When the residuals are flatter than Gaussian, a share a²/(σ² + a²) = √(deficit / 2) of
// their variance is a second sheet's offset, and it is taken out. That offset does not grow
// with the neighbourhood (the difference above keeps it), but its share of the points does
// vary between the two neighbourhoods, which the difference would amplify: the larger
// neighbourhood's residual alone is read then.
double noise_of(const Scales &s) {
    const double both = std::max(0.0, 2.0 * s.near * s.near - s.far * s.far);
    if (!(s.flatness > 0.0)) return std::sqrt(both);
    const double sheet = std::min(1.0, std::sqrt(0.5 * s.flatness));
    // Flatter residuals also spread less from centre to centre (the variance of a sample's
    // variance goes with kurtosis − 1, 2 for Gaussian noise), so their low quantile stands
    // closer to the typical value than the χ correction assumed.
    const double dof = double(kFar - 6);
    const double far = s.far * chi_quantile(dof) / chi_quantile(dof * 2.0 / (2.0 - std::min(1.0, s.flatness)));
    return std::sqrt(std::min(both, far * far) * (1.0 - sheet));
}

}  // namespace

NoiseEstimate estimate_noise_model(const PointSet &points, Progress &progress) {
    NoiseEstimate estimate;
    size_t ball = std::min(kBall, points.size());
    if (ball < kFar) return estimate;
    Scales s = measure(points, ball, kCentres, progress);
    double noise = noise_of(s);
    bool sheets = s.flatness > 0.0;
    // Heavy noise: a ball only a few σ high cuts the noise's tails; measure again in a ball
    // tall enough (radius ∝ √points on a surface). Cut tails look flat too, so the ball is
    // sized on the uncorrected reading, and only the tall ball tells a second sheet.
    Scales short_ball = s;
    short_ball.flatness = 0.0;
    const double uncorrected = noise_of(short_ball);
    if (s.ball > 0.0 && uncorrected * kBallPerNoise > s.ball) {
        double want = std::pow(uncorrected * kBallPerNoise / s.ball, 2.0) * double(ball);
        size_t wider = std::min({kMaxBall, points.size(), size_t(want)});
        // Fewer centres keep the cost of the taller balls bounded.
        if (wider > ball) {
            const size_t centres = std::max(kMinCentres, kCentres * ball / wider);
            const Scales tall = measure(points, wider, centres, progress);
            sheets = tall.flatness > 0.0;
            noise = sheets ? noise_of(tall) : std::max(uncorrected, noise_of(tall));
        }
    }
    estimate.sigma = noise;
    estimate.close_sheets = sheets && noise > 0.0;
    return estimate;
}

}  // namespace gmpu
