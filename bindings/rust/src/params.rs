//! [`Params`]: a typed builder of surface parameters, checked against the library's own
//! parameter table (`gmpu_param_info`), so its ranges are never restated here.

use std::ops::Deref;

use crate::{param_info, Error, Param, Result, Status, Surface};

/// Surface parameters, built by name and type instead of `(Param, f64)` pairs:
///
/// ```
/// use gmpu::Params;
/// # fn main() -> Result<(), gmpu::Error> {
/// let params = Params::new().max_depth(8).noise_scale(1.5).sharp_features(true).validated()?;
/// let mut surface = gmpu::Surface::new()?;
/// surface.apply(&params)?;
/// assert_eq!(surface.param(gmpu::Param::MaxDepth)?, 8.0);
/// // A Params is also the `&[(Param, f64)]` that reconstruct and set_params take.
/// assert_eq!(params.len(), 3);
/// # Ok(())
/// # }
/// ```
///
/// Setters only record the value (a later one for the same parameter replaces it);
/// [`validated`](Self::validated) checks every value against the library's table (type
/// and range, with the library's message), and [`Surface::apply`] sets them all.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Params {
    values: Vec<(Param, f64)>,
}

macro_rules! setters {
    ($($(#[$doc:meta])* $name:ident($ty:ty) => $key:ident;)*) => {
        $(
            $(#[$doc])*
            #[must_use]
            pub fn $name(self, value: $ty) -> Params {
                self.set(Param::$key, f64::from(value))
            }
        )*
    };
}

impl Params {
    /// No parameters: the library's defaults.
    pub fn new() -> Params {
        Params::default()
    }

    /// Sets `key` to `value`, replacing an earlier value of the same key.
    #[must_use]
    pub fn set(mut self, key: Param, value: f64) -> Params {
        match self.values.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => slot.1 = value,
            None => self.values.push((key, value)),
        }
        self
    }

    setters! {
        /// ε, as a fraction of the bounding-box diagonal ([`Param::Error`]).
        error(f64) => Error;
        /// Deepest octree level ([`Param::MaxDepth`]).
        max_depth(u32) => MaxDepth;
        /// Fewest points a local fit uses ([`Param::MinPoints`]).
        min_points(u32) => MinPoints;
        /// α: support radius = α × cell diagonal ([`Param::SupportScale`]).
        support_scale(f64) => SupportScale;
        /// Piecewise quadrics at sharp edges and corners ([`Param::SharpFeatures`]).
        sharp_features(bool) => SharpFeatures;
        /// Polygonize grid cubes along the longest side; 0 picks one ([`Param::Resolution`]).
        resolution(u32) => Resolution;
        /// Level of detail; 0 uses every level ([`Param::Level`]).
        level(u32) => Level;
        /// Worker threads; 0 uses every core ([`Param::Threads`]).
        threads(u32) => Threads;
        /// Cap on octree cells ([`Param::MaxCells`]).
        max_cells(f64) => MaxCells;
        /// Cap on triangles ([`Param::MaxTriangles`]).
        max_triangles(f64) => MaxTriangles;
        /// Noise floor for ε, in estimated noise units ([`Param::NoiseScale`]).
        noise_scale(f64) => NoiseScale;
        /// Memory budget in bytes ([`Param::MaxMemory`]).
        max_memory(f64) => MaxMemory;
        /// Leave the outliers set_points finds out of the fit ([`Param::RemoveOutliers`]).
        remove_outliers(bool) => RemoveOutliers;
        /// 0 the MPU blend, 1 the smooth surface, 2 chosen from the noise ([`Param::Surface`]).
        surface(u32) => Surface;
    }

    /// Checks every value against the library's parameter table: a whole number for an
    /// integer parameter, inside its range. Fails with [`Status::InvalidArgument`] naming the
    /// parameter, the value and the range.
    pub fn validated(self) -> Result<Params> {
        for &(key, value) in &self.values {
            let info = param_info(key.to_raw())?;
            let above_min = if info.min_exclusive { value > info.min } else { value >= info.min };
            let below_max = if info.max_exclusive { value < info.max } else { value <= info.max };
            let whole = !info.integer || value.fract() == 0.0;
            if !(above_min && below_max && whole && value.is_finite()) {
                let (open, close) = (if info.min_exclusive { '(' } else { '[' }, if info.max_exclusive { ')' } else { ']' });
                let kind = if info.integer { "an integer" } else { "a number" };
                return Err(Error::binding(
                    Status::InvalidArgument,
                    format_args!("{} = {value} is out of range: expected {kind} in {open}{}, {}{close}", info.name, info.min, info.max),
                ));
            }
        }
        Ok(self)
    }
}

impl Deref for Params {
    type Target = [(Param, f64)];
    fn deref(&self) -> &[(Param, f64)] {
        &self.values
    }
}

impl Surface {
    /// Sets every parameter of `params` (the library checks each; see [`Params::validated`]).
    pub fn apply(&mut self, params: &Params) -> Result<()> {
        self.set_params(params)
    }
}
