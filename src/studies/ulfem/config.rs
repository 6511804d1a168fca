//! The problem of the 1D solver: its configuration, boundary conditions, initial
//! velocity, and errors.

use serde::{Deserialize, Serialize};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::ulfem::fixtures::{name_of, small};
    use crate::studies::ulfem::UlFem;

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
}
