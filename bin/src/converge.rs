//! `mpm-cli converge`: a refinement study of a scene for several bases: error,
//! observed order and wall time per level, the project's answer to "what does
//! accuracy cost in time".
//!
//! Level `l` refines the scene as its `[study]` says (block counts times `2^l`).
//! Runs are sequential so that their wall times are comparable.

use crate::compare::variants;
use crate::error::CliError;
use crate::run::{read_scene, Overrides};
use crate::table::{fixed2, sci, Table};
use crate::Format;
use psmpm::output::chart::{line_plot, Axis, LinePlot, Scale, Series, SeriesStyle};
use psmpm::scene::Scene;
use psmpm::simulation::{self, RunError};
use serde::Serialize;
use std::path::PathBuf;

/// Arguments of `mpm-cli converge`.
#[derive(Debug, clap::Args)]
pub struct ConvergeArgs {
    /// Built-in scene (see `mpm-cli scenes`) or a scene file FILE.toml.
    scene: String,
    /// Bases, comma-separated (default: ps,pl in 2D, bspline,pl1d in 1D).
    #[arg(long, value_delimiter = ',')]
    basis: Vec<String>,
    /// Mass strategy (default: the scene's).
    #[arg(long)]
    mass: Option<String>,
    /// Number of levels (1 to 7).
    #[arg(long, default_value_t = 3)]
    levels: u32,
    #[command(flatten)]
    overrides: Overrides,
    /// Write the table as CSV and JSON and the log-log error-vs-h and
    /// error-vs-wall-time plots (SVG) into this directory.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Exit with status 1 when a variant failed or is unstable (default: 0, the
    /// table marks it).
    #[arg(long)]
    strict: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// One level of the study.
#[derive(Debug, Clone, Serialize)]
pub struct Level {
    /// Basis.
    pub basis: &'static str,
    /// Level (0 = the scene's resolution).
    pub level: u32,
    /// Mesh size.
    pub h: f64,
    /// Basis functions.
    pub functions: usize,
    /// Particles.
    pub particles: usize,
    /// Error against the reference.
    pub error: Option<f64>,
    /// Observed order against the previous level.
    pub order: Option<f64>,
    /// Wall time of the run.
    pub seconds: f64,
    /// Stable verdict.
    pub stable: bool,
}

/// Runs the study.
/// The scenes of the study, validated before any runs: per basis (and mass), its
/// levels in order.
fn levels(args: &ConvergeArgs) -> Result<(Scene, Vec<Vec<Scene>>), CliError> {
    if args.levels == 0 || args.levels > 7 {
        return Err(CliError::Input(format!(
            "--levels must be between 1 and 7, got {}",
            args.levels
        )));
    }
    let base = read_scene(&args.scene)?;
    if base.reference.is_none() {
        return Err(CliError::Input(format!(
            "scene `{}` has no reference solution, so there is no error to converge",
            base.name
        )));
    }
    let masses: Vec<String> = args.mass.iter().cloned().collect();
    let bases = variants(&base, &args.basis, &masses, &args.overrides)?;
    let levels = bases
        .iter()
        .map(|scene| {
            (0..args.levels)
                .map(|level| {
                    scene
                        .refined(level)
                        .map_err(|e| CliError::Input(format!("level {level}: {e}")))
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((base, levels))
}

/// Every scene the study would run, validated ([`crate::check`]).
pub fn prepare(args: &ConvergeArgs) -> Result<Vec<Scene>, CliError> {
    Ok(levels(args)?.1.into_iter().flatten().collect())
}

/// Runs the study and prints it.
pub fn converge(args: ConvergeArgs) -> Result<(), CliError> {
    let (base, levels) = levels(&args)?;
    let mut rows: Vec<Level> = Vec::new();
    let progress =
        crate::progress::Progress::new(levels.iter().map(Vec::len).sum::<usize>() as u64, "runs");
    for scenes in &levels {
        let mut previous: Option<(f64, f64)> = None;
        for (level, s) in (0..).zip(scenes) {
            let h = s.mesh_size().unwrap_or(f64::NAN);
            let summary = simulation::run(s, &mut |_| {})
                .map_err(|e: RunError| CliError::Input(e.to_string()))?;
            let order = match (previous, summary.error) {
                (Some((h0, e0)), Some(e)) if e > 0.0 && e0 > 0.0 => {
                    Some((e0 / e).ln() / (h0 / h).ln())
                }
                _ => None,
            };
            if let Some(e) = summary.error {
                previous = Some((h, e));
            }
            progress.inc(1);
            rows.push(Level {
                basis: summary.basis,
                level,
                h,
                functions: summary.functions,
                particles: summary.particles,
                error: summary.error,
                order,
                seconds: summary.seconds,
                stable: summary.stable,
            });
        }
    }
    progress.finish();
    print_levels(&rows, args.format);
    if let Some(dir) = &args.out {
        write_outputs(dir, &base.name, &rows)?;
    }
    let failed = rows.iter().filter(|r| !r.stable).count();
    crate::error::study_verdict(args.strict, failed, rows.len())
}

fn print_levels(rows: &[Level], format: Format) {
    match format {
        Format::Json => {
            let text = serde_json::to_string(rows).unwrap_or_else(|e| format!("\"{e}\""));
            println!("{text}");
        }
        Format::Csv => print!("{}", csv(rows)),
        Format::Table => {
            let mut table = Table::new(&[
                "basis",
                "level",
                "h",
                "functions",
                "particles",
                "error",
                "order",
                "seconds",
                "stable",
            ]);
            for r in rows {
                table.push(vec![
                    r.basis.to_string(),
                    r.level.to_string(),
                    sci(r.h),
                    r.functions.to_string(),
                    r.particles.to_string(),
                    r.error.map_or_else(|| "-".into(), sci),
                    fixed2(r.order),
                    format!("{:.3}", r.seconds),
                    if r.stable { "yes" } else { "NO" }.to_string(),
                ]);
            }
            print!("{}", table.render());
        }
    }
}

fn csv(rows: &[Level]) -> String {
    let opt = |v: Option<f64>| v.map_or_else(String::new, |x| x.to_string());
    let mut out = crate::out::csv_record(&[
        "basis",
        "level",
        "h",
        "functions",
        "particles",
        "error",
        "order",
        "seconds",
        "stable",
    ]);
    out.push('\n');
    for r in rows {
        out += &crate::out::csv_record(&[
            r.basis.to_string(),
            r.level.to_string(),
            r.h.to_string(),
            r.functions.to_string(),
            r.particles.to_string(),
            opt(r.error),
            opt(r.order),
            r.seconds.to_string(),
            r.stable.to_string(),
        ]);
        out.push('\n');
    }
    out
}

/// `converge.csv`, `converge.json`, `error-vs-h.svg`, `work-precision.svg`.
fn write_outputs(dir: &std::path::Path, scene: &str, rows: &[Level]) -> Result<(), CliError> {
    let io = |path: &std::path::Path, e: std::io::Error| {
        CliError::Input(format!("{}: cannot write: {e}", path.display()))
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let path = dir.join("converge.csv");
    std::fs::write(&path, csv(rows)).map_err(|e| io(&path, e))?;
    let path = dir.join("converge.json");
    let json = serde_json::to_string_pretty(rows).unwrap_or_default();
    std::fs::write(&path, json).map_err(|e| io(&path, e))?;
    let mut bases: Vec<&str> = rows.iter().map(|r| r.basis).collect();
    bases.dedup();
    let curves = |x: &dyn Fn(&Level) -> f64| -> Vec<Series> {
        bases
            .iter()
            .map(|b| Series {
                name: b.to_uppercase(),
                points: rows
                    .iter()
                    .filter(|r| r.basis == *b)
                    .filter_map(|r| r.error.map(|e| (x(r), e)))
                    .filter(|(x, e)| *x > 0.0 && *e > 0.0)
                    .collect(),
                style: SeriesStyle::LineAndMarkers,
            })
            .collect()
    };
    let plots = [
        (
            "error-vs-h.svg",
            format!("{scene}: error against mesh size"),
            "mesh size h",
            curves(&|r| r.h),
        ),
        (
            "work-precision.svg",
            format!("{scene}: error against wall time"),
            "wall time (s)",
            curves(&|r| r.seconds),
        ),
    ];
    for (file, title, x_label, series) in plots {
        let plot = LinePlot {
            title,
            x: Axis {
                label: x_label.into(),
                scale: Scale::Log10,
                include: None,
            },
            y: Axis {
                label: "error".into(),
                scale: Scale::Log10,
                include: None,
            },
            series,
            size: (800, 600),
        };
        let path = dir.join(file);
        line_plot(&path, &plot).map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}
