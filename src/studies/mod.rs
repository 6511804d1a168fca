//! The studies: checks of the method against the seeds' benchmarks and independent
//! references, kept apart from the method itself (the driver, the mass strategies,
//! the materials and the scenes never depend on them, except that a scene may name
//! an exact solution to measure its error against).
//!
//! - [`exact`]: the seeds' exact solutions (B2, B4, B5a, B5c) and the RMS position
//!   error of paper eq. (47);
//! - [`ulfem`]: the 1D updated-Lagrangian FEM reference of the large-deformation
//!   benchmarks B3 and B5b, with its on-disk cache of reference runs;
//! - [`projection`]: L² projection onto a basis, benchmark B1;
//! - [`published`]: the seeds' printed numbers the studies and tests compare against;
//! - [`self_convergence`]: the error of a run against the finest run of a study,
//!   for scenes without an exact solution;
//! - [`reproduction`]: the benchmarks B2–B5 as studies, the tables and figures of
//!   `docs/results.md`.

pub mod exact;
pub mod projection;
pub mod published;
pub mod reproduction;
pub mod self_convergence;
pub mod ulfem;
