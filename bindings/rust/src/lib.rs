//! Safe Rust bindings to **gmpu**: an unoriented point cloud in, a watertight, correctly
//! oriented implicit surface (MPU implicits + belief propagation) and triangle mesh out.
//!
//! The pipeline is the C library's: [`Surface::new`] → [`Surface::set_points`]
//! (→ [`Surface::set_normals`]) → [`Surface::fit`] → [`Surface::orient`] →
//! [`Surface::evaluate`] / [`Surface::normals`] / [`Surface::polygonize`].
//!
//! ```
//! use gmpu::{Param, Surface};
//!
//! # fn main() -> Result<(), gmpu::Error> {
//! // 1,500 points on the unit sphere (a Fibonacci lattice), no normals.
//! let n = 1500;
//! let points: Vec<[f64; 3]> = (0..n)
//!     .map(|i| {
//!         let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
//!         let r = (1.0 - z * z).sqrt();
//!         let a = i as f64 * 2.399963229728653;
//!         [r * a.cos(), r * a.sin(), z]
//!     })
//!     .collect();
//! let mut surface = Surface::new()?;
//! surface.set_param(Param::Resolution, 24.0)?;
//! surface.set_points(&points)?;
//! surface.fit()?;
//! surface.orient()?;
//! let f = surface.evaluate(&[[0.0, 0.0, 0.0], [0.0, 0.0, 2.0]])?;
//! assert!(f[0] > 0.0 && f[1] < 0.0); // positive inside, negative outside
//! let mesh = surface.polygonize()?;
//! assert!(mesh.triangles().len() > 100);
//! # Ok(())
//! # }
//! ```
//!
//! # Errors
//! Every fallible call returns [`Result`]; an [`Error`] carries the C status as a
//! [`Status`] and the C library's message (`"GMPU_ERROR_INVALID_INPUT: point 17 has a NaN
//! or infinite coordinate"`). A few errors are raised by the binding itself before calling C, where a
//! Rust slice cannot express what C would be asked (mismatched lengths, a stride of 0, a
//! path with a NUL byte); they use the same statuses and message format.
//!
//! # Threads
//! The header's contract, as types:
//! * [`Surface`] is `Send` (handles share no state) and `Sync`: every `&self` method calls
//!   one of the header's const functions (`evaluate`, `copy_normals`, `get_param`,
//!   `get_stat`, `point_count`, `last_error`), which may run concurrently on one surface;
//!   everything else takes `&mut self`. So after `orient`, `&Surface` can be shared by
//!   scoped threads that all call [`Surface::evaluate`].
//! * [`Mesh`] and [`Points`] are `Send` but not `Sync`: the header promises concurrent
//!   const calls only for surfaces. The slices they lend out are plain `&[[f64; 3]]` and
//!   may be shared freely.
//!
//! # Progress and cancellation
//! [`Surface::set_progress`] registers a closure called during `fit`, `orient` and
//! `polygonize` on the calling thread; returning [`ControlFlow::Break`] cancels the stage
//! ([`Status::Cancelled`]). A panic in the closure never crosses the C frames: the
//! trampoline catches it, cancels the C call, and the panic is resumed once the call has
//! returned (the surface stays valid and keeps the stages completed before).
//!
//! # Linking
//! `build.rs` links `libgmpu` from `GMPU_LIBRARY` (the library's path, as for the other
//! bindings), else `pkg-config --libs gmpu`, else
//! this source tree's meson build (`../../build/lib`), and sets an rpath to it for the
//! crate's own tests and examples.
#![warn(missing_docs)]

pub mod sys;
mod params;

pub use params::Params;

use std::any::Any;
use std::ffi::{CStr, CString};
use std::fmt;
use std::os::raw::{c_char, c_int, c_void};
use std::panic::{self, AssertUnwindSafe};
use std::path::Path;
use std::ptr::{self, NonNull};

pub use std::ops::ControlFlow;

/// `Result` with [`Error`] as the default error type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

// ---- status and error ---------------------------------------------------------------------

/// Why a call failed: the C library's `gmpu_status` (without `GMPU_OK`).
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Status {
    /// `GMPU_ERROR_INVALID_ARGUMENT`: NULL pointer, bad count/stride, parameter out of range.
    InvalidArgument,
    /// `GMPU_ERROR_INVALID_INPUT`: NaN/inf coordinates, too few points, size mismatch.
    InvalidInput,
    /// `GMPU_ERROR_DEGENERATE_INPUT`: identical, collinear or coplanar points.
    DegenerateInput,
    /// `GMPU_ERROR_WRONG_ORDER`: a stage called before the one it needs.
    WrongOrder,
    /// `GMPU_ERROR_OUT_OF_MEMORY`.
    OutOfMemory,
    /// `GMPU_ERROR_LIMIT_EXCEEDED`: [`Param::MaxCells`], [`Param::MaxTriangles`] or
    /// [`Param::MaxMemory`] was hit.
    LimitExceeded,
    /// `GMPU_ERROR_CANCELLED`: the progress callback asked to stop.
    Cancelled,
    /// `GMPU_ERROR_IO`: a file could not be opened, read or written.
    Io,
    /// `GMPU_ERROR_PARSE`: a file's contents are malformed or truncated.
    Parse,
    /// `GMPU_ERROR_UNSUPPORTED`: unknown file extension or format variant.
    Unsupported,
    /// `GMPU_ERROR_INTERNAL`: a bug in gmpu.
    Internal,
    /// `GMPU_ERROR_BUSY`: a call on a surface from its own progress callback.
    Busy,
    /// A status this binding does not know (from a newer library).
    Unknown(u32),
}

impl Status {
    /// Every known status, in the header's order.
    pub const ALL: [Status; 12] = [
        Status::InvalidArgument,
        Status::InvalidInput,
        Status::DegenerateInput,
        Status::WrongOrder,
        Status::OutOfMemory,
        Status::LimitExceeded,
        Status::Cancelled,
        Status::Io,
        Status::Parse,
        Status::Unsupported,
        Status::Internal,
        Status::Busy,
    ];

    /// The status of a raw `gmpu_status`; `None` for `GMPU_OK`.
    pub fn from_raw(raw: sys::gmpu_status) -> Option<Status> {
        use sys::*;
        Some(match raw {
            GMPU_OK => return None,
            GMPU_ERROR_INVALID_ARGUMENT => Status::InvalidArgument,
            GMPU_ERROR_INVALID_INPUT => Status::InvalidInput,
            GMPU_ERROR_DEGENERATE_INPUT => Status::DegenerateInput,
            GMPU_ERROR_WRONG_ORDER => Status::WrongOrder,
            GMPU_ERROR_OUT_OF_MEMORY => Status::OutOfMemory,
            GMPU_ERROR_LIMIT_EXCEEDED => Status::LimitExceeded,
            GMPU_ERROR_CANCELLED => Status::Cancelled,
            GMPU_ERROR_IO => Status::Io,
            GMPU_ERROR_PARSE => Status::Parse,
            GMPU_ERROR_UNSUPPORTED => Status::Unsupported,
            GMPU_ERROR_INTERNAL => Status::Internal,
            GMPU_ERROR_BUSY => Status::Busy,
            other => Status::Unknown(other),
        })
    }

    /// The raw `gmpu_status` value.
    pub fn to_raw(self) -> sys::gmpu_status {
        use sys::*;
        match self {
            Status::InvalidArgument => GMPU_ERROR_INVALID_ARGUMENT,
            Status::InvalidInput => GMPU_ERROR_INVALID_INPUT,
            Status::DegenerateInput => GMPU_ERROR_DEGENERATE_INPUT,
            Status::WrongOrder => GMPU_ERROR_WRONG_ORDER,
            Status::OutOfMemory => GMPU_ERROR_OUT_OF_MEMORY,
            Status::LimitExceeded => GMPU_ERROR_LIMIT_EXCEEDED,
            Status::Cancelled => GMPU_ERROR_CANCELLED,
            Status::Io => GMPU_ERROR_IO,
            Status::Parse => GMPU_ERROR_PARSE,
            Status::Unsupported => GMPU_ERROR_UNSUPPORTED,
            Status::Internal => GMPU_ERROR_INTERNAL,
            Status::Busy => GMPU_ERROR_BUSY,
            Status::Unknown(raw) => raw,
        }
    }

    /// The C enumerator's name (`"GMPU_ERROR_CANCELLED"`), from `gmpu_status_name`.
    pub fn name(self) -> &'static str {
        // SAFETY: gmpu_status_name accepts any value and returns a static, never-NULL string.
        let name = unsafe { CStr::from_ptr(sys::gmpu_status_name(self.to_raw())) };
        name.to_str().unwrap_or("GMPU_UNKNOWN_STATUS")
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A failed gmpu call: the [`Status`] and the C library's message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    status: Status,
    message: String,
}

impl Error {
    /// What kind of failure it was.
    pub fn status(&self) -> Status {
        self.status
    }

    /// The message, as the C library wrote it: the status name, a colon, the reason
    /// (`"GMPU_ERROR_WRONG_ORDER: gmpu_surface_fit needs gmpu_surface_set_points first"`).
    pub fn message(&self) -> &str {
        &self.message
    }

    /// The error of a failed call made just now on this thread (reads `gmpu_last_error`).
    fn last(status: Status) -> Error {
        // SAFETY: gmpu_last_error never returns NULL; the string is valid until the next gmpu
        // call on this thread, and it is copied before any.
        let text = unsafe { CStr::from_ptr(sys::gmpu_last_error()) };
        let mut message = text.to_string_lossy().into_owned();
        if message.is_empty() {
            message = status.name().to_string();
        }
        Error { status, message }
    }

    /// An error found by the binding before calling C, worded as C words its own.
    fn binding(status: Status, reason: impl fmt::Display) -> Error {
        Error { status, message: format!("{}: {reason}", status.name()) }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// Ok for `GMPU_OK`, else the error with this thread's last message.
fn check(status: sys::gmpu_status) -> Result<()> {
    match Status::from_raw(status) {
        None => Ok(()),
        Some(s) => Err(Error::last(s)),
    }
}

// ---- enums: parameters, stages, statistics ------------------------------------------------

macro_rules! key_enum {
    ($(#[$meta:meta])* $name:ident : $raw:ty { $( $(#[$vmeta:meta])* $variant:ident = $value:path, )* }) => {
        $(#[$meta])*
        #[non_exhaustive]
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u32)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $value, )*
        }
        impl $name {
            /// Every variant, in the header's order.
            pub const ALL: &'static [$name] = &[ $( $name::$variant, )* ];
            /// The raw C enum value.
            pub fn to_raw(self) -> $raw {
                self as $raw
            }
            /// The variant of a raw C enum value, if this binding knows it.
            pub fn from_raw(raw: $raw) -> Option<$name> {
                match raw {
                    $( $value => Some($name::$variant), )*
                    _ => None,
                }
            }
        }
    };
}

key_enum! {
    /// A parameter of [`Surface::set_param`] (`gmpu_param`). Its name, default, range and
    /// doc are the library's: [`Param::info`].
    Param: sys::gmpu_param {
        /// ε, the largest fit error allowed, as a fraction of the bounding-box diagonal.
        Error = sys::GMPU_PARAM_ERROR,
        /// Deepest octree level.
        MaxDepth = sys::GMPU_PARAM_MAX_DEPTH,
        /// Fewest points a local fit uses.
        MinPoints = sys::GMPU_PARAM_MIN_POINTS,
        /// α: support radius = α × cell diagonal.
        SupportScale = sys::GMPU_PARAM_SUPPORT_SCALE,
        /// 1: piecewise quadrics where a small cell straddles a sharp edge or corner.
        SharpFeatures = sys::GMPU_PARAM_SHARP_FEATURES,
        /// Polygonize grid cubes along the longest side; 0 picks one from the octree.
        Resolution = sys::GMPU_PARAM_RESOLUTION,
        /// Level of detail for evaluate and polygonize; 0 uses every level.
        Level = sys::GMPU_PARAM_LEVEL,
        /// Worker threads for set_points (kd-tree build, outlier scan), fit, orient and polygonize;
        /// 0 uses every core.
        Threads = sys::GMPU_PARAM_THREADS,
        /// Fit fails with [`Status::LimitExceeded`] instead of making more cells than this.
        MaxCells = sys::GMPU_PARAM_MAX_CELLS,
        /// Polygonize fails with [`Status::LimitExceeded`] instead of making more triangles.
        MaxTriangles = sys::GMPU_PARAM_MAX_TRIANGLES,
        /// Noise floor for ε: fit works to max(Error, NoiseScale × estimated noise).
        NoiseScale = sys::GMPU_PARAM_NOISE_SCALE,
        /// Memory budget in bytes: fit and polygonize fail with [`Status::LimitExceeded`]
        /// when their estimated peak exceeds it.
        MaxMemory = sys::GMPU_PARAM_MAX_MEMORY,
        /// 1 (default): set_points leaves the outliers it finds out of the fit; 0 fits them.
        RemoveOutliers = sys::GMPU_PARAM_REMOVE_OUTLIERS,
        /// 0: the MPU blend; 1: a smooth surface solved from the oriented points; 2
        /// (default): 1 where the estimated noise is at least 0.3 % of the diagonal.
        Surface = sys::GMPU_PARAM_SURFACE,
    }
}

/// One row of the library's parameter table (`gmpu_param_info`).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamInfo {
    /// The raw `gmpu_param` key (1..=[`param_count`]).
    pub key: u32,
    /// The library's name (`"max_depth"`).
    pub name: &'static str,
    /// Only whole numbers are accepted.
    pub integer: bool,
    /// A new surface's value.
    pub default: f64,
    /// Smallest accepted value (refused itself when `min_exclusive`).
    pub min: f64,
    /// Largest accepted value (refused itself when `max_exclusive`).
    pub max: f64,
    /// `min` itself is refused.
    pub min_exclusive: bool,
    /// `max` itself is refused.
    pub max_exclusive: bool,
    /// Changing the value discards a previous fit.
    pub refits: bool,
    /// One line: what the parameter does.
    pub doc: &'static str,
}

fn static_str(p: *const c_char) -> &'static str {
    // SAFETY: the library's parameter strings are NUL-terminated static storage.
    unsafe { CStr::from_ptr(p) }.to_str().unwrap_or("")
}

/// Number of parameter keys the library has: they are `1..=param_count()`.
pub fn param_count() -> u32 {
    // SAFETY: no arguments, no state.
    u32::try_from(unsafe { sys::gmpu_param_count() }).unwrap_or(0)
}

/// The library's description of a raw key (also of keys newer than this binding's [`Param`]).
pub fn param_info(key: u32) -> Result<ParamInfo> {
    let mut raw = std::mem::MaybeUninit::<sys::gmpu_param_info_t>::zeroed();
    // SAFETY: valid out pointer; unknown keys are refused with a status.
    check(unsafe { sys::gmpu_param_info(key, raw.as_mut_ptr()) })?;
    // SAFETY: filled by the successful call above.
    let raw = unsafe { raw.assume_init() };
    Ok(ParamInfo {
        key,
        name: static_str(raw.name),
        integer: raw.type_ == sys::GMPU_TYPE_INT,
        default: raw.default_value,
        min: raw.min,
        max: raw.max,
        min_exclusive: raw.min_exclusive != 0,
        max_exclusive: raw.max_exclusive != 0,
        refits: raw.refits != 0,
        doc: static_str(raw.doc),
    })
}

/// Every parameter the library has, in key order.
pub fn param_table() -> Vec<ParamInfo> {
    (1..=param_count()).filter_map(|key| param_info(key).ok()).collect()
}

impl Param {
    /// The library's description of this parameter.
    pub fn info(self) -> ParamInfo {
        param_info(self.to_raw()).expect("every Param variant is a key of the library it links")
    }

    /// The library's name of this parameter (`"max_depth"`).
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The parameter the library calls `name` (`"max_depth"` or `"GMPU_PARAM_MAX_DEPTH"`).
    pub fn from_name(name: &str) -> Option<Param> {
        let c = CString::new(name).ok()?;
        // SAFETY: NUL-terminated string, read only during the call.
        let key = unsafe { sys::gmpu_param_key(c.as_ptr()) };
        Param::from_raw(u32::try_from(key).ok()?)
    }
}

key_enum! {
    /// A statistic of [`Surface::stat`] (`gmpu_stat`).
    Stat: sys::gmpu_stat {
        /// Input points.
        Points = sys::GMPU_STAT_POINTS,
        /// Octree cells, all levels.
        Cells = sys::GMPU_STAT_CELLS,
        /// Leaf cells.
        Leaves = sys::GMPU_STAT_LEAVES,
        /// Deepest leaf level.
        Depth = sys::GMPU_STAT_DEPTH,
        /// Leaves fitted with a general quadric.
        QuadricCells = sys::GMPU_STAT_QUADRIC_CELLS,
        /// Leaves fitted with a bivariate quadratic.
        BivariateCells = sys::GMPU_STAT_BIVARIATE_CELLS,
        /// Leaves fitted with piecewise quadrics.
        PiecewiseCells = sys::GMPU_STAT_PIECEWISE_CELLS,
        /// Connected pieces found by orient.
        Components = sys::GMPU_STAT_COMPONENTS,
        /// Leaves whose fitted sign orient reversed.
        FlippedCells = sys::GMPU_STAT_FLIPPED_CELLS,
        /// Wall time of the last fit.
        FitSeconds = sys::GMPU_STAT_FIT_SECONDS,
        /// Wall time of the last orient.
        OrientSeconds = sys::GMPU_STAT_ORIENT_SECONDS,
        /// Wall time of the last polygonize.
        PolygonizeSeconds = sys::GMPU_STAT_POLYGONIZE_SECONDS,
        /// Grid resolution the last polygonize used.
        Resolution = sys::GMPU_STAT_RESOLUTION,
        /// Diagonal of the points' bounding box.
        BboxDiagonal = sys::GMPU_STAT_BBOX_DIAGONAL,
        /// Estimated noise, as a fraction of the diagonal.
        Noise = sys::GMPU_STAT_NOISE,
        /// The ε fit worked to, as a fraction of the diagonal.
        EffectiveError = sys::GMPU_STAT_EFFECTIVE_ERROR,
        /// Input points set aside as outliers (far from every other point).
        Outliers = sys::GMPU_STAT_OUTLIERS,
    }
}

/// The stage a progress report is about (`gmpu_stage`).
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// [`Surface::fit`].
    Fit,
    /// [`Surface::orient`].
    Orient,
    /// [`Surface::polygonize`].
    Polygonize,
    /// [`Points::read_with`].
    Read,
    /// A stage this binding does not know (from a newer library).
    Unknown(u32),
}

impl Stage {
    /// The stage of a raw `gmpu_stage`.
    pub fn from_raw(raw: sys::gmpu_stage) -> Stage {
        match raw {
            sys::GMPU_STAGE_FIT => Stage::Fit,
            sys::GMPU_STAGE_ORIENT => Stage::Orient,
            sys::GMPU_STAGE_POLYGONIZE => Stage::Polygonize,
            sys::GMPU_STAGE_READ => Stage::Read,
            other => Stage::Unknown(other),
        }
    }

    /// The raw `gmpu_stage` value.
    pub fn to_raw(self) -> sys::gmpu_stage {
        match self {
            Stage::Fit => sys::GMPU_STAGE_FIT,
            Stage::Orient => sys::GMPU_STAGE_ORIENT,
            Stage::Polygonize => sys::GMPU_STAGE_POLYGONIZE,
            Stage::Read => sys::GMPU_STAGE_READ,
            Stage::Unknown(raw) => raw,
        }
    }
}

// ---- coordinates in -----------------------------------------------------------------------

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// `f64` or `f32`: the coordinate types the C library takes points and normals in.
pub trait Real: Copy + sealed::Sealed + 'static {
    #[doc(hidden)]
    unsafe fn set_points(s: *mut sys::gmpu_surface, p: *const Self, count: usize, stride: usize) -> sys::gmpu_status;
    #[doc(hidden)]
    unsafe fn set_normals(s: *mut sys::gmpu_surface, p: *const Self, count: usize, stride: usize) -> sys::gmpu_status;
}

impl Real for f64 {
    unsafe fn set_points(s: *mut sys::gmpu_surface, p: *const f64, n: usize, stride: usize) -> sys::gmpu_status {
        sys::gmpu_surface_set_points_f64(s, p, n, stride)
    }
    unsafe fn set_normals(s: *mut sys::gmpu_surface, p: *const f64, n: usize, stride: usize) -> sys::gmpu_status {
        sys::gmpu_surface_set_normals_f64(s, p, n, stride)
    }
}

impl Real for f32 {
    unsafe fn set_points(s: *mut sys::gmpu_surface, p: *const f32, n: usize, stride: usize) -> sys::gmpu_status {
        sys::gmpu_surface_set_points_f32(s, p, n, stride)
    }
    unsafe fn set_normals(s: *mut sys::gmpu_surface, p: *const f32, n: usize, stride: usize) -> sys::gmpu_status {
        sys::gmpu_surface_set_normals_f32(s, p, n, stride)
    }
}

/// Number of points in `data` with `stride` elements from one point to the next: the last
/// point needs only its 3 coordinates, so `[x y z nx ny nz]*n` and the same without the last
/// normal both hold n points.
fn strided_count(len: usize, stride: usize, what: &str) -> Result<usize> {
    if stride < 3 {
        return Err(Error::binding(
            Status::InvalidArgument,
            format_args!("{what} stride {stride} is smaller than one point (3 elements)"),
        ));
    }
    if len == 0 {
        return Ok(0);
    }
    let tail = len % stride;
    match tail {
        0 => Ok(len / stride),
        t if t >= 3 => Ok(len / stride + 1),
        _ => Err(Error::binding(
            Status::InvalidArgument,
            format_args!("{what} has {len} elements: not a whole number of points at stride {stride}"),
        )),
    }
}

fn flat<T>(points: &[[T; 3]]) -> *const T {
    points.as_ptr().cast()
}

fn c_path(path: &Path) -> Result<CString> {
    #[cfg(unix)]
    let bytes = {
        use std::os::unix::ffi::OsStrExt;
        path.as_os_str().as_bytes().to_vec()
    };
    #[cfg(not(unix))]
    let bytes = match path.to_str() {
        Some(s) => s.as_bytes().to_vec(),
        None => return Err(Error::binding(Status::InvalidArgument, format_args!("path {path:?} is not UTF-8"))),
    };
    CString::new(bytes)
        .map_err(|_| Error::binding(Status::InvalidArgument, format_args!("path {path:?} contains a NUL byte")))
}

/// A C array of `count` triples as a slice (empty for a NULL pointer or a zero count).
///
/// # Safety
/// `ptr` must be NULL or point to `3 × count` values that live as long as `'a`.
unsafe fn triples<'a, T>(ptr: *const T, count: usize) -> &'a [[T; 3]] {
    if ptr.is_null() || count == 0 {
        &[]
    } else {
        std::slice::from_raw_parts(ptr.cast::<[T; 3]>(), count)
    }
}

// ---- progress -----------------------------------------------------------------------------

type ProgressFn = dyn FnMut(Stage, f64) -> ControlFlow<()> + Send;

/// What the C library's `user` pointer points at while a callback is registered.
struct ProgressState {
    callback: Box<ProgressFn>,
    /// A panic caught in the trampoline, resumed when the C call has returned.
    panic: Option<Box<dyn Any + Send + 'static>>,
}

unsafe extern "C" fn progress_trampoline(user: *mut c_void, stage: sys::gmpu_stage, fraction: f64) -> c_int {
    // SAFETY: user is the ProgressState registered with this trampoline; the C library calls
    // it only on the thread inside a `&mut self` call of the owning Surface, so this is the
    // only reference to it.
    let state = unsafe { &mut *user.cast::<ProgressState>() };
    if state.panic.is_some() {
        return 1; // keep cancelling; never call a closure that panicked again
    }
    let callback = &mut state.callback;
    match panic::catch_unwind(AssertUnwindSafe(|| callback(Stage::from_raw(stage), fraction))) {
        Ok(ControlFlow::Continue(())) => 0,
        Ok(ControlFlow::Break(())) => 1,
        Err(payload) => {
            state.panic = Some(payload);
            1
        }
    }
}

// ---- surface ------------------------------------------------------------------------------

/// A reconstruction: input points, the octree of local fits and their orientation.
/// Owns its `gmpu_surface` handle (freed on drop).
pub struct Surface {
    raw: NonNull<sys::gmpu_surface>,
    /// Box::into_raw of the registered progress state, freed after the handle.
    progress: *mut ProgressState,
}

// SAFETY: a gmpu_surface shares no state with other handles and has no thread affinity; the
// progress closure is required to be Send.
unsafe impl Send for Surface {}
// SAFETY: every `&self` method calls only functions the header declares with a const
// surface pointer, which it allows to run concurrently; the progress state is touched only
// under `&mut self`.
unsafe impl Sync for Surface {}

impl fmt::Debug for Surface {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Surface").field("raw", &self.raw).field("points", &self.point_count()).finish()
    }
}

impl Surface {
    /// An empty surface with default parameters.
    pub fn new() -> Result<Surface> {
        let mut raw = ptr::null_mut();
        // SAFETY: out is a valid pointer.
        check(unsafe { sys::gmpu_surface_create(&mut raw) })?;
        let raw = NonNull::new(raw)
            .ok_or_else(|| Error::binding(Status::Internal, "gmpu_surface_create returned GMPU_OK and NULL"))?;
        Ok(Surface { raw, progress: ptr::null_mut() })
    }

    /// The raw handle, for calling [`sys`] functions that take a const surface.
    pub fn as_ptr(&self) -> *const sys::gmpu_surface {
        self.raw.as_ptr()
    }

    /// The raw handle, for calling [`sys`] functions. Do not destroy it or replace its
    /// progress callback.
    pub fn as_mut_ptr(&mut self) -> *mut sys::gmpu_surface {
        self.raw.as_ptr()
    }

    /// Runs a modifying C call, then resumes a panic its progress callback caught.
    fn call(&mut self, f: impl FnOnce(*mut sys::gmpu_surface) -> sys::gmpu_status) -> Result<()> {
        let result = check(f(self.raw.as_ptr()));
        if !self.progress.is_null() {
            // SAFETY: progress is our live Box, and the C call that could use it has returned.
            if let Some(payload) = unsafe { (*self.progress).panic.take() } {
                panic::resume_unwind(payload);
            }
        }
        result
    }

    /// Sets one parameter. Fails with [`Status::InvalidArgument`] (naming the range) when
    /// the value is out of range. Parameters marked so in the header discard a previous fit.
    pub fn set_param(&mut self, key: Param, value: f64) -> Result<()> {
        // SAFETY: valid handle, exclusive access.
        self.call(|s| unsafe { sys::gmpu_surface_set_param(s, key.to_raw(), value) })
    }

    /// Sets several parameters, stopping at the first failure.
    pub fn set_params(&mut self, params: &[(Param, f64)]) -> Result<()> {
        params.iter().try_for_each(|&(key, value)| self.set_param(key, value))
    }

    /// The current value of a parameter.
    pub fn param(&self, key: Param) -> Result<f64> {
        let mut value = 0.0;
        // SAFETY: const call, valid handle and out pointer.
        check(unsafe { sys::gmpu_surface_get_param(self.raw.as_ptr(), key.to_raw(), &mut value) })?;
        Ok(value)
    }

    /// A statistic of the latest completed stages (0 before they ran).
    pub fn stat(&self, key: Stat) -> Result<f64> {
        let mut value = 0.0;
        // SAFETY: const call, valid handle and out pointer.
        check(unsafe { sys::gmpu_surface_get_stat(self.raw.as_ptr(), key.to_raw(), &mut value) })?;
        Ok(value)
    }

    /// Message of the last failed call that modified this surface (`""` if none).
    pub fn last_error(&self) -> String {
        // SAFETY: const call; the string lives until the next non-const call, which `&self`
        // excludes while it is copied.
        unsafe { CStr::from_ptr(sys::gmpu_surface_last_error(self.raw.as_ptr())) }.to_string_lossy().into_owned()
    }

    /// Registers `callback` for progress reports of `fit`, `orient` and `polygonize`
    /// (replacing an earlier one). It is called on the thread making the call, at least
    /// every 50 ms, with the stage and a fraction in [0, 1]; returning
    /// [`ControlFlow::Break`] cancels the stage, which then fails with
    /// [`Status::Cancelled`] within 100 ms, keeping the stages completed before. A panic in
    /// the callback cancels the stage too and is resumed when the call returns; the closure
    /// is not called again during that call.
    /// Every report counts, the final one (fraction 1) included.
    pub fn set_progress<F>(&mut self, callback: F) -> Result<()>
    where
        F: FnMut(Stage, f64) -> ControlFlow<()> + Send + 'static,
    {
        let state = Box::into_raw(Box::new(ProgressState { callback: Box::new(callback), panic: None }));
        // SAFETY: valid handle; state stays alive until replaced or the surface is dropped.
        let status =
            unsafe { sys::gmpu_surface_set_progress(self.raw.as_ptr(), Some(progress_trampoline), state.cast()) };
        if let Err(e) = check(status) {
            // SAFETY: not registered, still ours.
            drop(unsafe { Box::from_raw(state) });
            return Err(e);
        }
        self.free_progress();
        self.progress = state;
        Ok(())
    }

    /// Removes the progress callback.
    pub fn clear_progress(&mut self) -> Result<()> {
        // SAFETY: valid handle.
        check(unsafe { sys::gmpu_surface_set_progress(self.raw.as_ptr(), None, ptr::null_mut()) })?;
        self.free_progress();
        Ok(())
    }

    fn free_progress(&mut self) {
        if !self.progress.is_null() {
            // SAFETY: made by Box::into_raw in set_progress and no longer registered.
            drop(unsafe { Box::from_raw(self.progress) });
            self.progress = ptr::null_mut();
        }
    }

    /// Copies the points (replacing earlier ones and discarding any fit, orientation and
    /// normals). Fails with [`Status::InvalidInput`] for fewer points than
    /// [`Param::MinPoints`] or a NaN/infinite coordinate (the message gives its index), and
    /// [`Status::DegenerateInput`] when they bound no volume. On failure the previous points
    /// are kept.
    pub fn set_points<T: Real>(&mut self, points: &[[T; 3]]) -> Result<()> {
        // SAFETY: points.len() packed triples.
        self.call(|s| unsafe { T::set_points(s, flat(points), points.len(), 0) })
    }

    /// Like [`set_points`](Self::set_points) from an interleaved array: point i is
    /// `data[i * stride .. i * stride + 3]` (stride in elements, at least 3), e.g. stride 6
    /// for `x y z nx ny nz` records.
    pub fn set_points_strided<T: Real>(&mut self, data: &[T], stride: usize) -> Result<()> {
        let count = strided_count(data.len(), stride, "xyz")?;
        let bytes = stride * std::mem::size_of::<T>();
        // SAFETY: count points at that stride lie within data.
        self.call(|s| unsafe { T::set_points(s, data.as_ptr(), count, bytes) })
    }

    /// Optional outward normals for the points, same count and order; orient then signs
    /// the fits by agreement with them instead of belief propagation. They need not be unit
    /// length but must be finite and non-zero.
    pub fn set_normals<T: Real>(&mut self, normals: &[[T; 3]]) -> Result<()> {
        // SAFETY: normals.len() packed triples.
        self.call(|s| unsafe { T::set_normals(s, flat(normals), normals.len(), 0) })
    }

    /// Like [`set_normals`](Self::set_normals) from an interleaved array (stride in
    /// elements); for `x y z nx ny nz` records pass `&data[3..]` and stride 6.
    pub fn set_normals_strided<T: Real>(&mut self, data: &[T], stride: usize) -> Result<()> {
        let count = strided_count(data.len(), stride, "nxyz")?;
        let bytes = stride * std::mem::size_of::<T>();
        // SAFETY: count triples at that stride lie within data.
        self.call(|s| unsafe { T::set_normals(s, data.as_ptr(), count, bytes) })
    }

    /// Number of points set (0 before [`set_points`](Self::set_points)).
    pub fn point_count(&self) -> usize {
        // SAFETY: const call.
        unsafe { sys::gmpu_surface_point_count(self.raw.as_ptr()) }
    }

    /// Builds the adaptive octree of local fits. Needs points; discards a previous
    /// orientation.
    pub fn fit(&mut self) -> Result<()> {
        // SAFETY: valid handle, exclusive access.
        self.call(|s| unsafe { sys::gmpu_surface_fit(s) })
    }

    /// Gives the local fits one consistent, outward sign. Needs [`fit`](Self::fit).
    pub fn orient(&mut self) -> Result<()> {
        // SAFETY: valid handle, exclusive access.
        self.call(|s| unsafe { sys::gmpu_surface_orient(s) })
    }

    /// The implicit f at each query point (positive inside, about the signed distance near
    /// the surface). Needs [`orient`](Self::orient). May run on several threads at once.
    pub fn evaluate(&self, points: &[[f64; 3]]) -> Result<Vec<f64>> {
        let mut values = vec![0.0; points.len()];
        self.evaluate_into(points, Some(&mut values), None)?;
        Ok(values)
    }

    /// ∇f at each query point.
    pub fn gradients(&self, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
        let mut gradients = vec![[0.0; 3]; points.len()];
        self.evaluate_into(points, None, Some(&mut gradients))?;
        Ok(gradients)
    }

    /// f and ∇f at each query point.
    pub fn evaluate_with_gradients(&self, points: &[[f64; 3]]) -> Result<(Vec<f64>, Vec<[f64; 3]>)> {
        let mut values = vec![0.0; points.len()];
        let mut gradients = vec![[0.0; 3]; points.len()];
        self.evaluate_into(points, Some(&mut values), Some(&mut gradients))?;
        Ok((values, gradients))
    }

    /// f and/or ∇f into caller buffers of `points.len()` entries (at least one of them).
    /// Fails with [`Status::InvalidInput`] for a NaN or infinite query (the message gives its
    /// index), leaving the outputs untouched.
    pub fn evaluate_into(
        &self,
        points: &[[f64; 3]],
        values: Option<&mut [f64]>,
        gradients: Option<&mut [[f64; 3]]>,
    ) -> Result<()> {
        let n = points.len();
        if values.as_ref().is_some_and(|v| v.len() != n) || gradients.as_ref().is_some_and(|g| g.len() != n) {
            return Err(Error::binding(
                Status::InvalidArgument,
                format_args!("output buffers must hold one entry per query point ({n})"),
            ));
        }
        let v = values.map_or(ptr::null_mut(), |v| v.as_mut_ptr());
        let g = gradients.map_or(ptr::null_mut(), |g| g.as_mut_ptr().cast::<f64>());
        // SAFETY: const call; inputs hold n triples, outputs n entries each or NULL.
        check(unsafe { sys::gmpu_surface_evaluate(self.raw.as_ptr(), flat(points), n, v, g) })
    }

    /// The oriented unit normal of every input point (−∇f normalised). Needs
    /// [`orient`](Self::orient).
    pub fn normals(&self) -> Result<Vec<[f64; 3]>> {
        let n = self.point_count();
        let mut out = vec![[0.0; 3]; n];
        // SAFETY: const call; out holds n triples.
        check(unsafe { sys::gmpu_surface_copy_normals(self.raw.as_ptr(), out.as_mut_ptr().cast(), n) })?;
        Ok(out)
    }

    /// The oriented unit normals of the input points `indices` only, as [`normals`](Self::normals)
    /// gives them, without an array of every point's normal. Needs [`orient`](Self::orient);
    /// an index not below the point count is [`Status::InvalidArgument`].
    pub fn normals_at(&self, indices: &[usize]) -> Result<Vec<[f64; 3]>> {
        // An index beyond i64 is out of range for any surface: -1 says so to the library.
        let idx: Vec<i64> = indices.iter().map(|&i| i64::try_from(i).unwrap_or(-1)).collect();
        let mut out = vec![[0.0; 3]; idx.len()];
        // SAFETY: const call; idx holds idx.len() indices and out as many triples.
        check(unsafe {
            sys::gmpu_surface_copy_normals_at(self.raw.as_ptr(), idx.as_ptr(), idx.len(), out.as_mut_ptr().cast())
        })?;
        Ok(out)
    }

    /// Extracts the zero set of f as a closed, edge-manifold, outward-wound triangle mesh.
    /// Needs [`orient`](Self::orient); uses [`Param::Resolution`] and [`Param::Level`].
    pub fn polygonize(&mut self) -> Result<Mesh> {
        let mut raw = ptr::null_mut();
        // SAFETY: valid handle, exclusive access, out pointer valid.
        self.call(|s| unsafe { sys::gmpu_surface_polygonize(s, &mut raw) })?;
        // SAFETY: on GMPU_OK raw is a mesh we now own.
        unsafe { Mesh::from_raw(raw) }
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        // SAFETY: we own the handle; destroyed exactly once, before the progress state it
        // points to.
        unsafe { sys::gmpu_surface_destroy(self.raw.as_ptr()) };
        self.free_progress();
    }
}

/// Reconstructs a mesh from points in one call: sets `params`, then fit, orient and
/// polygonize on a fresh [`Surface`].
pub fn reconstruct<T: Real>(points: &[[T; 3]], params: &[(Param, f64)]) -> Result<Mesh> {
    let mut surface = Surface::new()?;
    surface.set_params(params)?;
    surface.set_points(points)?;
    surface.fit()?;
    surface.orient()?;
    surface.polygonize()
}

// ---- mesh ---------------------------------------------------------------------------------

/// A triangle mesh: from [`Surface::polygonize`] or built with [`Mesh::new`]. Owns its
/// `gmpu_mesh` handle.
pub struct Mesh {
    raw: NonNull<sys::gmpu_mesh>,
}

// SAFETY: a mesh shares nothing with other handles. Not Sync: the header does not promise
// concurrent calls on one mesh.
unsafe impl Send for Mesh {}

impl fmt::Debug for Mesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Mesh")
            .field("vertices", &self.vertex_count())
            .field("triangles", &self.triangle_count())
            .finish()
    }
}

impl Mesh {
    /// # Safety
    /// `raw` must be NULL or a mesh handle nobody else owns.
    unsafe fn from_raw(raw: *mut sys::gmpu_mesh) -> Result<Mesh> {
        NonNull::new(raw)
            .map(|raw| Mesh { raw })
            .ok_or_else(|| Error::binding(Status::Internal, "gmpu returned GMPU_OK and a NULL mesh"))
    }

    /// A mesh from vertices and triangles (copied), e.g. to write it with
    /// [`write`](Self::write). Fails with [`Status::InvalidInput`] for an index out of range
    /// or a non-finite coordinate.
    pub fn new(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Mesh> {
        let mut raw = ptr::null_mut();
        // SAFETY: arrays of the given counts.
        check(unsafe {
            sys::gmpu_mesh_create(flat(vertices), vertices.len(), flat(triangles), triangles.len(), &mut raw)
        })?;
        // SAFETY: a new mesh we own.
        unsafe { Mesh::from_raw(raw) }
    }

    /// A mesh from vertices and triangles with optional per-vertex normals (any non-zero
    /// length; kept as unit vectors), confidence and colours (red green blue), all copied and
    /// all kept by [`write`](Self::write) and [`simplify`](Self::simplify). Fails with
    /// [`Status::InvalidInput`] for an index out of range, a non-finite coordinate, a zero or
    /// non-finite normal, a negative or NaN confidence, or an array whose length is not the
    /// vertex count.
    pub fn with_attributes(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        normals: Option<&[[f64; 3]]>,
        confidence: Option<&[f64]>,
        colors: Option<&[[u8; 3]]>,
    ) -> Result<Mesh> {
        let n = vertices.len();
        let lengths = [("normals", normals.map(<[_]>::len)), ("confidence", confidence.map(<[_]>::len)), ("colors", colors.map(<[_]>::len))];
        if let Some((what, Some(len))) = lengths.into_iter().find(|(_, len)| len.is_some_and(|len| len != n)) {
            return Err(Error::binding(Status::InvalidInput, format_args!("{len} {what} given for {n} vertices")));
        }
        let mut raw = ptr::null_mut();
        // SAFETY: arrays of the given counts (checked above), or NULL.
        check(unsafe {
            sys::gmpu_mesh_create_with(
                flat(vertices),
                n,
                flat(triangles),
                triangles.len(),
                normals.map_or(ptr::null(), flat),
                confidence.map_or(ptr::null(), <[f64]>::as_ptr),
                colors.map_or(ptr::null(), flat),
                &mut raw,
            )
        })?;
        // SAFETY: a new mesh we own.
        unsafe { Mesh::from_raw(raw) }
    }

    /// Red green blue per vertex; `None` unless the mesh was coloured
    /// ([`color_from`](Self::color_from)) or built with colours.
    pub fn colors(&self) -> Option<&[[u8; 3]]> {
        // SAFETY: NULL or 3 × vertex_count bytes owned by the mesh.
        let p = unsafe { sys::gmpu_mesh_colors(self.raw.as_ptr()) };
        (!p.is_null()).then(|| unsafe { triples(p, self.vertex_count()) })
    }

    /// A copy whose every vertex takes the colour of the nearest of `points` (read from a
    /// `.ply` with red green blue, or [`Points::with_colors`]). Fails with
    /// [`Status::InvalidArgument`] when the points have no colours.
    pub fn color_from(&self, points: &Points) -> Result<Mesh> {
        let mut raw = ptr::null_mut();
        // SAFETY: valid handles and out pointer.
        check(unsafe { sys::gmpu_mesh_color_from_points(self.raw.as_ptr(), points.as_ptr(), &mut raw) })?;
        // SAFETY: a new mesh we own.
        unsafe { Mesh::from_raw(raw) }
    }

    /// The raw handle, for calling [`sys`] functions. Do not destroy it.
    pub fn as_ptr(&self) -> *const sys::gmpu_mesh {
        self.raw.as_ptr()
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        // SAFETY: valid handle.
        unsafe { sys::gmpu_mesh_vertex_count(self.raw.as_ptr()) }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        // SAFETY: valid handle.
        unsafe { sys::gmpu_mesh_triangle_count(self.raw.as_ptr()) }
    }

    /// Vertex positions, borrowed from the mesh (`.to_vec()` for an owned copy).
    pub fn vertices(&self) -> &[[f64; 3]] {
        // SAFETY: 3 × vertex_count doubles owned by the mesh, which outlives the borrow.
        unsafe { triples(sys::gmpu_mesh_vertices(self.raw.as_ptr()), self.vertex_count()) }
    }

    /// Unit outward normal per vertex; `None` for a mesh made by [`Mesh::new`].
    pub fn normals(&self) -> Option<&[[f64; 3]]> {
        // SAFETY: NULL or 3 × vertex_count doubles owned by the mesh.
        let p = unsafe { sys::gmpu_mesh_normals(self.raw.as_ptr()) };
        (!p.is_null()).then(|| unsafe { triples(p, self.vertex_count()) })
    }

    /// Three vertex indices per triangle, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        // SAFETY: 3 × triangle_count indices owned by the mesh.
        unsafe { triples(sys::gmpu_mesh_triangles(self.raw.as_ptr()), self.triangle_count()) }
    }

    /// Per vertex: distance to the nearest input point in sample spacings (about 0.5 or
    /// less on sampled surface, several over a scan's holes); `None` for a mesh made by
    /// [`Mesh::new`].
    pub fn confidence(&self) -> Option<&[f64]> {
        // SAFETY: NULL or vertex_count doubles owned by the mesh.
        let p = unsafe { sys::gmpu_mesh_confidence(self.raw.as_ptr()) };
        (!p.is_null()).then(|| unsafe { std::slice::from_raw_parts(p, self.vertex_count()) })
    }

    /// A decimated copy: at most `target_triangles` triangles (0: no count target), the
    /// surface moved by at most `target_error` × the bounding-box diagonal (1: no bound).
    /// Topology is kept (closed, manifold, components, genus), so it may stop above the
    /// count. Normals are recomputed, confidence carried. Fails with
    /// [`Status::InvalidArgument`] for `target_error` outside [0, 1].
    pub fn simplify(&self, target_triangles: usize, target_error: f64) -> Result<Mesh> {
        let mut raw = ptr::null_mut();
        // SAFETY: valid handle and out pointer.
        check(unsafe { sys::gmpu_mesh_simplify(self.raw.as_ptr(), target_triangles, target_error, &mut raw) })?;
        // SAFETY: a new mesh we own.
        unsafe { Mesh::from_raw(raw) }
    }

    /// A copy cut where the confidence passes `threshold` sample spacings, in the regions
    /// that rise to twice it (1.5 is a good start): the caps over a scan's holes go, leaving
    /// boundaries (triangles across the cut are clipped). Fails with
    /// [`Status::InvalidArgument`] for a mesh without confidence (made by [`Mesh::new`]) or a
    /// threshold that is not finite and positive.
    pub fn trim(&self, threshold: f64) -> Result<Mesh> {
        let mut raw = ptr::null_mut();
        // SAFETY: valid handle and out pointer.
        check(unsafe { sys::gmpu_mesh_trim(self.raw.as_ptr(), threshold, &mut raw) })?;
        // SAFETY: a new mesh we own.
        unsafe { Mesh::from_raw(raw) }
    }

    /// Writes the mesh; the format comes from the extension (`.ply` binary little-endian,
    /// `.obj`, `.off`, `.stl`, `.glb`). Atomic: a failure never leaves a partial file.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = c_path(path.as_ref())?;
        // SAFETY: valid handle and NUL-terminated path.
        check(unsafe { sys::gmpu_mesh_write(self.raw.as_ptr(), path.as_ptr()) })
    }
}

impl Drop for Mesh {
    fn drop(&mut self) {
        // SAFETY: we own the handle.
        unsafe { sys::gmpu_mesh_destroy(self.raw.as_ptr()) }
    }
}

// ---- points -------------------------------------------------------------------------------

/// A point cloud with optional normals: read from a file or built from slices. Owns its
/// `gmpu_points` handle.
pub struct Points {
    raw: NonNull<sys::gmpu_points>,
}

// SAFETY: a point set shares nothing with other handles. Not Sync (see Mesh).
unsafe impl Send for Points {}

impl fmt::Debug for Points {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Points").field("len", &self.len()).field("normals", &self.normals().is_some()).finish()
    }
}

impl Points {
    /// Reads `.ply` (ascii or binary; x y z and optional nx ny nz), `.xyz`/`.txt` (3 or 6
    /// columns), `.off` or `.obj` (vertices). Fails with [`Status::Io`], [`Status::Parse`],
    /// [`Status::Unsupported`] or [`Status::InvalidInput`] (no points).
    pub fn read(path: impl AsRef<Path>) -> Result<Points> {
        let path = c_path(path.as_ref())?;
        let mut raw = ptr::null_mut();
        // SAFETY: NUL-terminated path, valid out pointer.
        check(unsafe { sys::gmpu_points_read(path.as_ptr(), &mut raw) })?;
        NonNull::new(raw)
            .map(|raw| Points { raw })
            .ok_or_else(|| Error::binding(Status::Internal, "gmpu_points_read returned GMPU_OK and NULL"))
    }

    /// [`read`](Self::read) with a memory budget and progress (`gmpu_points_read_with`):
    /// `max_memory` in bytes (0: half the physical memory) — a file whose points would need
    /// more fails with [`Status::LimitExceeded`] before its body is read; `progress` gets
    /// [`Stage::Read`] and the fraction read, with the contract of
    /// [`Surface::set_progress`] ([`ControlFlow::Break`] cancels: [`Status::Cancelled`]; a
    /// panic cancels and is resumed).
    pub fn read_with<F>(path: impl AsRef<Path>, max_memory: f64, progress: F) -> Result<Points>
    where
        F: FnMut(Stage, f64) -> ControlFlow<()> + Send + 'static,
    {
        let path = c_path(path.as_ref())?;
        let mut state = ProgressState { callback: Box::new(progress), panic: None };
        let mut raw = ptr::null_mut();
        // SAFETY: NUL-terminated path, valid out pointer; state outlives the call, which is
        // the only user of the trampoline's pointer.
        let status = unsafe {
            sys::gmpu_points_read_with(
                path.as_ptr(),
                max_memory,
                Some(progress_trampoline),
                ptr::addr_of_mut!(state).cast(),
                &mut raw,
            )
        };
        if let Some(payload) = state.panic.take() {
            panic::resume_unwind(payload);
        }
        check(status)?;
        NonNull::new(raw)
            .map(|raw| Points { raw })
            .ok_or_else(|| Error::binding(Status::Internal, "gmpu_points_read_with returned GMPU_OK and NULL"))
    }

    /// A point set from positions and optional normals (copied; same length).
    pub fn new(positions: &[[f64; 3]], normals: Option<&[[f64; 3]]>) -> Result<Points> {
        Points::with_colors(positions, normals, None)
    }

    /// A point set from positions, optional normals and optional colours (red green blue),
    /// copied; every array as long as `positions`.
    pub fn with_colors(positions: &[[f64; 3]], normals: Option<&[[f64; 3]]>, colors: Option<&[[u8; 3]]>) -> Result<Points> {
        if let Some(n) = normals.filter(|n| n.len() != positions.len()) {
            return Err(Error::binding(
                Status::InvalidInput,
                format_args!("{} normals given for {} points", n.len(), positions.len()),
            ));
        }
        if let Some(c) = colors.filter(|c| c.len() != positions.len()) {
            return Err(Error::binding(
                Status::InvalidInput,
                format_args!("{} colors given for {} points", c.len(), positions.len()),
            ));
        }
        let mut raw = ptr::null_mut();
        // SAFETY: positions.len() triples each, normals and colors NULL or as many.
        check(unsafe {
            sys::gmpu_points_create_with(
                flat(positions),
                normals.map_or(ptr::null(), flat),
                colors.map_or(ptr::null(), flat),
                positions.len(),
                &mut raw,
            )
        })?;
        NonNull::new(raw)
            .map(|raw| Points { raw })
            .ok_or_else(|| Error::binding(Status::Internal, "gmpu_points_create returned GMPU_OK and NULL"))
    }

    /// The raw handle, for calling [`sys`] functions. Do not destroy it.
    pub fn as_ptr(&self) -> *const sys::gmpu_points {
        self.raw.as_ptr()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        // SAFETY: valid handle.
        unsafe { sys::gmpu_points_count(self.raw.as_ptr()) }
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Positions, borrowed from the point set.
    pub fn positions(&self) -> &[[f64; 3]] {
        // SAFETY: 3 × count doubles owned by the point set.
        unsafe { triples(sys::gmpu_points_positions(self.raw.as_ptr()), self.len()) }
    }

    /// Normals, if the file or the caller gave them.
    pub fn normals(&self) -> Option<&[[f64; 3]]> {
        // SAFETY: NULL or 3 × count doubles owned by the point set.
        let p = unsafe { sys::gmpu_points_normals(self.raw.as_ptr()) };
        (!p.is_null()).then(|| unsafe { triples(p, self.len()) })
    }

    /// Red green blue per point, from a `.ply` with uchar red green blue (or
    /// [`with_colors`](Self::with_colors)).
    pub fn colors(&self) -> Option<&[[u8; 3]]> {
        // SAFETY: NULL or 3 × count bytes owned by the point set.
        let p = unsafe { sys::gmpu_points_colors(self.raw.as_ptr()) };
        (!p.is_null()).then(|| unsafe { triples(p, self.len()) })
    }

    /// Writes the points (and normals, if any): `.ply` (binary little-endian) or `.xyz`.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = c_path(path.as_ref())?;
        // SAFETY: valid handle and NUL-terminated path.
        check(unsafe { sys::gmpu_points_write(self.raw.as_ptr(), path.as_ptr()) })
    }
}

impl Drop for Points {
    fn drop(&mut self) {
        // SAFETY: we own the handle.
        unsafe { sys::gmpu_points_destroy(self.raw.as_ptr()) }
    }
}

// ---- version ------------------------------------------------------------------------------

/// The library's version string (`"0.1.0"`).
pub fn version() -> &'static str {
    // SAFETY: static, NUL-terminated storage.
    unsafe { CStr::from_ptr(sys::gmpu_version_string()) }.to_str().unwrap_or("")
}

/// The library's `GMPU_VERSION_NUMBER` (MAJOR×10000 + MINOR×100 + PATCH).
pub fn version_number() -> u32 {
    // SAFETY: no arguments.
    unsafe { sys::gmpu_version_number() }
}

/// The library's ABI version (its SONAME number); [`sys::GMPU_ABI_VERSION`] is this
/// binding's.
pub fn abi_version() -> u32 {
    // SAFETY: no arguments.
    unsafe { sys::gmpu_abi_version() }
}
