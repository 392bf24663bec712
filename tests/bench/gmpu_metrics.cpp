// gmpu-metrics: the benchmark's one scorer, so gmpu and every peer are measured by the same
// code (tests/support). Two modes:
//
//   gmpu-metrics [--mesh OUT.ply] [--gt GT.off] [--points-normals ORIENTED.ply
//                --gt-normals CLOUD_gt.ply] [--samples 100000] [--seed 1] [--threads 0]
//       prints one JSON object: mesh checks of OUT, distances and normal consistency of
//       OUT against GT, orientation accuracy of ORIENTED's normals against the _gt file's
//       (same points, same order), and the time each part took. Any part whose inputs
//       are missing is left out.
//
//   gmpu-metrics --sample GT.off --n 35000 --seed 1 [--noise 0.0025] [--nonuniform]
//                [--sparse] -o CLOUD.ply --gt-out CLOUD_gt.ply
//       draws a cloud from GT the way tests/data/clouds was made: CLOUD.ply has
//       positions only, CLOUD_gt.ply the same points with the ground-truth outward
//       normals; prints the metadata as JSON.
//
// Exit status: 0 done, 1 a file could not be read or written, 2 bad command line.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "files.hpp"
#include "mesh_checks.hpp"
#include "metrics.hpp"
#include "sampling.hpp"

using namespace gmpu::testing;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// Appends "key": value pairs to one JSON object; non-finite numbers become null.
class Json {
public:
    void number(const std::string &key, double v) {
        char buf[64];
        if (std::isfinite(v)) std::snprintf(buf, sizeof buf, "%.10g", v);
        else std::snprintf(buf, sizeof buf, "null");
        raw(key, buf);
    }
    void integer(const std::string &key, long long v) { raw(key, std::to_string(v)); }
    void boolean(const std::string &key, bool v) { raw(key, v ? "true" : "false"); }
    void string(const std::string &key, const std::string &v) { raw(key, quote(v)); }
    void integers(const std::string &key, const std::vector<long long> &v) {
        std::string list = "[";
        for (size_t i = 0; i < v.size(); ++i) list += (i ? ", " : "") + std::to_string(v[i]);
        raw(key, list + "]");
    }
    void print() const { std::printf("{\n%s\n}\n", body_.c_str()); }

private:
    static std::string quote(const std::string &s) {
        std::string q = "\"";
        for (char c : s) {
            if (c == '"' || c == '\\') q += '\\';
            if (static_cast<unsigned char>(c) < 0x20) {
                char esc[8];
                std::snprintf(esc, sizeof esc, "\\u%04x", c);
                q += esc;
            } else {
                q += c;
            }
        }
        return q + "\"";
    }
    void raw(const std::string &key, const std::string &value) {
        body_ += (body_.empty() ? "  " : ",\n  ") + quote(key) + ": " + value;
    }
    std::string body_;
};

// "1%" → "1", "0.5%" → "0.5": the key suffix of a threshold.
std::string percent(double tau) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", tau * 100);
    return buf;
}

[[noreturn]] void usage(const std::string &problem) {
    std::fprintf(stderr,
                 "gmpu-metrics: %s\n"
                 "usage: gmpu-metrics [--mesh OUT.ply] [--gt GT.off] [--points-normals ORIENTED.ply"
                 " --gt-normals CLOUD_gt.ply]\n"
                 "                    [--samples 100000] [--seed 1] [--threads 0]\n"
                 "       gmpu-metrics --sample GT.off --n 35000 [--seed 1] [--noise 0.0025]"
                 " [--nonuniform] [--sparse]\n"
                 "                    -o CLOUD.ply --gt-out CLOUD_gt.ply\n",
                 problem.c_str());
    std::exit(2);
}

struct Args {
    std::map<std::string, std::string> values;
    bool nonuniform = false, sparse = false;

    std::string get(const std::string &key, const std::string &fallback = "") const {
        auto it = values.find(key);
        return it == values.end() ? fallback : it->second;
    }
    bool has(const std::string &key) const { return values.count(key) > 0; }
    double number(const std::string &key, double fallback) const {
        if (!has(key)) return fallback;
        char *end = nullptr;
        const double v = std::strtod(get(key).c_str(), &end);
        if (end == get(key).c_str() || *end != '\0' || !std::isfinite(v))
            usage(key + " needs a number, got '" + get(key) + "'");
        return v;
    }
};

Args parse(int argc, char **argv) {
    static const char *with_value[] = {"--mesh", "--gt", "--points-normals", "--gt-normals",
                                       "--samples", "--seed", "--threads", "--sample", "--n",
                                       "--noise", "-o", "--gt-out"};
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--nonuniform") { a.nonuniform = true; continue; }
        if (arg == "--sparse") { a.sparse = true; continue; }
        if (arg == "-h" || arg == "--help") usage("help");
        bool known = false;
        for (const char *k : with_value) known = known || arg == k;
        if (!known) usage("unknown option " + arg);
        if (i + 1 >= argc) usage(arg + " needs a value");
        a.values[arg] = argv[++i];
    }
    return a;
}

int sample_mode(const Args &a) {
    if (!a.has("-o") || !a.has("--gt-out")) usage("--sample needs -o and --gt-out");
    if (!a.has("--n") && !a.sparse) usage("--sample needs --n (or --sparse)");
    const auto n = static_cast<size_t>(a.number("--n", kSparseSampleCount));
    const auto seed = static_cast<uint64_t>(a.number("--seed", 1));
    SamplingOptions options;
    options.noise = a.number("--noise", 0);
    options.nonuniform = a.nonuniform;
    if (n == 0 || options.noise < 0) usage("--n must be positive and --noise not negative");

    const TriangleMesh gt = load_mesh(a.get("--sample"));
    const MeshSamples s = sample_mesh(gt, n, seed, options);
    save_points(a.get("-o"), s, false);
    save_points(a.get("--gt-out"), s, true);

    Json j;
    j.string("mesh", a.get("--sample"));
    j.integer("n", static_cast<long long>(n));
    j.number("noise", options.noise);
    j.number("noise_sigma_abs", options.noise * bbox_diagonal(gt));
    j.boolean("nonuniform", options.nonuniform);
    j.integer("axis", options.axis);
    j.number("ratio", options.ratio);
    j.integer("seed", static_cast<long long>(seed));
    j.number("bbox_diag", bbox_diagonal(gt));
    j.number("signed_volume", check_mesh(gt).signed_volume);
    j.integer("gt_vertices", static_cast<long long>(gt.vertices.size()));
    j.integer("gt_faces", static_cast<long long>(gt.triangles.size()));
    j.print();
    return 0;
}

int measure_mode(const Args &a) {
    if (!a.has("--mesh") && !a.has("--points-normals")) usage("nothing to measure");
    if (a.has("--gt") && !a.has("--mesh")) usage("--gt needs --mesh");
    if (a.has("--points-normals") != a.has("--gt-normals"))
        usage("--points-normals and --gt-normals go together");
    const auto total_start = Clock::now();
    Json j;

    if (a.has("--mesh")) {
        auto start = Clock::now();
        const TriangleMesh mesh = load_mesh(a.get("--mesh"));
        j.string("mesh", a.get("--mesh"));
        j.number("mesh_load_seconds", since(start));

        start = Clock::now();
        const MeshCheck c = check_mesh(mesh);
        j.integer("vertices", static_cast<long long>(c.vertices));
        j.integer("triangles", static_cast<long long>(c.triangles));
        j.boolean("watertight", c.watertight);
        j.boolean("edge_manifold", c.edge_manifold);
        j.boolean("consistently_wound", c.consistently_wound);
        j.integer("boundary_edges", static_cast<long long>(c.boundary_edges));
        j.integer("nonmanifold_edges", static_cast<long long>(c.nonmanifold_edges));
        j.integer("misoriented_edges", static_cast<long long>(c.misoriented_edges));
        j.integer("nonmanifold_vertices", static_cast<long long>(c.nonmanifold_vertices));
        j.integer("degenerate_triangles", static_cast<long long>(c.degenerate_triangles));
        j.integer("duplicate_triangles", static_cast<long long>(c.duplicate_triangles));
        j.integer("components", static_cast<long long>(c.components));
        std::vector<long long> genus;
        for (const ComponentReport &r : c.component_reports) genus.push_back(r.genus);
        if (genus.size() > 20) genus.resize(20);  // the largest pieces tell the story
        j.integers("genus", genus);
        j.integer("euler_characteristic", c.euler_characteristic);
        j.number("signed_volume", c.signed_volume);
        j.number("area", c.area);
        j.number("check_seconds", since(start));

        if (a.has("--gt")) {
            start = Clock::now();
            const TriangleMesh gt = load_mesh(a.get("--gt"));
            j.string("gt", a.get("--gt"));
            j.number("gt_load_seconds", since(start));
            ComparisonOptions o;
            o.samples = static_cast<size_t>(a.number("--samples", 100000));
            o.seed = static_cast<uint64_t>(a.number("--seed", 1));
            o.threads = static_cast<unsigned>(a.number("--threads", 0));
            if (o.samples == 0) usage("--samples must be positive");
            const SurfaceComparison r = compare_surfaces(mesh, gt, o);
            j.integer("samples", static_cast<long long>(r.samples));
            j.integer("seed", static_cast<long long>(o.seed));
            j.number("gt_bbox_diagonal", r.diagonal);
            j.number("gt_signed_volume", check_mesh(gt).signed_volume);
            j.number("chamfer_l1", r.chamfer_l1);
            j.number("accuracy", r.accuracy);
            j.number("completeness", r.completeness);
            j.number("hausdorff", r.hausdorff);
            for (const FScore &f : r.fscores) {
                j.number("precision_" + percent(f.tau), f.precision);
                j.number("recall_" + percent(f.tau), f.recall);
                j.number("fscore_" + percent(f.tau), f.fscore);
            }
            j.number("normal_consistency", r.normal_consistency);
            j.number("compare_seconds", r.seconds);
        }
    }

    if (a.has("--points-normals")) {
        const auto start = Clock::now();
        const OrientedPoints out = load_points(a.get("--points-normals"));
        const OrientedPoints gt = load_points(a.get("--gt-normals"));
        if (out.normals.empty() || gt.normals.empty()) {
            std::fprintf(stderr, "gmpu-metrics: %s has no normals\n",
                         (out.normals.empty() ? a.get("--points-normals") : a.get("--gt-normals")).c_str());
            return 1;
        }
        const OrientationScore s = orientation_accuracy(out.normals, gt.normals);
        j.string("points_normals", a.get("--points-normals"));
        j.integer("orientation_points", static_cast<long long>(s.points));
        j.integer("orientation_correct", static_cast<long long>(s.correct));
        j.number("orientation_accuracy", s.accuracy);
        j.number("orientation_seconds", since(start));
    }
    j.number("total_seconds", since(total_start));
    j.print();
    return 0;
}

}  // namespace

int main(int argc, char **argv) {
    const Args args = parse(argc, argv);
    try {
        return args.has("--sample") ? sample_mode(args) : measure_mode(args);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "gmpu-metrics: %s\n", e.what());
        return 1;
    }
}
