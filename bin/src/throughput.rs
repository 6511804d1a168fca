//! `mpm-cli throughput`: particle-steps per second and heap bytes per particle of
//! the whole time step, per variant and size, at fixed particles per element, and
//! the exponent of the cost per step against the particle count: so that a user can
//! measure their own machine (docs/performance.md has ours).
//!
//! The scene is the B5a column (`column-small`: linear elastic, gravity, walls)
//! refined to about N particles: `b × 8b` blocks of 8 × 8 particles each (16 per
//! triangle), `b` chosen for N. Each variant runs `--steps` steps of a fixed
//! `Δt = 1e-6` (below the critical step of every variant and size here); the time is
//! the driver's time loop (set-up, including the critical-step estimate, is not
//! timed); the memory is the peak of heap bytes over set-up and steps, less what was
//! in use before.

use crate::error::CliError;
use crate::run::thread_pool;
use crate::table::{fixed2, sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::mass::MassKind;
use psmpm::scene::limits::echo_number;
use psmpm::scene::{MeshSpec, Scene};
use psmpm::simulation;
use serde::Serialize;

/// Particles per block along each axis.
const PER_BLOCK: usize = 8;
/// Blocks are `b × ASPECT b`.
const ASPECT: usize = 8;
/// The fixed time step.
const DT: f64 = 1e-6;
/// Particles of one block.
const BLOCK_PARTICLES: usize = PER_BLOCK * PER_BLOCK;

/// The blocks `b` of the `b × ASPECT b` grid nearest `n` particles.
fn blocks_for(n: f64) -> usize {
    ((n / BLOCK_PARTICLES as f64 / ASPECT as f64).sqrt().round() as usize).max(1)
}

/// The particles of the `b × ASPECT b` grid.
fn particles_of(b: usize) -> usize {
    BLOCK_PARTICLES * ASPECT * b * b
}

/// Checks a `--sizes` entry before any scene is built: at least 100 particles, and
/// the grid it rounds to within the scenes' particle limit
/// ([`psmpm::scene::MAX_PARTICLES`]).
fn check_size(n: f64) -> Result<(), CliError> {
    let limit = psmpm::scene::MAX_PARTICLES;
    // The largest grid within the limit.
    let most = particles_of((limit as f64 / (BLOCK_PARTICLES * ASPECT) as f64).sqrt() as usize);
    if !(n >= 100.0 && n.is_finite()) {
        return Err(CliError::Input(format!(
            "--sizes: {} {} is outside 100..={most}",
            echo_number(n),
            if n == 1.0 { "particle" } else { "particles" }
        )));
    }
    if n > limit as f64 {
        return Err(CliError::Input(format!(
            "--sizes: {} particles is above the limit of {limit} particles; give at most {most}",
            echo_number(n)
        )));
    }
    let b = blocks_for(n);
    let particles = particles_of(b);
    if particles > limit {
        return Err(CliError::Input(format!(
            "--sizes: {} particles rounds to {particles} ({b} × {} blocks of {PER_BLOCK} × {PER_BLOCK}), above the limit of {limit} particles; give at most {most}",
            echo_number(n),
            ASPECT * b
        )));
    }
    Ok(())
}

/// Arguments of `mpm-cli throughput`.
#[derive(Debug, clap::Args)]
pub struct ThroughputArgs {
    /// Particle counts, comma-separated (each rounded to the nearest block grid).
    #[arg(long, value_delimiter = ',', default_values_t = [1e4, 1e5], allow_hyphen_values = true)]
    sizes: Vec<f64>,
    /// Variants BASIS:MASS, comma-separated (mass `default` is the default strategy).
    #[arg(long, value_delimiter = ',', default_values_t = ["pl:lumped".to_string(), "ps:lumped".to_string(), "ps:consistent".to_string(), "ps:default".to_string()])]
    variants: Vec<String>,
    /// Steps timed per variant and size.
    #[arg(long, default_value_t = 10, allow_hyphen_values = true, value_parser = crate::whole::<usize>("from 1 to 10000"))]
    steps: usize,
    /// Threads of the particle phases (default: all cores).
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = crate::whole::<usize>(crate::THREADS_RANGE))]
    threads: Option<usize>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// One variant at one size.
#[derive(Debug, Clone, Serialize)]
pub struct Measurement {
    /// `basis:mass`.
    pub variant: String,
    /// Particles.
    pub particles: usize,
    /// Basis functions.
    pub functions: usize,
    /// Steps timed.
    pub steps: usize,
    /// Wall time per step (s).
    pub seconds_per_step: f64,
    /// Particles × steps per second of wall time.
    pub particle_steps_per_second: f64,
    /// Peak heap bytes of set-up and steps.
    pub peak_bytes: usize,
    /// `peak_bytes / particles`.
    pub bytes_per_particle: f64,
}

/// The exponent `a` of `seconds_per_step ∝ particles^a`, least squares in log-log,
/// per variant.
#[derive(Debug, Clone, Serialize)]
pub struct Scaling {
    /// `basis:mass`.
    pub variant: String,
    /// The fitted exponent (`None` with fewer than two sizes).
    pub exponent: Option<f64>,
}

fn variant(text: &str) -> Result<(BasisKind, MassKind), CliError> {
    let bad = |why: String| CliError::Input(format!("--variants: `{text}`: {why}"));
    let (basis, mass) = text
        .split_once(':')
        .ok_or_else(|| bad("must look like ps:consistent".into()))?;
    let basis = BasisKind::parse(basis).map_err(bad)?;
    if basis.dim() != 2 {
        return Err(bad("the throughput scene is 2D: ps or pl".into()));
    }
    let mass = MassKind::parse(mass).map_err(|e| bad(e.to_string()))?;
    Ok((basis, mass))
}

/// The column refined to about `n` particles.
fn scene(n: f64, basis: BasisKind, mass: MassKind, steps: usize) -> Result<Scene, CliError> {
    let b = blocks_for(n);
    let mut s = Scene::builtin("column-small")
        .map_err(|e| CliError::Input(e.to_string()))?
        .with_basis(basis)
        .map_err(|e| CliError::Input(e.to_string()))?;
    s.mass = mass;
    match &mut s.mesh {
        MeshSpec::Blocks { blocks, .. } => *blocks = [b, ASPECT * b],
        _ => return Err(CliError::Input("column-small is not a block mesh".into())),
    }
    for body in &mut s.bodies {
        body.per_block = Some(vec![PER_BLOCK, PER_BLOCK]);
        body.count = None;
    }
    s.reference = None;
    s.output = Default::default();
    s.time.dt = Some(DT);
    s.time.courant = None;
    s.time.t_end = DT * steps as f64;
    s.validate().map_err(|e| CliError::Input(e.to_string()))?;
    Ok(s)
}

/// Runs the measurements.
pub fn throughput(args: ThroughputArgs) -> Result<(), CliError> {
    if args.steps == 0 || args.steps > 10_000 {
        return Err(CliError::Input(format!(
            "--steps must be in 1..=10000, got {}",
            args.steps
        )));
    }
    for &n in &args.sizes {
        check_size(n)?;
    }
    let variants: Vec<(String, BasisKind, MassKind)> = args
        .variants
        .iter()
        .map(|v| variant(v).map(|(b, m)| (v.clone(), b, m)))
        .collect::<Result<_, _>>()?;
    let pool = thread_pool(args.threads)?;
    let mut rows = Vec::new();
    for (name, basis, mass) in &variants {
        for &n in &args.sizes {
            let s = scene(n, *basis, *mass, args.steps)?;
            let before = crate::memory::reset_peak();
            let summary = pool
                .install(|| simulation::run(&s, &mut |_| {}))
                .map_err(|e| CliError::Input(e.to_string()))?;
            let peak_bytes = crate::memory::peak().saturating_sub(before);
            if let Some(failure) = &summary.failure {
                return Err(CliError::Numerical(format!("{name} at {n:e}: {failure}")));
            }
            let per_step = summary.seconds / summary.steps.max(1) as f64;
            rows.push(Measurement {
                variant: name.clone(),
                particles: summary.particles,
                functions: summary.functions,
                steps: summary.steps,
                seconds_per_step: per_step,
                particle_steps_per_second: summary.particles as f64 / per_step,
                peak_bytes,
                bytes_per_particle: peak_bytes as f64 / summary.particles as f64,
            });
        }
    }
    let scaling: Vec<Scaling> = variants
        .iter()
        .map(|(name, _, _)| {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| &r.variant == name)
                .map(|r| ((r.particles as f64).ln(), r.seconds_per_step.ln()))
                .collect();
            Scaling {
                variant: name.clone(),
                exponent: slope(&points),
            }
        })
        .collect();
    print(&rows, &scaling, args.format);
    Ok(())
}

/// Least-squares slope of `points`, `None` with fewer than two distinct x.
fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (points.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

fn print(rows: &[Measurement], scaling: &[Scaling], format: Format) {
    match format {
        Format::Json => println!(
            "{}",
            serde_json::json!({ "measurements": rows, "scaling": scaling })
        ),
        Format::Csv => {
            println!(
                "{}",
                crate::out::csv_record(&[
                    "variant",
                    "particles",
                    "functions",
                    "steps",
                    "seconds_per_step",
                    "particle_steps_per_second",
                    "peak_bytes",
                    "bytes_per_particle"
                ])
            );
            for r in rows {
                println!(
                    "{}",
                    crate::out::csv_record(&[
                        r.variant.clone(),
                        r.particles.to_string(),
                        r.functions.to_string(),
                        r.steps.to_string(),
                        r.seconds_per_step.to_string(),
                        r.particle_steps_per_second.to_string(),
                        r.peak_bytes.to_string(),
                        r.bytes_per_particle.to_string(),
                    ])
                );
            }
        }
        Format::Table => {
            let mut table = Table::new(&[
                "variant",
                "particles",
                "functions",
                "s/step",
                "particle-steps/s",
                "peak MB",
                "bytes/particle",
            ]);
            for r in rows {
                table.push(vec![
                    r.variant.clone(),
                    r.particles.to_string(),
                    r.functions.to_string(),
                    sci(r.seconds_per_step),
                    sci(r.particle_steps_per_second),
                    format!("{:.1}", r.peak_bytes as f64 / 1e6),
                    format!("{:.0}", r.bytes_per_particle),
                ]);
            }
            print!("{}", table.render());
            for s in scaling {
                match s.exponent {
                    Some(_) => println!(
                        "{}: cost per step ∝ particles^{}",
                        s.variant,
                        fixed2(s.exponent)
                    ),
                    None => println!("{}: one size, no exponent", s.variant),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slope_of_a_power_law_is_its_exponent() {
        let points: Vec<(f64, f64)> = [1e4f64, 1e5, 1e6]
            .iter()
            .map(|&n| (n.ln(), (3e-7 * n.powf(1.04)).ln()))
            .collect();
        assert!((slope(&points).unwrap() - 1.04).abs() < 1e-12);
        assert_eq!(slope(&points[..1]), None);
    }

    #[test]
    fn sizes_map_to_block_grids_of_8_by_8_particles() {
        let s = scene(1e5, BasisKind::Ps, MassKind::Lumped, 3).unwrap();
        match &s.mesh {
            MeshSpec::Blocks { blocks, .. } => assert_eq!(blocks, &[14, 112]),
            _ => unreachable!(),
        }
        assert_eq!(s.steps(), 3);
    }
}
