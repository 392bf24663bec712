/// <reference lib="esnext.disposable" />
// Type declarations for the `gmpu` package (index.js). The C ABI behind it is
// include/gmpu/gmpu.h; every function here documents which C call it makes.

/**
 * Points as x y z triples: a packed Float32Array / Float64Array (length 3n, used without a
 * copy) or an array of [x, y, z].
 */
export type Points = Float32Array | Float64Array | ReadonlyArray<ArrayLike<number>>;

/** Where points can come from: coordinates, a PointCloud from readPoints (its positions), or a point file's path. */
export type PointSource = Points | PointCloud | string | URL;

/** Triangles as vertex indices: a packed Uint32Array (length 3n), a flat array of integers, or [a, b, c] triples. */
export type Faces = Uint32Array | ArrayLike<number> | ReadonlyArray<ArrayLike<number>>;

/** The C status names (gmpu_status), and their numbers. */
export type StatusName =
    | 'GMPU_OK'
    | 'GMPU_ERROR_INVALID_ARGUMENT'
    | 'GMPU_ERROR_INVALID_INPUT'
    | 'GMPU_ERROR_DEGENERATE_INPUT'
    | 'GMPU_ERROR_WRONG_ORDER'
    | 'GMPU_ERROR_OUT_OF_MEMORY'
    | 'GMPU_ERROR_LIMIT_EXCEEDED'
    | 'GMPU_ERROR_CANCELLED'
    | 'GMPU_ERROR_IO'
    | 'GMPU_ERROR_PARSE'
    | 'GMPU_ERROR_UNSUPPORTED'
    | 'GMPU_ERROR_INTERNAL'
    | 'GMPU_ERROR_BUSY';
export declare const Status: Readonly<Record<StatusName, number>>;

/**
 * Every error this package throws (except one rethrown from your onProgress callback).
 * `code` is the C status name; `message` the C library's message (which starts with it),
 * e.g. "GMPU_ERROR_INVALID_INPUT: point 7 has a NaN or infinite coordinate".
 * `code` is 'GMPU_LIBRARY_NOT_FOUND' when libgmpu could not be loaded (the message lists
 * where it was looked for).
 */
export declare class GmpuError extends Error {
    constructor(code: StatusName | 'GMPU_LIBRARY_NOT_FOUND', message: string, options?: { cause?: unknown });
    readonly name: 'GmpuError';
    readonly code: StatusName | 'GMPU_LIBRARY_NOT_FOUND';
    /** The numeric gmpu_status, undefined for GMPU_LIBRARY_NOT_FOUND. */
    readonly status: number | undefined;
}

/** The stage a progress report is about. */
export type Stage = 'fit' | 'orient' | 'polygonize' | 'read';

/**
 * Progress of fit / orient / polygonize: called on the calling thread at least every 50 ms
 * of work, fraction in [0, 1], non-decreasing within a stage, 1 when it completes.
 * Returning `false` cancels the stage (it throws a GmpuError with code
 * 'GMPU_ERROR_CANCELLED'); throwing cancels it too, and the stage rethrows your error.
 * The Surface keeps the stages completed before the cancelled one. It must not use the
 * Surface it reports on (that throws, and so cancels); calling close() cancels the stage
 * and closes the surface once it has returned. A cancel that comes with a stage's last
 * report (fraction 1, or the only report of a trivial stage) is too late: the C library
 * completes the stage and `false` is then ignored, while a thrown error is still rethrown.
 */
export type ProgressCallback = (stage: Stage, fraction: number) => boolean | void;

/**
 * The parameters (gmpu_param), by name. Their defaults, ranges and docs are the library's:
 * see parameterInfo() (tests/node/api.test.mjs checks these names against it).
 */
export interface Parameters {
    /** ε: largest fit error, as a fraction of the bounding-box diagonal. */
    error?: number;
    /** Deepest octree level. */
    maxDepth?: number;
    /** Fewest points per local fit. */
    minPoints?: number;
    /** α: support radius = α × cell diagonal. */
    supportScale?: number;
    /** Piecewise quadrics at sharp edges and corners (true or 1). */
    sharpFeatures?: boolean | number;
    /** Polygonize grid cubes along the longest side; 0 picks from the octree. */
    resolution?: number;
    /** Level of detail: use octree cells down to this level only; 0 = all. */
    level?: number;
    /** Worker threads; 0 = every core. */
    threads?: number;
    /** Cap on octree cells (GMPU_ERROR_LIMIT_EXCEEDED beyond). */
    maxCells?: number;
    /** Cap on polygonize triangles. */
    maxTriangles?: number;
    /** Noise floor for ε, in units of the estimated noise; 0 = off. */
    noiseScale?: number;
    /** Memory budget in bytes that fit and polygonize check their estimated peak against. */
    maxMemory?: number;
    /** 1: set_points leaves the outliers it finds out of the fit; 0: fits them too (GMPU_STAT_OUTLIERS counts them either way). Default 1, 0..1. */
    removeOutliers?: boolean | number;
    /** The surface: 0 the MPU blend, 1 a smooth field solved from the oriented points, 2 chosen from the estimated noise (the smooth one from 0.3 % of the diagonal). Default 2. */
    surface?: number;
}
export type ParameterName = keyof Parameters;
export declare const parameterNames: readonly ParameterName[];

/** One row of the library's parameter table (gmpu_param_info). */
export interface ParameterInfo {
    readonly key: number;
    /** camelCase name (the Surface option). */
    readonly name: ParameterName;
    /** The C library's name (snake_case). */
    readonly cName: string;
    readonly type: 'int' | 'real';
    /** A new surface's value. */
    readonly default: number;
    readonly min: number;
    readonly max: number;
    readonly minExclusive: boolean;
    readonly maxExclusive: boolean;
    /** Changing it discards a previous fit. */
    readonly refits: boolean;
    readonly doc: string;
}
/** Every parameter as the library describes it, in key order. */
export declare function parameterInfo(): readonly ParameterInfo[];

export interface SurfaceOptions extends Parameters {
    onProgress?: ProgressCallback | null;
}

export interface ReconstructOptions extends SurfaceOptions {
    /** Known outward normals for the points (same count and order): orient signs the fits by them, skipping belief propagation. */
    normals?: Points | null;
}

/** Per-call overrides for polygonize (the surface's parameters are restored afterwards). */
export interface PolygonizeOptions {
    resolution?: number;
    level?: number;
}

/**
 * For the ...Async stages: aborting the signal cancels the running stage at its next
 * progress report (within about 100 ms, when the event loop is free to deliver it); the
 * promise rejects with GMPU_ERROR_CANCELLED whose `cause` is the signal's reason.
 */
export interface AsyncOptions {
    signal?: AbortSignal | null;
}

/** The statistics (gmpu_stat) of the latest completed stages, by name. */
export interface Statistics {
    points: number;
    cells: number;
    leaves: number;
    depth: number;
    quadricCells: number;
    bivariateCells: number;
    piecewiseCells: number;
    components: number;
    flippedCells: number;
    fitSeconds: number;
    orientSeconds: number;
    polygonizeSeconds: number;
    resolution: number;
    bboxDiagonal: number;
    noise: number;
    effectiveError: number;
    /** Input points set aside as outliers by setPoints (far from every other point). */
    outliers: number;
}
export type StatisticName = keyof Statistics;
export declare const statisticNames: readonly StatisticName[];

/** A triangle mesh: closed, edge-manifold, counter-clockwise seen from outside. */
export interface Mesh {
    /** x y z per vertex. */
    vertices: Float64Array;
    /** Three vertex indices per triangle. */
    faces: Uint32Array;
    /** Unit outward normal per vertex (null for meshes not made by polygonize). */
    normals: Float64Array | null;
    /** Per vertex: distance to the nearest input point in sample spacings (null for meshes not made by polygonize). */
    confidence: Float64Array | null;
    /** Red green blue per vertex (null unless colorMesh gave it colours). */
    colors?: Uint8Array | null;
}

/** What writeMesh, simplifyMesh and colorMesh take: a Mesh, or its arrays alone. */
export interface MeshInput {
    vertices: Points;
    faces: Faces;
    normals?: Float64Array | ArrayLike<number> | null;
    confidence?: Float64Array | ArrayLike<number> | null;
    colors?: Uint8Array | ArrayLike<number> | null;
}

/** A point cloud read from a file. */
export interface PointCloud {
    /** x y z per point. */
    positions: Float64Array;
    /** nx ny nz per point, or null if the file has none. */
    normals: Float64Array | null;
    /** Red green blue per point (a .ply with uchar red green blue), or null. */
    colors?: Uint8Array | null;
    count: number;
}

/**
 * A reconstruction (gmpu_surface): setPoints → fit → orient → evaluate / normals /
 * polygonize. Owns a native handle: call close() when done (idempotent). A
 * FinalizationRegistry frees a forgotten one when it is garbage-collected, eventually.
 * Methods throw GmpuError; a closed Surface throws GMPU_ERROR_INVALID_ARGUMENT.
 */
export declare class Surface {
    /** gmpu_surface_create, then the given parameters, setPoints(points) and setNormals(options.normals). */
    constructor(points?: PointSource | null, options?: ReconstructOptions);
    /** gmpu_surface_create, then the given parameters. */
    constructor(options?: SurfaceOptions);
    /** Called during fit / orient / polygonize; null for none. */
    onProgress: ProgressCallback | null;
    /** True once close() has run. */
    readonly closed: boolean;
    /** Number of points set (gmpu_surface_point_count). */
    readonly pointCount: number;
    /** gmpu_surface_set_param. Fit parameters discard a previous fit. */
    setParam(name: ParameterName, value: number | boolean): this;
    /** gmpu_surface_get_param. */
    getParam(name: ParameterName): number;
    /** setParam for each entry. */
    setParams(params: Parameters): this;
    /** Every parameter. */
    params(): { [K in ParameterName]: number };
    /** gmpu_surface_get_stat. */
    stat(name: StatisticName): number;
    /** Every statistic. */
    stats(): Statistics;
    /** gmpu_surface_set_points_f32 / _f64 (copies; replaces earlier points, discards any fit). */
    setPoints(points: PointSource): this;
    /** gmpu_surface_set_normals_f32 / _f64: known outward normals, one per point. */
    setNormals(normals: Points): this;
    /** gmpu_surface_fit, after setPoints(points) if points are given. */
    fit(points?: PointSource): this;
    /** gmpu_surface_orient: consistent signs, f > 0 inside, normals outward. */
    orient(): this;
    /** gmpu_surface_evaluate: f at each point (positive inside, about the signed distance near the surface). */
    evaluate(points: Points, options?: { gradient?: false }): Float64Array;
    /** gmpu_surface_evaluate: f and ∇f (3 per point; it points into the solid) at each point, in one pass. */
    evaluate(points: Points, options: { gradient: true }): { values: Float64Array; gradients: Float64Array };
    /** gmpu_surface_evaluate: ∇f only (3 per point). */
    gradient(points: Points): Float64Array;
    /** gmpu_surface_copy_normals: the oriented unit normal of every input point (3 per point). */
    normals(): Float64Array;
    /** gmpu_surface_copy_normals_at: the normals of the input points `indices` only (3 per index). */
    normalsAt(indices: ArrayLike<number> | BigInt64Array): Float64Array;
    /** gmpu_surface_polygonize: the zero set as a closed mesh (copied into JS arrays). */
    polygonize(options?: PolygonizeOptions): Mesh;
    /**
     * The stages without blocking the event loop: the C call runs on a worker thread and
     * onProgress is delivered on this thread. Until the promise settles, every other method
     * of this Surface throws GMPU_ERROR_WRONG_ORDER ("busy"); close() cancels the stage and
     * frees the surface once it has returned. fitAsync(points) sets the points first
     * (synchronously: they are copied).
     */
    fitAsync(points?: PointSource, options?: AsyncOptions): Promise<this>;
    fitAsync(options?: AsyncOptions): Promise<this>;
    orientAsync(options?: AsyncOptions): Promise<this>;
    polygonizeAsync(options?: PolygonizeOptions & AsyncOptions): Promise<Mesh>;
    /**
     * gmpu_surface_destroy. Idempotent. During a stage (from onProgress, or while an async
     * stage runs) it cancels the stage and frees the surface when the stage has returned.
     * (Also available as [Symbol.dispose] where the runtime has it.)
     */
    close(): void;
    /** close(), for `using surface = new Surface(...)`. */
    [Symbol.dispose](): void;
    /** close(), for `await using`: an async stage still running is cancelled. */
    [Symbol.asyncDispose](): Promise<void>;
}

/** Points → fit → orient → polygonize in one call; the native surface is always freed. */
export declare function reconstruct(points: PointSource, options?: ReconstructOptions): Mesh;

/**
 * reconstruct() without blocking the event loop (fit, orient and polygonize run on a worker
 * thread; a path is read synchronously first). options.signal cancels.
 */
export declare function reconstructAsync(points: PointSource, options?: ReconstructOptions & AsyncOptions): Promise<Mesh>;

/**
 * gmpu_points_read_with: .ply (ascii / binary), .xyz / .txt, .off, .obj. maxMemory: budget in
 * bytes (0: half the physical memory); onProgress('read', fraction): false or a throw cancels.
 */
export declare function readPoints(
    path: string | URL,
    options?: { maxMemory?: number; onProgress?: ProgressCallback | null },
): PointCloud;

/**
 * gmpu_mesh_create_with + gmpu_mesh_write: .ply (binary little-endian, double coordinates),
 * .obj, .off, .stl or .glb from the extension; atomic; normals, confidence and colours kept.
 */
export declare function writeMesh(path: string | URL, mesh: MeshInput): void;

/** gmpu_mesh_color_from_points: a copy whose vertices take the colour of the nearest point of cloud. */
export declare function colorMesh(mesh: MeshInput, cloud: { positions: Points; colors: Uint8Array | ArrayLike<number> }): Mesh;

/** gmpu_mesh_simplify: a decimated copy with at most targetTriangles triangles and error at most targetError × diagonal; topology kept. */
export declare function simplifyMesh(
    mesh: MeshInput,
    options?: { targetTriangles?: number; targetError?: number },
): Mesh;

/** gmpu_points_create + gmpu_points_write: .ply (binary little-endian) or .xyz; atomic. */
export declare function writePoints(path: string | URL, cloud: { positions: Points; normals?: Points | null }): void;

/** The loaded C library: version and the file it was loaded from. */
export declare function libraryInfo(): { version: string; versionNumber: number; abiVersion: number; path: string };
