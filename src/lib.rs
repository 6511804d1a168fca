//! psmpm: the Material Point Method with Powell–Sabin spline bases on
//! unstructured triangular grids.
//!
//! The library is generic over the [`Basis`](psmpm_basis::Basis) (piecewise-linear,
//! Powell–Sabin, 1D quadratic B-spline) and works in `f64` or `f32`.
//!
//! - [`bases`]: the typed choice of basis made at the edge (command line, scene);
//! - [`sparse`]: symmetric sparsity patterns on a basis and the sparse Cholesky solver
//!   (symbolic once, numeric per call);
//! - [`driver`]: the MPM time step, generic over basis, [`mass`] strategy and
//!   [`material`]; [`particles`]; [`effect`]s (gravity, local damping, traction,
//!   body-force fields) with their work in the energy balance, and initial stress
//!   states;
//! - [`scene`]: a run declared as data (TOML): the schema, validation, the location
//!   of errors in the file, and the built-in scenes;
//! - [`setup`]: a scene turned into mesh, basis, particles with their initial states
//!   (velocity, geostatic stress), effects and the one concrete driver;
//!   [`simulation`]: the run loop with its observers, the summary and stability
//!   verdict; [`arrangement`]: how the particles lie at the end (stray particles,
//!   bodies in pieces, an arrangement gone irregular), which the verdict does not see;
//! - [`studies`]: the checks of the method, apart from it: the seeds' exact solutions
//!   ([`studies::exact`]), the 1D updated-Lagrangian FEM reference ([`studies::ulfem`]),
//!   L² projection onto a basis, benchmark B1 ([`studies::projection`]), and the
//!   benchmark studies of `docs/results.md` ([`studies::reproduction`]);
//! - [`output`]: VTK XML, ParaView collections, CSV and SVG figures (line plots, mesh
//!   and basis function pictures), apart from the method.
//!
//! # Examples
//!
//! Run a built-in scene, changed in code, with a callback after every step:
//!
//! ```
//! use psmpm::{mass::MassKind, scene::Scene, simulation::run};
//!
//! let mut scene = Scene::builtin("column-small").unwrap();
//! scene.mass = MassKind::parse("partial").unwrap();
//! scene.time.t_end = 0.01;
//! let mut energies = Vec::new();
//! let summary = run(&scene, &mut |r| energies.push(r.total_energy())).unwrap();
//! assert!(summary.stable && summary.error.unwrap() < 1e-3);
//! assert_eq!(energies.len(), 100);
//! ```
//!
//! Project `sin(πx) sin(πy)` onto Powell–Sabin splines on a 9 × 9 lattice:
//!
//! ```
//! use psmpm::bases;
//! use psmpm::studies::projection::{l2_errors, project, MassOption, SineProduct};
//! use psmpm::basis::mesh::generators::lattice_delaunay;
//!
//! let mesh = lattice_delaunay(9, 0.0, 1.0, 0.0, 1.0).unwrap();
//! let ps = bases::powell_sabin::<f64>(mesh).unwrap();
//! let c = project(&ps, &SineProduct, MassOption::Consistent).unwrap();
//! let (error, _error_dx) = l2_errors(&ps, &c, &SineProduct);
//! assert!(error < 2e-4);
//! ```

// Index loops over components and stored entries read like the paper's sums.
#![allow(clippy::needless_range_loop)]

pub use psmpm_basis as basis;

pub mod arrangement;
pub mod bases;
pub mod body_contact;
pub mod contact;
pub mod diagnostics;
pub mod driver;
pub mod effect;
mod last_written;
pub mod mass;
pub mod material;
pub mod materials;
pub mod output;
pub mod particles;
pub mod scene;
pub mod setup;
pub mod simulation;
pub mod snapshot;
pub mod sparse;
pub mod studies;
pub mod threads;
