//! A 1D updated-Lagrangian finite-element solver (linear elements): the reference
//! solution of the large-deformation benchmarks B3 (vibrating bar) and B5b (column
//! under self-weight), see `shared/docs/benchmarks.md`.
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
//! history as JSON in [`cache_dir`]: `$PSMPM_CACHE_DIR` if set, else
//! `$XDG_CACHE_HOME/psmpm`, else `$HOME/.cache/psmpm` (never the source tree), under
//! `ulfem-<16 hex digits>.json`, the 64-bit FNV-1a hash ([`fnv1a64`]) of a key string
//! ([`history_key`]) listing every input. The key is stored in the file and checked
//! on reading; if the cache cannot be read or written the history is simply
//! computed.
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

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Boundary condition at one end of the bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum End {
    /// `u = 0` (velocity and acceleration zero).
    Fixed,
    /// Traction free.
    Free,
}

/// Mass matrix of eq. (5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum UlMass {
    /// Diagonal row-sum (lumped) mass `m_i`.
    #[default]
    Lumped,
    /// Consistent tridiagonal mass `M` (Thomas algorithm, factored once).
    Consistent,
}

/// Largest number of elements accepted (guards against absurd allocations).
pub const MAX_ELEMENTS: usize = 100_000_000;

/// Invalid input or a failed step. Never a panic.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UlFemError {
    /// A real parameter is outside its range.
    #[error("{name} = {value} is out of range: {allowed}")]
    OutOfRange {
        /// Parameter name (field of [`UlFemConfig`], `t_end`, `v0`).
        name: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range.
        allowed: &'static str,
    },
    /// `elements` is 0 or larger than [`MAX_ELEMENTS`].
    #[error("elements = {elements} is out of range: 1 ≤ elements ≤ {max}")]
    Elements {
        /// The value given.
        elements: usize,
        /// [`MAX_ELEMENTS`].
        max: usize,
    },
    /// The initial velocity function returned a non-finite value.
    #[error("the initial velocity at node {node} (X = {reference}) is not finite: {value}")]
    InitialVelocity {
        /// Node index.
        node: usize,
        /// Its reference coordinate.
        reference: f64,
        /// The value returned.
        value: f64,
    },
    /// A sample point of a history is not in `[0, L]`.
    #[error("sample point {index} (X = {value}) is not in the bar [0, {length}]")]
    SamplePoint {
        /// Index in `sample_points`.
        index: usize,
        /// The value given.
        value: f64,
        /// The bar's reference length.
        length: f64,
    },
    /// `output_every` is 0.
    #[error("output_every = 0: it must be at least 1")]
    OutputEvery,
    /// An element inverted (`F ≤ 0`) in a step.
    #[error("step {step} (t = {time}): element {element} inverted (F = {stretch} ≤ 0)")]
    Inverted {
        /// The step (1-based) that produced it.
        step: u64,
        /// The time after that step.
        time: f64,
        /// Element index.
        element: usize,
        /// Its stretch `F`.
        stretch: f64,
    },
    /// A position or velocity became NaN or infinite in a step.
    #[error("step {step} (t = {time}): the {quantity} of node {node} is not finite ({value})")]
    NonFinite {
        /// The step (1-based) that produced it.
        step: u64,
        /// The time after that step.
        time: f64,
        /// `"velocity"` or `"position"`.
        quantity: &'static str,
        /// Node index.
        node: usize,
        /// The value.
        value: f64,
    },
}

fn positive(name: &'static str, value: f64) -> Result<(), UlFemError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(UlFemError::OutOfRange {
            name,
            value,
            allowed: "finite and > 0",
        })
    }
}

/// The problem: geometry, material, load, boundary conditions, time step, mass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UlFemConfig {
    /// Reference length `L` of the bar, `> 0`.
    pub length: f64,
    /// Number of elements `N ≥ 1`.
    pub elements: usize,
    /// Young's modulus `E > 0` (eq. (2)).
    pub young: f64,
    /// Reference density `ρ0 > 0` (mass per reference length; area 1).
    pub density: f64,
    /// Constant acceleration `g` along the bar (eq. (6); `−9.81` for a column whose
    /// bottom is `X = 0`), finite.
    pub gravity: f64,
    /// Condition at `X = 0`.
    pub left: End,
    /// Condition at `X = L`.
    pub right: End,
    /// Time step `Δt > 0` (eq. (7)); not checked against [`Self::critical_dt`].
    pub dt: f64,
    /// Mass matrix (eq. (5)).
    pub mass: UlMass,
}

impl UlFemConfig {
    /// B2 in 1D: `L = 25`, `E = 100`, `ρ0 = 1`, both ends fixed, no gravity.
    pub fn vibrating_bar(elements: usize, dt: f64) -> Self {
        UlFemConfig {
            length: 25.0,
            elements,
            young: 100.0,
            density: 1.0,
            gravity: 0.0,
            left: End::Fixed,
            right: End::Fixed,
            dt,
            mass: UlMass::Lumped,
        }
    }

    /// B3 (thesis 4.2) in 1D: `L = 25`, `E = 50`, `ρ0 = 25`, both ends fixed; with
    /// [`InitialVelocity::SineMode`] `v0 = 0.1` the maximal strain is 7 %.
    pub fn vibrating_bar_large(elements: usize, dt: f64) -> Self {
        UlFemConfig {
            young: 50.0,
            density: 25.0,
            ..Self::vibrating_bar(elements, dt)
        }
    }

    /// B5a in 1D: `H = 25`, `E = 5e4`, `ρ0 = 1`, `g = −9.81`, bottom `X = 0` fixed,
    /// top free.
    pub fn column_small(elements: usize, dt: f64) -> Self {
        UlFemConfig {
            length: 25.0,
            elements,
            young: 5e4,
            density: 1.0,
            gravity: -9.81,
            left: End::Fixed,
            right: End::Free,
            dt,
            mass: UlMass::Lumped,
        }
    }

    /// B5b in 1D: `H = 1`, `E = 1e5`, `ρ0 = 1e3`, `g = −9.81`, bottom fixed, top free.
    pub fn column_large(elements: usize, dt: f64) -> Self {
        UlFemConfig {
            length: 1.0,
            young: 1e5,
            density: 1e3,
            ..Self::column_small(elements, dt)
        }
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), UlFemError> {
        positive("length", self.length)?;
        if self.elements == 0 || self.elements > MAX_ELEMENTS {
            return Err(UlFemError::Elements {
                elements: self.elements,
                max: MAX_ELEMENTS,
            });
        }
        positive("young", self.young)?;
        positive("density", self.density)?;
        if !self.gravity.is_finite() {
            return Err(UlFemError::OutOfRange {
                name: "gravity",
                value: self.gravity,
                allowed: "finite",
            });
        }
        positive("dt", self.dt)?;
        // Derived quantities must be representable too (e.g. L = 1e300, N = 1e8 is fine,
        // E / ρ overflowing is not).
        positive("young / density", self.young / self.density)?;
        Ok(())
    }

    /// Reference element length `h = L / N`.
    pub fn element_length(&self) -> f64 {
        self.length / self.elements as f64
    }

    /// Wave speed `c = √(E/ρ0)`.
    pub fn wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }

    /// Stability limit of eq. (7), `2 / ω_max`: `h / c` (lumped), `h / (c √3)`
    /// (consistent).
    pub fn critical_dt(&self) -> f64 {
        let lumped = self.element_length() / self.wave_speed();
        match self.mass {
            UlMass::Lumped => lumped,
            UlMass::Consistent => lumped / 3f64.sqrt(),
        }
    }

    /// Courant number `c Δt / h`.
    pub fn courant(&self) -> f64 {
        self.wave_speed() * self.dt / self.element_length()
    }
}

/// Initial velocity as a function of the reference coordinate, keyed for caching.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum InitialVelocity {
    /// At rest.
    Rest,
    /// `v(X, 0) = v0 sin(πX/L)`.
    SineMode {
        /// Amplitude `v0`.
        v0: f64,
    },
}

impl InitialVelocity {
    /// `v(X, 0)` on a bar of length `length`.
    pub fn eval(&self, x: f64, length: f64) -> f64 {
        match *self {
            InitialVelocity::Rest => 0.0,
            InitialVelocity::SineMode { v0 } => v0 * (std::f64::consts::PI * x / length).sin(),
        }
    }
}

/// Kinetic, strain and gravitational energy, eq. (8).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct UlEnergies {
    /// `K = ½ vᵀ M v`.
    pub kinetic: f64,
    /// `U = Σ_e h ½ E (F_e − 1)²`.
    pub strain: f64,
    /// `P = −Σ_i m_i g x_i`.
    pub potential: f64,
}

impl UlEnergies {
    /// `K + U + P`.
    pub fn total(&self) -> f64 {
        self.kinetic + self.strain + self.potential
    }
}

/// The solver state. Built by [`UlFem::new`], advanced by [`UlFem::step`].
#[derive(Debug, Clone)]
pub struct UlFem {
    config: UlFemConfig,
    h: f64,
    /// Current nodal positions `x_i`.
    x: Vec<f64>,
    /// Nodal velocities `v_i`.
    v: Vec<f64>,
    /// Scratch: right-hand side, then acceleration.
    a: Vec<f64>,
    /// Lumped (row-sum) masses `m_i`.
    lumped: Vec<f64>,
    /// First and one-past-last free node.
    free: (usize, usize),
    /// Thomas factorisation of the consistent mass on the free nodes: the modified
    /// super-diagonal `c'_k` and the inverse pivots.
    thomas_cp: Vec<f64>,
    thomas_inv: Vec<f64>,
    /// Off-diagonal entry `ρ0 h / 6` of the consistent mass.
    off: f64,
    steps: u64,
    failed: Option<UlFemError>,
}

impl UlFem {
    /// Validates `config` and sets up the undeformed bar with `v_i = initial_velocity(X_i)`
    /// (fixed ends get `v = 0`).
    pub fn new(
        config: UlFemConfig,
        initial_velocity: impl Fn(f64) -> f64,
    ) -> Result<UlFem, UlFemError> {
        config.validate()?;
        let n = config.elements;
        let h = config.element_length();
        let nodes = n + 1;
        let reference = |i: usize| if i == n { config.length } else { i as f64 * h };
        let x: Vec<f64> = (0..nodes).map(reference).collect();
        let lo = usize::from(config.left == End::Fixed);
        let hi = if config.right == End::Fixed { n } else { nodes };
        let mut v = vec![0.0; nodes];
        for i in 0..nodes {
            let value = initial_velocity(x[i]);
            if !value.is_finite() {
                return Err(UlFemError::InitialVelocity {
                    node: i,
                    reference: x[i],
                    value,
                });
            }
            if (lo..hi).contains(&i) {
                v[i] = value;
            }
        }
        let me = config.density * h;
        let mut lumped = vec![me; nodes];
        lumped[0] = 0.5 * me;
        lumped[n] = 0.5 * me;
        let off = me / 6.0;
        let (mut thomas_cp, mut thomas_inv) = (Vec::new(), Vec::new());
        if config.mass == UlMass::Consistent && hi > lo {
            // Diagonal of the consistent mass: ρ0 h / 3 per adjacent element, i.e.
            // 2/3 of the lumped mass, eq. (5).
            let m = hi - lo;
            thomas_cp = vec![0.0; m];
            thomas_inv = vec![0.0; m];
            for k in 0..m {
                let diag = lumped[lo + k] * (2.0 / 3.0);
                let pivot = if k == 0 {
                    diag
                } else {
                    diag - off * thomas_cp[k - 1]
                };
                thomas_inv[k] = 1.0 / pivot;
                thomas_cp[k] = off / pivot;
            }
        }
        Ok(UlFem {
            config,
            h,
            a: vec![0.0; nodes],
            x,
            v,
            lumped,
            free: (lo, hi),
            thomas_cp,
            thomas_inv,
            off,
            steps: 0,
            failed: None,
        })
    }

    /// [`UlFem::new`] with a keyed initial velocity.
    pub fn with_initial_velocity(
        config: UlFemConfig,
        initial_velocity: InitialVelocity,
    ) -> Result<UlFem, UlFemError> {
        UlFem::new(config, |x| initial_velocity.eval(x, config.length))
    }

    /// One step of eq. (7). Allocation-free. Fails if a velocity or position becomes
    /// non-finite or an element inverts (`F ≤ 0`), naming the step; after a failure
    /// the state is that of the failed step and every further call returns the same
    /// error.
    pub fn step(&mut self) -> Result<(), UlFemError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        let n = self.config.elements;
        let (e_mod, g, dt, h) = (
            self.config.young,
            self.config.gravity,
            self.config.dt,
            self.h,
        );
        // Right-hand side f_ext − f_int, eqs. (4) and (6).
        for (a, m) in self.a.iter_mut().zip(&self.lumped) {
            *a = m * g;
        }
        for e in 0..n {
            let sigma = e_mod * ((self.x[e + 1] - self.x[e]) / h - 1.0);
            self.a[e] += sigma;
            self.a[e + 1] -= sigma;
        }
        // a = M⁻¹ (f_ext − f_int) on the free nodes.
        let (lo, hi) = self.free;
        match self.config.mass {
            UlMass::Lumped => {
                for i in lo..hi {
                    self.a[i] /= self.lumped[i];
                }
            }
            UlMass::Consistent => {
                let r = &mut self.a[lo..hi];
                let m = r.len();
                for k in 0..m {
                    let prev = if k == 0 { 0.0 } else { r[k - 1] };
                    r[k] = (r[k] - self.off * prev) * self.thomas_inv[k];
                }
                for k in (0..m.saturating_sub(1)).rev() {
                    r[k] -= self.thomas_cp[k] * r[k + 1];
                }
            }
        }
        for i in lo..hi {
            self.v[i] += dt * self.a[i];
            self.x[i] += dt * self.v[i];
        }
        self.steps += 1;
        if let Some(error) = self.check() {
            self.failed = Some(error.clone());
            return Err(error);
        }
        Ok(())
    }

    fn check(&self) -> Option<UlFemError> {
        let (step, time) = (self.steps, self.time());
        for (quantity, values) in [("velocity", &self.v), ("position", &self.x)] {
            if let Some((node, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Some(UlFemError::NonFinite {
                    step,
                    time,
                    quantity,
                    node,
                    value,
                });
            }
        }
        (0..self.config.elements)
            .map(|e| (e, self.stretch(e)))
            .find(|(_, f)| f.is_nan() || *f <= 0.0)
            .map(|(element, stretch)| UlFemError::Inverted {
                step,
                time,
                element,
                stretch,
            })
    }

    /// The configuration.
    pub fn config(&self) -> &UlFemConfig {
        &self.config
    }

    /// Number of steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Current time `steps · Δt`.
    pub fn time(&self) -> f64 {
        self.steps as f64 * self.config.dt
    }

    /// Reference coordinate `X_i` of node `i` (`X_N = L` exactly).
    pub fn reference_position(&self, i: usize) -> f64 {
        if i == self.config.elements {
            self.config.length
        } else {
            i as f64 * self.h
        }
    }

    /// Current nodal positions `x_i`, `N + 1` of them.
    pub fn positions(&self) -> &[f64] {
        &self.x
    }

    /// Nodal velocities `v_i` (of the scheme (7): `v^{n}` after `n` steps).
    pub fn velocities(&self) -> &[f64] {
        &self.v
    }

    /// Lumped (row-sum) nodal masses `m_i`, eq. (5); they sum to `ρ0 L`.
    pub fn lumped_masses(&self) -> &[f64] {
        &self.lumped
    }

    /// Stretch `F_e` of element `e`, eq. (1) (`NaN` for `e ≥ N`).
    pub fn stretch(&self, e: usize) -> f64 {
        if e < self.config.elements {
            (self.x[e + 1] - self.x[e]) / self.h
        } else {
            f64::NAN
        }
    }

    /// Cauchy stress `σ_e` of element `e`, eq. (2) (`NaN` for `e ≥ N`).
    pub fn element_stress(&self, e: usize) -> f64 {
        self.config.young * (self.stretch(e) - 1.0)
    }

    /// Linear momentum `Σ_ij M_ij v_j = Σ_i m_i v_i` (row sums; same for both masses).
    pub fn momentum(&self) -> f64 {
        self.lumped.iter().zip(&self.v).map(|(m, v)| m * v).sum()
    }

    /// The element containing reference coordinate `X` and the local coordinate
    /// `ξ ∈ [0, 1]`; `None` outside `[0, L]` (a relative tolerance of 1e-12 is
    /// clamped) or for `NaN`.
    fn locate(&self, x: f64) -> Option<(usize, f64)> {
        let l = self.config.length;
        let tol = 1e-12 * l;
        if !(x >= -tol && x <= l + tol) {
            return None;
        }
        let s = (x.clamp(0.0, l) / self.h).max(0.0);
        let e = (s.floor() as usize).min(self.config.elements - 1);
        Some((e, (s - e as f64).clamp(0.0, 1.0)))
    }

    fn interpolate(&self, x: f64, nodal: impl Fn(usize) -> f64) -> f64 {
        match self.locate(x) {
            Some((e, xi)) => (1.0 - xi) * nodal(e) + xi * nodal(e + 1),
            None => f64::NAN,
        }
    }

    /// Displacement `u(X) = x(X) − X`, linear in the reference coordinate between
    /// nodes; `NaN` outside `[0, L]`.
    pub fn displacement_at(&self, x: f64) -> f64 {
        self.interpolate(x, |i| self.x[i] - self.reference_position(i))
    }

    /// Velocity `v(X)`, linear in the reference coordinate; `NaN` outside `[0, L]`.
    pub fn velocity_at(&self, x: f64) -> f64 {
        self.interpolate(x, |i| self.v[i])
    }

    /// Cauchy stress at reference coordinate `X`, piecewise constant (eq. (2); at an
    /// interior node, the element on the right); `NaN` outside `[0, L]`.
    pub fn stress_at(&self, x: f64) -> f64 {
        match self.locate(x) {
            Some((e, _)) => self.element_stress(e),
            None => f64::NAN,
        }
    }

    /// Energies of eq. (8), with the mass matrix of the run in `K`.
    pub fn energies(&self) -> UlEnergies {
        let c = &self.config;
        let kinetic = match c.mass {
            UlMass::Lumped => {
                0.5 * self
                    .lumped
                    .iter()
                    .zip(&self.v)
                    .map(|(m, v)| m * v * v)
                    .sum::<f64>()
            }
            // ½ vᵀ M_e v = ρ0 h / 6 (a² + ab + b²) per element.
            UlMass::Consistent => {
                self.off
                    * self
                        .v
                        .windows(2)
                        .map(|w| w[0] * w[0] + w[0] * w[1] + w[1] * w[1])
                        .sum::<f64>()
            }
        };
        let strain = (0..c.elements)
            .map(|e| {
                let d = self.stretch(e) - 1.0;
                0.5 * c.young * d * d * self.h
            })
            .sum();
        let potential = -c.gravity
            * self
                .lumped
                .iter()
                .zip(&self.x)
                .map(|(m, x)| m * x)
                .sum::<f64>();
        UlEnergies {
            kinetic,
            strain,
            potential,
        }
    }
}

/// One record of a [`History`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Time.
    pub time: f64,
    /// Displacement at each sample point.
    pub displacement: Vec<f64>,
    /// Velocity at each sample point.
    pub velocity: Vec<f64>,
    /// Cauchy stress at each sample point (piecewise constant).
    pub stress: Vec<f64>,
    /// Energies, eq. (8).
    pub energies: UlEnergies,
}

/// A reference run: its inputs, records every `output_every` steps, and the final
/// profiles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct History {
    /// [`history_key`] of the inputs.
    pub key: String,
    /// The configuration.
    pub config: UlFemConfig,
    /// The initial velocity.
    pub initial_velocity: InitialVelocity,
    /// Reference coordinates of the sample points.
    pub sample_points: Vec<f64>,
    /// Recording interval in steps.
    pub output_every: usize,
    /// Requested end time.
    pub t_end: f64,
    /// Steps taken, `round(t_end / Δt)`; the last record is at `steps · Δt`.
    pub steps: u64,
    /// Records at step 0, every `output_every` steps, and the last step.
    pub records: Vec<Record>,
    /// Nodal displacements `x_i − X_i` at the end.
    pub final_displacement: Vec<f64>,
    /// Element stresses `σ_e` at the end (element `e` spans `[e h, (e + 1) h]`).
    pub final_stress: Vec<f64>,
}

impl History {
    /// The recorded times.
    pub fn times(&self) -> Vec<f64> {
        self.records.iter().map(|r| r.time).collect()
    }
}

fn validate_run(
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> Result<(), UlFemError> {
    config.validate()?;
    if let InitialVelocity::SineMode { v0 } = initial_velocity {
        if !v0.is_finite() {
            return Err(UlFemError::OutOfRange {
                name: "v0",
                value: v0,
                allowed: "finite",
            });
        }
    }
    if let Some((index, &value)) = sample_points
        .iter()
        .enumerate()
        .find(|(_, &x)| !(x >= 0.0 && x <= config.length))
    {
        return Err(UlFemError::SamplePoint {
            index,
            value,
            length: config.length,
        });
    }
    if output_every == 0 {
        return Err(UlFemError::OutputEvery);
    }
    if !(t_end >= 0.0 && t_end.is_finite() && t_end / config.dt < 1e15) {
        return Err(UlFemError::OutOfRange {
            name: "t_end",
            value: t_end,
            allowed: "finite, ≥ 0, and t_end / dt < 1e15",
        });
    }
    Ok(())
}

/// Runs `config` from the initial state to `t_end` (`round(t_end / Δt)` steps) and
/// records, at step 0, every `output_every` steps and the last step, the time, the
/// displacement, velocity and stress at `sample_points` (reference coordinates in
/// `[0, L]`) and the energies.
pub fn reference_history(
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> Result<History, UlFemError> {
    validate_run(config, initial_velocity, sample_points, output_every, t_end)?;
    let mut fem = UlFem::with_initial_velocity(*config, initial_velocity)?;
    let steps = (t_end / config.dt).round() as u64;
    let record = |fem: &UlFem| Record {
        time: fem.time(),
        displacement: sample_points
            .iter()
            .map(|&x| fem.displacement_at(x))
            .collect(),
        velocity: sample_points.iter().map(|&x| fem.velocity_at(x)).collect(),
        stress: sample_points.iter().map(|&x| fem.stress_at(x)).collect(),
        energies: fem.energies(),
    };
    let capacity = (steps / output_every as u64).min(1 << 20) as usize + 2;
    let mut records = Vec::with_capacity(capacity);
    records.push(record(&fem));
    for s in 1..=steps {
        fem.step()?;
        if s % output_every as u64 == 0 || s == steps {
            records.push(record(&fem));
        }
    }
    Ok(History {
        key: history_key(config, initial_velocity, sample_points, output_every, t_end),
        config: *config,
        initial_velocity,
        sample_points: sample_points.to_vec(),
        output_every,
        t_end,
        steps,
        records,
        final_displacement: (0..=config.elements)
            .map(|i| fem.x[i] - fem.reference_position(i))
            .collect(),
        final_stress: (0..config.elements)
            .map(|e| fem.element_stress(e))
            .collect(),
    })
}

/// Version of the cache format and of the solver; part of every key.
pub const CACHE_VERSION: u32 = 1;

/// The deterministic key of a reference run: every input, floats in Rust's
/// shortest round-trip form.
pub fn history_key(
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> String {
    let c = config;
    format!(
        "psmpm-ulfem v{CACHE_VERSION}; length={:?}; elements={}; young={:?}; density={:?}; \
         gravity={:?}; left={:?}; right={:?}; dt={:?}; mass={:?}; initial={:?}; \
         samples={:?}; output_every={}; t_end={:?}",
        c.length,
        c.elements,
        c.young,
        c.density,
        c.gravity,
        c.left,
        c.right,
        c.dt,
        c.mass,
        initial_velocity,
        sample_points,
        output_every,
        t_end
    )
}

/// 64-bit FNV-1a hash (offset basis `0xcbf29ce484222325`, prime `0x100000001b3`):
/// deterministic across runs and platforms, unlike std's hasher.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// File name of a cached history: `ulfem-<fnv1a64(key) in 16 hex digits>.json`.
pub fn cache_file_name(key: &str) -> String {
    format!("ulfem-{:016x}.json", fnv1a64(key.as_bytes()))
}

/// The cache directory: `$PSMPM_CACHE_DIR` if set (and non-empty), else
/// `$XDG_CACHE_HOME/psmpm`, else `$HOME/.cache/psmpm`; `None` if none is set.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    var("PSMPM_CACHE_DIR")
        .map(PathBuf::from)
        .or_else(|| var("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("psmpm")))
        .or_else(|| var("HOME").map(|d| PathBuf::from(d).join(".cache").join("psmpm")))
}

/// [`reference_history`], read from or stored in [`cache_dir`] (see the module
/// documentation). Cache failures are silent: the history is then computed.
pub fn cached_reference_history(
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> Result<History, UlFemError> {
    cached_reference_history_in(
        cache_dir().as_deref(),
        config,
        initial_velocity,
        sample_points,
        output_every,
        t_end,
    )
}

/// [`cached_reference_history`] with an explicit cache directory (`None`: no cache).
/// The directory is created if needed; the file is written to a temporary name and
/// renamed, so concurrent runs never read a partial file.
pub fn cached_reference_history_in(
    dir: Option<&Path>,
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> Result<History, UlFemError> {
    validate_run(config, initial_velocity, sample_points, output_every, t_end)?;
    let key = history_key(config, initial_velocity, sample_points, output_every, t_end);
    let path = dir.map(|d| d.join(cache_file_name(&key)));
    if let Some(path) = &path {
        if let Some(history) = std::fs::read(path)
            .ok()
            .and_then(|bytes| serde_json::from_slice::<History>(&bytes).ok())
            .filter(|h| h.key == key)
        {
            return Ok(history);
        }
    }
    let history = reference_history(config, initial_velocity, sample_points, output_every, t_end)?;
    if let (Some(dir), Some(path)) = (dir, &path) {
        let _ = write_atomically(dir, path, &history);
    }
    Ok(history)
}

fn write_atomically(dir: &Path, path: &Path, history: &History) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let bytes = serde_json::to_vec(history).map_err(std::io::Error::other)?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    let tmp = path.with_extension(format!("json.tmp-{}-{nanos}", std::process::id()));
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small(mass: UlMass) -> UlFemConfig {
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

    fn name_of(e: UlFemError) -> &'static str {
        match e {
            UlFemError::OutOfRange { name, .. } => name,
            UlFemError::Elements { .. } => "elements",
            other => panic!("unexpected {other}"),
        }
    }

    #[test]
    fn validation_names_the_bad_field() {
        let ok = small(UlMass::Lumped);
        assert!(ok.validate().is_ok());
        let cases: Vec<(UlFemConfig, &str)> = vec![
            (UlFemConfig { length: 0.0, ..ok }, "length"),
            (UlFemConfig { length: -1.0, ..ok }, "length"),
            (
                UlFemConfig {
                    length: f64::NAN,
                    ..ok
                },
                "length",
            ),
            (UlFemConfig { elements: 0, ..ok }, "elements"),
            (
                UlFemConfig {
                    elements: MAX_ELEMENTS + 1,
                    ..ok
                },
                "elements",
            ),
            (UlFemConfig { young: 0.0, ..ok }, "young"),
            (
                UlFemConfig {
                    young: f64::INFINITY,
                    ..ok
                },
                "young",
            ),
            (
                UlFemConfig {
                    density: -2.0,
                    ..ok
                },
                "density",
            ),
            (
                UlFemConfig {
                    gravity: f64::NAN,
                    ..ok
                },
                "gravity",
            ),
            (UlFemConfig { dt: 0.0, ..ok }, "dt"),
            (UlFemConfig { dt: -1e-3, ..ok }, "dt"),
            (
                UlFemConfig {
                    young: 1e300,
                    density: 1e-300,
                    ..ok
                },
                "young / density",
            ),
        ];
        for (config, name) in cases {
            let e = UlFem::new(config, |_| 0.0).unwrap_err();
            assert!(!e.to_string().is_empty());
            assert_eq!(name_of(e), name, "{config:?}");
        }
        let e = UlFem::new(ok, |x| if x > 1.0 { f64::NAN } else { 0.0 }).unwrap_err();
        assert!(
            matches!(e, UlFemError::InitialVelocity { node: 6, .. }),
            "{e}"
        );
    }

    #[test]
    fn history_validation() {
        let c = small(UlMass::Lumped);
        let rest = InitialVelocity::Rest;
        let e = reference_history(&c, rest, &[0.5, 2.5], 1, 0.01).unwrap_err();
        assert!(matches!(e, UlFemError::SamplePoint { index: 1, .. }), "{e}");
        let e = reference_history(&c, rest, &[f64::NAN], 1, 0.01).unwrap_err();
        assert!(matches!(e, UlFemError::SamplePoint { index: 0, .. }), "{e}");
        let e = reference_history(&c, rest, &[1.0], 0, 0.01).unwrap_err();
        assert_eq!(e, UlFemError::OutputEvery);
        for t_end in [-1.0, f64::INFINITY, f64::NAN] {
            let e = reference_history(&c, rest, &[1.0], 1, t_end).unwrap_err();
            assert_eq!(name_of(e), "t_end");
        }
        let e = reference_history(&c, InitialVelocity::SineMode { v0: f64::NAN }, &[], 1, 0.1)
            .unwrap_err();
        assert_eq!(name_of(e), "v0");
        let h = reference_history(&c, rest, &[0.0, 2.0], 3, 0.001).unwrap();
        assert_eq!(h.steps, 10);
        // steps 0, 3, 6, 9 and the last, 10.
        let times: Vec<f64> = h.times().iter().map(|t| (t / c.dt).round()).collect();
        assert_eq!(times, [0.0, 3.0, 6.0, 9.0, 10.0]);
        assert_eq!(h.final_stress.len(), 10);
        assert_eq!(h.final_displacement.len(), 11);
    }

    #[test]
    fn energy_is_conserved() {
        for mass in [UlMass::Lumped, UlMass::Consistent] {
            let config = small(mass);
            let mut fem =
                UlFem::with_initial_velocity(config, InitialVelocity::SineMode { v0: 0.3 })
                    .unwrap();
            let e0 = fem.energies();
            assert!(e0.kinetic > 0.0 && e0.strain < 1e-20);
            let scale = e0.kinetic + 0.5 * config.density * config.length * 9.81 * 0.1;
            let mut worst: f64 = 0.0;
            // About 2 periods of the fundamental mode (T = 4L/c = 1.13).
            for _ in 0..20_000 {
                fem.step().unwrap();
                worst = worst.max((fem.energies().total() - e0.total()).abs());
            }
            assert!(fem.energies().strain > 0.0);
            assert!(worst < 2e-3 * scale, "{mass:?}: {worst} vs {scale}");
        }
    }

    #[test]
    fn mass_and_momentum_are_conserved() {
        // Free–free bar: total mass ρ0 L; without gravity the momentum stays (round-off),
        // with gravity it grows by ρ0 L g Δt per step; both masses.
        for mass in [UlMass::Lumped, UlMass::Consistent] {
            for gravity in [0.0, -9.81] {
                let config = UlFemConfig {
                    left: End::Free,
                    right: End::Free,
                    gravity,
                    mass,
                    ..small(mass)
                };
                let mut fem = UlFem::new(config, |x| 0.2 * (3.0 * x).cos() + 0.1).unwrap();
                let total: f64 = fem.lumped_masses().iter().sum();
                assert!((total - config.density * config.length).abs() < 1e-14 * total);
                let p0 = fem.momentum();
                for _ in 0..1000 {
                    fem.step().unwrap();
                }
                let expected = p0 + total * gravity * fem.time();
                assert!(
                    (fem.momentum() - expected).abs() < 1e-10,
                    "{mass:?} {gravity}"
                );
                // Mass per element ρ0 h: current density × current length.
                for e in 0..config.elements {
                    let rho = config.density / fem.stretch(e);
                    let len = fem.positions()[e + 1] - fem.positions()[e];
                    assert!((rho * len - config.density * fem.h).abs() < 1e-13);
                }
            }
        }
    }

    #[test]
    fn free_fall_is_rigid() {
        let config = UlFemConfig {
            left: End::Free,
            right: End::Free,
            ..small(UlMass::Consistent)
        };
        let mut fem = UlFem::new(config, |_| 0.0).unwrap();
        for _ in 0..100 {
            fem.step().unwrap();
        }
        // Symplectic Euler: x_n = X + g Δt² n (n + 1) / 2.
        let expected = config.gravity * config.dt * config.dt * 100.0 * 101.0 / 2.0;
        for x in [0.0, 0.7, 2.0] {
            assert!((fem.displacement_at(x) - expected).abs() < 1e-13);
            assert!(fem.stress_at(x).abs() < 1e-8);
        }
    }

    #[test]
    fn interpolation_in_the_reference_coordinate() {
        let config = UlFemConfig {
            gravity: 0.0,
            left: End::Free,
            ..small(UlMass::Lumped)
        };
        let mut fem = UlFem::new(config, |x| x * x).unwrap();
        // v at nodes, linear between.
        assert!((fem.velocity_at(0.4) - 0.16).abs() < 1e-15);
        assert!((fem.velocity_at(0.5) - 0.5 * (0.16 + 0.36)).abs() < 1e-15);
        assert!(fem.velocity_at(2.0 + 1e-9).is_nan());
        assert!(fem.velocity_at(-0.1).is_nan());
        assert!(fem.displacement_at(f64::NAN).is_nan());
        fem.step().unwrap();
        let u = |i: usize| fem.positions()[i] - fem.reference_position(i);
        assert!((fem.displacement_at(0.3) - 0.5 * (u(1) + u(2))).abs() < 1e-15);
        assert_eq!(fem.stress_at(0.2), fem.element_stress(1));
        assert_eq!(fem.stress_at(2.0), fem.element_stress(9));
        assert!(fem.element_stress(10).is_nan());
    }

    #[test]
    fn inversion_is_an_error_naming_the_step() {
        // Two ends rushing together at 10 c: the first element inverts quickly.
        let config = UlFemConfig {
            left: End::Free,
            gravity: 0.0,
            ..small(UlMass::Lumped)
        };
        let c = config.wave_speed();
        let mut fem = UlFem::new(config, |x| if x < 0.1 { 10.0 * c } else { 0.0 }).unwrap();
        let error = loop {
            if let Err(e) = fem.step() {
                break e;
            }
            assert!(fem.steps() < 10_000);
        };
        let UlFemError::Inverted { step, element, .. } = error.clone() else {
            panic!("{error}");
        };
        assert_eq!(step, fem.steps());
        assert_eq!(element, 0);
        assert!(error.to_string().contains(&format!("step {step}")));
        assert_eq!(fem.step().unwrap_err(), error);
    }

    #[test]
    fn unstable_step_is_reported() {
        let config = UlFemConfig {
            dt: 10.0 * small(UlMass::Lumped).critical_dt(),
            ..small(UlMass::Lumped)
        };
        let mut fem = UlFem::new(config, |_| 0.0).unwrap();
        let error = (0..100_000).find_map(|_| fem.step().err()).unwrap();
        assert!(
            matches!(
                error,
                UlFemError::Inverted { .. } | UlFemError::NonFinite { .. }
            ),
            "{error}"
        );
    }

    #[test]
    fn fnv1a_reference_values() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn key_lists_every_input() {
        let c = small(UlMass::Lumped);
        let rest = InitialVelocity::Rest;
        let base = history_key(&c, rest, &[1.0], 1, 1.0);
        let variants = [
            history_key(&UlFemConfig { length: 2.5, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { elements: 11, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { young: 101.0, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { density: 3.0, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { gravity: 0.0, ..c }, rest, &[1.0], 1, 1.0),
            history_key(
                &UlFemConfig {
                    left: End::Free,
                    ..c
                },
                rest,
                &[1.0],
                1,
                1.0,
            ),
            history_key(
                &UlFemConfig {
                    right: End::Fixed,
                    ..c
                },
                rest,
                &[1.0],
                1,
                1.0,
            ),
            history_key(&UlFemConfig { dt: 2e-4, ..c }, rest, &[1.0], 1, 1.0),
            history_key(
                &UlFemConfig {
                    mass: UlMass::Consistent,
                    ..c
                },
                rest,
                &[1.0],
                1,
                1.0,
            ),
            history_key(&c, InitialVelocity::SineMode { v0: 0.0 }, &[1.0], 1, 1.0),
            history_key(&c, rest, &[1.0 + 1e-15], 1, 1.0),
            history_key(&c, rest, &[1.0], 2, 1.0),
            history_key(&c, rest, &[1.0], 1, 1.5),
        ];
        let mut names: Vec<String> = variants.iter().map(|k| cache_file_name(k)).collect();
        names.push(cache_file_name(&base));
        for k in &variants {
            assert_ne!(k, &base);
        }
        names.sort();
        names.dedup();
        assert_eq!(names.len(), variants.len() + 1);
        assert_eq!(base, history_key(&c, rest, &[1.0], 1, 1.0));
    }
}
