/*
 * gmpu-reconstruct — unoriented point cloud in, watertight oriented mesh out.
 * A C program that uses only the public C ABI (include/gmpu/gmpu.h).
 *
 *   gmpu-reconstruct INPUT -o OUTPUT [--normals-out POINTS.ply] [--error E]
 *                    [--max-depth D] [--resolution R] [--level L] [--threads T]
 *                    [--noise-scale S] [--max-memory BYTES] [--param NAME=VALUE]...
 *                    [--use-normals] [--sharp] [--quiet] [--version]
 *                    [--trim[=T]] [--target-triangles N] [--target-error E]
 *
 * --param sets any parameter of the library's table by name (gmpu_param_key); --help lists
 * them all with their defaults and ranges (gmpu_param_info).
 *
 * Output format from the extension (.ply, .obj, .off, .stl, .glb). Exit status 0 on success, 1 on a
 * failure (one line on stderr), 2 on bad usage. The outputs are checked before any work
 * and replaced only once all of them are written (cli/staged_output.h).
 */
#define _GNU_SOURCE /* getopt_long */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "cli/staged_output.h"
#include "gmpu/gmpu.h"

#define MAX_PARAMS 64

/* Between stages, hand the heap's free pages back to the system: glibc keeps what a stage's
 * threads freed in their arenas, so the next stage (and this program's peak) would stack on
 * top of it. The library leaves the host's heap alone; this program is the host. */
static void release_free_memory(void) {
#ifdef __GLIBC__
    malloc_trim(0);
#endif
}

typedef struct {
    const char *input, *output, *normals_out;
    double error, max_depth, resolution, level, threads, noise_scale, max_memory;
    double trim, target_triangles, target_error; /* NAN: not asked for */
    int use_normals, sharp, quiet, keep_outliers;
    int param_count; /* --param NAME=VALUE, applied after the flags above, in order */
    gmpu_param param_keys[MAX_PARAMS];
    double param_values[MAX_PARAMS];
} options;

static int parse_number(const char *flag, const char *text, double *out);

static const char *usage =
    "usage: gmpu-reconstruct INPUT -o OUTPUT [--normals-out POINTS.ply] [--error E]\n"
    "                        [--max-depth D] [--resolution R] [--level L] [--threads T]\n"
    "                        [--noise-scale S] [--max-memory BYTES] [--param NAME=VALUE]...\n"
    "                        [--use-normals] [--sharp] [--keep-outliers] [--quiet] [--version]\n"
    "                        [--trim[=T]] [--target-triangles N] [--target-error E]\n"
    "  INPUT   .ply .xyz .txt .off .obj point cloud (normals ignored unless --use-normals)\n"
    "  OUTPUT  .ply .obj .off .stl .glb mesh (closed, outward-facing; .ply with a per-vertex confidence)\n"
    "  A .ply INPUT with uchar red green blue gives each vertex its nearest point's colour\n"
    "  (written to .ply and .glb).\n"
    "  --keep-outliers fits the outliers found (points far from all others) too; by default\n"
    "  they are reported and set aside.\n"
    "  --trim[=T]  cut away surface farther than T sample spacings from every point where it\n"
    "              rises to 2T (default 1.5): the caps over a scan's holes go, leaving an\n"
    "              open mesh\n"
    "  --target-triangles N, --target-error E  decimate to at most N triangles, moving the\n"
    "              surface by at most E x the diagonal (topology kept)\n"
    "  Options take their value as the next argument or after '=' (--resolution=64).\n"
    "  A file name starting with '-' must be written ./-name.\n"
    "  --param NAME=VALUE sets any parameter (--help lists them).\n";

/* Every parameter of the library's table: name, type, default, range, doc. */
static void print_parameters(FILE *out) {
    fputs("\nparameters (--param NAME=VALUE):\n", out);
    for (int key = 1; key <= gmpu_param_count(); ++key) {
        gmpu_param_info_t p;
        if (gmpu_param_info((gmpu_param)key, &p) != GMPU_OK) continue;
        char range[64];
        snprintf(range, sizeof range, "%c%g, %g%c", p.min_exclusive ? '(' : '[', p.min, p.max, p.max_exclusive ? ')' : ']');
        fprintf(out, "  %-15s %-4s default %-11g %-15s %s\n", p.name, p.type == GMPU_TYPE_INT ? "int" : "real",
                p.default_value, range, p.doc);
    }
}

/* --param NAME=VALUE: the key by the library's name, the value a number. */
static int parse_param(const char *text, options *o) {
    const char *eq = text ? strchr(text, '=') : NULL;
    char name[64];
    if (!eq || (size_t)(eq - text) >= sizeof name) {
        fprintf(stderr, "gmpu-reconstruct: --param needs NAME=VALUE, got '%s'\n", text ? text : "");
        return 0;
    }
    memcpy(name, text, (size_t)(eq - text));
    name[eq - text] = '\0';
    const int key = gmpu_param_key(name);
    if (key == 0) {
        fprintf(stderr, "gmpu-reconstruct: --param: unknown parameter '%s' (--help lists them)\n", name);
        return 0;
    }
    if (o->param_count == MAX_PARAMS) {
        fprintf(stderr, "gmpu-reconstruct: more than %d --param options\n", MAX_PARAMS);
        return 0;
    }
    if (!parse_number(name, eq + 1, &o->param_values[o->param_count])) return 0;
    o->param_keys[o->param_count++] = (gmpu_param)key;
    return 1;
}

static int parse_number(const char *flag, const char *text, double *out) {
    char *end = NULL;
    errno = 0;
    double v = text ? strtod(text, &end) : NAN;
    if (!text || end == text || *end != '\0' || errno != 0 || !isfinite(v)) {
        fprintf(stderr, "gmpu-reconstruct: %s needs a number, got '%s'\n", flag, text ? text : "");
        return 0;
    }
    *out = v;
    return 1;
}

/* A file name option's value: never another option ("-o --threads 4" is a mistake, not an
 * output called "--threads"). */
static int parse_path(const char *flag, const char *text, const char **out) {
    if (text[0] == '-') {
        fprintf(stderr, "gmpu-reconstruct: %s needs a file name, got '%s'\n%s", flag, text, usage);
        return 0;
    }
    *out = text;
    return 1;
}

enum { OPT_NORMALS_OUT = 256, OPT_ERROR, OPT_MAX_DEPTH, OPT_RESOLUTION, OPT_LEVEL, OPT_THREADS, OPT_USE_NORMALS,
       OPT_SHARP, OPT_NOISE_SCALE, OPT_MAX_MEMORY, OPT_PARAM, OPT_KEEP_OUTLIERS, OPT_TRIM, OPT_TARGET_TRIANGLES,
       OPT_TARGET_ERROR };

/* Sample spacings beyond which --trim cuts surface (where it rises to twice that): the
 * caps over holes rise farther. */
#define DEFAULT_TRIM 1.5

static const struct option long_options[] = {
    {"output", required_argument, NULL, 'o'},
    {"normals-out", required_argument, NULL, OPT_NORMALS_OUT},
    {"error", required_argument, NULL, OPT_ERROR},
    {"max-depth", required_argument, NULL, OPT_MAX_DEPTH},
    {"resolution", required_argument, NULL, OPT_RESOLUTION},
    {"level", required_argument, NULL, OPT_LEVEL},
    {"threads", required_argument, NULL, OPT_THREADS},
    {"noise-scale", required_argument, NULL, OPT_NOISE_SCALE},
    {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
    {"param", required_argument, NULL, OPT_PARAM},
    {"use-normals", no_argument, NULL, OPT_USE_NORMALS},
    {"sharp", no_argument, NULL, OPT_SHARP},
    {"keep-outliers", no_argument, NULL, OPT_KEEP_OUTLIERS},
    {"trim", optional_argument, NULL, OPT_TRIM},
    {"target-triangles", required_argument, NULL, OPT_TARGET_TRIANGLES},
    {"target-error", required_argument, NULL, OPT_TARGET_ERROR},
    {"quiet", no_argument, NULL, 'q'},
    {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, 'V'},
    {NULL, 0, NULL, 0},
};

static int positional(options *o, const char *a) {
    if (!o->input) {
        o->input = a;
        return 1;
    }
    fprintf(stderr, "gmpu-reconstruct: unexpected argument '%s'\n%s", a, usage);
    return 0;
}

static int parse_args(int argc, char **argv, options *o) {
    memset(o, 0, sizeof *o);
    /* NAN: not given (a negative value is given, and must reach the library's range check). */
    o->error = o->max_depth = o->resolution = o->level = o->threads = o->noise_scale = o->max_memory = NAN;
    o->trim = o->target_triangles = o->target_error = NAN;
    opterr = 0; /* our own messages, one line each */
    optind = 1;
    /* "-": non-options come back in order (code 1), whatever POSIXLY_CORRECT says; ":": a
     * missing value is reported as ':' rather than '?'. */
    int c, index = -1;
    while ((c = getopt_long(argc, argv, "-:o:qhV", long_options, &index)) != -1) {
        /* The option as the user wrote it, for messages: -o is the only short one with a value. */
        char flag[64] = "-o";
        if (index >= 0) snprintf(flag, sizeof flag, "--%s", long_options[index].name);
        index = -1;
        switch (c) {
            case 1:
                if (!positional(o, optarg)) return 0;
                break;
            case 'h':
                fputs(usage, stdout);
                print_parameters(stdout);
                exit(0);
            case 'V':
                printf("gmpu-reconstruct %d.%d.%d (library %s, ABI %u)\n", GMPU_VERSION_MAJOR, GMPU_VERSION_MINOR,
                       GMPU_VERSION_PATCH, gmpu_version_string(), (unsigned)gmpu_abi_version());
                exit(0);
            case 'o':
                if (!parse_path(flag, optarg, &o->output)) return 0;
                break;
            case OPT_NORMALS_OUT:
                if (!parse_path(flag, optarg, &o->normals_out)) return 0;
                break;
            case OPT_ERROR: if (!parse_number(flag, optarg, &o->error)) return 0; break;
            case OPT_MAX_DEPTH: if (!parse_number(flag, optarg, &o->max_depth)) return 0; break;
            case OPT_RESOLUTION: if (!parse_number(flag, optarg, &o->resolution)) return 0; break;
            case OPT_LEVEL: if (!parse_number(flag, optarg, &o->level)) return 0; break;
            case OPT_THREADS: if (!parse_number(flag, optarg, &o->threads)) return 0; break;
            case OPT_NOISE_SCALE: if (!parse_number(flag, optarg, &o->noise_scale)) return 0; break;
            case OPT_MAX_MEMORY: if (!parse_number(flag, optarg, &o->max_memory)) return 0; break;
            case OPT_PARAM: if (!parse_param(optarg, o)) return 0; break;
            case OPT_TRIM:
                o->trim = DEFAULT_TRIM;
                if (optarg && !parse_number(flag, optarg, &o->trim)) return 0;
                break;
            case OPT_TARGET_TRIANGLES:
                if (!parse_number(flag, optarg, &o->target_triangles)) return 0;
                if (o->target_triangles < 1 || o->target_triangles != floor(o->target_triangles) ||
                    o->target_triangles > 4e9) {
                    fprintf(stderr, "gmpu-reconstruct: %s needs a whole number of triangles >= 1, got '%s'\n", flag,
                            optarg);
                    return 0;
                }
                break;
            case OPT_TARGET_ERROR: if (!parse_number(flag, optarg, &o->target_error)) return 0; break;
            case OPT_USE_NORMALS: o->use_normals = 1; break;
            case OPT_SHARP: o->sharp = 1; break;
            case OPT_KEEP_OUTLIERS: o->keep_outliers = 1; break;
            case 'q': o->quiet = 1; break;
            case ':': {
                const char *what = argv[optind - 1];
                if (optopt == 'o') {
                    fprintf(stderr, "gmpu-reconstruct: missing -o OUTPUT\n%s", usage);
                } else {
                    fprintf(stderr, "gmpu-reconstruct: %s needs a %s\n%s", what,
                            optopt == OPT_NORMALS_OUT ? "file name" : "number", usage);
                }
                return 0;
            }
            default:
                fprintf(stderr, "gmpu-reconstruct: unknown option '%s'\n%s", argv[optind - 1], usage);
                return 0;
        }
    }
    for (; optind < argc; ++optind) /* after "--" */
        if (!positional(o, argv[optind])) return 0;
    if (!o->input || !o->output) {
        fprintf(stderr, "gmpu-reconstruct: %s\n%s", !o->input ? "missing INPUT" : "missing -o OUTPUT", usage);
        return 0;
    }
    return 1;
}

/* ---- progress: a bar on a terminal, one line per stage otherwise ---- */

typedef struct {
    int tty, quiet;
    gmpu_stage stage;
    int last_percent;
} progress_state;

static const char *stage_name(gmpu_stage s) {
    switch (s) {
        case GMPU_STAGE_FIT: return "fit";
        case GMPU_STAGE_ORIENT: return "orient";
        case GMPU_STAGE_POLYGONIZE: return "polygonize";
        case GMPU_STAGE_READ: return "read";
    }
    return "work";
}

static int on_progress(void *user, gmpu_stage stage, double fraction) {
    progress_state *p = user;
    if (p->quiet) return 0;
    int percent = (int)(fraction * 100.0 + 0.5);
    if (stage != p->stage) {
        p->stage = stage;
        p->last_percent = -1;
        if (!p->tty) fprintf(stderr, "gmpu: %s...\n", stage_name(stage));
    }
    if (p->tty && percent != p->last_percent) {
        int filled = percent * 30 / 100;
        fprintf(stderr, "\r%-11s [%.*s%*s] %3d%%", stage_name(stage), filled,
                "##############################", 30 - filled, "", percent);
        if (percent >= 100) fputc('\n', stderr);
        fflush(stderr);
    }
    p->last_percent = percent;
    return 0;
}

static double now_seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int fail(const char *what) {
    /* gmpu_last_error() already names the status and the problem. */
    fprintf(stderr, "gmpu-reconstruct: %s: %s\n", what, gmpu_last_error());
    return 1;
}

/* A failed write of a staging file, told about the user's file: the library's message names
 * the staging path (and its temporaries, which start with it), which the user never gave. */
static int fail_staged(const char *what, const staged_output *out) {
    const char *msg = gmpu_last_error(), *at = out->staging[0] ? strstr(msg, out->staging) : NULL;
    if (!at) return fail(what);
    const char *rest = at + strlen(out->staging);
    if (*rest == '.') /* a temporary beside the staging file: ".tmp-gmpu-PID-N" */
        while (*rest && *rest != ':' && *rest != ' ') ++rest;
    fprintf(stderr, "gmpu-reconstruct: %s: %.*s%s%s\n", what, (int)(at - msg), msg, out->given, rest);
    return 1;
}

static int set(gmpu_surface *s, gmpu_param key, double value) {
    return isnan(value) || gmpu_surface_set_param(s, key, value) == GMPU_OK;
}

/* Writes the mesh and the oriented points to their staging files, then moves both into
 * place: a failure anywhere leaves every target as it was. */
static int write_outputs(gmpu_mesh **mesh, gmpu_surface **surface, const gmpu_points *cloud, staged_output *mesh_out,
                         staged_output *points_out) {
    char msg[PATH_MAX + 256];
    const size_t n = gmpu_points_count(cloud);
    if (!output_stage(mesh_out, msg, sizeof msg)) goto failed;
    if (gmpu_mesh_write(*mesh, mesh_out->staging) != GMPU_OK) {
        const int status = fail_staged("cannot write mesh", mesh_out);
        output_discard(mesh_out);
        return status;
    }
    /* Written: free it before the oriented points need their memory (peak matters at 1M). */
    gmpu_mesh_destroy(*mesh);
    *mesh = NULL;
    if (points_out) {
        if (!output_stage(points_out, msg, sizeof msg)) goto failed;
        double *normals = malloc(3 * n * sizeof *normals);
        gmpu_points *oriented = NULL;
        int ok = normals && gmpu_surface_copy_normals(*surface, normals, n) == GMPU_OK;
        /* Its normals copied, the surface is done: free it before the copy below (at a
         * million points, the two together would set the peak). */
        gmpu_surface_destroy(*surface);
        *surface = NULL;
        /* The surface's pages back to the system before the copy: kept in the heap, the copy
         * would stack on them and set the run's peak. */
        release_free_memory();
        ok = ok && gmpu_points_create(gmpu_points_positions(cloud), normals, n, &oriented) == GMPU_OK;
        free(normals);
        const int written = ok && gmpu_points_write(oriented, points_out->staging) == GMPU_OK;
        gmpu_points_destroy(oriented);
        if (!written) {
            const int status = ok ? fail_staged("cannot write oriented points", points_out)
                                  : fail("cannot write oriented points");
            output_discard(points_out);
            output_discard(mesh_out);
            return status;
        }
    }
    if (!output_commit(mesh_out, msg, sizeof msg)) goto failed;
    if (points_out && !output_commit(points_out, msg, sizeof msg)) goto failed;
    return 0;
failed:
    output_discard(mesh_out);
    if (points_out) output_discard(points_out);
    fprintf(stderr, "gmpu-reconstruct: %s\n", msg);
    return 1;
}

/* Every output checked before any work: a bad path fails in milliseconds, not after the
 * reconstruction, and nothing the user did not ask to replace can be. */
static int prepare_outputs(const options *o, staged_output *mesh_out, staged_output *points_out) {
    char msg[PATH_MAX + 256];
    if (!output_prepare(mesh_out, o->output, OUTPUT_MESH, o->input, msg, sizeof msg) ||
        (o->normals_out && !output_prepare(points_out, o->normals_out, OUTPUT_POINTS, o->input, msg, sizeof msg))) {
        fprintf(stderr, "gmpu-reconstruct: %s\n", msg);
        return 0;
    }
    if (o->normals_out && output_same_target(mesh_out, points_out)) {
        fprintf(stderr, "gmpu-reconstruct: -o %s and --normals-out %s are the same file\n", o->output,
                o->normals_out);
        return 0;
    }
    return 1;
}

/* Replaces *mesh with its trimmed, then simplified, version when the options ask for it. */
static int finish_mesh(const options *o, gmpu_mesh **mesh) {
    gmpu_mesh *next = NULL;
    if (!isnan(o->trim)) {
        if (gmpu_mesh_trim(*mesh, o->trim, &next) != GMPU_OK) return !fail("trim failed");
        gmpu_mesh_destroy(*mesh);
        *mesh = next;
    }
    if (!isnan(o->target_triangles) || !isnan(o->target_error)) {
        /* One limit alone: the other does not bound. */
        const size_t triangles = isnan(o->target_triangles) ? 0 : (size_t)o->target_triangles;
        const double error = isnan(o->target_error) ? 1.0 : o->target_error;
        if (gmpu_mesh_simplify(*mesh, triangles, error, &next) != GMPU_OK) return !fail("simplify failed");
        gmpu_mesh_destroy(*mesh);
        *mesh = next;
    }
    return 1;
}

/* Coloured input (a PLY with red green blue) gives a coloured mesh: each vertex takes its
 * nearest input point's colour. */
static int colour_mesh(const gmpu_points *cloud, gmpu_mesh **mesh) {
    gmpu_mesh *next = NULL;
    if (!gmpu_points_colors(cloud)) return 1;
    if (gmpu_mesh_color_from_points(*mesh, cloud, &next) != GMPU_OK) return !fail("colouring the mesh failed");
    gmpu_mesh_destroy(*mesh);
    *mesh = next;
    return 1;
}

int main(int argc, char **argv) {
    options o;
    if (!parse_args(argc, argv, &o)) return 2;
    staged_output mesh_out, points_out;
    if (!prepare_outputs(&o, &mesh_out, &points_out)) return 1;
    output_install_signal_cleanup();

    progress_state prog = {isatty(STDERR_FILENO), o.quiet, 0, -1};
    double t_start = now_seconds();
    gmpu_points *cloud = NULL;
    gmpu_surface *surface = NULL;
    gmpu_mesh *mesh = NULL;
    size_t mesh_vertices = 0, mesh_triangles = 0;
    double stat[10] = {0};
    int stat_count = 0, rc = 1;

    /* The budget bounds the read too: a file whose points would not fit fails before its
     * body is read. Reading shows a bar on a terminal (elsewhere its line would precede a
     * read error's, which is one line). */
    if (gmpu_points_read_with(o.input, isnan(o.max_memory) ? 0.0 : o.max_memory, prog.tty ? on_progress : NULL, &prog,
                              &cloud) != GMPU_OK) {
        rc = fail("cannot read input");
        goto done;
    }
    double t_read = now_seconds();
    size_t n = gmpu_points_count(cloud);
    if (gmpu_surface_create(&surface) != GMPU_OK) { rc = fail("cannot create surface"); goto done; }
    if (!set(surface, GMPU_PARAM_ERROR, o.error) || !set(surface, GMPU_PARAM_MAX_DEPTH, o.max_depth) ||
        !set(surface, GMPU_PARAM_RESOLUTION, o.resolution) || !set(surface, GMPU_PARAM_LEVEL, o.level) ||
        !set(surface, GMPU_PARAM_THREADS, o.threads) || !set(surface, GMPU_PARAM_NOISE_SCALE, o.noise_scale) ||
        !set(surface, GMPU_PARAM_MAX_MEMORY, o.max_memory) ||
        !set(surface, GMPU_PARAM_SHARP_FEATURES, o.sharp ? 1.0 : NAN) ||
        !set(surface, GMPU_PARAM_REMOVE_OUTLIERS, o.keep_outliers ? 0.0 : NAN)) {
        rc = fail("bad parameter");
        goto done;
    }
    for (int k = 0; k < o.param_count; ++k)
        if (!set(surface, o.param_keys[k], o.param_values[k])) {
            rc = fail("bad parameter");
            goto done;
        }
    gmpu_surface_set_progress(surface, on_progress, &prog);
    if (gmpu_surface_set_points_f64(surface, gmpu_points_positions(cloud), n, 0) != GMPU_OK) {
        rc = fail("bad input points");
        goto done;
    }
    double t_points = now_seconds();
    double outliers = 0;
    if (!o.quiet && gmpu_surface_get_stat(surface, GMPU_STAT_OUTLIERS, &outliers) == GMPU_OK && outliers > 0)
        fprintf(stderr, "gmpu: %.0f outlier points (far from all others) %s\n", outliers,
                o.keep_outliers ? "kept (--keep-outliers)" : "set aside");
    if (o.use_normals) {
        if (!gmpu_points_normals(cloud)) {
            fprintf(stderr, "gmpu-reconstruct: --use-normals given but %s has no normals\n", o.input);
            goto done;
        }
        if (gmpu_surface_set_normals_f64(surface, gmpu_points_normals(cloud), n, 0) != GMPU_OK) {
            rc = fail("bad input normals");
            goto done;
        }
    }
    if (gmpu_surface_fit(surface) != GMPU_OK) { rc = fail("fit failed"); goto done; }
    release_free_memory();
    if (gmpu_surface_orient(surface) != GMPU_OK) { rc = fail("orient failed"); goto done; }
    release_free_memory();
    if (gmpu_surface_polygonize(surface, &mesh) != GMPU_OK) { rc = fail("polygonize failed"); goto done; }
    release_free_memory();
    double t_finish = now_seconds();
    if (!finish_mesh(&o, &mesh) || !colour_mesh(cloud, &mesh)) goto done;
    double t_write = now_seconds();
    mesh_vertices = gmpu_mesh_vertex_count(mesh);
    mesh_triangles = gmpu_mesh_triangle_count(mesh);
    /* The summary's figures, read now: writing the oriented points frees the surface. */
    const gmpu_stat keys[] = {GMPU_STAT_CELLS, GMPU_STAT_LEAVES, GMPU_STAT_DEPTH, GMPU_STAT_COMPONENTS,
                              GMPU_STAT_NOISE, GMPU_STAT_EFFECTIVE_ERROR, GMPU_STAT_FIT_SECONDS,
                              GMPU_STAT_ORIENT_SECONDS, GMPU_STAT_POLYGONIZE_SECONDS, GMPU_STAT_RESOLUTION};
    stat_count = (int)(sizeof keys / sizeof keys[0]);
    for (int k = 0; k < stat_count; ++k) gmpu_surface_get_stat(surface, keys[k], &stat[k]);
    if (write_outputs(&mesh, &surface, cloud, &mesh_out, o.normals_out ? &points_out : NULL) != 0) goto done;
    double t_end = now_seconds();

    if (!o.quiet) {
        const double cells = stat[0], leaves = stat[1], depth = stat[2], comps = stat[3], noise = stat[4],
                     eps = stat[5], fit = stat[6], orient = stat[7], poly = stat[8], res = stat[9];
        fprintf(stderr,
                "gmpu: %zu points, %.0f cells (%.0f leaves, depth %.0f) in %.0f connected group%s\n"
                "gmpu: estimated noise %.3f%% of the diagonal, fitted to error %.3f%%\n"
                "gmpu: mesh %zu vertices, %zu triangles at resolution %.0f -> %s\n"
                "gmpu: time read %.3f s, points %.3f s, fit %.3f s, orient %.3f s, polygonize %.3f s, "
                "finish %.3f s, write %.3f s, total %.3f s\n",
                n, cells, leaves, depth, comps, comps == 1 ? "" : "s", 100 * noise, 100 * eps,
                mesh_vertices, mesh_triangles, res, o.output, t_read - t_start, t_points - t_read, fit,
                orient, poly, t_write - t_finish, t_end - t_write, t_end - t_start);
    }
    rc = 0;

done:
    gmpu_mesh_destroy(mesh);
    gmpu_surface_destroy(surface);
    gmpu_points_destroy(cloud);
    return rc;
}
