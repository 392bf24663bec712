// libFuzzer target for the whole pipeline through the C ABI: set_points → fit → orient →
// polygonize → evaluate / copy_normals, on small point sets (n ≤ 200) derived from the
// input bytes: exact duplicates, NaN / inf / subnormal / huge / tiny coordinates,
// collinear, coplanar and spherical layouts, at scales from 1e-30 to 1e30, with random
// parameters (MAX_CELLS, the resolution and the memory budget kept small, so most runs take
// milliseconds; the smooth field's solve, seconds in this build).
//
// A finding is: a crash, a sanitizer report, a status the header does not document for
// that call (GMPU_ERROR_INTERNAL above all), a failure without a message, a mesh that is
// not closed and consistently wound, a non-finite value where finite input went in, or a
// run over its CPU budget (work not bounded by the points, cells and grid it was given).
//
// The budget is the process's CPU time, not the wall clock: the fuzzer often shares its
// machine with other jobs, and a unit that waited for a core did no extra work.
// run.sh gives libFuzzer's wall-clock -timeout a wide margin over it, to catch hangs only.
#include <time.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <algorithm>
#include <vector>

#include "gmpu/gmpu.h"

namespace {

[[noreturn]] void finding(const char *what, gmpu_status st = GMPU_OK) {
    std::fprintf(stderr, "fuzz_pipeline finding: %s (status %s, last error \"%s\")\n", what, gmpu_status_name(st),
                 gmpu_last_error());
    __builtin_trap();
}

// A failing call must name its status in the message and use one of the statuses allowed.
void check_failure(gmpu_status st, std::initializer_list<gmpu_status> allowed, const char *call) {
    if (st == GMPU_OK) return;
    if (std::find(allowed.begin(), allowed.end(), st) == allowed.end()) finding(call, st);
    const char *msg = gmpu_last_error();
    if (std::strncmp(msg, gmpu_status_name(st), std::strlen(gmpu_status_name(st))) != 0 ||
        std::strlen(msg) < std::strlen(gmpu_status_name(st)) + 4)
        finding("failure without a proper message", st);
}

// CPU seconds (every thread of the process) one input may take in the sanitizer build:
// many times what the slowest seed (a full smooth solve) takes there, since inside the
// fuzzing loop (coverage tracing, allocation hooks) an input costs more than run alone,
// and only a runaway input should be a finding. GMPU_FUZZ_CPU_BUDGET overrides it (a
// tighter budget finds the slowest inputs faster).
double cpu_budget_seconds() {
    static const double budget = [] {
        const char *text = std::getenv("GMPU_FUZZ_CPU_BUDGET");
        return text ? std::atof(text) : 120.0;
    }();
    return budget;
}

constexpr double kMaxMemoryBytes = 16e6;

double process_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

class Bytes {
public:
    Bytes(const uint8_t *d, size_t n) : d_(d), n_(n) {}
    uint8_t u8() { return i_ < n_ ? d_[i_++] : 0; }
    uint16_t u16() { return uint16_t(u8() | u8() << 8); }
    double unit() { return u16() / 65535.0; }  // [0, 1]
    double f64() {
        uint64_t bits = 0;
        for (int k = 0; k < 8; ++k) bits |= uint64_t(u8()) << (8 * k);
        double v;
        std::memcpy(&v, &bits, sizeof v);
        return v;
    }
    bool empty() const { return i_ >= n_; }

private:
    const uint8_t *d_;
    size_t n_, i_ = 0;
};

// A coordinate: mostly a scaled small number, sometimes a special value or raw bits.
double coordinate(Bytes &in, double scale) {
    const uint8_t b = in.u8();
    if (b < 224) return scale * ((b - 112) / 37.0 + 0.01 * (in.u8() - 128) / 128.0);
    switch (b) {
        case 224: return std::numeric_limits<double>::quiet_NaN();
        case 225: return std::numeric_limits<double>::infinity();
        case 226: return -std::numeric_limits<double>::infinity();
        case 227: return 0.0;
        case 228: return std::numeric_limits<double>::max();
        case 229: return std::numeric_limits<double>::min();
        case 230: return std::numeric_limits<double>::denorm_min();
        case 231: return 1e300;
        case 232: return -1e300;
        case 233: return 1e-300;
        case 234: return 1e30;
        case 235: return -1e-30;
        case 236: return 3.4e38;  // past float
        default: return in.f64();  // anything at all
    }
}

std::vector<double> make_points(Bytes &in, size_t n, int layout, double scale) {
    std::vector<double> p(3 * n);
    double a[3], b[3], c[3];  // a line or plane: origin a, directions b, c
    for (int k = 0; k < 3; ++k) a[k] = coordinate(in, scale), b[k] = in.unit() - 0.5, c[k] = in.unit() - 0.5;
    for (size_t i = 0; i < n; ++i) {
        double *q = &p[3 * i];
        switch (layout) {
            case 0:  // anything
                for (int k = 0; k < 3; ++k) q[k] = coordinate(in, scale);
                break;
            case 1: {  // a sphere (a real surface: the pipeline runs to the end)
                const double z = 2 * in.unit() - 1, phi = 2 * M_PI * in.unit(), s = std::sqrt(std::max(0.0, 1 - z * z));
                q[0] = a[0] + scale * s * std::cos(phi), q[1] = a[1] + scale * s * std::sin(phi), q[2] = a[2] + scale * z;
                break;
            }
            case 2: {  // collinear
                const double t = scale * (in.unit() - 0.5);
                for (int k = 0; k < 3; ++k) q[k] = a[k] + t * b[k];
                break;
            }
            case 3: {  // coplanar
                const double s = scale * (in.unit() - 0.5), t = scale * (in.unit() - 0.5);
                for (int k = 0; k < 3; ++k) q[k] = a[k] + s * b[k] + t * c[k];
                break;
            }
            case 4: {  // a box's surface, with its sharp edges
                for (int k = 0; k < 3; ++k) q[k] = scale * (in.unit() - 0.5);
                q[in.u8() % 3] = (in.u8() & 1 ? 0.5 : -0.5) * scale;
                for (int k = 0; k < 3; ++k) q[k] += a[k];
                break;
            }
            default:  // two tori-ish rings of clustered duplicates
                for (int k = 0; k < 3; ++k) q[k] = a[k] + scale * std::round(4 * (in.unit() - 0.5));
                break;
        }
        // Exact duplicates of earlier points, and the odd special value, in any layout.
        const uint8_t twist = in.u8();
        if (i > 0 && twist < 40) std::memcpy(q, &p[3 * (twist % i)], 3 * sizeof(double));
        else if (twist == 255) q[in.u8() % 3] = coordinate(in, scale);
    }
    return p;
}

bool finite(const double *v, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(v[i])) return false;
    return true;
}

// Closed, edge-manifold and consistently wound: every directed edge once, its reverse once.
// GMPU_FUZZ_ALLOW_OPEN=1 reports an open mesh on stderr instead of trapping, to look for
// other findings while one is being fixed.
void check_mesh(const gmpu_mesh *m) {
    static const bool allow_open = std::getenv("GMPU_FUZZ_ALLOW_OPEN") != nullptr;
    const size_t nv = gmpu_mesh_vertex_count(m), nt = gmpu_mesh_triangle_count(m);
    const double *v = gmpu_mesh_vertices(m), *nrm = gmpu_mesh_normals(m);
    const uint32_t *t = gmpu_mesh_triangles(m);
    if (nt > 0 && (!v || !t)) finding("a mesh without arrays");
    if (!finite(v, 3 * nv)) finding("a non-finite mesh vertex");
    if (nrm && !finite(nrm, 3 * nv)) finding("a non-finite mesh normal");
    std::vector<uint64_t> edges;
    edges.reserve(3 * nt);
    for (size_t i = 0; i < 3 * nt; ++i) {
        const uint32_t a = t[i], b = t[i - i % 3 + (i + 1) % 3];
        if (a >= nv || b >= nv) finding("a triangle index out of range");
        if (a == b) finding("a triangle with a repeated vertex");
        edges.push_back(uint64_t(a) << 32 | b);
    }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size(); ++i) {
        if (i > 0 && edges[i] == edges[i - 1] && !allow_open)
            finding("a directed edge used twice: not manifold or misoriented");
        const uint64_t rev = (edges[i] & 0xffffffffu) << 32 | edges[i] >> 32;
        if (!std::binary_search(edges.begin(), edges.end(), rev)) {
            if (!allow_open) finding("a boundary edge: the mesh is not closed");
            std::fprintf(stderr, "fuzz_pipeline: an open mesh (allowed by GMPU_FUZZ_ALLOW_OPEN)\n");
            return;
        }
    }
}

void run_pipeline(const uint8_t *data, size_t size) {
    Bytes in(data, size);
    const size_t n = in.u8() % 201;
    const uint8_t flags = in.u8(), knobs = in.u8();
    const int layout = in.u8() % 6;
    const double scale = std::pow(10.0, int(in.u8() % 61) - 30);  // 1e-30 .. 1e30
    std::vector<double> p = make_points(in, n, layout, scale);

    gmpu_surface *s = nullptr;
    if (gmpu_surface_create(&s) != GMPU_OK) finding("create");
    // Small and fast: few cells, a coarse grid, at most two threads, and a memory budget that
    // also bounds the smooth field's solve (orient then fails with LIMIT_EXCEEDED, as
    // documented, where a scattered cloud would ask for a wide band).
    if (gmpu_surface_set_param(s, GMPU_PARAM_MAX_CELLS, 2000 + 50 * (knobs & 63)) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_MAX_MEMORY, kMaxMemoryBytes) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_RESOLUTION, 8 + 8 * (flags & 1)) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_MAX_TRIANGLES, 20000) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_THREADS, 1 + (flags >> 7)) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_MIN_POINTS, 6 + (knobs >> 6) * 4) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_MAX_DEPTH, 1 + (flags >> 2 & 7)) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_SHARP_FEATURES, flags >> 5 & 1) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_ERROR, 0.001 + 0.02 * in.unit()) != GMPU_OK ||
        gmpu_surface_set_param(s, GMPU_PARAM_NOISE_SCALE, (knobs & 1) ? 0.0 : 3.0) != GMPU_OK)
        finding("set_param with a value in range");

    gmpu_status st;
    if (flags & 0x40) {  // as floats: out-of-range doubles become inf, tiny ones 0
        std::vector<float> f(p.begin(), p.end());
        st = gmpu_surface_set_points_f32(s, f.data(), n, 0);
    } else {
        st = gmpu_surface_set_points_f64(s, p.data(), n, 0);
    }
    if (n == 0 && st == GMPU_ERROR_INVALID_ARGUMENT) {
        // An empty vector's data() may be NULL: "xyz is NULL" is the documented answer.
    } else {
        check_failure(st, {GMPU_ERROR_INVALID_INPUT, GMPU_ERROR_DEGENERATE_INPUT}, "set_points");
    }
    if (st == GMPU_OK && gmpu_surface_point_count(s) != n) finding("point count");
    if (st == GMPU_OK) {
        st = gmpu_surface_fit(s);
        check_failure(st, {GMPU_ERROR_LIMIT_EXCEEDED}, "fit");
    }
    if (st == GMPU_OK) {
        // Half the time with normals: the other branch of orient.
        if (knobs & 2) {
            std::vector<double> normals(3 * n);
            for (size_t i = 0; i < 3 * n; ++i) normals[i] = in.unit() - 0.5;
            check_failure(gmpu_surface_set_normals_f64(s, normals.data(), n, 0), {GMPU_ERROR_INVALID_INPUT},
                          "set_normals");
        }
        st = gmpu_surface_orient(s);
        check_failure(st, {GMPU_ERROR_LIMIT_EXCEEDED}, "orient");
    }
    gmpu_mesh *mesh = nullptr;
    if (st == GMPU_OK) {
        st = gmpu_surface_polygonize(s, &mesh);
        // DEGENERATE_INPUT is polygonize's documented answer when no piece of surface is near
        // the points (a few points in a coarse grid, say): a failure with its message, never
        // an empty mesh.
        check_failure(st, {GMPU_ERROR_LIMIT_EXCEEDED, GMPU_ERROR_DEGENERATE_INPUT}, "polygonize");
        if (st == GMPU_OK) check_mesh(mesh);
        if (st != GMPU_OK && mesh) finding("a failed polygonize handed out a mesh", st);
    }
    if (st == GMPU_OK) {
        // f and ∇f at the inputs, far away, and at huge (finite) queries: finite, OK.
        std::vector<double> q(p.begin(), p.begin() + long(3 * std::min<size_t>(n, 16)));
        const double extra[] = {0, 0, 0, 1e30, -1e30, 1e30, 1e300, 0, -1e300, scale, scale, scale};
        q.insert(q.end(), std::begin(extra), std::end(extra));
        const size_t nq = q.size() / 3;
        std::vector<double> val(nq), grad(3 * nq);
        st = gmpu_surface_evaluate(s, q.data(), nq, val.data(), grad.data());
        if (st != GMPU_OK) finding("evaluate at finite points", st);
        if (!finite(val.data(), nq) || !finite(grad.data(), 3 * nq)) finding("evaluate gave a non-finite value");
        std::vector<double> normals(3 * n);
        if (gmpu_surface_copy_normals(s, normals.data(), n) != GMPU_OK) finding("copy_normals");
        for (size_t i = 0; i < n; ++i) {
            const double len = std::hypot(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
            if (!(std::fabs(len - 1) < 1e-3)) finding("copy_normals gave a non-unit normal");
        }
        double stat = 0;
        for (int k = GMPU_STAT_POINTS; k <= GMPU_STAT_EFFECTIVE_ERROR; ++k)
            if (gmpu_surface_get_stat(s, gmpu_stat(k), &stat) != GMPU_OK || !std::isfinite(stat)) finding("a statistic");
        // A level-of-detail cap and a second polygonize on the same handle.
        gmpu_mesh *again = nullptr;
        if (gmpu_surface_set_param(s, GMPU_PARAM_LEVEL, 1 + (knobs & 3)) != GMPU_OK) finding("set LEVEL");
        st = gmpu_surface_polygonize(s, &again);
        check_failure(st, {GMPU_ERROR_LIMIT_EXCEEDED, GMPU_ERROR_DEGENERATE_INPUT}, "polygonize at a level");
        if (st == GMPU_OK) check_mesh(again);
        gmpu_mesh_destroy(again);
    }
    gmpu_mesh_destroy(mesh);
    gmpu_surface_destroy(s);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const double start = process_cpu_seconds();
    run_pipeline(data, size);
    if (process_cpu_seconds() - start > cpu_budget_seconds()) finding("over the CPU budget");
    return 0;
}
