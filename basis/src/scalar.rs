//! The scalar type of bases and of everything built on them.
//!
//! Meshes keep their geometry in `f64`; a basis evaluates in any [`Real`] (f64 by
//! default, f32 where memory or bandwidth matter). `Real` is nalgebra's
//! [`RealField`] plus the conversions numerical code needs.

use nalgebra::RealField;

/// A floating-point scalar usable by the bases and the MPM driver (`f32` or `f64`).
pub trait Real:
    RealField + Copy + Default + Send + Sync + std::fmt::Debug + std::fmt::LowerExp + 'static
{
    /// Converts an `f64` constant or coordinate into this type (rounding for `f32`).
    fn of(x: f64) -> Self;
    /// Widens to `f64` (exact for both implementations).
    fn to_f64(self) -> f64;
    /// Machine epsilon of this type.
    const EPSILON: Self;
}

impl Real for f64 {
    #[inline(always)]
    fn of(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    const EPSILON: Self = f64::EPSILON;
}

impl Real for f32 {
    #[inline(always)]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    const EPSILON: Self = f32::EPSILON;
}
