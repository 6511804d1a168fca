//! Exact solutions of the seed benchmarks: every analytic formula the project
//! measures errors against, in one place, as plain `f64` structs and functions.
//!
//! Sources: the seed paper (de Koster, Tielen, Wobbes, Möller 2020, "Extension of
//! B-spline Material Point Method for unstructured triangular grids using Powell–Sabin
//! splines"; equation numbers "(n)") and the thesis (de Koster 2018; "thesis (4.n)"),
//! as specified in the benchmark definitions of the seeds (paper and thesis, as checked against their tables). Symbols are those of the paper:
//! `E` Young's modulus, `ν` Poisson's ratio, `ρ⁰` reference density, `x⁰` the
//! reference (initial) position of a material point, `u` its displacement.
//!
//! | item | benchmark | formula |
//! |---|---|---|
//! | [`VibratingBar`] | B2 (and small-amplitude B3) | thesis (4.2) |
//! | [`ColumnSelfWeight`] | B5a | thesis (4.6), sign-corrected; closed form by d'Alembert |
//! | [`AxisAligned`] | B4 | paper (40)–(46) |
//! | [`column_equilibrium_stress`] | B5c | paper (48) |
//! | [`column_equilibrium_stress_linear`], [`column_equilibrium_position_linear`] | B5c | exact equilibrium of the project's linear law |
//! | [`bar_equilibrium_stress_linear`], [`bar_equilibrium_stress_at_reference`] | B5c, a bar standing or hanging | the same with signed `g` |
//! | [`RmsPositionError`] | B4 | paper (47) |
//!
//! # Conventions
//!
//! Tension is positive, compression negative (the column at rest under gravity has
//! `σ_yy < 0` at its bottom). Gravity is a signed acceleration (`g = −9.81` points
//! down) except where an argument is explicitly named `gravity_magnitude`.
//! Everything is evaluated at the material point's reference position `x⁰`
//! (`benchmarks.md`, B2 "error detail").
//!
//! These are pure formulas: they never panic. Each item documents the domain on
//! which it is meaningful (positive `E`, `ρ⁰`, a length, `J > 0`, ...); outside it the
//! result may be `NaN` or infinite.
//!
//! # Findings on the printed formulas
//!
//! * **Paper eqs. (42)–(43) hold as printed.** For the compressible neo-Hookean law
//!   of the project in plane strain (paper (27), [`crate::material::NeoHookean`]) and
//!   λ, μ of (44), the first Piola–Kirchhoff stress of the motion (40)–(41) is
//!   diagonal with `P_xx = λ ln J / D_xx + μ (D_xx − 1/D_xx)`, `J = D_xx D_yy`, so
//!   `∂P_xx/∂x⁰ = D_xx' (μ + (μ − λ (ln J − 1)) / D_xx²)` with
//!   `D_xx' = −4π² u_x`; with `ü_x = −π² (E/ρ⁰) u_x` the balance
//!   `ρ⁰ ü = Div P + ρ⁰ g` gives exactly (42), and likewise (43). Here `g` is a body
//!   force per unit mass (an acceleration). `tests/exact.rs` checks this without
//!   using (42)–(46): `ü` and `Div P` by exact (jet) automatic differentiation of
//!   (40)–(41) and of `P = λ ln J F⁻ᵀ + μ (F − F⁻ᵀ)`, that `P` cross-checked against
//!   `J σ F⁻ᵀ` of the project's `NeoHookean` to round-off (≤ 4e-15 of `λ + 2μ`). At
//!   10⁴ sample points `(x⁰, t)` over two periods, for the paper's parameters and two
//!   other sets (ν = 0.45, ν = −0.3), the residual `ρ⁰ ü − Div P − ρ⁰ g` is at most
//!   7e-15 of the term amplitudes `ρ⁰ω²|u⁰| + 4π²|u⁰|(λ + 2μ)` and at most 2.2e-12 of
//!   `|ρ⁰ ü| + |Div P|` pointwise (all terms vanish together with `sin(2πx⁰)` and
//!   `sin(ωt)`, so the pointwise ratio only measures how the rounding of their
//!   arguments is amplified near those zeros). Flipping the sign of λ or of `ln J`, or
//!   writing 2 for the factor 4, raises the residual to 0.4–1.4 of the terms.
//! * **Paper eq. (48) is not the exact equilibrium of the project's linear law.**
//!   The paper's column is linear elastic with ν = 0 between sides fixed in `x`, so
//!   in 1D the Cauchy stress is `σ = E (F − 1)`, `F = ∂y/∂Y`, and the first
//!   Piola–Kirchhoff stress equals σ. Equilibrium in the current configuration,
//!   `dσ/dy + ρ g = 0` with `ρ = ρ⁰/F` (mass conservation), is `dσ/dY = −ρ⁰ g` in the
//!   reference coordinate, so `σ = −ρ⁰|g| (H − Y)` is linear in `Y`, the top sits at
//!   `H (1 + κ)` and `σ(y)` is the root of a quadratic ([`column_equilibrium_stress_linear`]).
//!   Eq. (48) instead puts the top at `H/(1 − κ)` and is rational in `y`. It is the
//!   *exact* equilibrium (current position `y`, mass conservation, `σ(0) = Hρ⁰g`) of
//!   the 1D law `F = (1 − σ/(2E))⁻²`, i.e. `σ = 2E (1 − F^{−1/2})`, which agrees with
//!   `σ = E (F − 1)` only to first order in the strain. `tests/exact.rs` integrates
//!   the equilibrium ODE (RK4, 10⁴ steps) for both laws: (48) matches the
//!   `2E (1 − F^{−1/2})` law to round-off (9e-14 of |σ(0)|, the rounding accumulated
//!   over the steps) and misses the linear law by about `κ² |σ(0)|`: for B5b
//!   (`ρ⁰ = 10³`, `E = 10⁵`, `H = 1`, `κ = −0.049`) the largest difference is 0.23 %
//!   of `|σ(0)|` (near `y ≈ 0.82`). That is invisible in Fig. 18 but can mask the
//!   error of a well-resolved run, so compare runs of the project's linear law
//!   against [`column_equilibrium_stress_linear`], and use (48) to reproduce the
//!   paper's figure. Sign: with the paper's `g = −9.81`, `σ_yy(0) = Hρg < 0` is
//!   compression, as in the project; [`column_equilibrium_stress`] takes `|g|`.
//! * **Thesis (4.6)** has two sign errors as printed (it gives `u(y, 0) ≠ 0`);
//!   [`ColumnSelfWeight`] uses the corrected form of `benchmarks.md`, which is the
//!   Fourier sine series of the d'Alembert solution [`ColumnSelfWeight::displacement_closed_form`]
//!   (the unit tests check the two agree within the documented tail bound).

use std::f64::consts::PI;

// ---------------------------------------------------------------------------------
// B2: vibrating bar, small deformation.
// ---------------------------------------------------------------------------------

/// Vibrating bar with small deformation (B2; thesis §4.1, eq. (4.2)), fixed at
/// `x = 0` and `x = L`, initial velocity `v₀ sin(πx/L)`, no initial displacement:
///
/// `u_x(x⁰, t) = (v₀/ω) sin(ωt) sin(πx⁰/L)`, `ω = π √(E/ρ) / L`.
///
/// One-dimensional along `x`. Domain: `L > 0`, `E > 0`, `ρ > 0`, `0 ≤ x⁰ ≤ L`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VibratingBar {
    /// Length `L`.
    pub length: f64,
    /// Young's modulus `E`.
    pub young: f64,
    /// Density `ρ`.
    pub density: f64,
    /// Velocity amplitude `v₀`.
    pub v0: f64,
}

impl VibratingBar {
    /// Angular frequency `ω = π √(E/ρ) / L` (thesis (4.2)).
    pub fn omega(&self) -> f64 {
        PI * (self.young / self.density).sqrt() / self.length
    }

    /// Displacement `u_x(x⁰, t) = (v₀/ω) sin(ωt) sin(πx⁰/L)` (thesis (4.2)).
    pub fn displacement(&self, x0: f64, t: f64) -> f64 {
        let omega = self.omega();
        self.v0 / omega * (omega * t).sin() * (PI * x0 / self.length).sin()
    }

    /// Velocity `v_x(x⁰, t) = v₀ cos(ωt) sin(πx⁰/L)`, the time derivative of
    /// [`Self::displacement`].
    pub fn velocity(&self, x0: f64, t: f64) -> f64 {
        self.v0 * (self.omega() * t).cos() * (PI * x0 / self.length).sin()
    }

    /// Small-strain stress `σ_xx = E ∂u_x/∂x⁰ = E (v₀/ω)(π/L) sin(ωt) cos(πx⁰/L)`.
    pub fn stress(&self, x0: f64, t: f64) -> f64 {
        let omega = self.omega();
        let k = PI / self.length;
        self.young * self.v0 / omega * (omega * t).sin() * k * (k * x0).cos()
    }
}

// ---------------------------------------------------------------------------------
// B5a: column under self-weight, small deformation.
// ---------------------------------------------------------------------------------

/// Column under self-weight with small deformation (B5a; thesis §4.3, eq. (4.6)
/// with its two sign errors corrected as in `benchmarks.md`): the solution of
/// `u_tt = (E/ρ) u_yy + g`, `u(0, t) = 0`, `u_y(H, t) = 0`, at rest and unstressed at
/// `t = 0`,
///
/// `u(y⁰, t) = (ρg/E)(H y⁰ − y⁰²/2) − Σ_{n≥1} u_n cos(√(E/ρ) k_n t) sin(k_n y⁰)`,
/// `k_n = (2n − 1)π/(2H)`, `u_n = 16 ρ g H² / ((2n − 1)³ π³ E)`.
///
/// `gravity` is signed: `g = −9.81` pulls down and gives `u ≤ 0`. `y⁰` is the
/// reference height above the fixed bottom. Domain: `H, E, ρ > 0`, `0 ≤ y⁰ ≤ H`,
/// `t ≥ 0` (the formulas extend to all real `t`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnSelfWeight {
    /// Height `H`.
    pub height: f64,
    /// Young's modulus `E`.
    pub young: f64,
    /// Density `ρ`.
    pub density: f64,
    /// Signed gravitational acceleration `g` (negative pulls down).
    pub gravity: f64,
}

impl ColumnSelfWeight {
    /// Number of series terms used by [`Self::displacement`]. The terms decay like
    /// `(2n − 1)⁻³`; the truncation error after 400 terms is at most
    /// [`Self::series_tail_bound`]`(400)` ≈ `2.0e-7 ρ|g|H²/E`, i.e. `4e-7` of the
    /// largest static displacement `ρ|g|H²/(2E)`.
    pub const DEFAULT_TERMS: usize = 400;

    /// Wave speed `c = √(E/ρ)`.
    pub fn wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }

    /// Static displacement `u_s(y⁰) = (ρg/E)(H y⁰ − y⁰²/2)`, the mean about which the
    /// column oscillates (and its equilibrium under small deformation).
    pub fn static_displacement(&self, y0: f64) -> f64 {
        self.density * self.gravity / self.young * (self.height * y0 - 0.5 * y0 * y0)
    }

    /// Displacement by the series of thesis (4.6) (corrected) with
    /// [`Self::DEFAULT_TERMS`] terms.
    pub fn displacement(&self, y0: f64, t: f64) -> f64 {
        self.displacement_with_terms(y0, t, Self::DEFAULT_TERMS)
    }

    /// Displacement by the series of thesis (4.6) (corrected) with `terms` terms;
    /// the error is at most [`Self::series_tail_bound`]`(terms)`.
    pub fn displacement_with_terms(&self, y0: f64, t: f64, terms: usize) -> f64 {
        let h = self.height;
        let c = self.wave_speed();
        let amplitude = 16.0 * self.density * self.gravity * h * h / (PI.powi(3) * self.young);
        let mut u = self.static_displacement(y0);
        for n in 1..=terms {
            let m = 2.0 * n as f64 - 1.0;
            let k = m * PI / (2.0 * h);
            u -= amplitude / (m * m * m) * (c * k * t).cos() * (k * y0).sin();
        }
        u
    }

    /// Bound on the truncation error of the series after `terms` terms:
    /// `Σ_{n>N} |u_n| ≤ (16ρ|g|H²/(π³E)) ∫_N^∞ (2x − 1)⁻³ dx = 4ρ|g|H² / (π³E (2N − 1)²)`.
    /// Infinite for `terms = 0` (the bound is then useless; the static part alone is
    /// off by up to `ρ|g|H²/(2E)`).
    pub fn series_tail_bound(&self, terms: usize) -> f64 {
        if terms == 0 {
            return f64::INFINITY;
        }
        let m = 2.0 * terms as f64 - 1.0;
        4.0 * self.density * self.gravity.abs() * self.height.powi(2)
            / (PI.powi(3) * self.young * m * m)
    }

    /// The same displacement in closed form (d'Alembert): with `ũ` the extension of
    /// the static displacement `u_s` that is odd about `y = 0` and even about `y = H`
    /// (period `4H`),
    /// `u(y⁰, t) = u_s(y⁰) − ½ (ũ(y⁰ + ct) + ũ(y⁰ − ct))`.
    /// Exact to round-off for every `t`; the series of [`Self::displacement`] is its
    /// Fourier sine series.
    pub fn displacement_closed_form(&self, y0: f64, t: f64) -> f64 {
        let ct = self.wave_speed() * t;
        self.static_displacement(y0)
            - 0.5 * (self.extended_static(y0 + ct).0 + self.extended_static(y0 - ct).0)
    }

    /// Velocity `u_t(y⁰, t) = −(c/2)(ũ'(y⁰ + ct) − ũ'(y⁰ − ct))` (closed form, see
    /// [`Self::displacement_closed_form`]); exact for every `t`. (Its Fourier series
    /// converges only like `1/N`, so no series version is offered.)
    pub fn velocity(&self, y0: f64, t: f64) -> f64 {
        let c = self.wave_speed();
        let ct = c * t;
        -0.5 * c * (self.extended_static(y0 + ct).1 - self.extended_static(y0 - ct).1)
    }

    /// `(ũ(y), ũ'(y))`: the static displacement extended oddly about 0 and evenly
    /// about `H` (period `4H`), and its derivative.
    fn extended_static(&self, y: f64) -> (f64, f64) {
        let h = self.height;
        let r = y.rem_euclid(4.0 * h);
        // (reference point z in [0, H], sign of the value, sign of the derivative)
        let (z, sv, sd) = if r <= h {
            (r, 1.0, 1.0)
        } else if r <= 2.0 * h {
            (2.0 * h - r, 1.0, -1.0)
        } else if r <= 3.0 * h {
            (r - 2.0 * h, -1.0, -1.0)
        } else {
            (4.0 * h - r, -1.0, 1.0)
        };
        let a = self.density * self.gravity / self.young;
        (sv * a * (h * z - 0.5 * z * z), sd * a * (h - z))
    }
}

// ---------------------------------------------------------------------------------
// B4: axis-aligned displacement (manufactured solution).
// ---------------------------------------------------------------------------------

/// Axis-aligned displacement on the unit square (B4; paper §4.2, eqs. (40)–(46)),
/// a manufactured solution for the compressible neo-Hookean law in plane strain:
///
/// `u_x = u⁰ sin(2πx⁰) sin(√(E/ρ⁰) π t)`, `u_y = u⁰ sin(2πy⁰) sin(√(E/ρ⁰) π t + π)`,
///
/// driven by the body force (per unit mass) of eqs. (42)–(43), [`Self::body_force`].
/// The paper's values: `ρ⁰ = 10³`, `E = 10⁷`, `ν = 0.3`, `u⁰ = 0.05`, period 0.02.
///
/// Domain: `E, ρ⁰ > 0`, `−1 < ν < ½`, and `2π|u⁰| < 1` so that `D_xx, D_yy > 0`
/// (otherwise `ln J` is `NaN`); for `u⁰ = 0.05`, `D ∈ [0.686, 1.314]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisAligned {
    /// Amplitude `u⁰`.
    pub u0: f64,
    /// Young's modulus `E`.
    pub young: f64,
    /// Poisson's ratio `ν`.
    pub poisson: f64,
    /// Reference density `ρ⁰`.
    pub density: f64,
}

impl AxisAligned {
    /// The paper's parameters: `u⁰ = 0.05`, `E = 10⁷`, `ν = 0.3`, `ρ⁰ = 10³`.
    pub const PAPER: AxisAligned = AxisAligned {
        u0: 0.05,
        young: 1e7,
        poisson: 0.3,
        density: 1e3,
    };

    /// Lamé constants `(λ, μ)` of eq. (44) (plane strain):
    /// `λ = Eν/((1 + ν)(1 − 2ν))`, `μ = E/(2(1 + ν))`.
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young, self.poisson);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }

    /// Angular frequency `ω = π √(E/ρ⁰)` of the imposed motion.
    pub fn omega(&self) -> f64 {
        PI * (self.young / self.density).sqrt()
    }

    /// Period `T = 2π/ω = 2/√(E/ρ⁰)` (0.02 for the paper's `E = 10⁷`, `ρ⁰ = 10³`).
    pub fn period(&self) -> f64 {
        2.0 / (self.young / self.density).sqrt()
    }

    /// Time factors `(sin(ωt), sin(ωt + π))` of eqs. (40)–(41); the second is
    /// evaluated as `−sin(ωt)` so that both vanish exactly at `t = 0`.
    fn time_factors(&self, t: f64) -> (f64, f64) {
        let s = (self.omega() * t).sin();
        (s, -s)
    }

    /// Displacement `[u_x, u_y]` of eqs. (40)–(41).
    pub fn displacement(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let (sx, sy) = self.time_factors(t);
        [
            self.u0 * (2.0 * PI * x0[0]).sin() * sx,
            self.u0 * (2.0 * PI * x0[1]).sin() * sy,
        ]
    }

    /// Velocity, the time derivative of [`Self::displacement`]:
    /// `v_x = u⁰ ω sin(2πx⁰) cos(ωt)`, `v_y = u⁰ ω sin(2πy⁰) cos(ωt + π)`.
    pub fn velocity(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let w = self.omega();
        [
            self.u0 * w * (2.0 * PI * x0[0]).sin() * (w * t).cos(),
            -self.u0 * w * (2.0 * PI * x0[1]).sin() * (w * t).cos(),
        ]
    }

    /// Acceleration `ü = −ω² u = −π² (E/ρ⁰) u`.
    pub fn acceleration(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let w2 = self.omega().powi(2);
        let u = self.displacement(x0, t);
        [-w2 * u[0], -w2 * u[1]]
    }

    /// Current position `x = x⁰ + u` (the `x̂_p` of eq. (47)).
    pub fn position(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let u = self.displacement(x0, t);
        [x0[0] + u[0], x0[1] + u[1]]
    }

    /// Diagonal `[D_xx, D_yy]` of the deformation gradient, eqs. (45)–(46)
    /// (the off-diagonal entries vanish):
    /// `D_xx = 1 + 2u⁰π cos(2πx⁰) sin(ωt)`, `D_yy = 1 + 2u⁰π cos(2πy⁰) sin(ωt + π)`.
    pub fn deformation_gradient(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let (sx, sy) = self.time_factors(t);
        [
            1.0 + 2.0 * self.u0 * PI * (2.0 * PI * x0[0]).cos() * sx,
            1.0 + 2.0 * self.u0 * PI * (2.0 * PI * x0[1]).cos() * sy,
        ]
    }

    /// Diagonal `[P_xx, P_yy]` of the first Piola–Kirchhoff stress `P = J σ F⁻ᵀ` of
    /// the neo-Hookean law (paper (27)) for `F = diag(D_xx, D_yy)`:
    /// `P_xx = λ ln J / D_xx + μ (D_xx − 1/D_xx)`, `J = D_xx D_yy` (likewise `P_yy`).
    pub fn first_piola_kirchhoff(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let (lambda, mu) = self.lame();
        let [dxx, dyy] = self.deformation_gradient(x0, t);
        let ln_j = (dxx * dyy).ln();
        [
            lambda * ln_j / dxx + mu * (dxx - 1.0 / dxx),
            lambda * ln_j / dyy + mu * (dyy - 1.0 / dyy),
        ]
    }

    /// Diagonal `[σ_xx, σ_yy]` of the Cauchy stress
    /// `σ = (λ ln J / J) I + (μ/J)(F Fᵀ − I)` (paper (27); `σ_xy = 0`; the
    /// out-of-plane `σ_zz = λ ln J / J` is not returned). Fig. 13–14 plot `σ_xx`.
    pub fn cauchy_stress(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let (lambda, mu) = self.lame();
        let [dxx, dyy] = self.deformation_gradient(x0, t);
        let j = dxx * dyy;
        let iso = lambda * j.ln() / j;
        [
            iso + mu / j * (dxx * dxx - 1.0),
            iso + mu / j * (dyy * dyy - 1.0),
        ]
    }

    /// Body force per unit mass `[g_x, g_y]` of eqs. (42)–(43), as printed:
    ///
    /// `g_x = π² u_x (4μ/ρ⁰ − E/ρ⁰ − 4 (λ [ln(D_xx D_yy) − 1] − μ) / (ρ⁰ D_xx²))`,
    /// and `g_y` with `u_y`, `D_yy²`. Verified (module docs, `tests/exact.rs`): with it,
    /// `ρ⁰ ü = Div P + ρ⁰ g` holds to round-off. Add `ρ⁰ g` times the particle volume
    /// to the external force, evaluated at the particle's reference position.
    pub fn body_force(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        let (lambda, mu) = self.lame();
        let rho = self.density;
        let u = self.displacement(x0, t);
        let [dxx, dyy] = self.deformation_gradient(x0, t);
        let ln_j = (dxx * dyy).ln();
        let common = 4.0 * mu / rho - self.young / rho;
        let nonlinear = lambda * (ln_j - 1.0) - mu;
        let pi2 = PI * PI;
        [
            pi2 * u[0] * (common - 4.0 * nonlinear / (rho * dxx * dxx)),
            pi2 * u[1] * (common - 4.0 * nonlinear / (rho * dyy * dyy)),
        ]
    }
}

// ---------------------------------------------------------------------------------
// B5c: equilibrium of the column under self-weight, large deformation.
// ---------------------------------------------------------------------------------

/// Equilibrium stress `σ_yy` of the column under self-weight, paper eq. (48):
///
/// `σ_yy(y) = σ_yy(0) ((1 − y/H) + κ y/H) / (1 − κ(1 − κ) y/H)`,
/// `σ_yy(0) = H ρ g`, `κ = σ_yy(0)/(2E)`,
///
/// with `y = y_eq` the *current* (equilibrium) height of the point above the fixed
/// bottom, `H` the reference height, `ρ` the reference density. Sign convention:
/// compression negative, so `σ_yy(0) = −H ρ |g| < 0` and `κ < 0` (the paper's
/// `g = −9.81`); the sign of `gravity_magnitude` is ignored. The stress vanishes at
/// the equilibrium top `y = H/(1 − κ)`.
///
/// As the module docs show, (48) is the exact equilibrium of the 1D law
/// `σ = 2E (1 − F^{−1/2})`, not of the project's `σ = E (F − 1)`; it agrees with
/// [`column_equilibrium_stress_linear`] to `O(κ²) |σ_yy(0)|`.
///
/// Domain: `H, ρ, E > 0`, `0 ≤ y_eq ≤ H/(1 − κ)`.
pub fn column_equilibrium_stress(
    y_eq: f64,
    height: f64,
    density: f64,
    gravity_magnitude: f64,
    young: f64,
) -> f64 {
    let sigma0 = -height * density * gravity_magnitude.abs();
    let kappa = sigma0 / (2.0 * young);
    let s = y_eq / height;
    sigma0 * ((1.0 - s) + kappa * s) / (1.0 - kappa * (1.0 - kappa) * s)
}

/// Exact equilibrium stress `σ_yy` at current height `y_eq` of the column under
/// self-weight for the project's 1D (ν = 0, sides fixed in `x`) linear law
/// `σ = E (F − 1)` (Cauchy stress, `F = ∂y/∂Y`).
///
/// In the reference height `Y`: `σ = −ρ|g| (H − Y)`, `y = Y − (ρ|g|/E)(HY − Y²/2)`,
/// top at `y_top = H (1 + κ)`, `κ = −Hρ|g|/(2E)`. Inverting at depth
/// `d = y_top − y_eq`: `H − Y = 2d / (1 + √(1 − 2ρ|g|d/E))` and `σ = −E a (H − Y)`
/// with `a = ρ|g|/E`.
///
/// Domain: `H, ρ, E > 0`, `ρ|g|H < E` (so `F > 0` at the bottom),
/// `0 ≤ y_eq ≤ y_top`. The sign of `gravity_magnitude` is ignored.
pub fn column_equilibrium_stress_linear(
    y_eq: f64,
    height: f64,
    density: f64,
    gravity_magnitude: f64,
    young: f64,
) -> f64 {
    bar_equilibrium_stress_linear(y_eq, height, density, -gravity_magnitude.abs(), young)
}

/// Exact equilibrium stress of a bar of length `H` fixed at its end `y = 0`
/// under its weight, at current position `y_eq` above that end, for the linear
/// law `σ = E (F − 1)`, with `gravity` the signed acceleration along the bar
/// (from the fixed end to the free one): `g < 0` toward the fixed end, a column
/// standing on it in compression ([`column_equilibrium_stress_linear`]);
/// `g > 0` away from it, a bar hanging from it in tension.
///
/// In the reference position `Y`: `σ = ρ g (H − Y)`, `y = Y − a (HY − Y²/2)` with
/// `a = −ρ g / E`, the free end at `y_top = H (1 − a H / 2)`. At `d = y_top − y_eq`
/// the depth `H − Y = 2d / (1 + √(1 − 2 a d))` and `σ = −E a (H − Y)`.
///
/// Domain: `H, ρ, E > 0`, `ρ|g|H < E` for `g < 0` (so `F > 0` at the fixed end),
/// `0 ≤ y_eq ≤ y_top`.
pub fn bar_equilibrium_stress_linear(
    y_eq: f64,
    height: f64,
    density: f64,
    gravity: f64,
    young: f64,
) -> f64 {
    let a = -density * gravity / young;
    let y_top = height * (1.0 - 0.5 * a * height);
    let d = y_top - y_eq;
    let depth_ref = 2.0 * d / (1.0 + (1.0 - 2.0 * a * d).sqrt());
    -young * a * depth_ref
}

/// Exact equilibrium stress `σ_yy` of the column under self-weight at the
/// *reference* height `Y = y0` of the point above the fixed bottom: the weight of
/// the column above it, `σ_yy = −ρ|g| (H − Y)`, whatever the law and the initial
/// stress. In the 1D bar, and in the 2D column whose sides are held in `x`
/// (`F_xx = 1`), the first Piola–Kirchhoff stress `P_yY = σ_yy F_xx = σ_yy`, and
/// equilibrium in the reference configuration, `∂P_yY/∂Y = ρ|g|` with `P_yY = 0` at
/// the free top `Y = H`, gives it. So it also holds for a column started from a
/// geostatic initial stress `σ⁰` (which the law's stress adds to): with
/// `σ⁰ = −ρ|g| (H − Y)` (surface at the top) the column is already there, `u = 0`.
///
/// Domain: `H, ρ > 0`, `0 ≤ y0 ≤ H`. The sign of `gravity_magnitude` is ignored.
pub fn column_equilibrium_stress_at_reference(
    y0: f64,
    height: f64,
    density: f64,
    gravity_magnitude: f64,
) -> f64 {
    bar_equilibrium_stress_at_reference(y0, height, density, -gravity_magnitude.abs())
}

/// The stress of [`column_equilibrium_stress_at_reference`] with `gravity` the
/// signed acceleration along the bar from its fixed end `Y = 0` to its free one:
/// `σ = ρ g (H − Y)`, compression for a column standing on the fixed end
/// (`g < 0`), tension for a bar hanging from it (`g > 0`).
pub fn bar_equilibrium_stress_at_reference(
    y0: f64,
    height: f64,
    density: f64,
    gravity: f64,
) -> f64 {
    density * gravity * (height - y0)
}

/// Exact equilibrium height `y_eq(Y) = Y − (ρ|g|/E)(HY − Y²/2)` of the point at
/// reference height `Y = y0` for the project's linear law `σ = E (F − 1)` (see
/// [`column_equilibrium_stress_linear`]; the stress there is `−ρ|g| (H − Y)`).
///
/// Domain: `H, ρ, E > 0`, `0 ≤ y0 ≤ H`. The sign of `gravity_magnitude` is ignored.
pub fn column_equilibrium_position_linear(
    y0: f64,
    height: f64,
    density: f64,
    gravity_magnitude: f64,
    young: f64,
) -> f64 {
    let a = density * gravity_magnitude.abs() / young;
    y0 - a * (height * y0 - 0.5 * y0 * y0)
}

// ---------------------------------------------------------------------------------
// Eq. (47): time-averaged RMS position error.
// ---------------------------------------------------------------------------------

/// Accumulator for the time-averaged RMS position error of paper eq. (47):
///
/// `RMS = √( Σ_{i=1}^{n_t} Σ_{p=1}^{n_p} |x_p(t_i) − x̂_p(t_i)|² / (n_p n_t) )`.
///
/// Call [`Self::add_sample`] for every particle after a step and then
/// [`Self::finish_step`]. Every step is weighted equally: the value is the square
/// root of the mean over steps of the per-step mean squared error, which is eq. (47)
/// when every step has the same `n_p` (and stays a fair average if it does not).
/// Samples added after the last `finish_step` count as one more step in
/// [`Self::value`]; `finish_step` after no samples does nothing.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RmsPositionError {
    /// Σ over finished steps of the per-step mean squared error.
    sum_of_step_means: f64,
    /// Finished steps with at least one sample.
    steps: usize,
    /// Σ |x − x̂|² of the current step.
    step_sum: f64,
    /// Samples in the current step.
    step_samples: usize,
}

impl RmsPositionError {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `|computed − exact|²` of one particle to the current step.
    pub fn add_sample(&mut self, exact: [f64; 2], computed: [f64; 2]) {
        let (dx, dy) = (computed[0] - exact[0], computed[1] - exact[1]);
        self.step_sum += dx * dx + dy * dy;
        self.step_samples += 1;
    }

    /// Closes the current step (a no-op when it has no samples).
    pub fn finish_step(&mut self) {
        if self.step_samples > 0 {
            self.sum_of_step_means += self.step_sum / self.step_samples as f64;
            self.steps += 1;
        }
        self.step_sum = 0.0;
        self.step_samples = 0;
    }

    /// Steps counted so far (`n_t`), including an unfinished one with samples.
    pub fn steps(&self) -> usize {
        self.steps + usize::from(self.step_samples > 0)
    }

    /// The RMS error of eq. (47) over all samples so far; 0 when there are none.
    pub fn value(&self) -> f64 {
        let mut sum = self.sum_of_step_means;
        if self.step_samples > 0 {
            sum += self.step_sum / self.step_samples as f64;
        }
        let n = self.steps();
        if n == 0 {
            0.0
        } else {
            (sum / n as f64).sqrt()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b5a() -> ColumnSelfWeight {
        ColumnSelfWeight {
            height: 25.0,
            young: 5e4,
            density: 1.0,
            gravity: -9.81,
        }
    }

    #[test]
    fn vibrating_bar_velocity_and_stress_are_derivatives() {
        let bar = VibratingBar {
            length: 25.0,
            young: 100.0,
            density: 1.0,
            v0: 0.1,
        };
        assert!((bar.omega() - PI * 10.0 / 25.0).abs() < 1e-15);
        let h = 1e-5;
        for &(x, t) in &[(3.0, 0.7), (12.5, 2.0), (20.0, 5.3)] {
            let dt = (bar.displacement(x, t + h) - bar.displacement(x, t - h)) / (2.0 * h);
            assert!((dt - bar.velocity(x, t)).abs() < 1e-9);
            let dx = (bar.displacement(x + h, t) - bar.displacement(x - h, t)) / (2.0 * h);
            assert!((100.0 * dx - bar.stress(x, t)).abs() < 1e-7);
        }
        // Initial conditions and fixed ends.
        assert_eq!(bar.displacement(7.0, 0.0), 0.0);
        assert!((bar.velocity(12.5, 0.0) - 0.1).abs() < 1e-15);
        assert!(bar.displacement(0.0, 1.3).abs() < 1e-15);
        assert!(bar.displacement(25.0, 1.3).abs() < 1e-15);
    }

    #[test]
    fn column_series_converges_to_the_closed_form_like_n_to_the_minus_two() {
        let c = b5a();
        let scale = c.density * c.gravity.abs() * c.height.powi(2) / c.young;
        // At rest, unstressed at t = 0: the series sums to the static displacement.
        for i in 0..=50 {
            let y = c.height * i as f64 / 50.0;
            assert!(c.displacement_closed_form(y, 0.0).abs() < 1e-15 * scale);
            assert!(c.displacement(y, 0.0).abs() <= c.series_tail_bound(400));
            assert!(c.velocity(y, 0.0).abs() < 1e-15);
        }
        // The truncation error respects the bound at all times, and decays like N⁻²:
        // its maximum sits at distance ~H/N from the kinks of the extended static
        // displacement (at t = 0, near y = 0), so sample geometrically there.
        let mut heights: Vec<f64> = (0..=100).map(|i| c.height * i as f64 / 100.0).collect();
        heights.extend((0..=400).map(|j| c.height * 10f64.powf(-4.0 + 4.0 * j as f64 / 400.0)));
        let mut previous = f64::INFINITY;
        for &terms in &[25usize, 50, 100, 200, 400, 800] {
            let mut worst_at_rest: f64 = 0.0;
            for &y in &heights {
                for &t in &[0.0, 0.013, 0.05, 0.3, 0.777] {
                    let e =
                        c.displacement_with_terms(y, t, terms) - c.displacement_closed_form(y, t);
                    assert!(
                        e.abs() <= c.series_tail_bound(terms),
                        "{terms} {y} {t}: {e}"
                    );
                    if t == 0.0 {
                        worst_at_rest = worst_at_rest.max(e.abs());
                    }
                }
            }
            // The bound is not loose by more than a small factor.
            assert!(worst_at_rest > 0.2 * c.series_tail_bound(terms));
            if previous.is_finite() {
                // Doubling N divides the error by ≈ 4 (N⁻²).
                let ratio = previous / worst_at_rest;
                assert!(ratio > 3.5 && ratio < 4.5, "{terms}: ratio {ratio}");
            }
            previous = worst_at_rest;
        }
        assert!(c.series_tail_bound(400) < 2.1e-7 * scale);
        assert!(c.series_tail_bound(0).is_infinite());
    }

    #[test]
    fn column_closed_form_solves_the_wave_equation_and_boundary_conditions() {
        let c = b5a();
        let cc = c.young / c.density;
        let (hy, ht) = (1e-3, 1e-5);
        for &y in &[1.0, 7.3, 12.5, 20.0, 24.0] {
            for &t in &[0.0123, 0.1, 0.37, 1.9] {
                let u = |y: f64, t: f64| c.displacement_closed_form(y, t);
                let utt = (u(y, t + ht) - 2.0 * u(y, t) + u(y, t - ht)) / (ht * ht);
                let uyy = (u(y + hy, t) - 2.0 * u(y, t) + u(y - hy, t)) / (hy * hy);
                let lhs = utt - cc * uyy - c.gravity;
                // Away from the kinks of the travelling fronts the residual is small.
                let front = |s: f64| {
                    let r = s.rem_euclid(c.height);
                    r.min(c.height - r)
                };
                let ct = c.wave_speed() * t;
                if front(y + ct) > 0.05 && front(y - ct) > 0.05 {
                    assert!(lhs.abs() < 1e-4 * c.gravity.abs(), "{y} {t}: {lhs}");
                }
                let v = (u(y, t + ht) - u(y, t - ht)) / (2.0 * ht);
                assert!((v - c.velocity(y, t)).abs() < 1e-6 * c.gravity.abs());
            }
            // Fixed bottom, free top.
            assert!(c.displacement_closed_form(0.0, y / 10.0).abs() < 1e-15);
            let t = y / 10.0;
            let h = c.height;
            let uy_top = (c.displacement_closed_form(h + hy, t)
                - c.displacement_closed_form(h - hy, t))
                / (2.0 * hy);
            assert!(uy_top.abs() < 1e-8);
        }
        // Long times: periodic with the fundamental period 4H/c.
        let period = 4.0 * c.height / c.wave_speed();
        let y = 17.0;
        assert!(
            (c.displacement_closed_form(y, 0.3)
                - c.displacement_closed_form(y, 0.3 + 7.0 * period))
            .abs()
                < 1e-12
        );
    }

    #[test]
    fn axis_aligned_period_and_derivatives() {
        let b = AxisAligned::PAPER;
        assert!((b.period() - 0.02).abs() < 1e-15);
        let x0 = [0.31, 0.77];
        for &t in &[0.0, 0.0031, 0.0117] {
            let (u, u_next) = (b.displacement(x0, t), b.displacement(x0, t + b.period()));
            assert!((u[0] - u_next[0]).abs() < 1e-14 && (u[1] - u_next[1]).abs() < 1e-14);
            let h = 1e-7;
            let (up, um) = (b.displacement(x0, t + h), b.displacement(x0, t - h));
            let v = b.velocity(x0, t);
            for k in 0..2 {
                assert!(((up[k] - um[k]) / (2.0 * h) - v[k]).abs() < 1e-6 * b.u0 * b.omega());
            }
            let d = b.deformation_gradient(x0, t);
            let (ux_p, ux_m) = (
                b.displacement([x0[0] + h, x0[1]], t),
                b.displacement([x0[0] - h, x0[1]], t),
            );
            assert!((1.0 + (ux_p[0] - ux_m[0]) / (2.0 * h) - d[0]).abs() < 1e-7);
            let (uy_p, uy_m) = (
                b.displacement([x0[0], x0[1] + h], t),
                b.displacement([x0[0], x0[1] - h], t),
            );
            assert!((1.0 + (uy_p[1] - uy_m[1]) / (2.0 * h) - d[1]).abs() < 1e-7);
            let x = b.position(x0, t);
            assert!((x[0] - x0[0] - u[0]).abs() < 1e-15 && (x[1] - x0[1] - u[1]).abs() < 1e-15);
        }
        // Opposite phases: u_y = −u_x at x⁰ = y⁰.
        let u = b.displacement([0.2, 0.2], 0.004);
        assert!((u[0] + u[1]).abs() < 1e-15);
        // Unstressed at rest.
        assert_eq!(b.body_force(x0, 0.0), [0.0, 0.0]);
        assert_eq!(b.cauchy_stress(x0, 0.0), [0.0, 0.0]);
    }

    /// A bar hanging from its fixed end (`g > 0`, away from it) is in tension,
    /// `σ = ρ g (L − X)`, at the position `x = X + (ρg/E)(LX − X²/2)` the linear
    /// law gives; with `g < 0` the signed forms are the column's.
    #[test]
    fn a_hanging_bar_is_in_tension_and_a_standing_one_in_compression() {
        let (l, rho, g, e) = (2.0, 1e3, 9.81, 1e6);
        for k in 0..=10 {
            let x0 = l * k as f64 / 10.0;
            let x = x0 + rho * g / e * (l * x0 - 0.5 * x0 * x0);
            let sigma = bar_equilibrium_stress_linear(x, l, rho, g, e);
            assert!(
                (sigma - rho * g * (l - x0)).abs() < 1e-9 * rho * g * l,
                "{k}: {sigma}"
            );
            assert_eq!(
                bar_equilibrium_stress_at_reference(x0, l, rho, g),
                rho * g * (l - x0)
            );
            let y = column_equilibrium_position_linear(x0, l, rho, g, e);
            assert_eq!(
                bar_equilibrium_stress_linear(y, l, rho, -g, e),
                column_equilibrium_stress_linear(y, l, rho, g, e)
            );
        }
    }

    #[test]
    fn equation_48_sign_and_end_values() {
        let (h, rho, g, e) = (1.0, 1e3, 9.81, 1e5);
        let s0 = column_equilibrium_stress(0.0, h, rho, g, e);
        assert!((s0 + h * rho * g).abs() < 1e-9);
        assert_eq!(s0, column_equilibrium_stress(0.0, h, rho, -g, e));
        let kappa = s0 / (2.0 * e);
        assert!(column_equilibrium_stress(h / (1.0 - kappa), h, rho, g, e).abs() < 1e-9);
        // The linear law: same bottom stress, top at H(1 + κ).
        assert!((column_equilibrium_stress_linear(0.0, h, rho, g, e) - s0).abs() < 1e-9);
        let top = column_equilibrium_position_linear(h, h, rho, g, e);
        assert!((top - h * (1.0 + kappa)).abs() < 1e-15);
        assert!(column_equilibrium_stress_linear(top, h, rho, g, e).abs() < 1e-9);
    }

    #[test]
    fn rms_position_error_is_equation_47() {
        let mut rms = RmsPositionError::new();
        assert_eq!(rms.value(), 0.0);
        rms.finish_step();
        assert_eq!(rms.steps(), 0);
        // Step 1: errors 3-4-5 and 0; step 2: errors 1 and 1.
        rms.add_sample([0.0, 0.0], [3.0, 4.0]);
        rms.add_sample([1.0, 1.0], [1.0, 1.0]);
        rms.finish_step();
        rms.add_sample([0.0, 0.0], [1.0, 0.0]);
        rms.add_sample([2.0, 0.0], [2.0, -1.0]);
        assert_eq!(rms.steps(), 2);
        let expected = ((25.0 + 0.0 + 1.0 + 1.0) / (2.0 * 2.0f64)).sqrt();
        assert!((rms.value() - expected).abs() < 1e-15);
        rms.finish_step();
        rms.finish_step();
        assert_eq!(rms.steps(), 2);
        assert!((rms.value() - expected).abs() < 1e-15);
    }
}
