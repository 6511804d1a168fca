//! The particles of a scene: the lattice filling its bodies, and the initial states
//! (velocity, initial stress) applied to them before the run.

use super::{to_vec, Solution};
use crate::effect::{Geostatic, InitialStress};
use crate::particles::Particles;
use crate::scene::{EffectSpec, ErrorKind, InitialVelocity, Scene, SceneError};
use crate::simulation::RunError;
use nalgebra::SMatrix;
use std::f64::consts::PI;

/// A body's extent is a whole number of lattice cells when it is within this
/// fraction of one.
const WHOLE_CELLS: f64 = 1e-6;

/// Particle positions and volumes of the scene's bodies, block by block for
/// `per_block` layouts (the order of the seeds' codes), row by row otherwise; a
/// body's `jitter` moves each particle inside its cell (deterministic, see
/// [`crate::scene::Body::jitter`]).
pub fn particle_lattice(scene: &Scene) -> Result<Lattice, RunError> {
    let d = scene.dim;
    let mut lattice = Lattice::default();
    for (b, body) in scene.bodies.iter().enumerate() {
        let first = lattice.positions.len();
        let mut spacing = [1.0; 2];
        let mut cells = [1usize; 2];
        let mut group = [1usize; 2];
        for k in 0..d {
            let extent = body.max[k] - body.min[k];
            let h = scene.lattice_spacing(body, k).ok_or_else(|| {
                SceneError::new(
                    format!("body[{b}].per_block"),
                    ErrorKind::Conflict,
                    "the mesh has no blocks",
                )
            })?;
            let n = if let Some(per) = &body.per_block {
                let n = extent / h;
                if (n - n.round()).abs() > WHOLE_CELLS * n.max(1.0) || n.round() < 1.0 {
                    return Err(SceneError::new(
                        format!("body[{b}].max"),
                        ErrorKind::Conflict,
                        format!("the body's extent {extent} along axis {k} is not a whole number of lattice cells of size {h}"),
                    )
                    .into());
                }
                group[k] = per[k];
                n.round() as usize
            } else {
                let c = body.count.as_ref().map_or(1, |c| c[k]);
                group[k] = c;
                c
            };
            spacing[k] = h;
            cells[k] = n;
        }
        let volume: f64 = spacing[..d].iter().product();
        // Jitter: a uniform offset in [-jitter, jitter) cells per axis, drawn in the
        // order the particles are made, from a generator seeded per body.
        let mut rng = psmpm_basis::rng::SplitMix64(
            body.seed
                .unwrap_or(crate::scene::DEFAULT_JITTER_SEED)
                .wrapping_add(b as u64),
        );
        let groups = [cells[0].div_ceil(group[0]), cells[1].div_ceil(group[1])];
        for gj in 0..groups[1] {
            for gi in 0..groups[0] {
                for j in 0..group[1] {
                    for i in 0..group[0] {
                        let (ci, cj) = (gi * group[0] + i, gj * group[1] + j);
                        if ci >= cells[0] || cj >= cells[1] {
                            continue;
                        }
                        let mut p = [0.0; 2];
                        for (k, c) in [ci, cj].into_iter().enumerate().take(d) {
                            let offset = if body.jitter > 0.0 {
                                body.jitter * (2.0 * rng.next_f64() - 1.0)
                            } else {
                                0.0
                            };
                            p[k] = body.min[k] + (c as f64 + 0.5 + offset) * spacing[k];
                        }
                        lattice.positions.push(p);
                        lattice.volumes.push(volume);
                    }
                }
            }
        }
        lattice.body_sizes.push(lattice.positions.len() - first);
    }
    Ok(lattice)
}

/// The particles of a scene's bodies before the run: positions, volumes, and how
/// many belong to each body (bodies in order).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Lattice {
    /// Positions (the second entry is 0 in 1D).
    pub positions: Vec<[f64; 2]>,
    /// Volumes.
    pub volumes: Vec<f64>,
    /// Particles per body.
    pub body_sizes: Vec<usize>,
}

/// The particles of `lattice` with density `density`, at rest and unstressed.
pub(crate) fn place<const D: usize>(lattice: &Lattice, density: f64) -> Particles<f64, D> {
    Particles::<f64, D>::new(
        lattice.positions.iter().map(|&p| to_vec::<D>(p)).collect(),
        lattice.volumes.clone(),
        density,
    )
}

/// Applies the scene's initial states to the particles placed at `positions`: the
/// initial velocity, and the geostatic initial stress (declared among the effects,
/// but no effect: it adds no force during the run, it sets `σ⁰` of the particles).
pub(crate) fn apply_initial_states<const D: usize>(
    scene: &Scene,
    positions: &[[f64; 2]],
    solution: Option<Solution>,
    origin: [f64; 2],
    particles: &mut Particles<f64, D>,
) {
    initial_velocity(scene, positions, solution, origin, particles);
    initial_stress(scene, particles);
}

/// `v` of every particle from the scene's `initial_velocity`.
fn initial_velocity<const D: usize>(
    scene: &Scene,
    positions: &[[f64; 2]],
    solution: Option<Solution>,
    origin: [f64; 2],
    particles: &mut Particles<f64, D>,
) {
    for (p, &x0) in positions.iter().enumerate() {
        let v = match &scene.initial_velocity {
            InitialVelocity::Rest {} => [0.0; 2],
            InitialVelocity::Uniform { value } => {
                let mut v = [0.0; 2];
                v[..D].copy_from_slice(&value[..D]);
                v
            }
            InitialVelocity::SineMode { v0 } => {
                let body = &scene.bodies[0];
                let length = body.max[0] - body.min[0];
                [v0 * (PI * (x0[0] - body.min[0]) / length).sin(), 0.0]
            }
            InitialVelocity::Exact {} => {
                solution.map_or([0.0; 2], |s| s.velocity(x0, origin, D, 0.0))
            }
        };
        particles.v[p] = to_vec::<D>(v);
    }
}

/// `σ⁰` of every particle from the scene's geostatic stress states, with the density
/// of the particles and `g` of the gravity effect.
fn initial_stress<const D: usize>(scene: &Scene, particles: &mut Particles<f64, D>) {
    for spec in &scene.effects {
        if let EffectSpec::GeostaticStress { surface, k0 } = spec {
            let g = scene.gravity().map_or(0.0, |g| g[D - 1]);
            let state = Geostatic {
                surface: *surface,
                density: scene.material.density,
                gravity: g,
                k0: *k0,
            };
            for p in 0..particles.len() {
                let s: SMatrix<f64, D, D> = state.sigma0(&particles.x0[p]);
                particles.sigma0[p] += s;
            }
        }
    }
}
