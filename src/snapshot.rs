//! Regression snapshots of a run: one call turns a scene's run into a value that a
//! snapshot test (the `insta` crate) can pin, the same on every machine and for
//! any thread count.
//!
//! [`snapshot`] runs the scene and keeps what a change to the method would move: the
//! summary (error, energy drift and growth, verdict, what the mass strategy did),
//! the energies and every tracked particle's displacement and velocity at a few
//! evenly spaced steps. Every float is rounded to [`SnapshotOptions::digits`]
//! significant digits, and a vector component below [`ROUND_OFF`] of its vector's
//! size (round-off, such as the vertical displacement of a bar that only
//! stretches) is written as 0, so that the last bits of a different compiler or
//! processor do not show. Wall times are left out. The run itself is bit-for-bit
//! deterministic (see [`crate::threads`]).
//!
//! The recipe, in a test of your own (`tests/my_scene.rs`, with `insta` as a
//! dev-dependency with its `json` feature), is the test `tests/snapshot_recipe.rs`
//! of this repository and is shown in `docs/tutorial.md` ("Pin your scene"):
//!
//! ```no_run
//! use psmpm::scene::Scene;
//! use psmpm::snapshot::{snapshot, SnapshotOptions};
//!
//! let path = "docs/examples/settle.toml";
//! let text = std::fs::read_to_string(path).unwrap();
//! let scene = Scene::from_toml(&text, path).unwrap();
//! let value = snapshot(&scene, &SnapshotOptions::default()).unwrap();
//! // insta::assert_json_snapshot!("settle", value);
//! # let _ = value;
//! ```

use crate::scene::Scene;
use crate::simulation::{self, RunError, Summary, Tracked};
use serde_json::{json, Map, Value};

/// A vector component below this fraction of its vector's largest component is
/// round-off and is written as 0.
pub const ROUND_OFF: f64 = 1e-10;

/// What [`snapshot`] keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SnapshotOptions {
    /// Significant digits of every float (1 to 15).
    pub digits: usize,
    /// Times at which the energies and tracked particles are kept: the initial
    /// state, the last step and evenly spaced steps between (at least 2).
    pub samples: usize,
}

impl Default for SnapshotOptions {
    /// Four significant digits, five times.
    fn default() -> Self {
        SnapshotOptions {
            digits: 4,
            samples: 5,
        }
    }
}

/// Why a snapshot cannot be taken.
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    /// Options out of range.
    #[error("snapshot options: {0}")]
    Options(String),
    /// The run could not be set up.
    #[error(transparent)]
    Run(#[from] RunError),
}

/// Runs `scene` and returns its snapshot (see the [module docs](self)): an object
/// with the summary's fields (without wall times), `energies` (time, kinetic, strain,
/// potential, work and total at the sampled steps) and `tracked` (per tracked
/// particle: index, initial position, and time, displacement and velocity at the
/// sampled steps). A run that fails numerically gives a snapshot too: its summary
/// holds the failure, and the samples stop at the last step taken.
pub fn snapshot(scene: &Scene, options: &SnapshotOptions) -> Result<Value, SnapshotError> {
    if !(1..=15).contains(&options.digits) {
        return Err(SnapshotError::Options(format!(
            "digits = {} is not in 1..=15",
            options.digits
        )));
    }
    if options.samples < 2 {
        return Err(SnapshotError::Options(format!(
            "samples = {} is below 2 (the start and the end)",
            options.samples
        )));
    }
    // Every step's energies are seen; the sampled ones are chosen at the end, when
    // the number of steps taken is known (Courant-number scenes know it only then).
    let mut energies: Vec<[f64; 6]> = Vec::new();
    let mut record = |r: &crate::driver::StepReport| energies.push(r.energy_row());
    let mut observer = |r: &crate::driver::StepReport, _: simulation::ParticlesRef<'_>| record(r);
    let (summary, tracked) = if scene.dim == 1 {
        let o = simulation::observe_1d(scene, &mut observer)?;
        (o.summary, o.tracked)
    } else {
        let o = simulation::observe_2d(scene, &mut observer)?;
        (o.summary, o.tracked)
    };
    let digits = options.digits;
    let picks = sample_indices(energies.len(), options.samples);
    let energies: Vec<Value> = picks
        .iter()
        .map(|&i| {
            let [time, kinetic, strain, potential, work, total] = energies[i];
            json!({
                "time": round(time, digits),
                "kinetic": round(kinetic, digits),
                "strain": round(strain, digits),
                "potential": round(potential, digits),
                "work": round(work, digits),
                "total": round(total, digits),
            })
        })
        .collect();
    let tracked: Vec<Value> = tracked
        .iter()
        .map(|t| tracked_value(t, scene.dim, options))
        .collect();
    let mut out = summary_value(&summary, digits);
    out.insert("energies".into(), Value::Array(energies));
    out.insert("tracked".into(), Value::Array(tracked));
    Ok(Value::Object(out))
}

/// `samples` indices spread evenly over `0..n` with the first and the last.
fn sample_indices(n: usize, samples: usize) -> Vec<usize> {
    if n == 0 {
        return Vec::new();
    }
    let k = samples.min(n);
    if k == 1 {
        return vec![n - 1];
    }
    let mut picks: Vec<usize> = (0..k).map(|j| j * (n - 1) / (k - 1)).collect();
    picks.dedup();
    picks
}

/// The summary's fields, wall times left out, floats rounded.
fn summary_value(summary: &Summary, digits: usize) -> Map<String, Value> {
    let mut map = match serde_json::to_value(summary) {
        Ok(Value::Object(map)) => map,
        _ => Map::new(),
    };
    map.remove("seconds");
    map.into_iter()
        .map(|(k, v)| (k, rounded(v, digits)))
        .collect()
}

/// One tracked particle at the sampled steps (the initial state is not in its
/// history: its first entry is step 1).
fn tracked_value(t: &Tracked, dim: usize, options: &SnapshotOptions) -> Value {
    let digits = options.digits;
    let picks = sample_indices(t.time.len(), options.samples);
    let vector = |v: [f64; 2]| vector(&v[..dim], digits);
    json!({
        "particle": t.particle,
        "x0": vector(t.x0),
        "time": picks.iter().map(|&i| round(t.time[i], digits)).collect::<Vec<_>>(),
        "displacement": picks.iter().map(|&i| vector(t.displacement[i])).collect::<Vec<_>>(),
        "velocity": picks.iter().map(|&i| vector(t.velocity[i])).collect::<Vec<_>>(),
    })
}

/// `x` rounded to `digits` significant digits (non-finite values as `null`).
pub fn round(x: f64, digits: usize) -> Value {
    if !x.is_finite() {
        return Value::Null;
    }
    if x == 0.0 {
        return json!(0.0);
    }
    let text = format!("{x:.*e}", digits.clamp(1, 15) - 1);
    json!(text.parse::<f64>().unwrap_or(x))
}

/// A vector with each component rounded, and components below [`ROUND_OFF`] of the
/// largest written as 0.
pub fn vector(v: &[f64], digits: usize) -> Value {
    let size = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    Value::Array(
        v.iter()
            .map(|&x| {
                if x.abs() <= ROUND_OFF * size {
                    json!(0.0)
                } else {
                    round(x, digits)
                }
            })
            .collect(),
    )
}

/// Every float in `value` rounded to `digits` significant digits (integers,
/// strings and booleans unchanged): for snapshot values of one's own.
pub fn rounded(value: Value, digits: usize) -> Value {
    match value {
        Value::Number(n) if n.is_f64() => round(n.as_f64().unwrap_or(f64::NAN), digits),
        Value::Array(items) => {
            Value::Array(items.into_iter().map(|v| rounded(v, digits)).collect())
        }
        Value::Object(map) => Value::Object(
            map.into_iter()
                .map(|(k, v)| (k, rounded(v, digits)))
                .collect(),
        ),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_keeps_significant_digits_and_drops_round_off() {
        assert_eq!(round(0.123456789, 4), json!(0.1235));
        assert_eq!(round(-98765.4321, 3), json!(-98800.0));
        assert_eq!(round(1.0e-17, 4), json!(1.0e-17));
        assert_eq!(round(f64::NAN, 4), Value::Null);
        assert_eq!(vector(&[0.5, -7.9e-18], 4), json!([0.5, 0.0]));
        assert_eq!(vector(&[0.0, 0.0], 4), json!([0.0, 0.0]));
        assert_eq!(
            rounded(json!({"a": [1.23456, 2], "b": "x"}), 2),
            json!({"a": [1.2, 2], "b": "x"})
        );
    }

    #[test]
    fn samples_include_both_ends() {
        assert_eq!(sample_indices(101, 5), [0, 25, 50, 75, 100]);
        assert_eq!(sample_indices(3, 5), [0, 1, 2]);
        assert_eq!(sample_indices(0, 5), Vec::<usize>::new());
    }

    #[test]
    fn a_snapshot_has_no_wall_time_and_is_the_same_twice() {
        let mut scene = Scene::builtin("vibrating-bar-1d").unwrap();
        scene.time.t_end = 0.05;
        scene.output.tracked = vec![vec![12.5]];
        let a = snapshot(&scene, &SnapshotOptions::default()).unwrap();
        let b = snapshot(&scene, &SnapshotOptions::default()).unwrap();
        assert_eq!(a, b);
        assert!(a.get("seconds").is_none());
        assert_eq!(a["energies"].as_array().unwrap().len(), 5);
        assert_eq!(a["energies"][0]["time"], json!(0.0));
        assert_eq!(a["energies"][4]["time"], json!(0.05));
        assert_eq!(a["tracked"][0]["displacement"].as_array().unwrap().len(), 5);
        let bad = SnapshotOptions {
            digits: 0,
            samples: 5,
        };
        assert!(matches!(
            snapshot(&scene, &bad),
            Err(SnapshotError::Options(_))
        ));
    }
}
