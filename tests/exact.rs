//! Independent checks of the exact solutions in `psmpm::studies::exact`:
//!
//! * B4 (paper (40)–(46)): the body force of eqs. (42)–(43) balances the imposed
//!   motion for the project's neo-Hookean law, `ρ⁰ ü − Div P − ρ⁰ g ≈ 0` to round-off,
//!   with `ü` and `Div P` from exact automatic differentiation (second-order jets) of
//!   (40)–(41) and of `P = λ ln J F⁻ᵀ + μ (F − F⁻ᵀ)`, that `P` cross-checked against
//!   `J σ F⁻ᵀ` of `psmpm::material::NeoHookean`.
//! * B5c (paper (48)): the equilibrium ODE of the column integrated numerically for the
//!   project's linear law `σ = E (F − 1)` and for `σ = 2E (1 − F^{−1/2})`; (48) is
//!   exact for the second only.

// Index loops over the two components read like the formulas.
#![allow(clippy::needless_range_loop)]

use nalgebra::Matrix2;
use psmpm::material::{Elastic, Material, NeoHookean};
use psmpm::studies::exact::{
    column_equilibrium_position_linear, column_equilibrium_stress,
    column_equilibrium_stress_linear, AxisAligned,
};
use std::f64::consts::PI;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Truncated Taylor jet `(f, f', f'')` in one variable: exact first and second
/// derivatives of compositions, to round-off.
#[derive(Debug, Clone, Copy)]
struct Jet {
    v: f64,
    d1: f64,
    d2: f64,
}

impl Jet {
    fn var(x: f64) -> Jet {
        Jet {
            v: x,
            d1: 1.0,
            d2: 0.0,
        }
    }
    fn cst(x: f64) -> Jet {
        Jet {
            v: x,
            d1: 0.0,
            d2: 0.0,
        }
    }
    fn sin(self) -> Jet {
        let (s, c) = self.v.sin_cos();
        Jet {
            v: s,
            d1: c * self.d1,
            d2: -s * self.d1 * self.d1 + c * self.d2,
        }
    }
    fn ln(self) -> Jet {
        let r = 1.0 / self.v;
        Jet {
            v: self.v.ln(),
            d1: self.d1 * r,
            d2: self.d2 * r - self.d1 * self.d1 * r * r,
        }
    }
    fn recip(self) -> Jet {
        let r = 1.0 / self.v;
        Jet {
            v: r,
            d1: -self.d1 * r * r,
            d2: 2.0 * self.d1 * self.d1 * r * r * r - self.d2 * r * r,
        }
    }
}

impl Add for Jet {
    type Output = Jet;
    fn add(self, o: Jet) -> Jet {
        Jet {
            v: self.v + o.v,
            d1: self.d1 + o.d1,
            d2: self.d2 + o.d2,
        }
    }
}
impl Sub for Jet {
    type Output = Jet;
    fn sub(self, o: Jet) -> Jet {
        self + (-o)
    }
}
impl Neg for Jet {
    type Output = Jet;
    fn neg(self) -> Jet {
        Jet {
            v: -self.v,
            d1: -self.d1,
            d2: -self.d2,
        }
    }
}
impl Mul for Jet {
    type Output = Jet;
    fn mul(self, o: Jet) -> Jet {
        Jet {
            v: self.v * o.v,
            d1: self.d1 * o.v + self.v * o.d1,
            d2: self.d2 * o.v + 2.0 * self.d1 * o.d1 + self.v * o.d2,
        }
    }
}
impl Div for Jet {
    type Output = Jet;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Jet) -> Jet {
        self * o.recip()
    }
}
impl Mul<Jet> for f64 {
    type Output = Jet;
    fn mul(self, o: Jet) -> Jet {
        Jet::cst(self) * o
    }
}
impl Add<Jet> for f64 {
    type Output = Jet;
    fn add(self, o: Jet) -> Jet {
        Jet::cst(self) + o
    }
}

/// Eq. (40), written out independently of the library: `u_x(x⁰, t)`.
fn ux(b: &AxisAligned, x: Jet, t: Jet) -> Jet {
    let c = (b.young / b.density).sqrt();
    b.u0 * (2.0 * PI * x).sin() * (c * PI * t).sin()
}

/// Eq. (41), literally with `+ π`: `u_y(y⁰, t)`.
fn uy(b: &AxisAligned, y: Jet, t: Jet) -> Jet {
    let c = (b.young / b.density).sqrt();
    b.u0 * (2.0 * PI * y).sin() * (PI + c * PI * t).sin()
}

/// Plane-strain Lamé constants, computed here from their definition.
fn lame(b: &AxisAligned) -> (f64, f64) {
    let (e, nu) = (b.young, b.poisson);
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (lambda, e / (2.0 * (1.0 + nu)))
}

/// Diagonal entry `P_aa` of `P = λ ln J F⁻ᵀ + μ (F − F⁻ᵀ)` for diagonal `F`,
/// `F_aa = fa`, the other diagonal entry `fb`.
fn p_diag(lambda: f64, mu: f64, fa: Jet, fb: Jet) -> Jet {
    lambda * (fa * fb).ln() / fa + mu * (fa - fa.recip())
}

struct Balance {
    /// `ρ⁰ ü`.
    inertia: [f64; 2],
    /// `Div_X P`.
    div_p: [f64; 2],
    /// `[F_xx, F_yy]` from the derivatives of (40)–(41).
    f: [f64; 2],
    /// `[P_xx, P_yy]` of the formula above.
    p: [f64; 2],
}

/// `ρ⁰ ü` and `Div_X P` at `(x⁰, t)` by automatic differentiation.
///
/// `u_x` depends only on `x⁰` and `u_y` only on `y⁰`, so `F` and hence `P` are
/// diagonal everywhere and `Div P = (∂P_xx/∂x⁰, ∂P_yy/∂y⁰)`.
fn balance(b: &AxisAligned, x0: [f64; 2], t: f64) -> Balance {
    let (lambda, mu) = lame(b);
    let rho = b.density;
    // Accelerations: second time derivatives.
    let ax = ux(b, Jet::cst(x0[0]), Jet::var(t)).d2;
    let ay = uy(b, Jet::cst(x0[1]), Jet::var(t)).d2;
    // Displacement jets in space: (u, u', u'').
    let jx = ux(b, Jet::var(x0[0]), Jet::cst(t));
    let jy = uy(b, Jet::var(x0[1]), Jet::cst(t));
    // F_aa = 1 + ∂u_a/∂X_a as a function of X_a, with its first derivative (the
    // second-derivative slot is not needed and left 0).
    let fxx_x = Jet {
        v: 1.0 + jx.d1,
        d1: jx.d2,
        d2: 0.0,
    };
    let fyy_y = Jet {
        v: 1.0 + jy.d1,
        d1: jy.d2,
        d2: 0.0,
    };
    let pxx = p_diag(lambda, mu, fxx_x, Jet::cst(fyy_y.v));
    let pyy = p_diag(lambda, mu, fyy_y, Jet::cst(fxx_x.v));
    Balance {
        inertia: [rho * ax, rho * ay],
        div_p: [pxx.d1, pyy.d1],
        f: [fxx_x.v, fyy_y.v],
        p: [pxx.v, pyy.v],
    }
}

/// Low-discrepancy sample points in `[0, 1]² × [0, t_max]`.
fn samples(n: usize, t_max: f64) -> impl Iterator<Item = ([f64; 2], f64)> {
    let (a1, a2, a3) = (
        0.819_172_513_396_164_4,
        0.671_043_606_703_789_2,
        0.549_700_477_901_970_4,
    );
    (1..=n).map(move |i| {
        let i = i as f64;
        (
            [(i * a1).fract(), (i * a2).fract()],
            (i * a3).fract() * t_max,
        )
    })
}

/// Residual `ρ⁰ ü − Div P − ρ⁰ g` over the samples for the body force `g`, as
/// `(pointwise, scaled)`: the largest `|r| / (|ρ⁰ ü| + |Div P|)`, and the largest `|r|`
/// relative to the amplitudes of the inertia and stress terms,
/// `ρ⁰ ω² |u⁰| + 4π² |u⁰| (λ + 2μ)` (`λ` dominates as `ν → ½`).
///
/// All terms are proportional to `u_a` and vanish together where `sin(2πx⁰)` or
/// `sin(ωt)` does; there the pointwise ratio measures the conditioning of those sines
/// (an argument rounded by `ε ωt` changes `sin` by `ε ωt`, a large relative change
/// near a zero) rather than an error of the formula, so it is only ~1e-12.
fn worst_residual(b: &AxisAligned, g: impl Fn([f64; 2], f64) -> [f64; 2]) -> (f64, f64) {
    let (lambda, mu) = lame(b);
    let scale = (b.density * b.omega().powi(2) + 4.0 * PI * PI * (lambda + 2.0 * mu)) * b.u0.abs();
    let (mut pointwise, mut scaled): (f64, f64) = (0.0, 0.0);
    for (x0, t) in samples(10_000, 2.0 * b.period()) {
        let bal = balance(b, x0, t);
        let force = g(x0, t);
        for k in 0..2 {
            let r = bal.inertia[k] - bal.div_p[k] - b.density * force[k];
            let size = bal.inertia[k].abs() + bal.div_p[k].abs() + 1e-300;
            pointwise = pointwise.max(r.abs() / size);
            scaled = scaled.max(r.abs() / scale);
        }
    }
    (pointwise, scaled)
}

fn cases() -> [AxisAligned; 3] {
    [
        AxisAligned::PAPER,
        AxisAligned {
            u0: 0.1,
            young: 3e5,
            poisson: 0.45,
            density: 2.5,
        },
        AxisAligned {
            u0: -0.02,
            young: 1.0,
            poisson: -0.3,
            density: 1.0,
        },
    ]
}

#[test]
fn body_force_of_equations_42_43_balances_the_motion_to_round_off() {
    for b in cases() {
        let (pointwise, scaled) = worst_residual(&b, |x0, t| b.body_force(x0, t));
        eprintln!(
            "B4 {b:?}: residual of (42)-(43): pointwise relative {pointwise:.1e}, \
             relative to the term amplitudes {scaled:.1e}"
        );
        assert!(pointwise < 1e-10, "{b:?}: {pointwise}");
        assert!(scaled < 1e-14, "{b:?}: {scaled}");
    }
}

#[test]
fn the_residual_test_detects_wrong_body_forces() {
    let b = AxisAligned::PAPER;
    let (lambda, mu) = lame(&b);
    let rho = b.density;
    // (42)–(43) with one term altered at a time.
    let variant = |sign_lambda: f64, factor: f64, sign_ln: f64| {
        move |x0: [f64; 2], t: f64| {
            let u = b.displacement(x0, t);
            let d = b.deformation_gradient(x0, t);
            let ln_j = (d[0] * d[1]).ln();
            let mut g = [0.0; 2];
            for k in 0..2 {
                let nonlinear = sign_lambda * lambda * (sign_ln * ln_j - 1.0) - mu;
                g[k] = PI
                    * PI
                    * u[k]
                    * (4.0 * mu / rho - b.young / rho - factor * nonlinear / (rho * d[k] * d[k]));
            }
            g
        }
    };
    let good = worst_residual(&b, variant(1.0, 4.0, 1.0));
    assert!(good.0 < 1e-10 && good.1 < 1e-14, "{good:?}");
    for (name, v) in [
        ("λ sign", worst_residual(&b, variant(-1.0, 4.0, 1.0))),
        ("factor 2", worst_residual(&b, variant(1.0, 2.0, 1.0))),
        ("ln J sign", worst_residual(&b, variant(1.0, 4.0, -1.0))),
    ] {
        eprintln!(
            "B4 altered body force ({name}): residual pointwise {:.1e}, scaled {:.1e}",
            v.0, v.1
        );
        assert!(v.0 > 1e-2 && v.1 > 1e-3, "{name}: {v:?}");
    }
    // No body force at all: the motion is not free.
    assert!(worst_residual(&b, |_, _| [0.0, 0.0]).1 > 1e-2);
}

#[test]
fn motion_stress_and_deformation_gradient_agree_with_the_library_and_the_material() {
    for b in cases() {
        let material = NeoHookean::new(Elastic::new(b.young, b.poisson, b.density).unwrap(), 2);
        let (mut worst_p, mut worst_f, mut worst_a, mut worst_s): (f64, f64, f64, f64) =
            (0.0, 0.0, 0.0, 0.0);
        for (x0, t) in samples(2_000, b.period()) {
            let bal = balance(&b, x0, t);
            // Eqs. (45)–(46) against the derivative of (40)–(41).
            let d = b.deformation_gradient(x0, t);
            let u = b.displacement(x0, t);
            let jet_u = [
                ux(&b, Jet::cst(x0[0]), Jet::cst(t)).v,
                uy(&b, Jet::cst(x0[1]), Jet::cst(t)).v,
            ];
            let acc = b.acceleration(x0, t);
            for k in 0..2 {
                worst_f = worst_f.max((d[k] - bal.f[k]).abs());
                worst_f = worst_f.max((u[k] - jet_u[k]).abs());
                // Relative to the amplitude ρ⁰ ω² |u⁰| (see `worst_residual`).
                let size = b.density * b.omega().powi(2) * b.u0.abs();
                worst_a = worst_a.max((b.density * acc[k] - bal.inertia[k]).abs() / size);
            }
            // P of the formula against J σ F⁻ᵀ of the project's NeoHookean.
            let f = Matrix2::new(bal.f[0], 0.0, 0.0, bal.f[1]);
            let sigma: Matrix2<f64> = Material::<f64, 2>::stress(&material, &f);
            let j = f.determinant();
            let p = sigma * j * f.try_inverse().unwrap().transpose();
            let (lambda, mu) = lame(&b);
            let scale = lambda + 2.0 * mu;
            worst_p = worst_p.max((p[(0, 0)] - bal.p[0]).abs() / scale);
            worst_p = worst_p.max((p[(1, 1)] - bal.p[1]).abs() / scale);
            worst_p = worst_p.max(p[(0, 1)].abs().max(p[(1, 0)].abs()) / scale);
            let lib_p = b.first_piola_kirchhoff(x0, t);
            worst_p =
                worst_p.max((lib_p[0] - bal.p[0]).abs().max((lib_p[1] - bal.p[1]).abs()) / scale);
            let cauchy = b.cauchy_stress(x0, t);
            worst_s = worst_s.max((cauchy[0] - sigma[(0, 0)]).abs() / scale);
            worst_s = worst_s.max((cauchy[1] - sigma[(1, 1)]).abs() / scale);
        }
        eprintln!(
            "B4 {b:?}: |P - J σ F^-T|/(λ+2μ) = {worst_p:.1e}, |F - (45)-(46)| = {worst_f:.1e}, \
             ü rel = {worst_a:.1e}, σ rel = {worst_s:.1e}"
        );
        assert!(worst_p < 1e-14 && worst_s < 1e-14);
        assert!(worst_f < 1e-14 * (1.0 + b.u0.abs() * 2.0 * PI));
        assert!(worst_a < 1e-14);
    }
}

#[test]
fn period_of_the_axis_aligned_motion() {
    let b = AxisAligned::PAPER;
    assert!((b.period() - 0.02).abs() < 1e-15);
    assert!((b.period() * b.omega() - 2.0 * PI).abs() < 1e-13);
}

// ---------------------------------------------------------------------------------
// Eq. (48): the column in equilibrium.
// ---------------------------------------------------------------------------------

/// Equilibrium of the column for the 1D law `F = stretch(σ)`, integrated numerically.
///
/// Current configuration: `dσ/dy + ρ g = 0`, `ρ = ρ⁰/F` (mass conservation), σ the
/// Cauchy stress (= the first Piola–Kirchhoff stress in 1D with fixed sides), σ = 0 at
/// the free top. With `dy = F dY` this is `dσ/dY = −ρ⁰ g`, `dy/dY = F(σ)`, integrated
/// by RK4 from the top `Y = H` (σ = 0) down to the fixed bottom `Y = 0` (`y = 0`,
/// which fixes the unknown top position). Returns `(Y_i, y_i, σ_i)`.
fn integrate_column(
    h: f64,
    rho: f64,
    g: f64,
    steps: usize,
    stretch: impl Fn(f64) -> f64,
) -> Vec<(f64, f64, f64)> {
    let rhs = |s: [f64; 2]| [-rho * g, stretch(s[0])];
    let dy = -h / steps as f64;
    // State (σ, z = y − y_top).
    let mut s = [0.0, 0.0];
    let mut out = vec![(h, s[1], s[0])];
    for i in 0..steps {
        let k1 = rhs(s);
        let k2 = rhs([s[0] + 0.5 * dy * k1[0], s[1] + 0.5 * dy * k1[1]]);
        let k3 = rhs([s[0] + 0.5 * dy * k2[0], s[1] + 0.5 * dy * k2[1]]);
        let k4 = rhs([s[0] + dy * k3[0], s[1] + dy * k3[1]]);
        for k in 0..2 {
            s[k] += dy / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]);
        }
        let y_ref = h * (1.0 - (i + 1) as f64 / steps as f64);
        out.push((y_ref, s[1], s[0]));
    }
    let y_top = -s[1];
    out.into_iter()
        .map(|(yr, z, sig)| (yr, z + y_top, sig))
        .collect()
}

/// Largest `|σ_formula(y_i) − σ_i| / |σ(0)|` over the integrated profile.
fn profile_error(profile: &[(f64, f64, f64)], sigma0: f64, formula: impl Fn(f64) -> f64) -> f64 {
    profile
        .iter()
        .map(|&(_, y, s)| (formula(y) - s).abs() / sigma0.abs())
        .fold(0.0, f64::max)
}

#[test]
fn equation_48_is_exact_for_the_inverse_square_root_law_and_approximate_for_linear() {
    let g: f64 = -9.81;
    // (H, ρ⁰, E): B5b, a ten times stiffer column, and a very soft one.
    for &(h, rho, e) in &[(1.0, 1e3, 1e5), (1.0, 1e3, 1e6), (2.0, 1e3, 5e4)] {
        let gm = g.abs();
        let sigma0 = h * rho * g;
        let kappa = sigma0 / (2.0 * e);
        let eq48 = |y: f64| column_equilibrium_stress(y, h, rho, gm, e);
        let linear_exact = |y: f64| column_equilibrium_stress_linear(y, h, rho, gm, e);

        // The project's linear law σ = E (F − 1).
        let linear = integrate_column(h, rho, g, 10_000, |s| 1.0 + s / e);
        // The law for which (48) is exact: σ = 2E (1 − F^{−1/2}).
        let root = integrate_column(h, rho, g, 10_000, |s| (1.0 - s / (2.0 * e)).powi(-2));

        let lin_vs_exact = profile_error(&linear, sigma0, linear_exact);
        let root_vs_48 = profile_error(&root, sigma0, eq48);
        let lin_vs_48 = profile_error(&linear, sigma0, eq48);
        eprintln!(
            "column H={h} ρ={rho} E={e} κ={kappa:.4}: linear law vs closed form {lin_vs_exact:.1e}, \
             F=(1-σ/2E)^-2 law vs (48) {root_vs_48:.1e}, linear law vs (48) {lin_vs_48:.2e} \
             (κ² = {:.2e})",
            kappa * kappa
        );
        assert!(lin_vs_exact < 1e-12);
        assert!(root_vs_48 < 1e-12);
        // (48) misses the linear law by O(κ²).
        assert!(lin_vs_48 > 0.5 * kappa * kappa && lin_vs_48 < 2.0 * kappa * kappa);

        // Equilibrium positions and the bottom stress of the linear law.
        for &(y_ref, y, s) in linear.iter().step_by(97) {
            let y_lin = column_equilibrium_position_linear(y_ref, h, rho, gm, e);
            assert!((y_lin - y).abs() < 1e-13 * h, "{y_ref}: {y_lin} vs {y}");
            assert!((s + rho * gm * (h - y_ref)).abs() < 1e-12 * sigma0.abs());
        }
        let bottom = linear.last().unwrap();
        assert!(bottom.1.abs() < 1e-13 && (bottom.2 - sigma0).abs() < 1e-12 * sigma0.abs());
        // Tops: H (1 + κ) for the linear law, H / (1 − κ) for (48).
        assert!((linear[0].1 - h * (1.0 + kappa)).abs() < 1e-12 * h);
        assert!((root[0].1 - h / (1.0 - kappa)).abs() < 1e-12 * h);
    }
}

#[test]
fn equation_48_difference_for_b5b_is_a_quarter_percent() {
    let (h, rho, gm, e) = (1.0, 1e3, 9.81, 1e5);
    let sigma0 = -h * rho * gm;
    let mut worst: f64 = 0.0;
    let top = column_equilibrium_position_linear(h, h, rho, gm, e);
    for i in 0..=1000 {
        let y = top * i as f64 / 1000.0;
        let d = column_equilibrium_stress(y, h, rho, gm, e)
            - column_equilibrium_stress_linear(y, h, rho, gm, e);
        worst = worst.max(d.abs() / sigma0.abs());
    }
    assert!((worst - 2.32e-3).abs() < 0.02e-3, "{worst}");
}
