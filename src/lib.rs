//! psmpm: the Material Point Method with Powell–Sabin spline bases.
//!
//! The library is generic over the [`Basis`](psmpm_basis::Basis) (piecewise-linear,
//! Powell–Sabin, 1D quadratic B-spline) and works in `f64` or `f32`.
//!
//! - [`sparse`]: symmetric sparsity patterns on a basis and the sparse Cholesky solver;
//! - [`projection`]: L² projection onto a basis (benchmark B1 of the seeds).

pub use psmpm_basis as basis;

pub mod bases;
pub mod projection;
pub mod sparse;
