//! The seeds' benchmarks B2–B5 reproduced as studies: each runs the built-in scenes
//! at the resolutions of the seeds and returns the tables and figures of
//! `docs/results.md` (`mpm-cli reproduce NAME --out docs/figures`).
//!
//! Every study has a [`Effort::Quick`] form (coarse, short; the test suite pins it
//! with snapshots) and the [`Effort::Full`] form of the write-up. Nothing is tuned
//! to a printed number: the parameters are the seeds' where they give them, and
//! where they do not the choice is stated in the scene file or here.
//!
//! | study | scenes | what is measured |
//! |---|---|---|
//! | `b2` | `vibrating-bar-thesis`, `vibrating-bar` | E_u and orders against thesis Tables 4.2–4.3 |
//! | `b3` | `bar-large` | energies against the 1D UL-FEM reference, 1 % deviation time, decay at t = 20, small-amplitude check |
//! | `b4` | `axis-aligned` | RMS error (paper eq. (47)) in h and in particles per element; grid crossing |
//! | `b5b` | `column-large` | stability, condition, E_u and mid-height error against UL-FEM, σ_yy roughness, per mass strategy and grid |
//! | `b5c` | `column-damped` | σ_yy against the exact equilibrium, lumped and partially lumped |

use crate::output::chart::{LinePlot, Scale};
use crate::scene::Scene;
use crate::simulation::{self, Outcome, RunError};
use std::path::Path;

mod b2;
mod b3;
mod b4;
mod b5;

pub use b5::sigma_yy_roughness;

/// How much to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effort {
    /// Coarse grids and short runs, for tests (seconds).
    Quick,
    /// The resolutions of the write-up (minutes).
    Full,
}

/// A cell of a [`Table`]: the text shown, and the number behind it when the cell
/// shows one (unrounded).
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// As shown in the markdown table (`3.71e-4`, `ps`, `-`).
    pub text: String,
    /// The value the text rounds, when it is a computed number.
    pub value: Option<f64>,
}

impl Cell {
    /// A number shown as `text`.
    pub fn number(value: f64, text: String) -> Cell {
        Cell {
            text,
            value: Some(value),
        }
    }

    /// The cell as a JSON value: the unrounded number of a number cell (`null` if
    /// not finite); for a text cell, `null` for `-`, a boolean for `true`/`false`,
    /// a number for a text that is one (`42`, `4.5`), else the text.
    pub fn json(&self) -> serde_json::Value {
        use serde_json::Value;
        if let Some(v) = self.value {
            return serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number);
        }
        match self.text.as_str() {
            "-" => Value::Null,
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            t => {
                if let Ok(i) = t.parse::<i64>() {
                    Value::from(i)
                } else if let Some(n) = t.parse::<f64>().ok().and_then(serde_json::Number::from_f64)
                {
                    Value::Number(n)
                } else {
                    Value::String(t.to_string())
                }
            }
        }
    }
}

impl From<String> for Cell {
    fn from(text: String) -> Cell {
        Cell { text, value: None }
    }
}

impl From<&str> for Cell {
    fn from(text: &str) -> Cell {
        Cell::from(text.to_string())
    }
}

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.text)
    }
}

/// A row of cells from strings and [`Cell`]s.
macro_rules! row {
    ($($cell:expr),* $(,)?) => {
        vec![$($crate::studies::reproduction::Cell::from($cell)),*]
    };
}
use row;

/// A table of results.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Caption.
    pub title: String,
    /// Column names.
    pub columns: Vec<&'static str>,
    /// Rows of cells.
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    /// The table as GitHub markdown.
    pub fn markdown(&self) -> String {
        let mut out = format!("**{}**\n\n| {} |\n|", self.title, self.columns.join(" | "));
        out += &"---|".repeat(self.columns.len());
        out.push('\n');
        for row in &self.rows {
            let cells: Vec<&str> = row.iter().map(|c| c.text.as_str()).collect();
            out += &format!("| {} |\n", cells.join(" | "));
        }
        out
    }
}

/// A figure: the file name it is written to and the plot.
pub struct Figure {
    /// File name (SVG).
    pub file: String,
    /// The plot.
    pub plot: LinePlot,
}

/// What a study found.
pub struct Report {
    /// Benchmark id (`b3`).
    pub benchmark: &'static str,
    /// Tables.
    pub tables: Vec<Table>,
    /// Figures.
    pub figures: Vec<Figure>,
    /// Measured findings, one sentence each.
    pub findings: Vec<String>,
    /// The runs of the study and those of them that failed or are unstable
    /// (`mpm-cli reproduce --strict` exits with status 1 when any did).
    pub runs: Tally,
}

/// How many runs a study made and how many of them failed or are unstable (a
/// failed run is also unstable, so `failed` counts the runs whose verdict is not
/// stable). The study's tables show which ones.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tally {
    /// Runs made.
    pub total: usize,
    /// Runs that failed numerically or whose verdict is unstable.
    pub failed: usize,
}

impl Tally {
    /// Counts the run of `summary`.
    fn note(&mut self, summary: &simulation::Summary) {
        self.total += 1;
        if !summary.stable || summary.failure.is_some() {
            self.failed += 1;
        }
    }

    /// [`simulation::run`] with the seeds' time stepping ([`seeds_stepping`]),
    /// counted.
    fn run(
        &mut self,
        scene: &Scene,
        on_step: &mut dyn FnMut(&crate::driver::StepReport),
    ) -> Result<simulation::Summary, RunError> {
        let summary = simulation::run(&seeds_stepping(scene), on_step)?;
        self.note(&summary);
        Ok(summary)
    }

    /// [`simulation::run_2d`] with the seeds' time stepping ([`seeds_stepping`]),
    /// counted.
    fn run_2d(
        &mut self,
        scene: &Scene,
        on_step: &mut dyn FnMut(&crate::driver::StepReport),
    ) -> Result<Outcome<2>, RunError> {
        let outcome = simulation::run_2d(&seeds_stepping(scene), on_step)?;
        self.note(&outcome.summary);
        Ok(outcome)
    }
}

/// `scene` with every step whole (`time.watch = false`): the reproductions take the
/// seeds' steps, and where a seed's step turns unstable as the bodies move, that is
/// part of what they report.
fn seeds_stepping(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.time.watch = false;
    s
}

/// The studies, in order.
pub const STUDIES: [&str; 5] = ["b2", "b3", "b4", "b5b", "b5c"];

/// Runs study `name` (one of [`STUDIES`]). The UL-FEM references of `b3` and `b5b`
/// are read from or stored in the cache directory `cache` (`None`: no cache, they are
/// computed; see [`cached_reference_history`](crate::studies::ulfem::cached_reference_history)).
pub fn reproduce(name: &str, effort: Effort, cache: Option<&Path>) -> Result<Report, RunError> {
    match name {
        "b2" => b2::b2(effort),
        "b3" => b3::b3(effort, cache),
        "b4" => b4::b4(effort),
        "b5b" => b5::b5b(effort, cache),
        "b5c" => b5::b5c(effort),
        other => Err(RunError::UnknownName(format!(
            "unknown study `{other}` (known: {})",
            STUDIES.join(", ")
        ))),
    }
}

/// Three significant digits (`-` when not finite), with the value behind them.
pub fn sci(x: f64) -> Cell {
    if x.is_finite() {
        Cell::number(x, format!("{x:.2e}"))
    } else {
        "-".into()
    }
}

fn opt(x: Option<f64>) -> Cell {
    x.map_or_else(|| "-".into(), sci)
}

/// A plot with logarithmic axes (errors against sizes or particle counts).
fn log_log(title: impl Into<String>, x: &str, y: &str) -> LinePlot {
    LinePlot::new(title, x, y)
        .x_scale(Scale::Log10)
        .y_scale(Scale::Log10)
}

fn builtin(name: &str) -> Result<Scene, RunError> {
    Scene::builtin(name).map_err(RunError::UnknownName)
}

fn setup<T>(r: Result<T, crate::scene::SceneError>) -> Result<T, RunError> {
    r.map_err(RunError::Scene)
}

fn order(e0: f64, e1: f64, h0: f64, h1: f64) -> Cell {
    let p = (e0 / e1).ln() / (h0 / h1).ln();
    Cell::number(p, format!("{p:.2}"))
}

/// One run with its energy history `(t, kinetic, strain, total)` every `every` steps
/// and its condition history `(t, estimate)`.
struct Run {
    outcome: Outcome<2>,
    energy: Vec<(f64, f64, f64, f64)>,
    condition: Vec<(f64, f64)>,
}

fn run_2d(tally: &mut Tally, scene: &Scene, every: usize) -> Result<Run, RunError> {
    let (mut energy, mut condition) = (Vec::new(), Vec::new());
    let outcome = tally.run_2d(scene, &mut |r| {
        if r.step % every.max(1) == 0 {
            energy.push((r.time, r.kinetic, r.strain, r.total_energy()));
        }
        if let Some(c) = r.condition {
            condition.push((r.time, c));
        }
    })?;
    Ok(Run {
        outcome,
        energy,
        condition,
    })
}
