// lib/io through its C++ interface (io.hpp) and the in-memory parsers (formats.hpp):
// round trips, every PLY encoding and type, the text formats, hostile files, write
// failures and the shared data sets. Every failure is checked for its exact status and
// for a message naming the file and the offending thing.
#include <dirent.h>
#include <ftw.h>
#include <glob.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <utility>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/formats.hpp"
#include "io/io.hpp"

// cmocka last: its fail() macro would break the standard headers. Its header has no
// extern "C" of its own.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

using gmpu::io::MeshView;
using gmpu::io::PointCloud;

namespace {

std::string g_dir;  // per-run scratch directory (mkdtemp), removed by the teardown

std::string path_of(const std::string &name) { return g_dir + "/" + name; }

std::string put(const std::string &name, const std::string &bytes) {
    std::string p = path_of(name);
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
}

std::string slurp(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<std::string> entries(const std::string &dir) {
    std::vector<std::string> names;
    if (DIR *d = ::opendir(dir.c_str())) {
        while (dirent *e = ::readdir(d))
            if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) names.push_back(e->d_name);
        ::closedir(d);
    }
    return names;
}

// A fresh empty subdirectory of the scratch directory, for "nothing is left behind" checks.
std::string fresh_dir(const std::string &name) {
    std::string p = path_of(name);
    assert_int_equal(::mkdir(p.c_str(), 0755), 0);
    return p;
}

void assert_contains(const std::string &haystack, const std::string &needle) {
    if (haystack.find(needle) == std::string::npos)
        fail_msg("message \"%s\" does not contain \"%s\"", haystack.c_str(), needle.c_str());
}

// Runs f, which must throw gmpu::Error with `status` and a message containing each needle.
void expect_error(const std::function<void()> &f, gmpu_status status, std::vector<std::string> needles) {
    try {
        f();
    } catch (const gmpu::Error &e) {
        if (e.status() != status)
            fail_msg("expected %s, got %s: %s", gmpu_status_name(status), gmpu_status_name(e.status()), e.what());
        for (const std::string &n : needles) assert_contains(e.what(), n);
        return;
    }
    fail_msg("expected %s, but the call succeeded", gmpu_status_name(status));
}

void expect_read_error(const std::string &path, gmpu_status status, std::vector<std::string> needles) {
    needles.push_back(path);
    expect_error([&] { gmpu::io::read_points(path); }, status, needles);
}

void assert_doubles_equal(const std::vector<double> &a, const std::vector<double> &b) {
    assert_int_equal(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0)
            fail_msg("value %zu differs: %.17g vs %.17g", i, a[i], b[i]);
}

// Awkward doubles: shortest forms of 0.1, extremes, a subnormal, negative zero.
std::vector<double> tricky_values(size_t count, unsigned seed) {
    const double special[] = {0.1, -0.0, 1e-300, -1.7976931348623157e308, 4.9406564584124654e-324,
                              123456789.123456789, -2.5, 1.0 / 3.0, 6.02214076e23};
    std::vector<double> v(count);
    std::srand(seed);
    for (size_t i = 0; i < count; ++i)
        v[i] = i < std::size(special) ? special[i] : (std::rand() - RAND_MAX / 2) / 1234.567;
    return v;
}

// ---- PLY bodies in any encoding -------------------------------------------------------

enum class Enc { ascii, le, be };

const char *format_line(Enc e) {
    return e == Enc::ascii ? "format ascii 1.0\n"
           : e == Enc::le  ? "format binary_little_endian 1.0\n"
                           : "format binary_big_endian 1.0\n";
}

// Appends values to a PLY body in the chosen encoding; T is the property's C type.
struct Body {
    Enc enc;
    std::string out;
    template <class T>
    Body &v(double x) {
        if (enc == Enc::ascii) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.17g ", x);
            out += buf;
        } else {
            T t = static_cast<T>(x);
            unsigned char b[sizeof(T)];
            std::memcpy(b, &t, sizeof t);
            if (enc == Enc::be)
                for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
            out.append(reinterpret_cast<char *>(b), sizeof b);
        }
        return *this;
    }
    Body &end() {
        if (enc == Enc::ascii) out += "\n";
        return *this;
    }
};

std::string ply(Enc e, const std::string &header_rest, const std::string &body) {
    return "ply\n" + std::string(format_line(e)) + header_rest + "end_header\n" + body;
}

const char *enc_name(Enc e) { return e == Enc::ascii ? "ascii" : e == Enc::le ? "le" : "be"; }

// ---- fixtures -------------------------------------------------------------------------

int setup(void **) {
    char tmpl[] = "/tmp/gmpu_test_io_XXXXXX";
    if (!::mkdtemp(tmpl)) return -1;
    g_dir = tmpl;
    return 0;
}

int teardown(void **) {
    ::chmod(g_dir.c_str(), 0700);
    return ::nftw(g_dir.c_str(), [](const char *p, const struct stat *, int, struct FTW *) { return ::remove(p); },
                  16, FTW_DEPTH | FTW_PHYS);
}

// ---- round trips ----------------------------------------------------------------------

void test_points_round_trip(void **) {
    const size_t n = 57;
    const std::vector<double> xyz = tricky_values(3 * n, 1), nrm = tricky_values(3 * n, 2);
    for (const char *ext : {"ply", "xyz", "PLY"}) {
        for (bool with_normals : {false, true}) {
            const std::string p = path_of(std::string("round.") + ext);
            gmpu::io::write_points(p, xyz.data(), with_normals ? nrm.data() : nullptr, n);
            PointCloud c = gmpu::io::read_points(p);
            assert_int_equal(c.size(), n);
            assert_doubles_equal(c.positions, xyz);
            assert_doubles_equal(c.normals, with_normals ? nrm : std::vector<double>{});
        }
    }
}

void test_mesh_round_trip(void **) {
    // A tetrahedron's worth of tricky coordinates, four triangles.
    const std::vector<double> v = tricky_values(12, 3), nrm = tricky_values(12, 4);
    const std::vector<uint32_t> t = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0};
    for (const char *ext : {"ply", "obj", "off", "Obj"}) {
        for (bool with_normals : {false, true}) {
            MeshView view;
            view.vertices = v.data();
            view.vertex_count = 4;
            view.triangles = t.data();
            view.triangle_count = 4;
            view.normals = with_normals ? nrm.data() : nullptr;
            const std::string p = path_of(std::string("mesh.") + ext);
            gmpu::io::write_mesh(p, view);
            gmpu::io::MeshData m = gmpu::io::read_mesh(p);
            assert_doubles_equal(m.vertices, v);
            assert_true(m.triangles == t);
            // Normals survive where the format carries them (PLY; OBJ's vn are not read
            // back as point normals, and OFF has none).
            PointCloud c = gmpu::io::read_points(p);
            assert_doubles_equal(c.positions, v);
            const bool ply = std::strcmp(ext, "ply") == 0;
            assert_doubles_equal(c.normals, with_normals && ply ? nrm : std::vector<double>{});
        }
    }
    // The PLY header is the documented one.
    MeshView view{v.data(), 4, t.data(), 4, nullptr};
    gmpu::io::write_mesh(path_of("h.ply"), view);
    const std::string bytes = slurp(path_of("h.ply"));
    assert_contains(bytes, "format binary_little_endian 1.0\n");
    assert_contains(bytes, "property double x\n");
    assert_contains(bytes, "element face 4\nproperty list uchar int vertex_indices\nend_header\n");
    // 4 vertices × 24 bytes + 4 faces × 13 bytes after the header.
    assert_int_equal(bytes.size() - (bytes.find("end_header\n") + 11), 4 * 24 + 4 * 13);
}

void test_obj_writer_normals_reference_vertices(void **) {
    const double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const double n[] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    const uint32_t t[] = {0, 1, 2};
    gmpu::io::write_mesh(path_of("n.obj"), MeshView{v, 3, t, 1, n});
    const std::string s = slurp(path_of("n.obj"));
    assert_contains(s, "\nv 1 0 0\n");
    assert_contains(s, "\nvn 0 0 1\n");
    assert_contains(s, "\nf 1//1 2//2 3//3\n");
}

// ---- PLY ------------------------------------------------------------------------------

// The same file in all three encodings: an element before vertex (with a list), colour
// bytes, a vertex list property, float and double coordinates, a face element with a
// quad and another trailing element.
std::string rich_ply(Enc e) {
    const std::string header =
        "comment made by test_io\r\n"
        "obj_info anything\n"
        "element material 2\n"
        "property uchar id\n"
        "property list uint short weights\n"
        "element vertex 4\n"
        "property float x\n"
        "property uchar red\nproperty uint8 green\nproperty uchar blue\n"
        "property list uchar int neighbours\n"
        "property double y\n"
        "property float64 z\n"
        "property float32 nx\nproperty float ny\nproperty float nz\n"
        "property int16 flags\n"
        "element face 2\n"
        "property uchar kind\n"
        "property list uchar int vertex_indices\n"
        "property list int float texcoord\n"
        "element edge 1\n"
        "property int vertex1\nproperty int vertex2\n";
    Body b{e, {}};
    b.v<uint8_t>(7).v<uint32_t>(3).v<int16_t>(-1).v<int16_t>(2).v<int16_t>(3).end();
    b.v<uint8_t>(8).v<uint32_t>(0).end();
    const double pos[4][3] = {{0.5, 0.1, -2}, {1.5, 0.2, 3e10}, {-1, 1.0 / 3.0, 0}, {4, 5, 6}};
    for (int i = 0; i < 4; ++i) {
        b.v<float>(pos[i][0]).v<uint8_t>(255).v<uint8_t>(0).v<uint8_t>(i);
        b.v<uint8_t>(i % 3);  // list length 0, 1, 2, 0
        for (int k = 0; k < i % 3; ++k) b.v<int32_t>(k);
        b.v<double>(pos[i][1]).v<double>(pos[i][2]);
        b.v<float>(0).v<float>(0).v<float>(i + 1);
        b.v<int16_t>(-5).end();
    }
    b.v<uint8_t>(1).v<uint8_t>(4).v<int32_t>(0).v<int32_t>(1).v<int32_t>(2).v<int32_t>(3);
    b.v<int32_t>(2).v<float>(0.5).v<float>(0.25).end();
    b.v<uint8_t>(2).v<uint8_t>(3).v<int32_t>(3).v<int32_t>(2).v<int32_t>(1).v<int32_t>(0).end();
    b.v<int32_t>(0).v<int32_t>(1).end();
    return ply(e, header, b.out);
}

void test_ply_rich_all_encodings(void **) {
    for (Enc e : {Enc::ascii, Enc::le, Enc::be}) {
        const std::string p = put(std::string("rich_") + enc_name(e) + ".ply", rich_ply(e));
        PointCloud c = gmpu::io::read_points(p);
        assert_int_equal(c.size(), 4);
        // x is float (0.5, 1.5, -1, 4 are exact in float), y and z are double.
        const std::vector<double> expect = {0.5, 0.1, -2, 1.5, 0.2, 3e10, -1, 1.0 / 3.0, 0, 4, 5, 6};
        assert_doubles_equal(c.positions, expect);
        assert_doubles_equal(c.normals, {0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4});
        gmpu::io::MeshData m = gmpu::io::read_mesh(p);
        // The quad 0 1 2 3 fans into two triangles, then the triangle 3 2 1.
        assert_true(m.triangles == (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1}));
    }
}

void test_ply_every_scalar_type(void **) {
    struct T {
        const char *name;
        double value;
    };
    const T types[] = {{"char", -100},  {"int8", -100},     {"uchar", 200},   {"uint8", 200},
                       {"short", -30000}, {"int16", -30000}, {"ushort", 60000}, {"uint16", 60000},
                       {"int", -2e9},   {"int32", -2e9},    {"uint", 4e9},    {"uint32", 4e9},
                       {"float", 2.5},  {"float32", 2.5},   {"double", 0.1},  {"float64", 0.1}};
    for (Enc e : {Enc::ascii, Enc::le, Enc::be}) {
        for (const T &t : types) {
            Body b{e, {}};
            const std::string n = t.name;
            if (n == "char" || n == "int8") b.v<int8_t>(t.value);
            else if (n == "uchar" || n == "uint8") b.v<uint8_t>(t.value);
            else if (n == "short" || n == "int16") b.v<int16_t>(t.value);
            else if (n == "ushort" || n == "uint16") b.v<uint16_t>(t.value);
            else if (n == "int" || n == "int32") b.v<int32_t>(t.value);
            else if (n == "uint" || n == "uint32") b.v<uint32_t>(t.value);
            else if (n == "float" || n == "float32") b.v<float>(t.value);
            else b.v<double>(t.value);
            b.v<float>(1).v<float>(2).end();
            const std::string p = put("type.ply", ply(e, "element vertex 1\nproperty " + n + " x\nproperty float y\n"
                                                          "property float z\n", b.out));
            PointCloud c = gmpu::io::read_points(p);
            if (c.positions != std::vector<double>{t.value, 1, 2})
                fail_msg("%s %s: read %.17g", enc_name(e), t.name, c.positions[0]);
        }
    }
}

void test_ply_crlf_and_vertex_after_face(void **) {
    const std::string text =
        "ply\r\nformat ascii 1.0\r\nelement face 1\r\nproperty list uchar uint vertex_index\r\n"
        "element vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nend_header\r\n"
        "3 2 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n";
    const std::string p = put("crlf.ply", text);
    gmpu::io::MeshData m = gmpu::io::read_mesh(p);
    assert_doubles_equal(m.vertices, {0, 0, 0, 1, 0, 0, 0, 1, 0});
    assert_true(m.triangles == (std::vector<uint32_t>{2, 1, 0}));
}

void test_ply_header_errors(void **) {
    const std::string v3 = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
    expect_read_error(put("fmt.ply", "ply\nformat binary_middle_endian 1.0\n" + v3 + "end_header\n"),
                      GMPU_ERROR_UNSUPPORTED, {"binary_middle_endian"});
    expect_read_error(put("ver.ply", "ply\nformat ascii 2.0\n" + v3 + "end_header\n0 0 0\n"),
                      GMPU_ERROR_UNSUPPORTED, {"'2.0'"});
    expect_read_error(put("noend.ply", "ply\nformat ascii 1.0\n" + v3), GMPU_ERROR_PARSE, {"no end_header"});
    expect_read_error(put("noend2.ply", "ply\nformat ascii 1.0\n" + v3 + "0 0 0\n"), GMPU_ERROR_PARSE,
                      {"header line 7", "unknown header keyword '0'", "end_header missing"});
    expect_read_error(put("nox.ply", ply(Enc::ascii, "element vertex 1\nproperty float y\nproperty float z\n", "1 2\n")),
                      GMPU_ERROR_PARSE, {"'x'"});
    expect_read_error(put("magic.ply", "PLY\nformat ascii 1.0\n" + v3 + "end_header\n0 0 0\n"), GMPU_ERROR_PARSE,
                      {"not a PLY file"});
    expect_read_error(put("partialn.ply", ply(Enc::ascii, v3 + "property float nx\n", "0 0 0 1\n")),
                      GMPU_ERROR_PARSE, {"nx ny nz"});
    expect_read_error(put("type.ply", ply(Enc::ascii, v3 + "property int64 id\n", "0 0 0 1\n")),
                      GMPU_ERROR_UNSUPPORTED, {"'int64'"});
    expect_read_error(put("kw.ply", ply(Enc::ascii, v3 + "bogus line\n", "0 0 0\n")), GMPU_ERROR_PARSE,
                      {"header line 7", "'bogus'"});
    expect_read_error(put("count.ply", ply(Enc::ascii, "element vertex -3\nproperty float x\n", "")),
                      GMPU_ERROR_PARSE, {"header line 3"});
    expect_read_error(put("novertex.ply", ply(Enc::ascii, "element point 1\nproperty float x\n", "0\n")),
                      GMPU_ERROR_PARSE, {"no 'vertex' element"});
    expect_read_error(put("nofmt.ply", "ply\n" + v3 + "end_header\n0 0 0\n"), GMPU_ERROR_PARSE, {"format"});
}

void test_ply_truncated(void **) {
    const std::string v3 = "property float x\nproperty float y\nproperty float z\n";
    for (Enc e : {Enc::ascii, Enc::le, Enc::be}) {
        Body b{e, {}};
        for (int i = 0; i < 3; ++i) b.v<float>(i).v<float>(i).v<float>(i).end();
        // More vertices declared than present.
        expect_read_error(put("short.ply", ply(e, "element vertex 10\n" + v3, b.out)), GMPU_ERROR_PARSE,
                          {"expected 10 vertices, file ends after 3"});
        // A list property in the vertex element: the record-by-record path.
        Body l{e, {}};
        for (int i = 0; i < 3; ++i) l.v<float>(i).v<float>(i).v<float>(i).v<uint8_t>(1).v<int32_t>(7).end();
        expect_read_error(put("shortl.ply", ply(e, "element vertex 5\n" + v3 + "property list uchar int n\n", l.out)),
                          GMPU_ERROR_PARSE, {"expected 5 vertices, file ends after 3"});
        // Cut in the middle of the last value (binary) / missing the last value (ascii).
        std::string cut = b.out;
        cut.resize(e == Enc::ascii ? cut.rfind(' ', cut.size() - 3) : cut.size() - 2);
        expect_read_error(put("cut.ply", ply(e, "element vertex 3\n" + v3, cut)), GMPU_ERROR_PARSE,
                          {"expected 3 vertices, file ends after 2"});
        // Faces: declared but missing (read as a mesh).
        Body f = b;
        f.v<uint8_t>(3).v<int32_t>(0).v<int32_t>(1).v<int32_t>(2).end();
        const std::string fp =
            put("shortf.ply", ply(e, "element vertex 3\n" + v3 + "element face 4\nproperty list uchar int vertex_indices\n", f.out));
        expect_error([&] { gmpu::io::read_mesh(fp); }, GMPU_ERROR_PARSE, {fp, "expected 4 'face' elements, file ends after 1"});
        // An extra element that is cut short also counts, even when only points are read.
        expect_read_error(put("shortx.ply", ply(e, "element vertex 3\n" + v3 + "element extra 2\nproperty double w\n", b.out)),
                          GMPU_ERROR_PARSE, {"'extra'", "file ends after 0"});
    }
}

void test_ply_huge_counts_fail_fast(void **) {
    const std::string v3 = "property float x\nproperty float y\nproperty float z\n";
    const auto start = std::chrono::steady_clock::now();
    for (Enc e : {Enc::ascii, Enc::le, Enc::be}) {
        Body b{e, {}};
        b.v<float>(1).v<float>(2).v<float>(3).end();
        // PARSE, not OUT_OF_MEMORY: nothing the size of the claim is ever allocated.
        expect_read_error(put("huge.ply", ply(e, "element vertex 1000000000000000\n" + v3, b.out)), GMPU_ERROR_PARSE,
                          {"expected 1000000000000000 vertices, file ends after 1"});
        expect_read_error(put("hugel.ply", ply(e, "element vertex 1000000000000000\n" + v3 + "property list uchar int n\n",
                                               b.v<uint8_t>(0).out)),
                          GMPU_ERROR_PARSE, {"expected 1000000000000000 vertices"});
        Body f{e, {}};
        f.v<float>(1).v<float>(2).v<float>(3).end().v<uint8_t>(3).v<int32_t>(0).v<int32_t>(0).v<int32_t>(0).end();
        const std::string fp = put("hugef.ply", ply(e, "element vertex 1\n" + v3 + "element face 999999999999999\n"
                                                        "property list uchar int vertex_indices\n", f.out));
        expect_error([&] { gmpu::io::read_mesh(fp); }, GMPU_ERROR_PARSE, {"expected 999999999999999 'face' elements"});
        // A huge list length.
        Body l{e, {}};
        l.v<float>(1).v<float>(2).v<float>(3).v<uint32_t>(4000000000u).end();
        expect_read_error(put("hugelist.ply", ply(e, "element vertex 1\n" + v3 + "property list uint int n\n", l.out)),
                          GMPU_ERROR_PARSE, {"expected 1 vertices, file ends after 0"});
    }
    // An element with no properties claims nothing, however many items it has.
    const std::string p = put("empty_el.ply", ply(Enc::le, "element nothing 1000000000000000\nelement vertex 1\n" + v3,
                                                  std::string(12, '\0')));
    assert_int_equal(gmpu::io::read_points(p).size(), 1);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > 2.0) fail_msg("huge-count files took %.2f s to reject", seconds);
}

void test_ply_bad_values(void **) {
    const std::string v3 = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    auto ascii = [&](const std::string &name, const std::string &bad) {
        return put(name, ply(Enc::ascii, v3, "0 0 0\n1 " + bad + " 1\n2 2 2\n"));
    };
    expect_read_error(ascii("abc.ply", "1.0abc"), GMPU_ERROR_PARSE, {"line 9", "'1.0abc'"});
    expect_read_error(ascii("e999.ply", "1e999"), GMPU_ERROR_PARSE, {"line 9", "'1e999'", "out of range"});
    expect_read_error(ascii("nan.ply", "nan"), GMPU_ERROR_INVALID_INPUT, {"vertex 1", "non-finite"});
    expect_read_error(ascii("inf.ply", "-inf"), GMPU_ERROR_INVALID_INPUT, {"vertex 1", "non-finite"});
    // Subnormal underflow is a finite number, not an error.
    assert_true(gmpu::io::read_points(ascii("tiny.ply", "1e-320")).positions[4] > 0);
    for (Enc e : {Enc::le, Enc::be}) {
        Body b{e, {}};
        b.v<float>(0).v<float>(0).v<float>(0).v<float>(1).v<float>(1).v<float>(1);
        b.v<float>(2).v<float>(2).v<float>(NAN);
        expect_read_error(put("binnan.ply", ply(e, v3, b.out)), GMPU_ERROR_INVALID_INPUT, {"vertex 2", "non-finite"});
        Body n{e, {}};
        n.v<double>(0).v<double>(0).v<double>(0).v<double>(INFINITY).v<double>(0).v<double>(1);
        expect_read_error(put("nrmnan.ply", ply(e,
                                                "element vertex 1\nproperty double x\nproperty double y\nproperty double z\n"
                                                "property double nx\nproperty double ny\nproperty double nz\n",
                                                n.out)),
                          GMPU_ERROR_INVALID_INPUT, {"vertex 0", "normal"});
    }
}

void test_ply_bad_faces(void **) {
    const std::string header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\n";
    for (Enc e : {Enc::ascii, Enc::le, Enc::be}) {
        auto file = [&](const std::string &name, std::vector<double> face) {
            Body b{e, {}};
            for (int i = 0; i < 3; ++i) b.v<float>(i).v<float>(i * i).v<float>(1).end();
            b.v<uint8_t>(static_cast<double>(face.size()));
            for (double f : face) b.v<int32_t>(f);
            return put(name, ply(e, header, b.end().out));
        };
        std::string p = file("neg.ply", {0, -1, 2});
        expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "face 0", "vertex index -1 out of range"});
        p = file("big.ply", {0, 1, 3});
        expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "vertex index 3 out of range (3 vertices)"});
        p = file("two.ply", {0, 1});
        expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "face 0 has 2 vertices"});
        // Reading points ignores faces, broken or not.
        assert_int_equal(gmpu::io::read_points(p).size(), 3);
    }
    const std::string p = put("floatidx.ply", ply(Enc::ascii,
                                                  "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                                                  "element face 1\nproperty list uchar float vertex_indices\n",
                                                  "0 0 0\n3 0 0 0\n"));
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "integer type"});
    const std::string q = put("fracidx.ply", ply(Enc::ascii,
                                                 "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                                                 "element face 1\nproperty list uchar int vertex_indices\n",
                                                 "0 0 0\n3 0 0.5 0\n"));
    expect_error([&] { gmpu::io::read_mesh(q); }, GMPU_ERROR_PARSE, {q, "invalid integer '0.5'"});
}

// ---- XYZ ------------------------------------------------------------------------------

void test_xyz(void **) {
    PointCloud c = gmpu::io::read_points(put("a.xyz", "# header comment\n\n1 2 3\r\n  4\t5 6 # trailing\n+7 -8e1 .5\n"));
    assert_doubles_equal(c.positions, {1, 2, 3, 4, 5, 6, 7, -80, 0.5});
    assert_true(c.normals.empty());
    c = gmpu::io::read_points(put("b.txt", "1 2 3 0 0 1\n4 5 6 0 1 0\n"));
    assert_doubles_equal(c.positions, {1, 2, 3, 4, 5, 6});
    assert_doubles_equal(c.normals, {0, 0, 1, 0, 1, 0});
    c = gmpu::io::read_points(put("noeol.xyz", "1 2 3"));
    assert_int_equal(c.size(), 1);

    expect_read_error(put("cols.xyz", "1 2 3\n4 5 6\n7 8 9 1 1 1\n"), GMPU_ERROR_PARSE, {"line 3", "6 columns", "line 1 has 3"});
    expect_read_error(put("four.xyz", "# c\n1 2 3 4\n"), GMPU_ERROR_PARSE, {"line 2", "4 columns"});
    expect_read_error(put("seven.xyz", "1 2 3 4 5 6 7\n"), GMPU_ERROR_PARSE, {"line 1", "more than 6"});
    expect_read_error(put("abc.xyz", "1 2 3\n1 2.0abc 3\n"), GMPU_ERROR_PARSE, {"line 2", "'2.0abc'"});
    expect_read_error(put("e999.xyz", "1 2 3\n1 2 -1e999\n"), GMPU_ERROR_PARSE, {"line 2", "'-1e999'"});
    expect_read_error(put("nan.xyz", "1 2 3\n# x\n4 nan 6\n"), GMPU_ERROR_INVALID_INPUT, {"vertex 1"});
    expect_read_error(put("inf.xyz", "1 2 3 0 0 1\n4 5 6 inf 0 0\n"), GMPU_ERROR_INVALID_INPUT, {"vertex 1", "normal"});
    expect_read_error(put("comments.xyz", "# only\n\n   \n# comments\n"), GMPU_ERROR_INVALID_INPUT, {"no points"});
}

// ---- OFF ------------------------------------------------------------------------------

void test_off(void **) {
    const std::string quad = "OFF\n# a comment\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0 # trailing\n\n0 0 1\n"
                             "4 0 1 2 3\n3 0 1 4 255 0 0\n";
    gmpu::io::MeshData m = gmpu::io::read_mesh(put("quad.off", quad));
    assert_int_equal(m.vertices.size(), 15);
    assert_true(m.triangles == (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 1, 4}));
    assert_true(gmpu::io::read_points(path_of("quad.off")).normals.empty());

    PointCloud c = gmpu::io::read_points(put("n.off", "NOFF\n2 0 0\n1 2 3 0 0 1\n4 5 6 0 1 0\n"));
    assert_doubles_equal(c.positions, {1, 2, 3, 4, 5, 6});
    assert_doubles_equal(c.normals, {0, 0, 1, 0, 1, 0});
    c = gmpu::io::read_points(put("c.off", "COFF 2 0 0\r\n1 2 3 255 0 0 255\r\n4 5 6 0 255 0 255\r\n"));
    assert_doubles_equal(c.positions, {1, 2, 3, 4, 5, 6});
    assert_true(c.normals.empty());
    c = gmpu::io::read_points(put("cn.off", "STCNOFF\n1 0 0\n1 2 3 0 0 -1 1 1 1 1 0.5 0.5\n"));
    assert_doubles_equal(c.normals, {0, 0, -1});

    expect_read_error(put("4.off", "4OFF\n1 0 0\n1 2 3 1\n"), GMPU_ERROR_UNSUPPORTED, {"'4OFF'"});
    expect_read_error(put("bin.off", "OFF BINARY\n"), GMPU_ERROR_UNSUPPORTED, {"binary"});
    expect_read_error(put("hdr.off", "3 1 0\n0 0 0\n"), GMPU_ERROR_PARSE, {"not an OFF file"});
    expect_read_error(put("short.off", "OFF\n5 0 0\n0 0 0\n1 1 1\n"), GMPU_ERROR_PARSE,
                      {"expected 5 vertices, file ends after 2"});
    expect_read_error(put("huge.off", "OFF\n1000000000000000 0 0\n0 0 0\n"), GMPU_ERROR_PARSE,
                      {"expected 1000000000000000 vertices, file ends after 1"});
    expect_read_error(put("cols.off", "OFF\n2 0 0\n0 0 0\n1 1\n"), GMPU_ERROR_PARSE, {"line 4", "vertex 1"});
    expect_read_error(put("nfew.off", "NOFF\n1 0 0\n0 0 0\n"), GMPU_ERROR_PARSE, {"fewer than 6"});
    expect_read_error(put("garbage.off", "OFF\n1 0 0\n0 0x1 0\n"), GMPU_ERROR_PARSE, {"line 3", "'0x1'"});
    expect_read_error(put("counts.off", "OFF\nmany 0 0\n"), GMPU_ERROR_PARSE, {"'many'"});
    expect_read_error(put("nan.off", "OFF\n2 0 0\n0 0 0\nnan 0 0\n"), GMPU_ERROR_INVALID_INPUT, {"vertex 1"});

    const std::string tri = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
    std::string p = put("neg.off", tri + "3 0 -1 2\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "line 6", "vertex index -1 out of range"});
    p = put("big.off", tri + "3 0 1 3\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "vertex index 3 out of range (3 vertices)"});
    p = put("fshort.off", tri + "3 0 1\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "fewer than 3 indices"});
    p = put("fmiss.off", "OFF\n3 9 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "expected 9 faces, file ends after 1"});
    p = put("fhuge.off", "OFF\n3 999999999999 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "expected 999999999999 faces"});
}

// ---- OBJ ------------------------------------------------------------------------------

void test_obj(void **) {
    const std::string obj =
        "# comment\nmtllib x.mtl\no thing\n"
        "v 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\nv 0 0 1\nv 1 0 1\n"
        "vn 0 0 1\nvt 0.5 0.5\ng group\ns off\nusemtl m\n"
        "f 1 2 3\r\n"
        "f 1/1 2/1 3/1\n"
        "f 1/1/1 2/1/1 3/1/1\n"
        "f 1//1 2//1 3//1\n"
        "f -6 -5 -4\n"
        "f 1 2 3 4 5 6\n"
        "l 1 2\n";
    gmpu::io::MeshData m = gmpu::io::read_mesh(put("all.obj", obj));
    assert_doubles_equal(m.vertices, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1});
    std::vector<uint32_t> expect;
    for (int i = 0; i < 5; ++i) expect.insert(expect.end(), {0, 1, 2});
    expect.insert(expect.end(), {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5});
    assert_true(m.triangles == expect);
    PointCloud c = gmpu::io::read_points(path_of("all.obj"));
    assert_int_equal(c.size(), 6);
    assert_true(c.normals.empty());  // vn lines are not point normals

    // Negative indices are relative to the vertices read so far.
    m = gmpu::io::read_mesh(put("rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -3 -1\n"));
    assert_true(m.triangles == (std::vector<uint32_t>{0, 1, 2, 0, 1, 3}));

    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    std::string p = put("big.obj", tri + "f 1 2 9\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "line 4", "vertex index 9 out of range"});
    p = put("zero.obj", tri + "f 0 1 2\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "line 4", "'0'"});
    p = put("neg.obj", tri + "f -4 1 2\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "vertex index -4 out of range"});
    p = put("two.obj", tri + "f 1 2\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "at least 3"});
    p = put("fabc.obj", tri + "f 1 2 x/1\n");
    expect_error([&] { gmpu::io::read_mesh(p); }, GMPU_ERROR_PARSE, {p, "'x/1'"});
    expect_read_error(put("vabc.obj", "v 1 2 3abc\n"), GMPU_ERROR_PARSE, {"line 1", "'3abc'"});
    expect_read_error(put("vshort.obj", "v 1 2\n"), GMPU_ERROR_PARSE, {"line 1", "x y z"});
    expect_read_error(put("vinf.obj", "v 1 2 3\nv 1 inf 3\n"), GMPU_ERROR_INVALID_INPUT, {"vertex 1"});
    expect_read_error(put("nov.obj", "vn 0 0 1\nf 1 2 3\n"), GMPU_ERROR_INVALID_INPUT, {"no points"});
}

// ---- files and paths ------------------------------------------------------------------

void test_file_errors(void **) {
    for (const char *name : {"empty.ply", "empty.off"}) expect_read_error(put(name, ""), GMPU_ERROR_PARSE, {});
    for (const char *name : {"empty.xyz", "empty.obj", "empty.txt"})
        expect_read_error(put(name, ""), GMPU_ERROR_INVALID_INPUT, {"no points"});
    const std::string dir = fresh_dir("folder.ply");
    expect_read_error(dir, GMPU_ERROR_IO, {"Is a directory"});
    expect_read_error(path_of("missing.xyz"), GMPU_ERROR_IO, {"No such file or directory"});
    expect_read_error(path_of("no/such/dir/a.ply"), GMPU_ERROR_IO, {"No such file or directory"});
    expect_read_error(put("cloud.stl", "solid\n"), GMPU_ERROR_UNSUPPORTED, {"'.stl'", ".ply"});
    expect_read_error(path_of("noext"), GMPU_ERROR_UNSUPPORTED, {"no file extension"});
    expect_read_error(path_of("dir.ply/file"), GMPU_ERROR_UNSUPPORTED, {"no file extension"});
    const std::string xyz = put("cloud.xyz", "1 2 3\n");
    expect_error([&] { gmpu::io::read_mesh(xyz); }, GMPU_ERROR_UNSUPPORTED, {xyz, "'.xyz'"});
    // Extensions are case-insensitive.
    assert_int_equal(gmpu::io::read_points(put("UP.XYZ", "1 2 3\n")).size(), 1);
    assert_int_equal(gmpu::io::read_points(put("Mixed.Off", "OFF\n1 0 0\n1 2 3\n")).size(), 1);
}

void test_write_failures_leave_nothing(void **) {
    const double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint32_t t[] = {0, 1, 2};
    const MeshView mesh{v, 3, t, 1, nullptr};
    const std::string dir = fresh_dir("writes");

    // A missing directory, and a "directory" that is a file.
    const std::string missing = dir + "/nope/out.ply";
    expect_error([&] { gmpu::io::write_mesh(missing, mesh); }, GMPU_ERROR_IO, {missing, "No such file or directory"});
    put("writes/plain", "x");
    const std::string notdir = dir + "/plain/out.obj";
    expect_error([&] { gmpu::io::write_points(dir + "/plain/out.xyz", v, nullptr, 3); }, GMPU_ERROR_IO,
                 {dir + "/plain/out.xyz", "Not a directory"});
    expect_error([&] { gmpu::io::write_mesh(notdir, mesh); }, GMPU_ERROR_IO, {notdir, "Not a directory"});
    // The target is a directory: the rename fails, and the temporary goes.
    const std::string target_dir = dir + "/taken.off";
    assert_int_equal(::mkdir(target_dir.c_str(), 0755), 0);
    expect_error([&] { gmpu::io::write_mesh(target_dir, mesh); }, GMPU_ERROR_IO, {target_dir, "Is a directory"});
    // Unsupported extensions are refused before anything is created.
    expect_error([&] { gmpu::io::write_mesh(dir + "/m.xyz", mesh); }, GMPU_ERROR_UNSUPPORTED, {dir + "/m.xyz", "'.xyz'"});
    expect_error([&] { gmpu::io::write_points(dir + "/p.obj", v, nullptr, 3); }, GMPU_ERROR_UNSUPPORTED, {"'.obj'"});
    // Bad data is refused before anything is created.
    const uint32_t bad[] = {0, 1, 3};
    expect_error([&] { gmpu::io::write_mesh(dir + "/bad.ply", MeshView{v, 3, bad, 1, nullptr}); },
                 GMPU_ERROR_INVALID_INPUT, {"triangle 0 uses vertex 3"});
    const double nan_v[] = {0, 0, 0, 1, NAN, 0};
    expect_error([&] { gmpu::io::write_points(dir + "/nan.xyz", nan_v, nullptr, 2); }, GMPU_ERROR_INVALID_INPUT,
                 {"vertex 1", "non-finite"});
    expect_error([&] { gmpu::io::write_points(dir + "/null.ply", nullptr, nullptr, 2); }, GMPU_ERROR_INVALID_ARGUMENT,
                 {"NULL"});

    std::vector<std::string> left = entries(dir);
    std::sort(left.begin(), left.end());
    assert_int_equal(left.size(), 2);
    assert_string_equal(left[0].c_str(), "plain");
    assert_string_equal(left[1].c_str(), "taken.off");
    assert_true(entries(target_dir).empty());
}

void test_write_replaces_atomically(void **) {
    const std::string dir = fresh_dir("atomic");
    const std::string p = dir + "/cloud.xyz";
    const double a[] = {1, 2, 3}, b[] = {4, 5, 6, 7, 8, 9};
    gmpu::io::write_points(p, a, nullptr, 1);
    assert_string_equal(slurp(p).c_str(), "1 2 3\n");
    // A failed write (bad value) leaves the previous file as it was...
    const double nan_v[] = {1, NAN, 3};
    expect_error([&] { gmpu::io::write_points(p, nan_v, nullptr, 1); }, GMPU_ERROR_INVALID_INPUT, {p});
    assert_string_equal(slurp(p).c_str(), "1 2 3\n");
    // ...and a successful one replaces it whole, with no temporary left beside it.
    gmpu::io::write_points(p, b, nullptr, 2);
    assert_string_equal(slurp(p).c_str(), "4 5 6\n7 8 9\n");
    assert_int_equal(entries(dir).size(), 1);
    // The new file gets ordinary permissions (umask applied), not a temp file's 0600.
    struct stat st;
    assert_int_equal(::stat(p.c_str(), &st), 0);
    const mode_t mask = ::umask(0);
    ::umask(mask);
    assert_int_equal(st.st_mode & 0777, 0666 & ~mask);
}

void test_write_large_buffered(void **) {
    // Larger than the 1 MiB write buffer, so the flush path runs several times.
    const size_t n = 100000;
    std::vector<double> xyz = tricky_values(3 * n, 9);
    const std::string p = path_of("large.xyz");
    gmpu::io::write_points(p, xyz.data(), nullptr, n);
    assert_doubles_equal(gmpu::io::read_points(p).positions, xyz);
    const std::string q = path_of("large.ply");
    gmpu::io::write_points(q, xyz.data(), xyz.data(), n);
    PointCloud c = gmpu::io::read_points(q);
    assert_doubles_equal(c.positions, xyz);
    assert_doubles_equal(c.normals, xyz);
}


// ---- inputs that are not ordinary files, hostile headers, BOMs, memory ----------------

// GMPU_TEST_QUICK=1 (set by `make test-valgrind`): smaller inputs, no CPU-time bounds.
bool quick() {
    const char *q = std::getenv("GMPU_TEST_QUICK");
    return q && *q && std::strcmp(q, "0") != 0;
}

double thread_cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A FIFO would block the reader for ever, /dev/zero never ends: both fail at once, before
// a byte is read, as does a directory.
void test_input_must_be_a_regular_file(void **) {
    const std::string fifo = path_of("pipe.xyz");
    assert_int_equal(::mkfifo(fifo.c_str(), 0644), 0);
    expect_read_error(fifo, GMPU_ERROR_IO, {"FIFO", "not a regular file"});
    const std::string zero = path_of("zero.xyz");
    assert_int_equal(::symlink("/dev/zero", zero.c_str()), 0);
    expect_read_error(zero, GMPU_ERROR_IO, {"character device"});
    expect_read_error(fresh_dir("dir.xyz"), GMPU_ERROR_IO, {"Is a directory"});
}

// A 2 GB file of zeros (sparse: no disk used) is not read whole: the PLY fails on its first
// line, the text format on its first overlong line.
void test_huge_files_fail_on_their_first_bytes(void **) {
    for (const char *name : {"sparse.ply", "sparse.xyz", "sparse.obj", "sparse.off"}) {
        const std::string p = path_of(name);
        assert_int_equal(::truncate(put(name, "").c_str(), off_t{2} << 30), 0);
        const double t0 = thread_cpu_seconds();
        expect_read_error(p, GMPU_ERROR_PARSE, {std::string(name).find("ply") != std::string::npos ? "not a PLY file"
                                                                                                  : "longer than"});
        const double cpu = thread_cpu_seconds() - t0;
        if (cpu > 1.0 && !quick()) fail_msg("%s: %.2f s of CPU: the file was read whole", name, cpu);
        ::unlink(p.c_str());
    }
}

// 200,000 empty elements before the vertex: the duplicate-name checks are hashed, so the
// header is linear in its length (a pairwise check is quadratic: minutes of CPU).
void test_ply_header_with_many_elements_is_linear(void **) {
    std::string h = "ply\nformat ascii 1.0\n";
    const int elements = quick() ? 20000 : 200000;
    for (int i = 0; i < elements; ++i) h += "element e" + std::to_string(i) + " 0\n";
    h += "element vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n";
    const std::string p = put("many_elements.ply", h);
    const double t0 = thread_cpu_seconds();
    assert_doubles_equal(gmpu::io::read_points(p).positions, {1, 2, 3, 4, 5, 6});
    // The same with a duplicate at the very end: found, and as fast.
    std::string dup = h;
    dup.replace(dup.find("element vertex"), 0, "element e7 0\n");
    expect_read_error(put("dup_element.ply", dup), GMPU_ERROR_PARSE, {"duplicate element 'e7'"});
    const double cpu = thread_cpu_seconds() - t0;
    if (cpu > 5.0 && !quick()) fail_msg("200k-element header: %.2f s of CPU (quadratic?)", cpu);
}

// A UTF-8 byte order mark (what Windows editors write first) does not eat the first vertex.
void test_utf8_bom_is_skipped(void **) {
    const std::string bom = "\xEF\xBB\xBF";
    assert_doubles_equal(gmpu::io::read_points(put("bom.obj", bom + "v 1 2 3\nv 4 5 6\n")).positions, {1, 2, 3, 4, 5, 6});
    assert_doubles_equal(gmpu::io::read_points(put("bom.xyz", bom + "1 2 3\n4 5 6\n")).positions, {1, 2, 3, 4, 5, 6});
    assert_doubles_equal(gmpu::io::read_points(put("bom.off", bom + "OFF\n2 0 0\n1 2 3\n4 5 6\n")).positions,
                         {1, 2, 3, 4, 5, 6});
    assert_doubles_equal(gmpu::io::read_points(put("bom.ply", bom + "ply\nformat ascii 1.0\nelement vertex 1\n"
                                                                    "property float x\nproperty float y\n"
                                                                    "property float z\nend_header\n1 2 3\n"))
                             .positions,
                         {1, 2, 3});
    // In the buffer parsers too (the fuzzers' entry points).
    const std::string obj = bom + "v 7 8 9\n";
    assert_doubles_equal(gmpu::io::detail::parse_obj_buffer(obj.data(), obj.size(), "mem", gmpu::io::detail::Want::points)
                             .positions,
                         {7, 8, 9});
}

// Text formats are read into arrays sized once from a count of the lines: no growth by
// doubling (which holds up to 3x the points while copying). Lines split across the
// reader's 1 MiB chunks and a last line without its newline parse like any other.
void test_text_arrays_sized_once(void **) {
    const size_t n = 100001;
    std::string xyz, obj = "# mesh\n";
    for (size_t i = 0; i < n; ++i) {
        const std::string line = std::to_string(i) + " " + std::to_string(i % 7) + ".25 -" + std::to_string(i % 13);
        xyz += line + (i + 1 < n ? "\n" : "");
        obj += "v " + line + "\n";
    }
    for (const auto &[name, text] : {std::pair<const char *, std::string>{"many.xyz", xyz}, {"many.obj", obj}}) {
        PointCloud c = gmpu::io::read_points(put(name, text));
        assert_int_equal(c.size(), n);
        assert_true(c.positions.capacity() <= c.positions.size() + 3 * 2);
        assert_true(c.positions[3 * (n - 1)] == double(n - 1));
        assert_true(c.positions[3 * 77777 + 2] == -double(77777 % 13));
    }
}

// A symlink as the output is written through: its target gets the bytes, the link stays
// (relative links resolve from the link's directory; a chain is followed to its end).
void test_write_through_symlinks(void **) {
    const std::string dir = fresh_dir("links");
    const double v[] = {1, 2, 3};
    assert_int_equal(::mkdir((dir + "/real").c_str(), 0755), 0);
    std::ofstream(dir + "/real/cloud.xyz") << "old\n";
    assert_int_equal(::symlink("real/cloud.xyz", (dir + "/link1.xyz").c_str()), 0);
    assert_int_equal(::symlink("link1.xyz", (dir + "/link2.xyz").c_str()), 0);
    gmpu::io::write_points(dir + "/link2.xyz", v, nullptr, 1);
    assert_string_equal(slurp(dir + "/real/cloud.xyz").c_str(), "1 2 3\n");
    struct stat st;
    for (const char *link : {"/link1.xyz", "/link2.xyz"}) {
        assert_int_equal(::lstat((dir + link).c_str(), &st), 0);
        assert_true(S_ISLNK(st.st_mode));
    }
    assert_int_equal(entries(dir + "/real").size(), 1);
    assert_int_equal(::symlink("loop.xyz", (dir + "/loop.xyz").c_str()), 0);
    expect_error([&] { gmpu::io::write_points(dir + "/loop.xyz", v, nullptr, 1); }, GMPU_ERROR_IO,
                 {"loop.xyz", "symbolic links"});
    assert_int_equal(entries(dir).size(), 4);  // real, link1, link2, loop: nothing else
}

// A leftover temporary of a killed run with our pid (or any run of them) does not stop a
// write; a 251-character name (legal) gets a temporary that fits NAME_MAX.
void test_write_temporaries_fit_and_skip_leftovers(void **) {
    const std::string dir = fresh_dir("temps");
    const double v[] = {1, 2, 3};
    const std::string p = dir + "/out.xyz";
    for (int n = 0; n < 300; ++n)
        std::ofstream(p + ".tmp-gmpu-" + std::to_string(::getpid()) + "-" + std::to_string(n)) << "stale";
    gmpu::io::write_points(p, v, nullptr, 1);
    assert_string_equal(slurp(p).c_str(), "1 2 3\n");
    assert_int_equal(entries(dir).size(), 301);  // the leftovers are not ours to remove
    const std::string long_dir = fresh_dir("long");
    const std::string long_name = long_dir + "/" + std::string(247, 'n') + ".xyz";
    gmpu::io::write_points(long_name, v, nullptr, 1);
    assert_string_equal(slurp(long_name).c_str(), "1 2 3\n");
    assert_int_equal(entries(long_dir).size(), 1);
}

// ---- the in-memory parsers (what the fuzzers call) ------------------------------------

void test_buffer_parsers(void **) {
    using namespace gmpu::io::detail;
    const std::string xyz = "1 2 3\n";
    assert_int_equal(parse_xyz_buffer(xyz.data(), xyz.size(), "mem").positions.size(), 3);
    // No NUL terminator is needed: the parsers stop at `size`.
    const char digits[] = {'1', ' ', '2', ' ', '3', '4'};
    assert_doubles_equal(parse_xyz_buffer(digits, 5, "mem").positions, {1, 2, 3});
    expect_error([&] { parse_obj_buffer("f 1 2 3", 7, "buffer-name", Want::mesh); }, GMPU_ERROR_PARSE,
                 {"buffer-name: line 1"});
    expect_error([&] { parse_ply_buffer("ply", 3, "mem", Want::points); }, GMPU_ERROR_PARSE, {"end_header"});
    expect_error([&] { parse_off_buffer("", 0, "mem", Want::points); }, GMPU_ERROR_PARSE, {"mem:"});
}

// ---- the shared data sets -------------------------------------------------------------

std::string shared(const std::string &rel) {
    const char *root = std::getenv("GMPU_TEST_DATA");
    return std::string(root ? root : "tests/data") + "/" + rel;
}

void test_shared_clouds(void **) {
    glob_t g;
    assert_int_equal(::glob(shared("clouds/*.ply").c_str(), 0, nullptr, &g), 0);
    assert_true(g.gl_pathc >= 20);
    for (size_t i = 0; i < g.gl_pathc; ++i) {
        const std::string p = g.gl_pathv[i];
        const bool gt = p.size() > 7 && p.compare(p.size() - 7, 7, "_gt.ply") == 0;
        PointCloud c = gmpu::io::read_points(p);
        assert_true(c.size() >= 5000);
        assert_int_equal(c.normals.size(), gt ? c.positions.size() : 0);
        if (gt) {
            // Same points as the file without normals, and unit normals.
            PointCloud plain = gmpu::io::read_points(p.substr(0, p.size() - 7) + ".ply");
            assert_doubles_equal(plain.positions, c.positions);
            for (size_t k = 0; k < c.size(); ++k) {
                const double *n = &c.normals[3 * k];
                assert_true(std::fabs(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) - 1) < 1e-4);
            }
        }
    }
    ::globfree(&g);
    assert_int_equal(gmpu::io::read_points(shared("clouds/bunny_clean.ply")).size(), 35000);
    assert_int_equal(gmpu::io::read_points(shared("clouds/bunny_clean_gt.ply")).size(), 35000);
}

void test_shared_mesh_and_scan(void **) {
    gmpu::io::MeshData m = gmpu::io::read_mesh(shared("meshes/bunny00.off"));
    assert_int_equal(m.vertices.size(), 3 * 37706);
    assert_int_equal(m.triangles.size(), 3 * 75408);
    // The file's first vertex line.
    assert_true(std::fabs(m.vertices[0] + 0.167662) < 1e-12);
    PointCloud k = gmpu::io::read_points(shared("scans/kitten.xyz"));
    assert_int_equal(k.size(), 5210);
    assert_int_equal(k.normals.size(), 3 * 5210);
    // kitten_scan.ply holds the same points in float32.
    PointCloud f = gmpu::io::read_points(shared("clouds/kitten_scan.ply"));
    assert_int_equal(f.size(), 5210);
    for (size_t i = 0; i < f.positions.size(); ++i)
        assert_true(std::fabs(f.positions[i] - k.positions[i]) <= 1e-6 * (1 + std::fabs(k.positions[i])));
    // All the shared OFF meshes read as closed-ish meshes: indices in range, 2 V ≈ F.
    for (const char *name : {"meshes/fandisk.off", "meshes/knot2.off", "meshes/elephant.off"}) {
        gmpu::io::MeshData mm = gmpu::io::read_mesh(shared(name));
        assert_true(mm.triangles.size() / 3 > mm.vertices.size() / 3);
    }
}

}  // namespace

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_points_round_trip),
        cmocka_unit_test(test_mesh_round_trip),
        cmocka_unit_test(test_obj_writer_normals_reference_vertices),
        cmocka_unit_test(test_ply_rich_all_encodings),
        cmocka_unit_test(test_ply_every_scalar_type),
        cmocka_unit_test(test_ply_crlf_and_vertex_after_face),
        cmocka_unit_test(test_ply_header_errors),
        cmocka_unit_test(test_ply_truncated),
        cmocka_unit_test(test_ply_huge_counts_fail_fast),
        cmocka_unit_test(test_ply_bad_values),
        cmocka_unit_test(test_ply_bad_faces),
        cmocka_unit_test(test_xyz),
        cmocka_unit_test(test_off),
        cmocka_unit_test(test_obj),
        cmocka_unit_test(test_file_errors),
        cmocka_unit_test(test_write_failures_leave_nothing),
        cmocka_unit_test(test_write_replaces_atomically),
        cmocka_unit_test(test_write_large_buffered),
        cmocka_unit_test(test_input_must_be_a_regular_file),
        cmocka_unit_test(test_huge_files_fail_on_their_first_bytes),
        cmocka_unit_test(test_ply_header_with_many_elements_is_linear),
        cmocka_unit_test(test_utf8_bom_is_skipped),
        cmocka_unit_test(test_text_arrays_sized_once),
        cmocka_unit_test(test_write_temporaries_fit_and_skip_leftovers),
        cmocka_unit_test(test_write_through_symlinks),
        cmocka_unit_test(test_buffer_parsers),
        cmocka_unit_test(test_shared_clouds),
        cmocka_unit_test(test_shared_mesh_and_scan),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
