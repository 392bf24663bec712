//! Raw declarations of the C ABI in `include/gmpu/gmpu.h`, one for one.
//!
//! Everything here is `unsafe` and follows the header's rules (ownership, NULL handling,
//! thread safety); the safe API is in the crate root. The declarations are written through
//! two macros that also record them as data ([`FUNCTIONS`], [`ENUMS`], [`OPAQUE_TYPES`],
//! [`DEFINES`]); the test `tests/header_sync.rs` compares them with `bindings/abi.txt` (the
//! summary generated from the header) and fails when the two
//! drift apart (a function, parameter type, return type or enum value added, removed or
//! changed on either side).
//!
//! C enums are passed as their underlying integer (`c_uint`, as bindgen does for enums
//! without negative values), never as Rust enums: a value appended to the header by a newer
//! library must not be undefined behaviour in an older binding.
#![allow(non_camel_case_types, missing_docs)] // documented in gmpu.h

use std::os::raw::{c_char, c_int, c_uint, c_void};

/// One `extern "C"` function as declared below: its name, parameter types and return type
/// (`"()"` for `void`), as written in Rust (`stringify!`'d tokens).
#[derive(Debug, Clone, Copy)]
pub struct Signature {
    pub name: &'static str,
    pub params: &'static [&'static str],
    pub ret: &'static str,
}

/// One C enum: its typedef name and its enumerators with their values.
#[derive(Debug, Clone, Copy)]
pub struct EnumDecl {
    pub name: &'static str,
    pub values: &'static [(&'static str, c_uint)],
}

macro_rules! c_enums {
    ($( $ty:ident { $( $variant:ident = $value:expr ),* $(,)? } )*) => {
        $(
            pub type $ty = c_uint;
            $( pub const $variant: $ty = $value; )*
        )*
        /// Every C enum of the header with its values, as declared in this module.
        pub const ENUMS: &[EnumDecl] = &[
            $( EnumDecl { name: stringify!($ty), values: &[ $( (stringify!($variant), $value) ),* ] } ),*
        ];
    };
}

macro_rules! ret_str {
    () => {
        "()"
    };
    ($ret:ty) => {
        stringify!($ret)
    };
}

macro_rules! c_functions {
    ($( pub fn $name:ident ( $( $arg:ident : $argty:ty ),* $(,)? ) $( -> $ret:ty )? ; )*) => {
        extern "C" {
            $( pub fn $name( $( $arg: $argty ),* ) $( -> $ret )?; )*
        }
        /// Every function declared in this module's `extern "C"` block.
        pub const FUNCTIONS: &[Signature] = &[
            $( Signature { name: stringify!($name), params: &[ $( stringify!($argty) ),* ],
                           ret: ret_str!($( $ret )?) } ),*
        ];
        /// The address of every function in [`FUNCTIONS`], in the same order: calling this
        /// makes the linker resolve each one in the library.
        pub fn function_addresses() -> Vec<(&'static str, usize)> {
            vec![ $( (stringify!($name), $name as *const () as usize) ),* ]
        }
    };
}

/// `#define`d integer constants of the header.
pub const GMPU_VERSION_MAJOR: u32 = 0;
pub const GMPU_VERSION_MINOR: u32 = 5;
pub const GMPU_VERSION_PATCH: u32 = 0;
pub const GMPU_VERSION_NUMBER: u32 = 500;
pub const GMPU_ABI_VERSION: u32 = 1;
pub const DEFINES: &[(&str, u32)] = &[
    ("GMPU_VERSION_MAJOR", GMPU_VERSION_MAJOR),
    ("GMPU_VERSION_MINOR", GMPU_VERSION_MINOR),
    ("GMPU_VERSION_PATCH", GMPU_VERSION_PATCH),
    ("GMPU_VERSION_NUMBER", GMPU_VERSION_NUMBER),
    ("GMPU_ABI_VERSION", GMPU_ABI_VERSION),
];

/// Opaque handle: a reconstruction (points, octree of local fits, orientation).
#[repr(C)]
pub struct gmpu_surface {
    _private: [u8; 0],
    _not_send_sync_unpin: core::marker::PhantomData<(*mut u8, core::marker::PhantomPinned)>,
}
/// Opaque handle: a triangle mesh.
#[repr(C)]
pub struct gmpu_mesh {
    _private: [u8; 0],
    _not_send_sync_unpin: core::marker::PhantomData<(*mut u8, core::marker::PhantomPinned)>,
}
/// Opaque handle: a point cloud read from a file or built from arrays.
#[repr(C)]
pub struct gmpu_points {
    _private: [u8; 0],
    _not_send_sync_unpin: core::marker::PhantomData<(*mut u8, core::marker::PhantomPinned)>,
}
/// The header's `typedef struct X X;` handles declared above.
pub const OPAQUE_TYPES: &[&str] = &["gmpu_surface", "gmpu_mesh", "gmpu_points"];

c_enums! {
    gmpu_status {
        GMPU_OK = 0,
        GMPU_ERROR_INVALID_ARGUMENT = 1,
        GMPU_ERROR_INVALID_INPUT = 2,
        GMPU_ERROR_DEGENERATE_INPUT = 3,
        GMPU_ERROR_WRONG_ORDER = 4,
        GMPU_ERROR_OUT_OF_MEMORY = 5,
        GMPU_ERROR_LIMIT_EXCEEDED = 6,
        GMPU_ERROR_CANCELLED = 7,
        GMPU_ERROR_IO = 8,
        GMPU_ERROR_PARSE = 9,
        GMPU_ERROR_UNSUPPORTED = 10,
        GMPU_ERROR_INTERNAL = 11,
        GMPU_ERROR_BUSY = 12,
    }
    gmpu_param {
        GMPU_PARAM_ERROR = 1,
        GMPU_PARAM_MAX_DEPTH = 2,
        GMPU_PARAM_MIN_POINTS = 3,
        GMPU_PARAM_SUPPORT_SCALE = 4,
        GMPU_PARAM_SHARP_FEATURES = 5,
        GMPU_PARAM_RESOLUTION = 6,
        GMPU_PARAM_LEVEL = 7,
        GMPU_PARAM_THREADS = 8,
        GMPU_PARAM_MAX_CELLS = 9,
        GMPU_PARAM_MAX_TRIANGLES = 10,
        GMPU_PARAM_NOISE_SCALE = 11,
        GMPU_PARAM_MAX_MEMORY = 12,
        GMPU_PARAM_REMOVE_OUTLIERS = 13,
        GMPU_PARAM_SURFACE = 14,
    }
    gmpu_value_type {
        GMPU_TYPE_INT = 1,
        GMPU_TYPE_REAL = 2,
    }
    gmpu_stage {
        GMPU_STAGE_FIT = 1,
        GMPU_STAGE_ORIENT = 2,
        GMPU_STAGE_POLYGONIZE = 3,
        GMPU_STAGE_READ = 4,
    }
    gmpu_stat {
        GMPU_STAT_POINTS = 1,
        GMPU_STAT_CELLS = 2,
        GMPU_STAT_LEAVES = 3,
        GMPU_STAT_DEPTH = 4,
        GMPU_STAT_QUADRIC_CELLS = 5,
        GMPU_STAT_BIVARIATE_CELLS = 6,
        GMPU_STAT_PIECEWISE_CELLS = 7,
        GMPU_STAT_COMPONENTS = 8,
        GMPU_STAT_FLIPPED_CELLS = 9,
        GMPU_STAT_FIT_SECONDS = 10,
        GMPU_STAT_ORIENT_SECONDS = 11,
        GMPU_STAT_POLYGONIZE_SECONDS = 12,
        GMPU_STAT_RESOLUTION = 13,
        GMPU_STAT_BBOX_DIAGONAL = 14,
        GMPU_STAT_NOISE = 15,
        GMPU_STAT_EFFECTIVE_ERROR = 16,
        GMPU_STAT_OUTLIERS = 17,
    }
}

/// One row of the library's parameter table (`gmpu_param_info_t`); the strings are the
/// library's, in static storage.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct gmpu_param_info_t {
    pub name: *const c_char,
    pub type_: gmpu_value_type,
    pub default_value: f64,
    pub min: f64,
    pub max: f64,
    pub min_exclusive: c_int,
    pub max_exclusive: c_int,
    pub refits: c_int,
    pub doc: *const c_char,
}

/// `typedef int (*gmpu_progress_fn)(void *user, gmpu_stage stage, double fraction);`
/// (nullable, hence the `Option`).
pub type gmpu_progress_fn = Option<unsafe extern "C" fn(user: *mut c_void, stage: gmpu_stage, fraction: f64) -> c_int>;
/// The parameter and return types of [`gmpu_progress_fn`], for the header test.
pub const PROGRESS_FN: Signature =
    Signature { name: "gmpu_progress_fn", params: &["*mut c_void", "gmpu_stage", "f64"], ret: "c_int" };

c_functions! {
    pub fn gmpu_status_name(status: gmpu_status) -> *const c_char;
    pub fn gmpu_last_error() -> *const c_char;

    pub fn gmpu_version_number() -> u32;
    pub fn gmpu_version_string() -> *const c_char;
    pub fn gmpu_abi_version() -> u32;

    pub fn gmpu_param_count() -> c_int;
    pub fn gmpu_param_info(key: gmpu_param, info: *mut gmpu_param_info_t) -> gmpu_status;
    pub fn gmpu_param_key(name: *const c_char) -> c_int;
    pub fn gmpu_stat_count() -> c_int;
    pub fn gmpu_stat_name(key: gmpu_stat) -> *const c_char;

    pub fn gmpu_surface_create(out: *mut *mut gmpu_surface) -> gmpu_status;
    pub fn gmpu_surface_destroy(surface: *mut gmpu_surface);
    pub fn gmpu_surface_last_error(surface: *const gmpu_surface) -> *const c_char;
    pub fn gmpu_surface_set_param(surface: *mut gmpu_surface, key: gmpu_param, value: f64) -> gmpu_status;
    pub fn gmpu_surface_get_param(surface: *const gmpu_surface, key: gmpu_param, value: *mut f64) -> gmpu_status;
    pub fn gmpu_surface_get_stat(surface: *const gmpu_surface, key: gmpu_stat, value: *mut f64) -> gmpu_status;
    pub fn gmpu_surface_set_progress(surface: *mut gmpu_surface, fn_: gmpu_progress_fn, user: *mut c_void)
        -> gmpu_status;

    pub fn gmpu_surface_set_points_f64(surface: *mut gmpu_surface, xyz: *const f64, count: usize, stride: usize)
        -> gmpu_status;
    pub fn gmpu_surface_set_points_f32(surface: *mut gmpu_surface, xyz: *const f32, count: usize, stride: usize)
        -> gmpu_status;
    pub fn gmpu_surface_set_normals_f64(surface: *mut gmpu_surface, nxyz: *const f64, count: usize, stride: usize)
        -> gmpu_status;
    pub fn gmpu_surface_set_normals_f32(surface: *mut gmpu_surface, nxyz: *const f32, count: usize, stride: usize)
        -> gmpu_status;
    pub fn gmpu_surface_point_count(surface: *const gmpu_surface) -> usize;

    pub fn gmpu_surface_fit(surface: *mut gmpu_surface) -> gmpu_status;
    pub fn gmpu_surface_orient(surface: *mut gmpu_surface) -> gmpu_status;
    pub fn gmpu_surface_evaluate(surface: *const gmpu_surface, xyz: *const f64, count: usize, values: *mut f64,
        gradients: *mut f64) -> gmpu_status;
    pub fn gmpu_surface_copy_normals(surface: *const gmpu_surface, out: *mut f64, count: usize) -> gmpu_status;
    pub fn gmpu_surface_copy_normals_at(surface: *const gmpu_surface, indices: *const i64, count: usize,
        out: *mut f64) -> gmpu_status;
    pub fn gmpu_surface_polygonize(surface: *mut gmpu_surface, out: *mut *mut gmpu_mesh) -> gmpu_status;

    pub fn gmpu_mesh_create(vertices: *const f64, vertex_count: usize, triangles: *const u32,
        triangle_count: usize, out: *mut *mut gmpu_mesh) -> gmpu_status;
    pub fn gmpu_mesh_create_with(vertices: *const f64, vertex_count: usize, triangles: *const u32,
        triangle_count: usize, normals: *const f64, confidence: *const f64, colors: *const u8,
        out: *mut *mut gmpu_mesh) -> gmpu_status;
    pub fn gmpu_mesh_destroy(mesh: *mut gmpu_mesh);
    pub fn gmpu_mesh_vertex_count(mesh: *const gmpu_mesh) -> usize;
    pub fn gmpu_mesh_triangle_count(mesh: *const gmpu_mesh) -> usize;
    pub fn gmpu_mesh_vertices(mesh: *const gmpu_mesh) -> *const f64;
    pub fn gmpu_mesh_normals(mesh: *const gmpu_mesh) -> *const f64;
    pub fn gmpu_mesh_triangles(mesh: *const gmpu_mesh) -> *const u32;
    pub fn gmpu_mesh_write(mesh: *const gmpu_mesh, path: *const c_char) -> gmpu_status;
    pub fn gmpu_mesh_confidence(mesh: *const gmpu_mesh) -> *const f64;
    pub fn gmpu_mesh_colors(mesh: *const gmpu_mesh) -> *const u8;
    pub fn gmpu_mesh_color_from_points(mesh: *const gmpu_mesh, points: *const gmpu_points,
        out: *mut *mut gmpu_mesh) -> gmpu_status;
    pub fn gmpu_mesh_simplify(mesh: *const gmpu_mesh, target_triangles: usize, target_error: f64,
                              out: *mut *mut gmpu_mesh) -> gmpu_status;
    pub fn gmpu_mesh_trim(mesh: *const gmpu_mesh, threshold: f64, out: *mut *mut gmpu_mesh) -> gmpu_status;

    pub fn gmpu_surface_evaluate_grid(surface: *const gmpu_surface, grid_origin: *const f64, cell_size: f64,
        blocks: *const i64, block_count: usize, values: *mut f64) -> gmpu_status;
    pub fn gmpu_grid_polygonize(grid_origin: *const f64, cell_size: f64, grid_cells: *const i64, blocks: *const i64,
        block_count: usize, corner_values: *const f64, out: *mut *mut gmpu_mesh) -> gmpu_status;
    pub fn gmpu_mesh_grid_keys(mesh: *const gmpu_mesh) -> *const u64;

    pub fn gmpu_points_read(path: *const c_char, out: *mut *mut gmpu_points) -> gmpu_status;
    pub fn gmpu_points_read_with(
        path: *const c_char,
        max_memory: f64,
        fn_: gmpu_progress_fn,
        user: *mut c_void,
        out: *mut *mut gmpu_points,
    ) -> gmpu_status;
    pub fn gmpu_points_create(xyz: *const f64, normals: *const f64, count: usize, out: *mut *mut gmpu_points)
        -> gmpu_status;
    pub fn gmpu_points_create_with(xyz: *const f64, normals: *const f64, colors: *const u8, count: usize,
        out: *mut *mut gmpu_points) -> gmpu_status;
    pub fn gmpu_points_destroy(points: *mut gmpu_points);
    pub fn gmpu_points_count(points: *const gmpu_points) -> usize;
    pub fn gmpu_points_positions(points: *const gmpu_points) -> *const f64;
    pub fn gmpu_points_normals(points: *const gmpu_points) -> *const f64;
    pub fn gmpu_points_colors(points: *const gmpu_points) -> *const u8;
    pub fn gmpu_points_write(points: *const gmpu_points, path: *const c_char) -> gmpu_status;
}
