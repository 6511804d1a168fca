//! Meshes and spline bases for the Material Point Method.
//!
//! `psmpm-basis` is the geometric half of psmpm:
//! - [`mesh`]: validated triangle meshes with tagged boundaries, generators (the
//!   seeds' block grids, Delaunay lattices, quality meshes of polygons), Gmsh import,
//!   point location; 1D node vectors;
//! - [`quadrature`]: Gauss rules on intervals and triangles;
//! - [`refinement`]: the Powell–Sabin split of a triangulation;
//! - [`basis`]: the [`Basis`] trait and its implementations, piecewise-linear
//!   ([`basis::linear`], [`basis::linear1d`]), quadratic Powell–Sabin
//!   ([`basis::powell_sabin`]) and 1D quadratic B-splines ([`basis::bspline1d`]);
//! - [`check`]: the properties every basis must satisfy, as checks generic over the
//!   basis and its dimension, which the test suite runs on every basis and the same
//!   families of meshes;
//! - [`rng`]: the small deterministic generator behind the jittered meshes and the
//!   property tests.
//!
//! # Example
//!
//! Build the Powell–Sabin basis on the seeds' block grid and evaluate it:
//!
//! ```
//! use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
//! use psmpm_basis::mesh::generators::block_grid;
//! use psmpm_basis::{Basis, BasisEval};
//! use nalgebra::Vector2;
//!
//! // The vibrating bar's grid: 4 × 1 blocks of 4 triangles on [0, 25] × [0, 2].
//! let mesh = block_grid(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
//! let ps = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
//! assert_eq!(ps.num_functions(), 42); // 3 per vertex
//!
//! let x = Vector2::new(3.0, 0.7);
//! let element = ps.locate(&x, None).unwrap();
//! let mut eval = BasisEval::for_basis(&ps); // caller-owned, reused
//! ps.eval(element, &x, &mut eval);
//! let sum: f64 = eval.phi[..eval.len()].iter().sum();
//! assert!((sum - 1.0).abs() < 1e-14); // partition of unity
//!
//! // No-slip on the left wall: the coefficients to fix.
//! let constraints = ps.dirichlet("left", &Vector2::new(1.0, 0.0)).unwrap();
//! assert!(constraints.iter().all(|c| c.is_single()));
//! ```

pub mod basis;
pub mod check;
pub mod mesh;
pub mod quadrature;
pub mod refinement;
pub mod rng;
pub mod scalar;

pub use basis::{Basis, BasisError, BasisEval, Constraint, ElementCache, Point, Quadratic};
pub use mesh::{Mesh1d, MeshError, TriMesh, Vec2};
pub use scalar::Real;
