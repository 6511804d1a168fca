//! Reference runs: the time loop to `t_end` and the records of a [`History`].

use super::cache::history_key;
use super::config::{InitialVelocity, UlFemConfig, UlFemError};
use super::solver::{UlEnergies, UlFem};
use serde::{Deserialize, Serialize};

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

pub(super) fn validate_run(
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
            .map(|i| fem.positions()[i] - fem.reference_position(i))
            .collect(),
        final_stress: (0..config.elements)
            .map(|e| fem.element_stress(e))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::ulfem::fixtures::{name_of, small};
    use crate::studies::ulfem::UlMass;

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
}
