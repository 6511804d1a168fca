//! `mpm-cli run --out DIR`: the files of a run.
//!
//! `DIR` must be new, empty, or hold only the files of an earlier run (the names
//! below); with `--overwrite` those files are removed before the run starts, so no
//! stale frame of a longer earlier run is left. A directory holding anything else
//! (a file of another name, a sub-directory) is refused even with `--overwrite`:
//! the tool never removes a file it does not write, nor mixes a run with it.
//!
//! - `diagnostics.csv`: one row per step (not the initial state): `step, time,
//!   kinetic, strain, potential, work, total, total_centred, mass, momentum_x, momentum_y,
//!   max_speed, active, lumped_rows, deactivated, extended, worst_coverage,
//!   worst_function, worst_x, worst_y, condition, kinetic_motion, substeps,
//!   dt_critical` (the values of `--format json`; floats in Rust's shortest
//!   round-trip `{:e}` form, integers as integers, the `worst_*` columns empty when
//!   the mass strategy does not measure coverage, `worst_y` in 1D, `condition`
//!   unless `--condition`, `dt_critical` when the critical step was not estimated). All CSV files are written
//!   with the `csv` crate (RFC 4180 quoting where needed).
//! - `summary.json`: the summary of `--format json`, pretty-printed (with
//!   `"interrupted": true` when SIGINT/SIGTERM or a closed stdout stopped the run;
//!   the last frame and `particles.pvd` are written then too).
//! - `particles_NNNNN.vtu` and `particles.pvd`: particle frames (position,
//!   velocity, displacement, stress, volume, mass; see `psmpm::output::vtk`; binary
//!   zlib-compressed VTK XML unless `--vtu ascii`) of the
//!   initial state, every `--out-every` steps and the last step (on a numerical
//!   failure, the particles as the failed step left them, at the time of the last
//!   completed step); the `.pvd` collection plays them back in ParaView.
//! - `mesh.vtu`: the triangulation of a 2D scene (1D scenes have no mesh file).
//! - `tracked.csv` and `tracked.svg` when the scene tracks particles
//!   (`output.tracked`): `time, particle, u_x, u_y, v_x, v_y` and, with a reference
//!   solution that is a motion (not `column-equilibrium`, a settled state),
//!   `u_exact_x, u_exact_y, v_exact_x, v_exact_y`, one row per step and
//!   tracked particle; the plot shows the displacement against time (computed as
//!   markers, or as a line without a reference; the reference as a line) and below
//!   it the velocity in the same style, on the same time axis.
//! - `energy.svg`: kinetic, strain, potential and total energy against time, the
//!   work of the effects when they do some (`total = K + S + P − W`), and the
//!   time-centred total (`total_centred`), which does not swing with the step.
//! - `particles.svg`: the particles at the first frame, the step nearest half the
//!   run and the last step, coloured by `--picture FIELD` (default `displacement`,
//!   `|u|`) on one colour scale, over the mesh (2D); in 1D the field against the
//!   position, one curve per time.

use crate::error::CliError;
use psmpm::driver::StepReport;
use psmpm::output::chart::{stacked_line_plots, LinePlot, PlotError, Series};
use psmpm::output::dir::{is_frame, prepare_dir, write_file, OutputDir, OutputError};
use psmpm::output::particle_picture::{
    particle_plot, ParticleField, ParticleFrame, ParticlePicture,
};
use psmpm::output::vtk::VtuEncoding;
use psmpm::scene::Scene;
use psmpm::simulation::{self, ParticlesRef, Summary, Tracked};
use psmpm_basis::Vec2;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A row of `diagnostics.csv` (and of `run --format csv`): floats in Rust's
/// shortest round-trip `{:e}` form.
pub fn diagnostics_record(r: &StepReport) -> [String; 24] {
    let float = |x: f64| format!("{x:e}");
    let worst = r.mass_report.worst_coverage;
    let at = |k: usize| {
        r.worst_coverage_at
            .filter(|_| k < r.dim)
            .map_or_else(String::new, |x| float(x[k]))
    };
    [
        r.step.to_string(),
        float(r.time),
        float(r.kinetic),
        float(r.strain),
        float(r.potential),
        float(r.work),
        float(r.total_energy()),
        float(r.total_centred),
        float(r.mass),
        float(r.momentum()[0]),
        // (0 in 1D: the file has the same columns for every scene)
        float(r.momentum().get(1).copied().unwrap_or(0.0)),
        float(r.max_speed),
        r.mass_report.active.to_string(),
        r.mass_report.lumped_rows.to_string(),
        r.mass_report.deactivated.to_string(),
        r.mass_report.extended.to_string(),
        worst.map_or_else(String::new, |(_, c)| float(c)),
        worst.map_or_else(String::new, |(i, _)| i.to_string()),
        at(0),
        at(1),
        r.condition.map_or_else(String::new, float),
        float(r.kinetic_motion),
        r.substeps.to_string(),
        critical_step(r).map_or_else(String::new, float),
    ]
}

/// The critical time step a run knew at a step: the watch's latest estimate
/// while it watches, else the start's (`None` when neither was estimated).
pub fn critical_step(r: &StepReport) -> Option<f64> {
    r.dt_critical_latest.or(r.dt_critical)
}

/// Columns of `diagnostics.csv`.
pub const DIAGNOSTICS_COLUMNS: [&str; 24] = [
    "step",
    "time",
    "kinetic",
    "strain",
    "potential",
    "work",
    "total",
    "total_centred",
    "mass",
    "momentum_x",
    "momentum_y",
    "max_speed",
    "active",
    "lumped_rows",
    "deactivated",
    "extended",
    "worst_coverage",
    "worst_function",
    "worst_x",
    "worst_y",
    "condition",
    "kinetic_motion",
    "substeps",
    "dt_critical",
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
/// Particles at the first, middle and last frame, picture.
pub const PARTICLES_SVG: &str = "particles.svg";

/// Frames per run when `--out-every` is not given (plus the initial state).
pub const DEFAULT_FRAMES: usize = 50;

/// Most points per curve in a plot (longer series are thinned evenly).
const MAX_PLOT_POINTS: usize = 2000;
/// Most markers per computed curve in `tracked.svg`.
const MAX_MARKERS: usize = 120;

fn output_error(e: OutputError) -> CliError {
    CliError::Input(e.to_string())
}

/// Whether `name` is a file `run --out` writes (and so may remove with `--overwrite`).
pub fn is_output_file(name: &str) -> bool {
    is_frame(name)
        || [
            DIAGNOSTICS_FILE,
            SUMMARY_FILE,
            TRACKED_CSV,
            TRACKED_SVG,
            ENERGY_SVG,
            PARTICLES_SVG,
            OutputDir::MESH_FILE,
            OutputDir::PVD_FILE,
        ]
        .contains(&name)
}

/// Prepares the `--out DIR` of a command before it runs anything: `DIR` must be new,
/// empty, or hold only files the command writes (`owned`), which `overwrite`
/// (`--overwrite`) removes and which are refused without it; anything else in `DIR`
/// is refused. Returns whether `DIR` was made.
pub fn prepare_out(
    dir: &Path,
    overwrite: bool,
    owned: impl Fn(&str) -> bool,
) -> Result<bool, CliError> {
    // A name with a control character (a TAB typed into a shell) makes a
    // directory that listings show garbled: refused, as in a scene's `name`.
    if let Some(c) = dir.to_string_lossy().chars().find(|c| c.is_control()) {
        return Err(CliError::Input(format!(
            "--out: the path {:?} contains the control character {c:?} (U+{:04X}); use printable text",
            dir.to_string_lossy(),
            c as u32
        )));
    }
    let created = !dir.exists();
    prepare_dir(dir, overwrite, owned).map_err(|e| {
        let hint = match e {
            OutputError::NotEmpty { .. } => {
                "; pass --overwrite to replace them, or choose another --out"
            }
            OutputError::Foreign { .. } => {
                "; choose another --out (--overwrite only replaces the files this command writes)"
            }
            _ => "",
        };
        CliError::Input(format!("{e}{hint}"))
    })?;
    Ok(created)
}

/// How `run --out` writes its directory.
#[derive(Debug, Clone, Copy)]
pub struct OutOptions {
    /// `--out-every`, or `None` for the default.
    pub every: Option<usize>,
    /// `--overwrite`: replace the files of an earlier run.
    pub overwrite: bool,
    /// `--vtu`.
    pub encoding: VtuEncoding,
    /// `--picture`: the field of `particles.svg`.
    pub picture: ParticleField,
}

fn write_error(path: &Path, e: std::io::Error) -> CliError {
    output_error(OutputError::Write {
        path: path.to_path_buf(),
        source: e,
    })
}

/// Bytes per particle a [`Recorder`] holds at most: the two frames of the particle
/// picture (position, value and size: 32 B each) and, for binary `.vtu` frames, the
/// frame being written ([`psmpm::output::vtk::BINARY_BYTES_PER_PARTICLE`]).
pub fn bytes_per_particle(encoding: VtuEncoding) -> f64 {
    2.0 * 32.0
        + match encoding {
            VtuEncoding::Binary => psmpm::output::vtk::BINARY_BYTES_PER_PARTICLE,
            VtuEncoding::Ascii => 0.0,
        }
}

/// The frame of `particles` for `particles.svg` (1D positions on the x axis).
fn frame_of(particles: ParticlesRef<'_>, time: f64, field: ParticleField) -> ParticleFrame {
    match particles {
        ParticlesRef::Two(p) => ParticleFrame::of(p, time, field),
        ParticlesRef::One(p) => ParticleFrame {
            time,
            positions: p.x.iter().map(|x| Vec2::new(x[0], 0.0)).collect(),
            values: field.values(p),
            sizes: p.volume0.clone(),
        },
    }
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
    diagnostics: Option<csv::Writer<File>>,
    diagnostics_path: PathBuf,
    /// `(time, kinetic, strain, potential, total)` of the initial state and every step.
    energy: Vec<[f64; 6]>,
    /// `(time, total_centred)`: the time-centred total, at the start of each step.
    centred: Vec<(f64, f64)>,
    /// Step of the last frame written, and the last step seen.
    last_frame: Option<usize>,
    last_step: usize,
    mesh: bool,
    /// Mesh edges under the particles of `particles.svg` (2D).
    edges: Vec<[Vec2; 2]>,
    /// The field of `particles.svg`, and its first and middle frames.
    picture: ParticleField,
    pictured: Vec<ParticleFrame>,
    /// The first write error; nothing more is written after it.
    error: Option<CliError>,
    /// Whether [`Recorder::create`] made the directory.
    created_dir: bool,
}

impl Recorder {
    /// Prepares `dir` (see the module documentation), writes the mesh (2D) and the
    /// header of `diagnostics.csv`, so that a directory that cannot be written is
    /// reported before the run.
    pub fn create(dir: &Path, options: OutOptions, scene: &Scene) -> Result<Self, CliError> {
        let created_dir = prepare_out(dir, options.overwrite, is_output_file)?;
        let every = options.every;
        let out = OutputDir::create(dir, 0)
            .map_err(output_error)?
            .with_encoding(options.encoding);
        let mesh = scene.dim == 2;
        let mut edges = Vec::new();
        // A mesh that cannot be built is the run's set-up to report, with the scene's
        // file and line, after which the run discards this directory.
        if let (true, Ok(triangulation)) = (mesh, simulation::triangulation(scene)) {
            out.write_mesh(&triangulation, None).map_err(output_error)?;
            let v = triangulation.vertices();
            edges = triangulation
                .edges()
                .iter()
                .map(|e| [v[e.vertices[0]], v[e.vertices[1]]])
                .collect();
        }
        let path = out.file(DIAGNOSTICS_FILE);
        let mut w =
            csv::Writer::from_writer(File::create(&path).map_err(|e| write_error(&path, e))?);
        w.write_record(DIAGNOSTICS_COLUMNS)
            .map_err(|e| write_error(&path, e.into()))?;
        Ok(Recorder {
            dir: out,
            created_dir,
            scene: scene.name.clone(),
            dim: scene.dim,
            every,
            t_end: scene.time.t_end,
            total: scene.steps().max(1),
            diagnostics: Some(w),
            diagnostics_path: path,
            energy: Vec::new(),
            centred: Vec::new(),
            last_frame: None,
            last_step: 0,
            mesh,
            edges,
            picture: options.picture,
            pictured: Vec::new(),
            error: None,
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Removes what [`Recorder::create`] wrote (the mesh and the header of
    /// `diagnostics.csv`), and the directory if it made it: for a scene that turned
    /// out not to set up, which leaves no files ("nothing was run").
    pub fn discard(self) {
        drop(self.diagnostics);
        for name in [DIAGNOSTICS_FILE, "mesh.vtu"] {
            let _ = std::fs::remove_file(self.dir.file(name));
        }
        if self.created_dir {
            let _ = std::fs::remove_dir(self.dir.path());
        }
    }

    /// Records the initial state (`r.step == 0`) or a step.
    /// Whether writing has failed (the error is returned by [`finish`](Self::finish)).
    pub fn failed(&self) -> bool {
        self.error.is_some()
    }

    pub fn observe(&mut self, r: &StepReport, particles: ParticlesRef<'_>) {
        if self.error.is_some() {
            return;
        }
        if let Err(e) = self.record(r, particles) {
            self.error = Some(e);
        }
    }

    fn record(&mut self, r: &StepReport, particles: ParticlesRef<'_>) -> Result<(), CliError> {
        self.energy.push(r.energy_row());
        // A step's centred total is that of the state at its start.
        let at = if r.step == 0 { r.time } else { r.time - r.dt };
        self.centred.push((at, r.total_centred));
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
        if r.step == 0 || r.step == self.total / 2 {
            self.pictured
                .push(frame_of(particles, r.time, self.picture));
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
        let record = diagnostics_record(r);
        w.write_record(&record)
            .map_err(|e| write_error(path, e.into()))
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
        .map_err(|e| match &e {
            OutputError::Write { source, .. }
                if source.kind() == std::io::ErrorKind::OutOfMemory =>
            {
                CliError::Input(format!(
                    "step {step}: {e}: `--vtu ascii` writes the frames without holding them in memory; otherwise give fewer particles or run where more memory is allowed"
                ))
            }
            _ => output_error(e),
        })?;
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
        // The diagnostics so far are kept even when the run's output failed (whose
        // error comes first).
        let path = self.dir.file(DIAGNOSTICS_FILE);
        let flushed = self.diagnostics.take().map_or(Ok(()), |w| {
            w.into_inner()
                .map_err(|e| write_error(&path, std::io::Error::other(e.error().to_string())))?
                .sync_all()
                .map_err(|e| write_error(&path, e))
        });
        if let Some(e) = self.error.take() {
            // The diagnostics written in part are named too.
            return Err(match (e, flushed) {
                (CliError::Input(first), Err(CliError::Input(then))) => CliError::Input(format!(
                    "{first}; and {then}: `{DIAGNOSTICS_FILE}` holds the steps before it only in part"
                )),
                (e, _) => e,
            });
        }
        flushed?;
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
            let panels = vec![
                self.tracked_plot(tracked),
                self.tracked_velocity_plot(tracked),
            ];
            if self.plots(TRACKED_SVG, panels)? {
                files.push(TRACKED_SVG.to_string());
            }
        }
        if self.plots(ENERGY_SVG, vec![self.energy_plot()])? {
            files.push(ENERGY_SVG.to_string());
        }
        if self.last_step > 0 {
            self.pictured
                .push(frame_of(last, summary.t_end, self.picture));
        }
        if self.particle_picture(summary)? {
            files.push(PARTICLES_SVG.to_string());
        }
        Ok(files)
    }

    /// `particles.svg` from the frames kept (see the module documentation).
    fn particle_picture(&self, summary: &Summary) -> Result<bool, CliError> {
        let path = self.dir.file(PARTICLES_SVG);
        let title = format!(
            "{}: {} ({}, {} mass)",
            self.scene,
            self.picture.label(),
            summary.basis,
            summary.mass
        );
        if self.dim == 1 {
            let mut plot = LinePlot::new(title, "x", self.picture.label());
            for f in &self.pictured {
                let mut points: Vec<(f64, f64)> = f
                    .positions
                    .iter()
                    .zip(&f.values)
                    .map(|(x, &v)| (x.x, v))
                    .collect();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                plot = plot.with_series(Series::line(
                    // Four significant digits: a legend, not a record.
                    format!(
                        "t = {}",
                        format!("{:.3e}", f.time).parse::<f64>().unwrap_or(f.time)
                    ),
                    thin(points, MAX_PLOT_POINTS),
                ));
            }
            return self.plots(PARTICLES_SVG, vec![plot]);
        }
        let picture = ParticlePicture {
            title,
            field: self.picture.label().to_string(),
            frames: self.pictured.clone(),
            edges: self.edges.clone(),
        };
        match particle_plot(&path, &picture) {
            Ok(()) => Ok(true),
            // A failed run may leave nothing finite to draw: say so, keep the rest.
            Err(PlotError::Empty(why)) => {
                eprintln!("warning: no {PARTICLES_SVG}: {why}");
                Ok(false)
            }
            Err(e) => Err(CliError::Input(format!("{}: {e}", path.display()))),
        }
    }

    fn write_tracked_csv(&self, tracked: &[Tracked]) -> Result<(), CliError> {
        let exact = tracked.iter().all(|t| {
            !t.exact_displacement.is_empty()
                && t.exact_displacement.len() == t.time.len()
                && t.exact_velocity.len() == t.time.len()
        });
        let path = self.dir.file(TRACKED_CSV);
        let steps = tracked.iter().map(|t| t.time.len()).min().unwrap_or(0);
        write_file(&path, |w| {
            let mut csv = csv::Writer::from_writer(w);
            let mut header = vec!["time", "particle", "u_x", "u_y", "v_x", "v_y"];
            if exact {
                header.extend(["u_exact_x", "u_exact_y", "v_exact_x", "v_exact_y"]);
            }
            csv.write_record(&header)?;
            let float = |x: f64| format!("{x:e}");
            for i in 0..steps {
                for t in tracked {
                    let (u, v) = (t.displacement[i], t.velocity[i]);
                    let mut record = vec![
                        float(t.time[i]),
                        t.particle.to_string(),
                        float(u[0]),
                        float(u[1]),
                        float(v[0]),
                        float(v[1]),
                    ];
                    if exact {
                        let (e, w) = (t.exact_displacement[i], t.exact_velocity[i]);
                        record.extend([float(e[0]), float(e[1]), float(w[0]), float(w[1])]);
                    }
                    csv.write_record(&record)?;
                }
            }
            csv.flush()
        })
        .map_err(output_error)
    }

    /// The displacement of the tracked particles against time (see [`Self::tracked_panel`]).
    fn tracked_plot(&self, tracked: &[Tracked]) -> LinePlot {
        self.tracked_panel(
            tracked,
            format!("{}: tracked particles", self.scene),
            "displacement",
            "u",
            |t| (&t.displacement, &t.exact_displacement),
        )
    }

    /// The velocity of the tracked particles against time (see [`Self::tracked_panel`]).
    fn tracked_velocity_plot(&self, tracked: &[Tracked]) -> LinePlot {
        self.tracked_panel(
            tracked,
            format!("{}: tracked particles, velocity", self.scene),
            "velocity",
            "v",
            |t| (&t.velocity, &t.exact_velocity),
        )
    }

    /// One panel of `tracked.svg`: for each particle the components of the
    /// quantity `series(t) = (computed, reference)` that move (above 1e-3 of the
    /// largest; x only in 1D), named `particle P SYMBOL_x`. With a reference, the
    /// computed values as markers and the reference as a line; without, the computed
    /// values as a line.
    fn tracked_panel(
        &self,
        tracked: &[Tracked],
        title: String,
        label: &str,
        symbol: &str,
        series: impl Fn(&Tracked) -> (&Vec<[f64; 2]>, &Vec<[f64; 2]>),
    ) -> LinePlot {
        let mut plot = LinePlot::new(title, "time", label);
        let axis = ["x", "y"];
        for t in tracked {
            let (computed, exact) = series(t);
            let has_exact = !exact.is_empty() && exact.len() == t.time.len();
            let amplitude = |c: usize| {
                computed
                    .iter()
                    .chain(exact)
                    .map(|u| u[c].abs())
                    .filter(|a| a.is_finite())
                    .fold(0.0, f64::max)
            };
            let amplitudes = [amplitude(0), amplitude(1)];
            let largest = amplitudes[0].max(amplitudes[1]);
            let mut components: Vec<usize> = (0..self.dim)
                .filter(|&c| amplitudes[c] > 1e-3 * largest)
                .collect();
            if components.is_empty() {
                components.push(self.dim - 1);
            }
            for c in components {
                let name = format!("particle {} {symbol}_{}", t.particle, axis[c]);
                let points = |values: &Vec<[f64; 2]>| -> Vec<(f64, f64)> {
                    t.time.iter().zip(values).map(|(&s, u)| (s, u[c])).collect()
                };
                if has_exact {
                    plot = plot
                        .with_series(Series::markers(
                            format!("{name} (MPM)"),
                            thin(points(computed), MAX_MARKERS),
                        ))
                        .with_series(Series::line(
                            format!("{name} (exact)"),
                            thin(points(exact), MAX_PLOT_POINTS),
                        ));
                } else {
                    plot = plot.with_series(Series::line(
                        format!("{name} (MPM)"),
                        thin(points(computed), MAX_PLOT_POINTS),
                    ));
                }
            }
        }
        plot
    }

    fn energy_plot(&self) -> LinePlot {
        // No units: a scene's are whatever consistent system it is written in.
        let per = if self.dim == 2 {
            "thickness"
        } else {
            "cross-section"
        };
        let mut plot = LinePlot::new(
            format!("{}: energy (per unit {per})", self.scene),
            "time",
            format!("energy per unit {per}"),
        );
        // The work of the effects (traction, body forces, damping) only where there
        // is some: `total = kinetic + strain + potential − work` then reads as the
        // balance it is.
        let works = self.energy.iter().any(|e| e[4] != 0.0);
        // The potential and the total from their values at the start: their zero is
        // where gravity's potential is zero, which can put them far above the
        // motion's energies (and flatten those).
        let start = self.energy.first().copied().unwrap_or_default();
        for (k, name) in [
            "kinetic",
            "strain",
            "potential − P(0)",
            "work of the effects",
            "total − E(0)",
        ]
        .iter()
        .enumerate()
        {
            if k == 3 && !works {
                continue;
            }
            let from = if k == 2 || k == 4 { start[k + 1] } else { 0.0 };
            let points = self
                .energy
                .iter()
                .map(|e| (e[0], e[k + 1] - from))
                .collect();
            plot = plot.with_series(Series::line(*name, thin(points, MAX_PLOT_POINTS)));
        }
        // The time-centred total, which does not swing with the step after an
        // impact: where it stays flat, the total's swing is the step's oscillation.
        let points = self
            .centred
            .iter()
            .map(|&(t, e)| (t, e - start[5]))
            .collect();
        plot.with_series(Series::line(
            "centred total − E(0)",
            thin(points, MAX_PLOT_POINTS),
        ))
    }

    /// Draws `plots` (one below the other) into `file` without their non-finite
    /// points (an unstable run), empty series and empty plots; `false` when nothing
    /// is left to draw.
    fn plots(&self, file: &str, mut plots: Vec<LinePlot>) -> Result<bool, CliError> {
        for plot in &mut plots {
            for s in &mut plot.series {
                s.points.retain(|(x, y)| x.is_finite() && y.is_finite());
            }
            plot.series.retain(|s| !s.points.is_empty());
        }
        plots.retain(|p| !p.series.is_empty());
        if plots.is_empty() {
            return Ok(false);
        }
        let path = self.dir.file(file);
        stacked_line_plots(&path, &plots).map_err(|e| match e {
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

/// One CSV record (no line break), quoted as RFC 4180 needs (the `csv` crate).
pub fn csv_record<S: AsRef<[u8]>>(fields: &[S]) -> String {
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    // Writing into a Vec cannot fail.
    let _ = w.write_record(fields);
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8_lossy(&bytes)
        .trim_end_matches('\n')
        .to_string()
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

    #[test]
    fn csv_records_are_quoted_where_needed_and_output_files_are_known() {
        assert_eq!(csv_record(&["a", "b c", "1e0"]), "a,b c,1e0");
        assert_eq!(
            csv_record(&["x, y", "say \"hi\"", ""]),
            "\"x, y\",\"say \"\"hi\"\"\","
        );
        for name in [
            "particles_00012.vtu",
            "summary.json",
            "mesh.vtu",
            "energy.svg",
        ] {
            assert!(is_output_file(name), "{name}");
        }
        for name in ["notes.txt", "particles_a.vtu", "mesh.vtu.bak"] {
            assert!(!is_output_file(name), "{name}");
        }
    }
}
