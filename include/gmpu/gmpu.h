/*
 * gmpu.h — the whole C ABI of gmpu: unoriented points → oriented MPU implicit → mesh.
 *
 * The pipeline has one verb per stage, each reading the previous stage's result:
 *
 *     gmpu_surface_create → set_points (→ set_normals) → fit → orient → evaluate / polygonize
 *
 * Conventions that hold for every function below:
 *   - Every fallible function returns a gmpu_status; GMPU_OK is 0. On failure nothing is
 *     half-done: outputs are left untouched (or NULL), no file is left half-written, and
 *     the handle stays usable and destroyable.
 *   - The message of a failure is available from gmpu_last_error() (the calling thread's
 *     last failure, any function) and, for calls that modify a surface, also from
 *     gmpu_surface_last_error(surface).
 *   - Ownership: what gmpu_*_create / gmpu_*_read / gmpu_surface_polygonize /
 *     gmpu_mesh_simplify / gmpu_mesh_trim hands out,
 *     the matching gmpu_*_destroy frees. Pointers returned by accessors are owned by the
 *     object they came from and stay valid until it is destroyed. Input arrays are
 *     copied; gmpu never keeps a caller's pointer.
 *   - No function throws, aborts or longjmps. All coordinates are in the caller's units.
 *   - f is positive inside the reconstructed solid and negative outside; normals point
 *     out of the solid.
 *   - Thread safety: different handles never share mutable state and may be used from
 *     different threads at once. On one surface handle, functions taking a const pointer
 *     (evaluate, copy_normals, copy_normals_at, get_param, get_stat, point_count,
 *     last_error) may run concurrently with each other; every other call on that handle
 *     needs exclusive access. Meshes and point sets never change after creation: all their accessors may
 *     run concurrently; only destroy needs exclusive access. gmpu keeps no global mutable
 *     state; gmpu_last_error() is per thread; a progress callback runs only on the thread
 *     that called fit, orient or polygonize.
 *
 * Parameters and statistics go through gmpu_surface_set_param / gmpu_surface_get_stat with
 * an enum key (as zstd does), so new knobs never change a struct layout. Enum values are
 * fixed forever; new ones are only ever appended.
 */
#ifndef GMPU_GMPU_H
#define GMPU_GMPU_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32) && defined(GMPU_BUILDING_LIBRARY)
#define GMPU_API __declspec(dllexport)
#elif defined(_WIN32)
#define GMPU_API
#else
#define GMPU_API __attribute__((visibility("default")))
#endif

/* Version of this header. Compare with gmpu_version_number() to detect a mismatched
 * library at run time. GMPU_ABI_VERSION changes only when the ABI breaks (it is the
 * SONAME's number: libgmpu.so.1). The minor version grows with every addition:
 *   0.3: the parameter table (gmpu_param_count, gmpu_param_info, gmpu_param_key).
 *   0.4: meshes from arrays with normals, confidence, colours (gmpu_mesh_create_with);
 *        colours of PLY points and of meshes (gmpu_points_colors, gmpu_points_create_with,
 *        gmpu_mesh_colors, gmpu_mesh_color_from_points); statistics' names
 *        (gmpu_stat_count, gmpu_stat_name); tiles on a shared grid
 *        (gmpu_surface_evaluate_grid, gmpu_grid_polygonize, gmpu_mesh_grid_keys).
 *   0.5: the normals of chosen points (gmpu_surface_copy_normals_at). */
#define GMPU_VERSION_MAJOR 0
#define GMPU_VERSION_MINOR 5
#define GMPU_VERSION_PATCH 0
#define GMPU_VERSION_NUMBER 500 /* MAJOR*10000 + MINOR*100 + PATCH */
#define GMPU_ABI_VERSION 1

#ifdef __cplusplus
extern "C" {
#endif

/* ---- opaque handles ------------------------------------------------------------------ */

/* A reconstruction: the input points, the octree of local fits, their orientation. */
typedef struct gmpu_surface gmpu_surface;
/* A triangle mesh (output of polygonize, or built from caller arrays for writing). */
typedef struct gmpu_mesh gmpu_mesh;
/* A point cloud read from a file: positions and optional normals. */
typedef struct gmpu_points gmpu_points;

/* ---- status codes -------------------------------------------------------------------- */

typedef enum gmpu_status {
    GMPU_OK = 0,
    GMPU_ERROR_INVALID_ARGUMENT = 1, /* NULL pointer, bad count/stride, parameter out of range */
    GMPU_ERROR_INVALID_INPUT = 2,    /* NaN/inf coordinates, too few points, size mismatch */
    GMPU_ERROR_DEGENERATE_INPUT = 3, /* identical, collinear or coplanar points: no solid */
    GMPU_ERROR_WRONG_ORDER = 4,      /* a stage called before the one it needs */
    GMPU_ERROR_OUT_OF_MEMORY = 5,
    GMPU_ERROR_LIMIT_EXCEEDED = 6,   /* a cap (cells, triangles, memory budget) was hit */
    GMPU_ERROR_CANCELLED = 7,        /* the progress callback returned non-zero */
    GMPU_ERROR_IO = 8,               /* a file could not be opened, read or written */
    GMPU_ERROR_PARSE = 9,            /* a file's contents are malformed or truncated */
    GMPU_ERROR_UNSUPPORTED = 10,     /* unknown file extension or format variant */
    GMPU_ERROR_INTERNAL = 11,        /* a bug: please report it with the message */
    GMPU_ERROR_BUSY = 12             /* a call on a surface from its own progress callback */
} gmpu_status;

/* The enumerator's name ("GMPU_ERROR_CANCELLED"), or "GMPU_UNKNOWN_STATUS". Never NULL;
 * static storage. */
GMPU_API const char *gmpu_status_name(gmpu_status status);

/* Message of the most recent failed gmpu call made by the calling thread ("" if none).
 * Valid until the next gmpu call on this thread. Thread-safe. */
GMPU_API const char *gmpu_last_error(void);

/* ---- version ------------------------------------------------------------------------- */

GMPU_API uint32_t gmpu_version_number(void);     /* GMPU_VERSION_NUMBER of the library */
GMPU_API const char *gmpu_version_string(void);  /* "0.1.0"; static storage */
GMPU_API uint32_t gmpu_abi_version(void);        /* GMPU_ABI_VERSION of the library */

/* ---- parameters, stages, statistics -------------------------------------------------- */

/* Each parameter's comment ends with "Default D, range R." (R: "a..b" for integers, "[a, b]"
 * or "(a, b)" for reals); tests/c/test_docs_match.cpp checks both against the library. */
typedef enum gmpu_param {
    /* ε: how far a cell's points may lie from its local fit, as a fraction of the
     * bounding-box diagonal: the 90th percentile of their Taubin distances must be below ε
     * and the largest below 3ε. Smaller keeps more detail and costs time. Changing it
     * discards a previous fit. Default 0.002, range (0, 1). */
    GMPU_PARAM_ERROR = 1,
    /* Deepest octree level (root = 0). Discards a previous fit. Default 10, range 1..16. */
    GMPU_PARAM_MAX_DEPTH = 2,
    /* Fewest points a local fit uses; the support radius grows until it holds them.
     * Discards a previous fit. Default 15, range 6..1000. */
    GMPU_PARAM_MIN_POINTS = 3,
    /* α: support radius = α × cell diagonal. Discards a previous fit. Default 0.75,
     * range [0.5, 2]. */
    GMPU_PARAM_SUPPORT_SCALE = 4,
    /* 1: fit piecewise quadrics (min of two or three bivariate quadratics) where a small
     * cell straddles a sharp edge or corner, found by clustering local normals (paper §3.2).
     * 0: smooth models only. Off by default: on the clouds we measure the piecewise fits need
     * fewer cells and give slightly smaller distances, but the grid polygonizer rounds edges
     * anyway and they occasionally make a false edge (a handle on the bunny); see README.
     * Discards a previous fit. Default 0, range 0..1. */
    GMPU_PARAM_SHARP_FEATURES = 5,
    /* Polygonize: grid cubes along the longest side of the points' bounding box.
     * 0 picks one from the octree (fine enough for the detail the fit has; on dense, clean
     * clouds coarsened towards 2 triangles per input point) and decimates a mesh still over
     * 2 triangles per input point; otherwise at least 8, and every triangle of that grid is
     * kept. Default 0, range 0..4096. */
    GMPU_PARAM_RESOLUTION = 6,
    /* Level of detail: evaluate and polygonize using octree cells down to this level
     * only (paper Fig. 7), and deeper only where a cell of this level fits its points worse
     * than 7 % of its size (so the coarse surface keeps the topology of the full one);
     * 0 uses every level. Default 0, range 0..16. */
    GMPU_PARAM_LEVEL = 7,
    /* Worker threads for set_points (kd-tree build, outlier scan), fit, orient and
     * polygonize; 0 uses every core. Default 0, range 0..1024. */
    GMPU_PARAM_THREADS = 8,
    /* Resource cap: fit fails with GMPU_ERROR_LIMIT_EXCEEDED instead of creating more
     * octree cells than this (the default is about 4 GB). Default 2e7, range 1..1e9. */
    GMPU_PARAM_MAX_CELLS = 9,
    /* Resource cap: polygonize fails with GMPU_ERROR_LIMIT_EXCEEDED instead of making
     * more triangles than this, counted as marching cubes makes them (before closed
     * pieces that no input point supports are dropped). Default 1e8, range 1..2e9. */
    GMPU_PARAM_MAX_TRIANGLES = 10,
    /* Noise floor for ε: fit estimates the sampling noise σ̂ and works to
     * max(GMPU_PARAM_ERROR, NOISE_SCALE × σ̂), since fitting below the noise only fits the
     * noise; 0 turns the floor off. Discards a previous fit. Default 1.75, range [0, 20]. */
    GMPU_PARAM_NOISE_SCALE = 11,
    /* Memory budget in bytes: fit, orient and polygonize first estimate their peak memory
     * (from the point count, the cell cap, the fit's cells and the grid resolution) and fail with
     * GMPU_ERROR_LIMIT_EXCEEDED, naming the estimate and the budget, instead of starting
     * work the machine cannot hold. Default half the physical memory, range 1e6..1e15. */
    GMPU_PARAM_MAX_MEMORY = 12,
    /* 1: set_points leaves out of the fit the outliers it finds (points far from every other
     * compared with the cloud's spacing), so that they set neither the scale nor a blob; each
     * takes the normal of the kept point nearest to it. 0: they are fitted like the others.
     * Either way GMPU_STAT_OUTLIERS counts them. Read by set_points: set it before.
     * Default 1, range 0..1. */
    GMPU_PARAM_REMOVE_OUTLIERS = 13,
    /* Which implicit evaluate and polygonize use. 0: the MPU blend of the local fits (the
     * paper's). 1: a smooth implicit solved over the whole cloud from the oriented points
     * (screened-Poisson-like least squares on a grid around the points), which averages the
     * sampling noise instead of following it. 3: the blend held to within a quarter of the
     * sample spacing of that smooth implicit: the blend's detail where the two agree, the
     * smooth implicit's shape where the blend strays (past the end of a thin part, bridges
     * between parts that nearly touch). 2: 1 where fit's estimated noise is at least 0.3 % of
     * the bounding-box diagonal, else 3 on clouds of fewer than 20,000 points (where fit
     * found thin walls, two sheets in one leaf, held less tightly where the smooth implicit
     * has merged a wall's two sheets), and on clouds of up to 200,000 points without thin
     * walls where the blend's mesh strays from the data (over 0.5 % of its area more than 5 local
     * sample spacings from every point: a lump past a sparse foot, a bridge), there with the
     * smooth implicit on a grid twice as coarse and held to within one spacing; else 0. But a
     * cloud of fewer than 20,000 points with no estimated noise whose neighbourhoods read as
     * two sheets under a sample spacing apart in two of five (in one of five where they are
     * under 0.6 of a spacing apart) (a thin shell: a hollow box, a pipe, a plate; a part that
     * is mostly blades that thin) gets that wall instead: the slab between the two sheets its
     * points lie on, ended where they end, each point's normal facing away from the wall's
     * middle. Read by orient (which makes that test's mesh, handed out by the next
     * polygonize if the blend stays the surface, and solves the smooth implicit) and
     * polygonize (which tests, solves or drops them if the value changed since).
     * Default 2, range 0..3. */
    GMPU_PARAM_SURFACE = 14
} gmpu_param;

/* The parameter table: what every gmpu_param key is, for bindings and tools that list,
 * document or validate parameters without restating them. Keys are 1..gmpu_param_count(),
 * with no gaps. */
typedef enum gmpu_value_type {
    GMPU_TYPE_INT = 1,  /* only whole numbers are accepted (0/1 for a switch) */
    GMPU_TYPE_REAL = 2
} gmpu_value_type;

typedef struct gmpu_param_info_t {
    const char *name;       /* "max_depth": the enumerator's suffix, lower case */
    gmpu_value_type type;
    double default_value;   /* a new surface's value (GMPU_PARAM_MAX_MEMORY's is this machine's) */
    double min, max;        /* the accepted range */
    int min_exclusive;      /* 1 when min itself is refused */
    int max_exclusive;      /* 1 when max itself is refused */
    int refits;             /* 1 when changing the value discards a previous fit */
    const char *doc;        /* one line: what the parameter does */
} gmpu_param_info_t;

/* Number of parameter keys: they are 1..gmpu_param_count(). */
GMPU_API int gmpu_param_count(void);

/* Fills *info for key. The strings are the library's (static storage, never freed).
 * Errors: INVALID_ARGUMENT (info is NULL, or key is not 1..gmpu_param_count()). */
GMPU_API gmpu_status gmpu_param_info(gmpu_param key, gmpu_param_info_t *info);

/* The key whose name is name ("max_depth", or its enumerator "GMPU_PARAM_MAX_DEPTH");
 * 0 when there is none or name is NULL. */
GMPU_API int gmpu_param_key(const char *name);

typedef enum gmpu_stage {
    GMPU_STAGE_FIT = 1,
    GMPU_STAGE_ORIENT = 2,
    GMPU_STAGE_POLYGONIZE = 3,
    GMPU_STAGE_READ = 4 /* gmpu_points_read_with */
} gmpu_stage;

typedef enum gmpu_stat {
    GMPU_STAT_POINTS = 1,             /* input points */
    GMPU_STAT_CELLS = 2,              /* octree cells, all levels */
    GMPU_STAT_LEAVES = 3,             /* leaf cells (the local functions that are blended) */
    GMPU_STAT_DEPTH = 4,              /* deepest leaf level */
    GMPU_STAT_QUADRIC_CELLS = 5,      /* leaves fitted with a general quadric */
    GMPU_STAT_BIVARIATE_CELLS = 6,    /* leaves fitted with a bivariate quadratic */
    GMPU_STAT_PIECEWISE_CELLS = 7,    /* leaves fitted with piecewise quadrics (edge/corner) */
    GMPU_STAT_COMPONENTS = 8,         /* connected components of orient's leaf-cell graph: one
                                       * per separate shape, plus any isolated cells (the
                                       * mesh's own components may be fewer) */
    GMPU_STAT_FLIPPED_CELLS = 9,      /* leaves whose fitted sign orient reversed */
    GMPU_STAT_FIT_SECONDS = 10,       /* wall time of the last fit */
    GMPU_STAT_ORIENT_SECONDS = 11,    /* wall time of the last orient; on a dense noise-free
                                       * cloud orient polygonizes the blend to test it for
                                       * strays (README), and once polygonize hands that mesh
                                       * out its time counts as polygonize's instead */
    GMPU_STAT_POLYGONIZE_SECONDS = 12, /* wall time of the last polygonize, with that of the
                                        * mesh orient made for it */
    GMPU_STAT_RESOLUTION = 13,        /* grid resolution the last polygonize used */
    GMPU_STAT_BBOX_DIAGONAL = 14,     /* diagonal of the points' bounding box (outliers aside) */
    GMPU_STAT_NOISE = 15,             /* estimated noise σ̂, as a fraction of the diagonal */
    GMPU_STAT_EFFECTIVE_ERROR = 16,   /* the ε fit worked to, as a fraction of the diagonal */
    GMPU_STAT_OUTLIERS = 17           /* input points set_points found to be outliers: far
                                       * from every other point compared with the cloud's
                                       * spacing; unless GMPU_PARAM_REMOVE_OUTLIERS is 0 they
                                       * set no scale and join no fit */
} gmpu_stat;

/* Number of statistic keys: they are 1..gmpu_stat_count(). */
GMPU_API int gmpu_stat_count(void);
/* The statistic's name ("fit_seconds": the enumerator's suffix, lower case; static storage),
 * or NULL when key is not 1..gmpu_stat_count(). */
GMPU_API const char *gmpu_stat_name(gmpu_stat key);

/* Progress and cancellation. Called on the thread that called fit / orient / polygonize,
 * at least every 50 ms of that thread's CPU time (from the call to its return, so a machine
 * busy with other work stretches the wall-clock interval) and at most every 10 ms, with
 * fraction in [0, 1] (non-decreasing within a stage; 1 when the stage completes). Return 0
 * to go on; non-zero cancels: the call stops within 100 ms of work (CPU time of all its
 * threads) and returns GMPU_ERROR_CANCELLED, and the surface keeps the stages completed
 * before the cancelled one. The callback must not call gmpu functions on the same
 * surface: they return GMPU_ERROR_BUSY and do nothing (point_count and last_error answer);
 * gmpu_surface_destroy is deferred until the stage returns, and cancels it. Other surfaces
 * may be used freely. */
typedef int (*gmpu_progress_fn)(void *user, gmpu_stage stage, double fraction);

/* ---- surface: create, configure, destroy --------------------------------------------- */

/* Makes an empty surface with default parameters. *out is set to NULL on failure.
 * Errors: INVALID_ARGUMENT (out is NULL), OUT_OF_MEMORY. */
GMPU_API gmpu_status gmpu_surface_create(gmpu_surface **out);

/* Frees the surface and everything it owns. NULL is a no-op. Meshes made by polygonize
 * are independent and stay valid. Calling it twice on the same pointer is undefined (as
 * with free); bindings guard against that. */
GMPU_API void gmpu_surface_destroy(gmpu_surface *surface);

/* Message of the last failed call that modified this surface ("" if none). Valid until the
 * next non-const call on the surface. Returns "" for NULL. */
GMPU_API const char *gmpu_surface_last_error(const gmpu_surface *surface);

/* Sets / reads one parameter (see gmpu_param). Errors: INVALID_ARGUMENT (NULL surface,
 * unknown key, value out of range or not finite; the message names the range). */
GMPU_API gmpu_status gmpu_surface_set_param(gmpu_surface *surface, gmpu_param key, double value);
GMPU_API gmpu_status gmpu_surface_get_param(const gmpu_surface *surface, gmpu_param key,
                                            double *value);

/* Reads a statistic of the latest completed stages (0 before they ran). Errors:
 * INVALID_ARGUMENT (NULL pointer or unknown key). */
GMPU_API gmpu_status gmpu_surface_get_stat(const gmpu_surface *surface, gmpu_stat key,
                                           double *value);

/* Registers the progress callback (NULL to remove). user is passed back untouched. */
GMPU_API gmpu_status gmpu_surface_set_progress(gmpu_surface *surface, gmpu_progress_fn fn,
                                               void *user);

/* ---- surface: input ------------------------------------------------------------------ */

/* Copies count points, x y z each, from xyz; consecutive points are stride bytes apart
 * (0 means tightly packed: 3 × sizeof(double) or 3 × sizeof(float)). Replaces earlier
 * points and discards any fit, orientation and input normals. Outliers — points whose 4th
 * nearest neighbour is over 20 times farther than is typical for the cloud — are set aside
 * (GMPU_STAT_OUTLIERS) unless GMPU_PARAM_REMOVE_OUTLIERS is 0: they neither set the scale
 * (the bounding box, ε, the grid are the other points') nor join a fit; they still count as
 * points for set_normals and copy_normals. Spatially separated clusters — groups of points
 * whose bounding boxes are farther apart than the larger one's longest side, each of at
 * least 64 points and GMPU_PARAM_MIN_POINTS — are each reconstructed at their own scale
 * (their own outliers, octree, ε, orientation and grid, as if each were alone); every later
 * call treats them as one surface: one mesh (the clusters' meshes in the order of their
 * first points), normals in input order, evaluate answered by the cluster whose box is
 * nearest, statistics summed (depth and resolution: the largest; noise and effective
 * error: the cluster with most points). A failed or cancelled fit of such clusters keeps no
 * fit (the clusters refit in turn).
 * Errors: INVALID_ARGUMENT (NULL, stride smaller than one point, count × stride beyond the
 * address space), INVALID_INPUT (fewer
 * points than GMPU_PARAM_MIN_POINTS; a NaN or infinite coordinate, with its index; a
 * coordinate beyond ±1e300 or a cloud spanning less than 1e-300: they cannot be normalised;
 * points spaced below a millionth of their extent that do not form separate clusters), DEGENERATE_INPUT (all points identical, collinear or coplanar: they bound no volume),
 * OUT_OF_MEMORY. On failure the previous points are kept. Cost: O(n log n); the kd-tree and
 * the outlier scan run on GMPU_PARAM_THREADS threads (the same result on any number). */
GMPU_API gmpu_status gmpu_surface_set_points_f64(gmpu_surface *surface, const double *xyz,
                                                 size_t count, size_t stride);
GMPU_API gmpu_status gmpu_surface_set_points_f32(gmpu_surface *surface, const float *xyz,
                                                 size_t count, size_t stride);

/* Optional: outward normals for the points, same count and order. When given, orient
 * signs each local fit by agreement with them and belief propagation is skipped; they
 * need not be unit length (any finite, non-zero length: 1e-320 and 1e300 are fine).
 * Discards any orientation.
 * Errors: INVALID_ARGUMENT, WRONG_ORDER (no points yet), INVALID_INPUT (count differs from
 * the point count; NaN, inf or zero normal, with its index). */
GMPU_API gmpu_status gmpu_surface_set_normals_f64(gmpu_surface *surface, const double *nxyz,
                                                  size_t count, size_t stride);
GMPU_API gmpu_status gmpu_surface_set_normals_f32(gmpu_surface *surface, const float *nxyz,
                                                  size_t count, size_t stride);

/* Number of points set (0 before set_points or for NULL). */
GMPU_API size_t gmpu_surface_point_count(const gmpu_surface *surface);

/* ---- surface: the stages ------------------------------------------------------------- */

/* Builds the adaptive octree and a local shape function per cell (paper §3): surface
 * variation σ > 0.25 → general quadric (Taubin fit), else bivariate quadratic in the PCA
 * frame, piecewise quadrics at sharp features; cells are subdivided until the Taubin
 * error is below ε = max(GMPU_PARAM_ERROR, GMPU_PARAM_NOISE_SCALE × estimated noise).
 * Discards a previous orientation.
 * Errors: WRONG_ORDER (no points), LIMIT_EXCEEDED (GMPU_PARAM_MAX_CELLS, GMPU_PARAM_MAX_MEMORY), CANCELLED,
 * OUT_OF_MEMORY. Cost: about O(n log n); 35k points take ~0.1 s on 2 cores. */
GMPU_API gmpu_status gmpu_surface_fit(gmpu_surface *surface);

/* Gives every local function one consistent sign (paper §4): max-product belief
 * propagation on the face-adjacency graph of leaf cells, advanced as a front over each
 * connected piece; then each piece is turned so that f is positive inside the solid
 * (nested shells alternate: a shell inside a shell bounds a cavity). With input normals,
 * their agreement signs the fits instead. Also computes the per-point oriented normals.
 * Errors: WRONG_ORDER (not fitted), LIMIT_EXCEEDED (GMPU_PARAM_MAX_MEMORY, checked before it
 * starts; the fit is kept), CANCELLED, OUT_OF_MEMORY. */
GMPU_API gmpu_status gmpu_surface_orient(gmpu_surface *surface);

/* Evaluates the blended implicit f (partition of unity, quadratic B-spline weights) at
 * count points xyz (3 doubles each, packed). values (count doubles) and gradients
 * (3 × count doubles, ∇f) may each be NULL, but not both. f is in the caller's length
 * units (about the signed distance near the surface, positive inside). Away from the data
 * (beyond a few point spacings of every input point) f is the distance to the nearest
 * input point, signed by the winding number of the oriented points where it is clearly 0
 * or 1 and by the nearby points' normals elsewhere: never zero there, so no surface.
 * Honours GMPU_PARAM_LEVEL and GMPU_PARAM_RESOLUTION: near the data, trust is widened to two
 * cubes of the grid polygonize would use (GMPU_PARAM_RESOLUTION, or the default one when it is
 * 0), as polygonize widens it, so that f = 0 on the vertices of that mesh; changing the
 * resolution can change f near the data. Safe to call from several threads at once after orient.
 * Errors: INVALID_ARGUMENT (NULL; a count whose 3 × count doubles overflow), WRONG_ORDER
 * (not oriented; or GMPU_PARAM_SURFACE changed since orient and no polygonize has made that
 * surface yet), INVALID_INPUT (a NaN or infinite query, with its index; outputs untouched). Cost: O(count × log cells). */
GMPU_API gmpu_status gmpu_surface_evaluate(const gmpu_surface *surface, const double *xyz,
                                           size_t count, double *values, double *gradients);

/* Copies the oriented unit normal of every input point (−∇f normalised; the oriented
 * local fit where ∇f vanishes) into out: 3 × count doubles, count = point count.
 * Errors: INVALID_ARGUMENT (NULL, count differs from the point count), WRONG_ORDER. */
GMPU_API gmpu_status gmpu_surface_copy_normals(const gmpu_surface *surface, double *out,
                                               size_t count);

/* Copies the oriented unit normals of the count input points indices[0..count) into out
 * (3 × count doubles): for each, exactly what gmpu_surface_copy_normals gives it, without an
 * array of every point's normal (a tile's worker wants a few of millions). Indices are input
 * positions (0 ≤ index < gmpu_surface_point_count), in any order, repeats allowed; count 0
 * does nothing. Since 0.5.
 * Errors: INVALID_ARGUMENT (NULL surface; NULL indices or out with count > 0; an index
 * negative or not below the point count, with its position; out untouched), WRONG_ORDER
 * (not oriented). Cost: O(count × log outliers). */
GMPU_API gmpu_status gmpu_surface_copy_normals_at(const gmpu_surface *surface, const int64_t *indices,
                                                  size_t count, double *out);

/* Extracts the zero set of f as a closed, edge-manifold, consistently wound triangle mesh
 * (counter-clockwise seen from outside), restricted to a band around the data so that
 * spurious zero sets of far-away quadrics never become surface. Closed pieces that fit in
 * a box two grid cubes on a side are dropped beside a larger piece (the grid cannot resolve
 * them; a finer GMPU_PARAM_RESOLUTION keeps what the data holds at that scale). Uses
 * GMPU_PARAM_RESOLUTION and GMPU_PARAM_LEVEL. The mesh is the caller's: free it with
 * gmpu_mesh_destroy. Never an empty mesh: when no piece of surface is near the points (too
 * few or too sparse for a solid, or a grid too coarse for them) it fails with
 * DEGENERATE_INPUT. Errors: INVALID_ARGUMENT, WRONG_ORDER (not oriented), DEGENERATE_INPUT,
 * LIMIT_EXCEEDED (GMPU_PARAM_MAX_TRIANGLES, GMPU_PARAM_MAX_MEMORY), CANCELLED, OUT_OF_MEMORY. */
GMPU_API gmpu_status gmpu_surface_polygonize(gmpu_surface *surface, gmpu_mesh **out);

/* ---- meshes -------------------------------------------------------------------------- */

/* Builds a mesh from caller arrays (copied): vertex_count × 3 doubles, triangle_count × 3
 * vertex indices. Errors: INVALID_ARGUMENT (NULL with a non-zero count), INVALID_INPUT
 * (index out of range, non-finite coordinate). */
GMPU_API gmpu_status gmpu_mesh_create(const double *vertices, size_t vertex_count,
                                      const uint32_t *triangles, size_t triangle_count,
                                      gmpu_mesh **out);
/* gmpu_mesh_create with per-vertex attributes, each optional (NULL: none): normals
 * (3 × vertex_count doubles, any finite non-zero length; kept as unit vectors), confidence
 * (vertex_count doubles, >= 0 or +inf, as gmpu_mesh_confidence) and colors (3 × vertex_count
 * bytes, red green blue). Lets a binding rebuild a mesh it holds as arrays without losing
 * what gmpu_mesh_write writes. Errors: those of gmpu_mesh_create; INVALID_INPUT also for a
 * zero or non-finite normal or a negative or NaN confidence, naming the vertex. */
GMPU_API gmpu_status gmpu_mesh_create_with(const double *vertices, size_t vertex_count,
                                           const uint32_t *triangles, size_t triangle_count,
                                           const double *normals, const double *confidence,
                                           const uint8_t *colors, gmpu_mesh **out);
GMPU_API void gmpu_mesh_destroy(gmpu_mesh *mesh); /* NULL is a no-op */

GMPU_API size_t gmpu_mesh_vertex_count(const gmpu_mesh *mesh);   /* 0 for NULL */
GMPU_API size_t gmpu_mesh_triangle_count(const gmpu_mesh *mesh); /* 0 for NULL */
/* xyz per vertex (3 × vertex_count doubles). */
GMPU_API const double *gmpu_mesh_vertices(const gmpu_mesh *mesh);
/* Unit outward normal per vertex (3 × vertex_count doubles); NULL for a mesh made by
 * gmpu_mesh_create (or gmpu_mesh_create_with without normals). */
GMPU_API const double *gmpu_mesh_normals(const gmpu_mesh *mesh);
/* Three vertex indices per triangle (3 × triangle_count). */
GMPU_API const uint32_t *gmpu_mesh_triangles(const gmpu_mesh *mesh);
/* How well the input supports each vertex (vertex_count doubles): the distance to the
 * nearest input point in units of that point's sample spacing, up to tripled past the edge
 * of the data (where the nearest points all lie to one side of the vertex, as beyond a
 * hole's rim). About 0.5 or less where the points sample the surface; several where the
 * surface bridges a hole of the scan. NULL
 * for a mesh made by gmpu_mesh_create. Simplify and trim carry it; .ply files get it as
 * a float vertex property "confidence". */
GMPU_API const double *gmpu_mesh_confidence(const gmpu_mesh *mesh);
/* Colour per vertex: red green blue bytes (3 × vertex_count, sRGB as PLY files hold them);
 * NULL when the mesh has none. Simplify and trim carry them; .ply files get uchar red green
 * blue, .glb files COLOR_0 (linear float, as glTF defines it). */
GMPU_API const uint8_t *gmpu_mesh_colors(const gmpu_mesh *mesh);

/* A copy of mesh whose every vertex takes the colour of the point of points nearest to it
 * (give the points the surface was made from: the nearest is the sample the vertex stands
 * for). Errors: INVALID_ARGUMENT (NULL, points without colours), OUT_OF_MEMORY.
 * Cost: O((vertices + points) log points). */
GMPU_API gmpu_status gmpu_mesh_color_from_points(const gmpu_mesh *mesh, const gmpu_points *points,
                                                 gmpu_mesh **out);

/* Decimation: a new mesh with fewer triangles, the input untouched. Vertices at identical
 * positions are first welded; then edges collapse (quadric error, meshoptimizer) until at
 * most target_triangles remain (0: no count target) or a further collapse would move the
 * surface by more than target_error × the bounding-box diagonal (1 bounds nothing; 0 still
 * merges flat areas). Topology is kept: a closed, edge-manifold mesh stays one, with the
 * same components and genus, and borders stay where they are; when that stops further
 * collapses, the result has more triangles than target_triangles. Vertices are a subset
 * of the input's (confidence carried); normals are recomputed from the triangles (area-
 * weighted); the vertices no triangle uses are dropped (a mesh without triangles gives an
 * empty mesh). Errors: INVALID_ARGUMENT (NULL, target_error outside [0, 1] or NaN),
 * OUT_OF_MEMORY. Cost: O(n log n). */
GMPU_API gmpu_status gmpu_mesh_simplify(const gmpu_mesh *mesh, size_t target_triangles, double target_error,
                                        gmpu_mesh **out);

/* Trimming an open scan: a new mesh cut where the confidence (in sample spacings, linear
 * along each edge) passes threshold, within the regions over it that rise to twice the
 * threshold somewhere: the caps polygonize closes holes with go (0.75 to 2 removes them;
 * 1.5 is the CLI's default), while spots just over it inside the scanned surface stay, so
 * the result has boundaries where the data has holes and nowhere else. Triangles across
 * the cut are clipped (new vertices, their confidence the threshold); pieces of fewer
 * than 8 triangles left apart are dropped unless they are half the result. Errors:
 * INVALID_ARGUMENT (NULL, threshold not finite and positive, a mesh without confidence),
 * OUT_OF_MEMORY. */
GMPU_API gmpu_status gmpu_mesh_trim(const gmpu_mesh *mesh, double threshold, gmpu_mesh **out);

/* Writes the mesh; the format comes from the extension: .ply (binary little-endian),
 * .obj, .off, .stl (binary, float32, a normal per triangle), .glb (glTF 2.0 binary,
 * float32 positions, the vertex normals when the mesh has them, uint32 indices); .ply and
 * .glb also carry the confidence (.ply) and the colours the mesh has. The file is written
 * beside the target under a temporary name and renamed,
 * so a failure never leaves a partial file. A symlink as path is written through: the file
 * it points to is replaced, the link stays. Errors: INVALID_ARGUMENT, UNSUPPORTED
 * (extension), IO (with the system's reason). */
GMPU_API gmpu_status gmpu_mesh_write(const gmpu_mesh *mesh, const char *path);

/* ---- point files --------------------------------------------------------------------- */

/* Reads a point cloud: .ply (ascii, binary little or big endian; x y z, optional
 * nx ny nz, optional uchar red green blue; other properties and elements skipped), .xyz / .txt (3 or 6 columns),
 * .off and .obj (vertices only). Only regular files are read: a FIFO, a device or a
 * directory fails at once. Errors: INVALID_ARGUMENT, IO (missing, unreadable, not a regular
 * file), PARSE (malformed, truncated or lying header, not the format its extension says;
 * the message gives the line or element), UNSUPPORTED (extension or PLY variant),
 * INVALID_INPUT (no points), LIMIT_EXCEEDED (the points would need more memory than half the
 * physical memory: see gmpu_points_read_with). */
GMPU_API gmpu_status gmpu_points_read(const char *path, gmpu_points **out);

/* gmpu_points_read with a memory budget and progress. max_memory: bytes (0: the default,
 * half the physical memory; else 1e6..1e15, as GMPU_PARAM_MAX_MEMORY): a file whose points
 * would need more — estimated from a PLY header's vertex count and the file's size, or a
 * text file's line count, 48 bytes a point — fails with LIMIT_EXCEEDED naming the estimate
 * and the budget, before its body is read or parsed. fn (may be NULL) gets stage
 * GMPU_STAGE_READ and the fraction of the file read and parsed, with the cadence and the
 * cancel promise of gmpu_progress_fn (every 50 ms of the calling thread's CPU, stops within
 * 100 ms; then CANCELLED and *out stays NULL). */
GMPU_API gmpu_status gmpu_points_read_with(const char *path, double max_memory, gmpu_progress_fn fn,
                                           void *user, gmpu_points **out);

/* Builds a point set from caller arrays (copied); normals may be NULL. */
GMPU_API gmpu_status gmpu_points_create(const double *xyz, const double *normals,
                                        size_t count, gmpu_points **out);
/* gmpu_points_create with colours: colors (may be NULL) holds red green blue bytes per
 * point (3 × count), as gmpu_points_colors gives them, for gmpu_mesh_color_from_points. */
GMPU_API gmpu_status gmpu_points_create_with(const double *xyz, const double *normals, const uint8_t *colors,
                                             size_t count, gmpu_points **out);
GMPU_API void gmpu_points_destroy(gmpu_points *points); /* NULL is a no-op */

GMPU_API size_t gmpu_points_count(const gmpu_points *points);           /* 0 for NULL */
GMPU_API const double *gmpu_points_positions(const gmpu_points *points); /* 3 × count */
GMPU_API const double *gmpu_points_normals(const gmpu_points *points);   /* NULL if none */
/* Red green blue bytes per point (3 × count), from a .ply file with uchar red green blue;
 * NULL if none. */
GMPU_API const uint8_t *gmpu_points_colors(const gmpu_points *points);

/* Writes points (and normals, if any): .ply (binary little-endian) or .xyz (ascii).
 * Atomic like gmpu_mesh_write. Errors: INVALID_ARGUMENT, UNSUPPORTED, IO. */
GMPU_API gmpu_status gmpu_points_write(const gmpu_points *points, const char *path);

/* ---- tiles: one surface reconstructed piecewise on a shared grid ------------------------
 *
 * For clouds too large for one process (bindings/python/gmpu/dask.py): the domain is cut
 * into tiles, each reconstructed by its own surface from its points and an overlap margin;
 * all tiles share one global grid — cubes of side cell_size from grid_origin (caller's
 * units), grid_cells[3] cubes along x, y, z (multiples of 8), cut in blocks of 8³ cubes;
 * block (bx, by, bz) spans lattice corners 8·bx .. 8·bx + 8 along x, and so on. Each block
 * is owned by one tile, and a block owns the corners 8·b .. 8·b + 7 (half-open), so every
 * corner has one owner and one value: marching a block also needs the first corner layer
 * of its +x, +y, +z neighbours, which the caller exchanges between tiles. Vertices are
 * named by their lattice edge, so the tiles' meshes weld into one closed mesh. */

/* f (as gmpu_surface_evaluate) at the corners each block owns: for block n of blocks
 * (3 int64 block coordinates each), values[512·n + i + 8·(j + 8·k)] is f at corner
 * (8·bx + i, 8·by + j, 8·bz + k), i, j, k in 0..7, located at grid_origin + cell_size ·
 * corner (the same arithmetic as gmpu_grid_polygonize's vertices). Runs on
 * GMPU_PARAM_THREADS threads. Errors: INVALID_ARGUMENT (NULL, cell_size not finite and
 * positive, a non-finite origin, block_count × 512 doubles beyond memory), WRONG_ORDER (not
 * oriented). */
GMPU_API gmpu_status gmpu_surface_evaluate_grid(const gmpu_surface *surface, const double *grid_origin,
                                                double cell_size, const int64_t *blocks, size_t block_count,
                                                double *values);

/* Marching cubes (the cases gmpu_surface_polygonize uses) over the given blocks
 * of the global grid, with the caller's corner values: corner_values[729·n + i + 9·(j + 9·k)]
 * for block n at corner (8·bx + i, 8·by + j, 8·bz + k), i, j, k in 0..8, positive inside.
 * Two calls that give the same value to a shared corner cut the shared face identically.
 * *out gets the triangles (counter-clockwise seen from outside, where f < 0) with one vertex
 * per lattice edge among the given blocks, at grid_origin + cell_size · (linear
 * interpolation of the edge's corners); the mesh has no normals and no confidence, and
 * gmpu_mesh_grid_keys gives each vertex's edge, for welding the tiles' meshes. An empty
 * mesh when no block holds a sign change. Errors: INVALID_ARGUMENT (NULL with a non-zero
 * count, cell_size not finite and positive, grid_cells not positive multiples of 8, a block
 * outside the grid), INVALID_INPUT (a NaN corner value), OUT_OF_MEMORY. */
GMPU_API gmpu_status gmpu_grid_polygonize(const double *grid_origin, double cell_size, const int64_t *grid_cells,
                                          const int64_t *blocks, size_t block_count, const double *corner_values,
                                          gmpu_mesh **out);

/* Per vertex of a mesh made by gmpu_grid_polygonize: its lattice edge, (x + (cx + 1)·(y +
 * (cy + 1)·z))·8 + d for its lower corner (x, y, z), grid_cells (cx, cy, cz) and the edge's
 * direction d (0, 1 or 3: the corner-offset bit of its axis, minus one). Equal keys from two tiles are one
 * vertex. NULL for any other mesh. */
GMPU_API const uint64_t *gmpu_mesh_grid_keys(const gmpu_mesh *mesh);

#ifdef __cplusplus
}
#endif

#endif /* GMPU_GMPU_H */
