//! `mpm-cli run --out DIR`: the files of a run.
//!
//! - `diagnostics.csv`: one row per step (not the initial state): `step, time,
//!   kinetic, strain, potential, work, total, mass, momentum_x, momentum_y,
//!   max_speed, active, lumped_rows, deactivated, condition` (the values of
//!   `--format json`; floats in Rust's shortest round-trip `{:e}` form, integers as
//!   integers, `condition` empty unless `--condition`).
//! - `summary.json`: the summary of `--format json`, pretty-printed (with
//!   `"interrupted": true` when SIGINT/SIGTERM or a closed stdout stopped the run;
//!   the last frame and `particles.pvd` are written then too).
//! - `particles_NNNNN.vtu` and `particles.pvd`: particle frames (position,
//!   velocity, displacement, stress, volume, mass; see `psmpm::output::vtk`) of the
//!   initial state, every `--out-every` steps and the last step (on a numerical
//!   failure, the particles as the failed step left them, at the time of the last
//!   completed step); the `.pvd` collection plays them back in ParaView.
//! - `mesh.vtu`: the triangulation of a 2D scene (1D scenes have no mesh file).
//! - `tracked.csv` and `tracked.svg` when the scene tracks particles
//!   (`output.tracked`): `time, particle, u_x, u_y, v_x, v_y` and, with a reference
//!   solution, `u_exact_x, u_exact_y`, one row per step and tracked particle; the
//!   plot shows the displacement against time (computed as markers, or as a line
//!   without a reference; the reference as a line).
//! - `energy.svg`: kinetic, strain, potential and total energy against time.

use crate::error::CliError;
use psmpm::driver::StepReport;
use psmpm::output::chart::{line_plot, LinePlot, Series};
use psmpm::output::dir::{write_file, OutputDir, OutputError};
use psmpm::scene::Scene;
use psmpm::simulation::{self, ParticlesRef, Summary, Tracked};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Columns of `diagnostics.csv`.
pub const DIAGNOSTICS_COLUMNS: [&str; 15] = [
    "step",
    "time",
    "kinetic",
    "strain",
    "potential",
    "work",
    "total",
    "mass",
    "momentum_x",
    "momentum_y",
    "max_speed",
    "active",
    "lumped_rows",
    "deactivated",
    "condition",
];

/// File names.
pub const DIAGNOSTICS_FILE: &str = "diagnostics.csv";
/// The summary.
pub const SUMMARY_FILE: &str = "summary.json";
/// Tracked particles, data.
pub const TRACKED_CSV: &str = "tracked.csv";
/// Tracked particles, plot.
pub const TRACKED_SVG: &str = "tracked.svg";
/// Energies, plot.
pub const ENERGY_SVG: &str = "energy.svg";

/// Frames per run when `--out-every` is not given (plus the initial state).
pub const DEFAULT_FRAMES: usize = 50;

/// Most points per curve in a plot (longer series are thinned evenly).
const MAX_PLOT_POINTS: usize = 2000;
/// Most markers per computed curve in `tracked.svg`.
const MAX_MARKERS: usize = 120;

fn output_error(e: OutputError) -> CliError {
    CliError::Input(e.to_string())
}

fn write_error(path: &Path, e: std::io::Error) -> CliError {
    output_error(OutputError::Write {
        path: path.to_path_buf(),
        source: e,
    })
}

/// Writes the files of one run while it runs ([`Recorder::observe`]) and at its end
/// ([`Recorder::finish`]).
pub struct Recorder {
    dir: OutputDir,
    scene: String,
    dim: usize,
    /// `--out-every`, or `None` for the default (set at step 1).
    every: Option<usize>,
    /// End time and steps of the run (the steps are known at step 1).
    t_end: f64,
    total: usize,
    diagnostics: Option<BufWriter<File>>,
    diagnostics_path: PathBuf,
    /// `(time, kinetic, strain, potential, total)` of the initial state and every step.
    energy: Vec<[f64; 5]>,
    /// Step of the last frame written, and the last step seen.
    last_frame: Option<usize>,
    last_step: usize,
    mesh: bool,
    /// The first write error; nothing more is written after it.
    error: Option<CliError>,
}

impl Recorder {
    /// Creates `dir`, writes the mesh (2D) and the header of `diagnostics.csv`, so
    /// that a directory that cannot be written is reported before the run.
    pub fn create(dir: &Path, every: Option<usize>, scene: &Scene) -> Result<Self, CliError> {
        let out = OutputDir::create(dir, 0).map_err(output_error)?;
        let mesh = scene.dim == 2;
        if mesh {
            let triangulation =
                simulation::triangulation(scene).map_err(|e| CliError::Input(e.to_string()))?;
            out.write_mesh(&triangulation, None).map_err(output_error)?;
        }
        let path = out.file(DIAGNOSTICS_FILE);
        let mut w = BufWriter::new(File::create(&path).map_err(|e| write_error(&path, e))?);
        writeln!(w, "{}", DIAGNOSTICS_COLUMNS.join(",")).map_err(|e| write_error(&path, e))?;
        Ok(Recorder {
            dir: out,
            scene: scene.name.clone(),
            dim: scene.dim,
            every,
            t_end: scene.time.t_end,
            total: scene.steps().max(1),
            diagnostics: Some(w),
            diagnostics_path: path,
            energy: Vec::new(),
            last_frame: None,
            last_step: 0,
            mesh,
            error: None,
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Records the initial state (`r.step == 0`) or a step.
    pub fn observe(&mut self, r: &StepReport, particles: ParticlesRef<'_>) {
        if self.error.is_some() {
            return;
        }
        if let Err(e) = self.record(r, particles) {
            self.error = Some(e);
        }
    }

    fn record(&mut self, r: &StepReport, particles: ParticlesRef<'_>) -> Result<(), CliError> {
        self.energy
            .push([r.time, r.kinetic, r.strain, r.potential, r.total_energy()]);
        if r.step == 1 && r.time > 0.0 {
            // The library's step count: t_end / dt, rounded (dt = the first step's time).
            // (The scene's own count is 1 for Courant-number scenes.)
            self.total = steps_from_dt(self.t_end, r.time);
            let limit = psmpm::scene::limits::MAX_FRAMES;
            if let Some(n) = self.every.filter(|&n| n > 0) {
                let frames = self.total / n + 2;
                if frames > limit {
                    return Err(CliError::Input(format!(
                        "--out-every {n}: {} steps give {frames} particle frames, above the limit of {limit}",
                        self.total
                    )));
                }
            }
        }
        if r.step > 0 {
            self.last_step = r.step;
            self.diagnostics_row(r)?;
        }
        let every = self.every();
        let due = r.step == 0 || r.step == self.total || (every > 0 && r.step % every == 0);
        if due {
            self.frame(r.step, r.time, particles)?;
        }
        Ok(())
    }

    fn every(&self) -> usize {
        self.every
            .unwrap_or_else(|| self.total.div_ceil(DEFAULT_FRAMES).max(1))
    }

    fn diagnostics_row(&mut self, r: &StepReport) -> Result<(), CliError> {
        let path = &self.diagnostics_path;
        let Some(w) = self.diagnostics.as_mut() else {
            return Ok(());
        };
        let condition = r.condition.map_or_else(String::new, |c| format!("{c:e}"));
        writeln!(
            w,
            "{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{}",
            r.step,
            r.time,
            r.kinetic,
            r.strain,
            r.potential,
            r.work,
            r.total_energy(),
            r.mass,
            r.momentum[0],
            r.momentum[1],
            r.max_speed,
            r.mass_report.active,
            r.mass_report.lumped_rows,
            r.mass_report.deactivated,
            condition
        )
        .map_err(|e| write_error(path, e))
    }

    fn frame(
        &mut self,
        step: usize,
        time: f64,
        particles: ParticlesRef<'_>,
    ) -> Result<(), CliError> {
        match particles {
            ParticlesRef::One(p) => self.dir.write_particles(time, p),
            ParticlesRef::Two(p) => self.dir.write_particles(time, p),
        }
        .map_err(output_error)?;
        self.last_frame = Some(step);
        Ok(())
    }

    /// Writes what is left: the last frame after a numerical failure (`last` are the
    /// particles at the end of the run), `particles.pvd`, `summary.json`, the
    /// tracked particles and the plots. Returns the names of the files written.
    pub fn finish(
        mut self,
        summary: &Summary,
        tracked: &[Tracked],
        last: ParticlesRef<'_>,
    ) -> Result<Vec<String>, CliError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let path = self.dir.file(DIAGNOSTICS_FILE);
        if let Some(w) = self.diagnostics.take() {
            w.into_inner()
                .map_err(|e| write_error(&path, e.into_error()))?
                .sync_all()
                .map_err(|e| write_error(&path, e))?;
        }
        if self.last_frame != Some(self.last_step) {
            self.frame(self.last_step, summary.t_end, last)?;
        }
        let mut files = vec![DIAGNOSTICS_FILE.to_string(), SUMMARY_FILE.to_string()];
        let path = self.dir.file(SUMMARY_FILE);
        let json = serde_json::to_string_pretty(&crate::run::summary_json(summary))
            .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"));
        write_file(&path, |w| writeln!(w, "{json}")).map_err(output_error)?;
        if self.mesh {
            files.push(OutputDir::MESH_FILE.to_string());
        }
        self.dir.finish().map_err(output_error)?;
        files.push(format!(
            "{} ({} frames)",
            OutputDir::PVD_FILE,
            self.dir.frames().len()
        ));
        if !tracked.is_empty() {
            self.write_tracked_csv(tracked)?;
            files.push(TRACKED_CSV.to_string());
            if self.plot(TRACKED_SVG, self.tracked_plot(tracked))? {
                files.push(TRACKED_SVG.to_string());
            }
        }
        if self.plot(ENERGY_SVG, self.energy_plot())? {
            files.push(ENERGY_SVG.to_string());
        }
        Ok(files)
    }

    fn write_tracked_csv(&self, tracked: &[Tracked]) -> Result<(), CliError> {
        let exact = tracked.iter().all(|t| {
            !t.exact_displacement.is_empty() && t.exact_displacement.len() == t.time.len()
        });
        let path = self.dir.file(TRACKED_CSV);
        let steps = tracked.iter().map(|t| t.time.len()).min().unwrap_or(0);
        write_file(&path, |w| {
            w.write_all(b"time,particle,u_x,u_y,v_x,v_y")?;
            if exact {
                w.write_all(b",u_exact_x,u_exact_y")?;
            }
            w.write_all(b"\n")?;
            for i in 0..steps {
                for t in tracked {
                    let (u, v) = (t.displacement[i], t.velocity[i]);
                    write!(
                        w,
                        "{:e},{},{:e},{:e},{:e},{:e}",
                        t.time[i], t.particle, u[0], u[1], v[0], v[1]
                    )?;
                    if exact {
                        let e = t.exact_displacement[i];
                        write!(w, ",{:e},{:e}", e[0], e[1])?;
                    }
                    w.write_all(b"\n")?;
                }
            }
            Ok(())
        })
        .map_err(output_error)
    }

    /// The displacement of the tracked particles against time: for each particle,
    /// the components that move (x only in 1D), computed and reference.
    fn tracked_plot(&self, tracked: &[Tracked]) -> LinePlot {
        let mut plot = LinePlot::new(
            format!("{}: tracked particles", self.scene),
            "time (s)",
            "displacement (m)",
        );
        let axis = ["x", "y"];
        for t in tracked {
            let has_exact =
                !t.exact_displacement.is_empty() && t.exact_displacement.len() == t.time.len();
            let amplitude = |c: usize| {
                t.displacement
                    .iter()
                    .chain(&t.exact_displacement)
                    .map(|u| u[c].abs())
                    .filter(|a| a.is_finite())
                    .fold(0.0, f64::max)
            };
            let amplitudes = [amplitude(0), amplitude(1)];
            let largest = amplitudes[0].max(amplitudes[1]);
            let components: Vec<usize> = (0..self.dim)
                .filter(|&c| amplitudes[c] > 1e-3 * largest)
                .collect();
            let components = if components.is_empty() {
                vec![self.dim - 1]
            } else {
                components
            };
            for c in components {
                let name = format!("particle {} u_{}", t.particle, axis[c]);
                let computed = t.time.iter().zip(&t.displacement).map(|(&s, u)| (s, u[c]));
                if has_exact {
                    plot = plot.with_series(Series::markers(
                        format!("{name} (MPM)"),
                        thin(computed.collect(), MAX_MARKERS),
                    ));
                    let exact = t
                        .time
                        .iter()
                        .zip(&t.exact_displacement)
                        .map(|(&s, u)| (s, u[c]));
                    plot = plot.with_series(Series::line(
                        format!("{name} (exact)"),
                        thin(exact.collect(), MAX_PLOT_POINTS),
                    ));
                } else {
                    plot = plot.with_series(Series::line(
                        format!("{name} (MPM)"),
                        thin(computed.collect(), MAX_PLOT_POINTS),
                    ));
                }
            }
        }
        plot
    }

    fn energy_plot(&self) -> LinePlot {
        let (per, unit) = if self.dim == 2 {
            ("thickness", "energy (J/m)")
        } else {
            ("cross-section", "energy (J/m²)")
        };
        let mut plot = LinePlot::new(
            format!("{}: energy (per unit {per})", self.scene),
            "time (s)",
            unit,
        );
        for (k, name) in ["kinetic", "strain", "potential", "total"]
            .iter()
            .enumerate()
        {
            let points = self.energy.iter().map(|e| (e[0], e[k + 1])).collect();
            plot = plot.with_series(Series::line(*name, thin(points, MAX_PLOT_POINTS)));
        }
        plot
    }

    /// Draws `plot` into `file` without its non-finite points (an unstable run) and
    /// empty series; `false` when nothing is left to draw.
    fn plot(&self, file: &str, mut plot: LinePlot) -> Result<bool, CliError> {
        for s in &mut plot.series {
            s.points.retain(|(x, y)| x.is_finite() && y.is_finite());
        }
        plot.series.retain(|s| !s.points.is_empty());
        if plot.series.is_empty() {
            return Ok(false);
        }
        let path = self.dir.file(file);
        line_plot(&path, &plot).map_err(|e| match e {
            psmpm::output::chart::PlotError::Io { .. } => CliError::Input(e.to_string()),
            other => CliError::Input(format!("{}: {other}", path.display())),
        })?;
        Ok(true)
    }
}

/// `t_end / dt` rounded, at least 1 (the library's step count).
pub fn steps_from_dt(t_end: f64, dt: f64) -> usize {
    (t_end / dt).round().max(1.0) as usize
}

/// At most about `max` of `points`, evenly spaced, always with the last one.
fn thin(points: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    let n = points.len();
    if n <= max || max < 2 {
        return points;
    }
    let stride = n.div_ceil(max - 1);
    let mut out: Vec<(f64, f64)> = points.iter().step_by(stride).copied().collect();
    if (n - 1) % stride != 0 {
        out.push(points[n - 1]);
    }
    out
}

/// `DIR: files` for the one line `run` prints.
pub fn files_line(dir: &Path, files: &[String]) -> String {
    format!("output written to {}: {}", dir.display(), files.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_the_ends_and_bounds_the_count() {
        let points: Vec<(f64, f64)> = (0..5001).map(|i| (i as f64, 0.0)).collect();
        let t = thin(points.clone(), 120);
        assert!(t.len() <= 121, "{}", t.len());
        assert_eq!(t.first(), points.first());
        assert_eq!(t.last(), points.last());
        assert_eq!(thin(points[..10].to_vec(), 120).len(), 10);
        assert_eq!(steps_from_dt(5.0, 1e-3), 5000);
        assert_eq!(steps_from_dt(1e-9, 1.0), 1);
    }
}
