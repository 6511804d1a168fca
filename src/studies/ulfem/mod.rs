//! A 1D updated-Lagrangian finite-element solver (linear elements): the reference
//! solution of the large-deformation benchmarks B3 (vibrating bar) and B5b (column
//! under self-weight), see the benchmark definitions of the seeds (paper and thesis, as checked against their tables).
//!
//! # The model
//!
//! A bar of reference length `L` (reference coordinate `X ∈ [0, L]`, cross-section
//! area 1, mass `ρ0` per reference length) is cut into `N` equal elements of
//! reference length `h = L / N`, nodes `X_i = i h`, current positions `x_i`. In each
//! element `e = [x_e, x_{e+1}]`
//!
//! ```text
//! (1)  F_e = (x_{e+1} − x_e) / h                      stretch (1D deformation gradient)
//! (2)  σ_e = E (F_e − 1)                              Cauchy stress
//! (3)  W_e = ½ E (F_e − 1)²                           strain energy per reference length
//! (4)  f_int,e = σ_e · [−1, +1]                       internal force on nodes e, e+1
//! ```
//!
//! which is the MPM code's 1D linear elastic law
//! ([`crate::material::LinearElastic`] with `d = 1`: `λ = 0`, `μ = E/2`, so
//! `σ = 2μ (½(F + Fᵀ) − 1) = E (F − 1)`). With area 1 the internal force (4) is the
//! current-configuration integral `∫ σ ∂N/∂x dx`, and `∂W_e/∂x_{e+1} · h = σ_e`,
//! so (4) is the gradient of the strain energy `Σ_e h W_e`.
//!
//! The mass matrix is that of the reference (= current, by mass conservation)
//! configuration, constant in time:
//!
//! ```text
//! (5)  M_e = ρ0 h / 6 · [[2, 1], [1, 2]]   (consistent),   m_i = Σ_j M_ij  (lumped, row sums)
//! (6)  f_ext,i = m_i g                     (g a constant acceleration along the bar)
//! ```
//!
//! Each end is [`End::Fixed`] (`u = 0`: its velocity and acceleration are zero and its
//! row is removed from the system) or [`End::Free`] (traction free).
//!
//! # Time integration
//!
//! The symplectic (semi-implicit) Euler scheme of the MPM driver:
//!
//! ```text
//! (7)  a = M⁻¹ (f_ext − f_int(x^n)),   v^{n+1} = v^n + Δt a,   x^{n+1} = x^n + Δt v^{n+1}
//! ```
//!
//! with the lumped (diagonal) mass by default ([`UlMass::Lumped`]) or the consistent
//! one ([`UlMass::Consistent`], a tridiagonal system factored once by the Thomas
//! algorithm; no dense matrix). It is stable for `Δt < h / c` (lumped) or
//! `Δt < h / (c √3)` (consistent), `c = √(E/ρ0)`
//! ([`UlFemConfig::critical_dt`]). A step allocates nothing. The bar starts
//! undeformed (`x_i = X_i`) with the nodal values `v_i = v(X_i)` of the given
//! initial velocity.
//!
//! # Energies
//!
//! ```text
//! (8)  K = ½ vᵀ M v,   U = Σ_e h ½ E (F_e − 1)²,   P = −Σ_i m_i g x_i
//! ```
//!
//! (`P` is exact for the piecewise-linear `x`, since `m_i` are the row sums.) The
//! scheme (7) conserves a modified energy: `K + U + P` oscillates by `O(Δt)` without
//! drift.
//!
//! # A finding: in 1D this law is linear
//!
//! With `σ = E (F − 1)` and area 1, the first Piola–Kirchhoff stress equals the
//! Cauchy stress and the balance law is `ρ0 u_tt = E u_XX + ρ0 g`: **linear in the
//! displacement for any amplitude** (only `F > 0` is needed). The nodal forces (4)
//! are linear in `x`, so the "updated-Lagrangian" solver is exactly the linear one.
//! Hence the small-deformation exact solutions also hold for the large-deformation
//! runs: B3 is `u = (v0/ω) sin(ωt) sin(πX/L)` with max strain 7 %, and B5b the series
//! of B5a with B5b's constants (strain 9.8 % at the bottom in static equilibrium,
//! 19 % in the suddenly loaded motion: minimum stretch 0.806 measured).
//! `tests/ulfem.rs` checks both (convergence to the exact solutions at 7 % and 19 %
//! strain). So for these uniaxial benchmarks with this law, whatever nonlinear
//! behaviour the MPM runs show comes from the discretisation (particles moving
//! through the grid, empty elements), not from the continuum problem. (A reference
//! computed with another law, e.g. the rate form `σ̇ = E ∂v/∂x`, i.e. `σ = E ln F`,
//! as a thesis' UL-FEM may have used, would differ at large strain.) This module
//! remains the reference the benchmarks ask for, with energies and stress profiles,
//! and an independent check of the exact formulas.
//!
//! # Convergence (measured)
//!
//! `cargo test --release -p psmpm --test ulfem -- --nocapture` prints the tables
//! (`tests/ulfem.rs`). L² displacement error `(∫_0^L (u_h − u)² dX)^½` at `t_end`
//! against the exact solutions, `N = 8, 16, 32, 64` elements:
//!
//! | case | mass | `t_end`, `Δt` | errors | observed orders |
//! |---|---|---|---|---|
//! | B2, `v0 = 0.1` | lumped | 1, 1e-4 | 2.88e-3, 7.18e-4, 1.79e-4, 4.48e-5 | 2.00, 2.00, 2.00 |
//! | B2, `v0 = 0.1` | consistent | 1, 1e-4 | 4.69e-3, 1.18e-3, 2.95e-4, 7.37e-5 | 1.99, 2.00, 2.00 |
//! | B3, `v0 = 0.1` (7 % strain) | lumped | 10, 1e-3 | 1.39e-2, 3.43e-3, 8.55e-4, 2.14e-4 | 2.02, 2.00, 2.00 |
//! | B5a | lumped | 0.5, 2.5e-6 | 3.21e-3, 1.01e-3, 3.18e-4, 9.89e-5 | 1.67, 1.67, 1.68 |
//! | B5b (19 % strain) | lumped | 2.5, 1e-5 | 2.68e-3, 8.44e-4, 2.64e-4, 8.21e-5 | 1.67, 1.68, 1.69 |
//!
//! Halving `Δt` changes every finest-grid error by less than 1 % (the error is
//! spatial). B5a continues with orders 1.69, 1.68 to 128 and 256 elements. The
//! suddenly applied weight of B5a/B5b gives a solution whose strain gradient jumps
//! across a travelling front (modal amplitudes decay only like `n⁻³`), hence the
//! order ≈ 5/3 rather than 2. It also makes the time error first order (the scheme's
//! velocity starts half a step off by `Δt g / 2`): at `Δt = 1e-5` B5a's 64-element
//! error is about 3 % off its small-`Δt` limit, at 256 elements 33 %, so reference runs
//! of suddenly loaded columns need `Δt` well below the stability limit.
//!
//! # Reference runs and their cache
//!
//! [`reference_history`] runs a configuration to `t_end` and records the time,
//! displacement, velocity and stress at sample reference points, and the energies,
//! every `output_every` steps ([`History`]). [`cached_reference_history`] stores the
//! history as JSON in the directory it is given (`None`: no cache), under
//! `ulfem-<16 hex digits>.json`, the 64-bit FNV-1a hash ([`fnv1a64`]) of a key string
//! ([`history_key`]) listing every input. The key is stored in the file and checked
//! on reading; if the cache cannot be read or written the history is simply
//! computed.
//!
//! The library reads no environment: the caller chooses the directory. `mpm-cli`
//! (`reproduce`, through [`reproduction::reproduce`](crate::studies::reproduction::reproduce))
//! uses `$PSMPM_CACHE_DIR` if set (and non-empty), else `$XDG_CACHE_HOME/psmpm`, else
//! `$HOME/.cache/psmpm` (never the source tree), and no cache if none is set.
//!
//! # Example
//!
//! ```
//! use psmpm::studies::ulfem::{End, InitialVelocity, UlFem, UlFemConfig, UlMass};
//!
//! let config = UlFemConfig {
//!     length: 25.0,
//!     elements: 16,
//!     young: 100.0,
//!     density: 1.0,
//!     gravity: 0.0,
//!     left: End::Fixed,
//!     right: End::Fixed,
//!     dt: 1e-3,
//!     mass: UlMass::Lumped,
//! };
//! let v = InitialVelocity::SineMode { v0: 0.1 };
//! let mut fem = UlFem::with_initial_velocity(config, v).unwrap();
//! for _ in 0..1000 {
//!     fem.step().unwrap();
//! }
//! let omega = std::f64::consts::PI * 10.0 / 25.0;
//! let exact = 0.1 / omega * omega.sin(); // u(L/2, t = 1)
//! assert!((fem.displacement_at(12.5) - exact).abs() < 1e-3 * exact);
//! ```

mod cache;
mod config;
mod history;
mod solver;

pub use cache::{cache_file_name, cached_reference_history, fnv1a64, history_key, CACHE_VERSION};
pub use config::{End, InitialVelocity, UlFemConfig, UlFemError, UlMass, MAX_ELEMENTS};
pub use history::{reference_history, History, Record};
pub use solver::{UlEnergies, UlFem};

/// Configurations and error names shared by the unit tests of the submodules.
#[cfg(test)]
mod fixtures {
    use super::*;

    pub(super) fn small(mass: UlMass) -> UlFemConfig {
        UlFemConfig {
            length: 2.0,
            elements: 10,
            young: 100.0,
            density: 2.0,
            gravity: -9.81,
            left: End::Fixed,
            right: End::Free,
            dt: 1e-4,
            mass,
        }
    }

    pub(super) fn name_of(e: UlFemError) -> &'static str {
        match e {
            UlFemError::OutOfRange { name, .. } => name,
            UlFemError::Elements { .. } => "elements",
            other => panic!("unexpected {other}"),
        }
    }
}
