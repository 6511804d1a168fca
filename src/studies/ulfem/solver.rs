//! The solver: the mesh of linear elements, the mass (lumped or consistent, factored
//! once), the time step of eq. (7), sampling in the reference coordinate, and the
//! energies of eq. (8).

use super::config::{End, InitialVelocity, UlFemConfig, UlFemError, UlMass};
use serde::{Deserialize, Serialize};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::ulfem::fixtures::small;

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
}
