//! psmpm: the Material Point Method with Powell–Sabin spline bases.
pub use psmpm_basis as basis;
