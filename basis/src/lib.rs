//! Meshes and spline bases for the Material Point Method.
//!
//! `psmpm-basis` is the geometric half of psmpm: triangle meshes ([`mesh`]),
//! quadrature rules ([`quadrature`]), the Powell–Sabin refinement
//! ([`refinement`]) and the [`Basis`](basis::Basis) trait with its
//! piecewise-linear, Powell–Sabin and 1D quadratic B-spline implementations.

pub mod basis;
pub mod check;
pub mod mesh;
pub mod quadrature;
pub mod refinement;
pub mod scalar;

pub use basis::{Basis, BasisError, BasisEval, Constraint, Point};
pub use mesh::{Mesh1d, MeshError, TriMesh, Vec2};
pub use scalar::Real;
