//! The particles of a scene: the lattice filling its box bodies, the other shapes
//! (regions.rs), no two bodies overlapping, and the initial states (velocity,
//! initial stress) applied to them before the run, per body.

use super::regions::{self, Region};
use super::{to_vec, Solution};
use crate::effect::{Geostatic, InitialStress};
use crate::particles::Particles;
use crate::scene::limits::{echo_number, MAX_PARTICLES};
use crate::scene::{BodyShape, EffectSpec, ErrorKind, InitialVelocity, Scene, SceneError};
use crate::simulation::RunError;
use nalgebra::SMatrix;
use std::f64::consts::PI;

/// A body's extent is a whole number of lattice cells when it is within this
/// fraction of one.
const WHOLE_CELLS: f64 = 1e-6;

/// Particle positions and volumes of the scene's bodies, body by body. A box is
/// filled block by block for `per_block` layouts (the order of the seeds' codes),
/// row by row otherwise; polygons and disks row by row over their bounding box, Gmsh
/// surfaces triangle by triangle (see [`crate::scene::Body`]). A body's `jitter`
/// moves each particle inside its cell (deterministic, see
/// [`crate::scene::Body::jitter`]). Bodies must not overlap: a particle of one body
/// inside another's region is an error naming both.
pub fn particle_lattice(scene: &Scene) -> Result<Lattice, RunError> {
    let d = scene.dim;
    let mut lattice = Lattice::default();
    let mut regions = Vec::with_capacity(scene.bodies.len());
    for (b, body) in scene.bodies.iter().enumerate() {
        let first = lattice.positions.len();
        let room = MAX_PARTICLES.saturating_sub(first);
        if body.shape != BodyShape::Box {
            let (filled, region) = if body.shape == BodyShape::Gmsh {
                regions::fill_surface(b, body, room)?
            } else {
                let region = Region::of(body, d).ok_or_else(|| {
                    SceneError::new(format!("body[{b}]"), ErrorKind::Value, "has no region")
                })?;
                let mut h = [1.0; 2];
                for (k, h) in h.iter_mut().enumerate().take(d) {
                    *h = scene.lattice_spacing(body, k).ok_or_else(|| {
                        SceneError::new(
                            format!("body[{b}].per_block"),
                            ErrorKind::Conflict,
                            "the mesh has no blocks",
                        )
                    })?;
                }
                let mut rng = jitter_rng(body, b);
                let filled = regions::fill_lattice(b, body, &region, h, room, || {
                    2.0 * rng.next_f64() - 1.0
                })?;
                (filled, region)
            };
            lattice.positions.extend(filled.positions);
            lattice.volumes.extend(filled.volumes);
            lattice.bounds.push(filled.bounds);
            lattice.body_sizes.push(lattice.positions.len() - first);
            regions.push(region);
            continue;
        }
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
            let n = if body.per_block.is_some() || body.spacing.is_some() {
                let n = extent / h;
                if (n - n.round()).abs() > WHOLE_CELLS * n.max(1.0) || n.round() < 1.0 {
                    // A box beyond a block mesh: say so rather than that its extent is
                    // not a whole number of the lattice's cells, the mesh's blocks.
                    if let (Some(_), Some((lo, hi))) = (&body.per_block, scene.block_mesh_range(k))
                    {
                        let (field, end, side) = if body.min[k] < lo {
                            ("min", lo, "at least")
                        } else {
                            ("max", hi, "at most")
                        };
                        if body.min[k] < lo || body.max[k] > hi {
                            return Err(SceneError::new(
                                format!("body[{b}].{field}"),
                                ErrorKind::Conflict,
                                format!(
                                    "the body's box [{}, {}] along axis {k} reaches beyond the mesh's [{}, {}]: a body must lie inside the mesh; make `{field}` {side} {}, or enlarge the mesh",
                                    echo_number(body.min[k]),
                                    echo_number(body.max[k]),
                                    echo_number(lo),
                                    echo_number(hi),
                                    echo_number(end)
                                ),
                            )
                            .into());
                        }
                    }
                    // Ten significant digits: 0.8, not 0.7999999999999999.
                    let shown = |x: f64| format!("{x:.9e}").parse::<f64>().unwrap_or(x);
                    let (extent, h) = (shown(extent), shown(h));
                    return Err(SceneError::new(
                        format!("body[{b}].max"),
                        ErrorKind::Conflict,
                        if body.per_block.is_some() {
                            format!("the body's extent {} along axis {k} is not a whole number of lattice cells of size {} (the mesh's block size along that axis over `per_block`): make the extent a multiple of it, choose `blocks` (or `--blocks`) so that it is, or give `count` instead of `per_block`", echo_number(extent), echo_number(h))
                        } else {
                            format!("the body's extent {} along axis {k} is not a whole number of lattice cells of size {} (`spacing`): make the extent a multiple of it, or give `count` instead", echo_number(extent), echo_number(h))
                        },
                    )
                    .into());
                }
                let n = n.round() as usize;
                // `per_block`: block by block; `spacing`: row by row.
                group[k] = body.per_block.as_ref().map_or(n, |per| per[k]);
                n
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
        let mut rng = jitter_rng(body, b);
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
        let bounds = body.bounds().unwrap_or_default();
        lattice.bounds.push(bounds);
        regions.push(Region::Box {
            min: bounds.0,
            max: bounds.1,
            dim: d,
        });
    }
    check_overlaps(&lattice, &regions)?;
    Ok(lattice)
}

/// The generator of a body's jitter, seeded per body.
fn jitter_rng(body: &crate::scene::Body, b: usize) -> psmpm_basis::rng::SplitMix64 {
    psmpm_basis::rng::SplitMix64(
        body.seed
            .unwrap_or(crate::scene::DEFAULT_JITTER_SEED)
            .wrapping_add(b as u64),
    )
}

/// Bodies do not overlap: no particle of one body lies inside another's region
/// (bodies that only touch along a boundary are fine: their particles sit inside
/// their own cells). Two overlapping bodies would put two materials, and twice the
/// mass, in one place.
fn check_overlaps(lattice: &Lattice, regions: &[Region]) -> Result<(), SceneError> {
    let mut first = 0;
    for (j, &n) in lattice.body_sizes.iter().enumerate() {
        let particles = &lattice.positions[first..first + n];
        for (i, region) in regions.iter().enumerate() {
            if i == j {
                continue;
            }
            // Only particles in the other region's bounding box can lie in it.
            let (lo, hi) = lattice.bounds[i];
            let in_box = |p: &[f64; 2]| (0..2).all(|k| lo[k] <= p[k] && p[k] <= hi[k]);
            if let Some(p) = particles
                .iter()
                .find(|&&p| in_box(&p) && region.contains(p))
            {
                let (a, b) = (i.min(j), i.max(j));
                return Err(SceneError::new(
                    format!("body[{b}]"),
                    ErrorKind::Conflict,
                    format!(
                        "body[{a}] and body[{b}] overlap: the particle of body[{j}] at {} lies inside body[{i}]; bodies must not overlap (they may touch)",
                        crate::driver::point(p.as_slice())
                    ),
                ));
            }
        }
        first += n;
    }
    Ok(())
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
    /// Bounding box `(min, max)` of each body's region (the second entries 0 in 1D).
    pub bounds: Vec<([f64; 2], [f64; 2])>,
}

impl Lattice {
    /// The body of every particle.
    pub fn body_of_particles(&self) -> Vec<usize> {
        self.body_sizes
            .iter()
            .enumerate()
            .flat_map(|(b, &n)| std::iter::repeat_n(b, n))
            .collect()
    }
}

/// The particles of `lattice`, at rest and unstressed, each with the density of its
/// body's material (`m_p = ρ_b V_p⁰`).
pub(crate) fn place<const D: usize>(scene: &Scene, lattice: &Lattice) -> Particles<f64, D> {
    let mut particles = Particles::<f64, D>::new(
        lattice.positions.iter().map(|&p| to_vec::<D>(p)).collect(),
        lattice.volumes.clone(),
        scene.body_material(0).density,
    );
    for (p, b) in lattice.body_of_particles().into_iter().enumerate() {
        particles.mass[p] = lattice.volumes[p] * scene.body_material(b).density;
    }
    particles
}

/// Applies the scene's initial states to the particles of `lattice`: each body's
/// initial velocity, and the geostatic initial stress (declared among the effects,
/// but no effect: it adds no force during the run, it sets `σ⁰` of the particles).
pub(crate) fn apply_initial_states<const D: usize>(
    scene: &Scene,
    lattice: &Lattice,
    solution: Option<Solution>,
    origin: [f64; 2],
    particles: &mut Particles<f64, D>,
) -> Result<(), SceneError> {
    let mut first = 0;
    for (b, &n) in lattice.body_sizes.iter().enumerate() {
        // A body's own sine mode spans its own extent, the scene's that of the
        // first body.
        let extent = if scene.bodies[b].initial_velocity.is_some() {
            lattice.bounds[b]
        } else {
            lattice.bounds[0]
        };
        for p in first..first + n {
            let v = initial_velocity(
                scene.body_velocity(b),
                lattice.positions[p],
                extent,
                solution,
                origin,
                D,
            );
            particles.v[p] = to_vec::<D>(v);
        }
        first += n;
    }
    initial_stress(scene, lattice, particles)
}

/// The velocity `kind` gives at `x0` (the second entry 0 in 1D); `extent` is the
/// bounding box a sine mode spans.
fn initial_velocity(
    kind: &InitialVelocity,
    x0: [f64; 2],
    extent: ([f64; 2], [f64; 2]),
    solution: Option<Solution>,
    origin: [f64; 2],
    d: usize,
) -> [f64; 2] {
    match kind {
        InitialVelocity::Rest {} => [0.0; 2],
        InitialVelocity::Uniform { value } => {
            let mut v = [0.0; 2];
            v[..d].copy_from_slice(&value[..d]);
            v
        }
        InitialVelocity::SineMode { v0 } => {
            let (min, max) = extent;
            let length = max[0] - min[0];
            [v0 * (PI * (x0[0] - min[0]) / length).sin(), 0.0]
        }
        InitialVelocity::Exact {} => solution.map_or([0.0; 2], |s| s.velocity(x0, origin, d, 0.0)),
        InitialVelocity::RigidRotation { omega, centre } => {
            [-omega * (x0[1] - centre[1]), omega * (x0[0] - centre[0])]
        }
        InitialVelocity::Linear {
            value,
            origin: x_ref,
            gradient,
        } => {
            let mut v = [0.0; 2];
            for i in 0..d {
                v[i] = value[i];
                for j in 0..d {
                    v[i] += gradient[i][j] * (x0[j] - x_ref[j]);
                }
            }
            v
        }
    }
}

/// Samples of the density between a particle and the surface ([`weight_above`]).
const LAYER_SAMPLES: usize = 400;

/// `∫_y^surface ρ(s) ds` of a piecewise-constant `density`: sampled at the midpoints
/// of [`LAYER_SAMPLES`] intervals, and where two samples differ the jump between
/// them located by bisection (to round-off), so that layers thicker than an
/// interval are integrated exactly.
fn weight_above(density: &impl Fn(f64) -> f64, y: f64, surface: f64) -> f64 {
    let ds = (surface - y) / LAYER_SAMPLES as f64;
    let mid = |k: usize| y + (k as f64 + 0.5) * ds;
    let (mut total, mut from, mut rho) = (0.0, y, density(mid(0)));
    for k in 1..LAYER_SAMPLES {
        let next = density(mid(k));
        if next != rho {
            let (mut lo, mut hi) = (mid(k - 1), mid(k));
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if density(m) == rho {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            total += rho * (hi - from);
            from = hi;
            rho = next;
        }
    }
    total + rho * (surface - from)
}

/// `σ⁰` of every particle from the scene's geostatic stress states, with `g` of the
/// gravity effect. With one density (every body the same material density) it is
/// `ρ g (surface − y)`. With bodies of several densities stacked (a stiff layer under
/// a soft one) the vertical stress is the weight of what lies above the particle,
/// `g ∫_y^surface ρ(x, s) ds`, `ρ` the density of the body at `(x, s)` (zero
/// outside every body; [`weight_above`]).
///
/// A free surface below the highest particle is refused (the particles above it
/// would start without stress, silently), and so is one whose stress at the lowest
/// particle exceeds the Young's modulus of its body (crushed at once: a surface
/// far off, or in other units).
fn initial_stress<const D: usize>(
    scene: &Scene,
    lattice: &Lattice,
    particles: &mut Particles<f64, D>,
) -> Result<(), SceneError> {
    let densities: Vec<f64> = (0..scene.bodies.len())
        .map(|b| scene.body_material(b).density)
        .collect();
    let layered = scene.layered();
    let regions: Vec<Option<Region>> = scene
        .bodies
        .iter()
        .map(|body| Region::of(body, D))
        .collect();
    // The density at a point: of the first body containing it.
    let density_at = |x: &nalgebra::SVector<f64, D>, height: f64| -> f64 {
        let mut point = [0.0; 2];
        for k in 0..D {
            point[k] = x[k];
        }
        point[D - 1] = height;
        regions
            .iter()
            .zip(&densities)
            .find(|(r, _)| r.as_ref().is_some_and(|r| r.contains(point)))
            .map_or(0.0, |(_, &rho)| rho)
    };
    for (i, spec) in scene.effects.iter().enumerate() {
        if let EffectSpec::GeostaticStress { surface, k0 } = spec {
            let g = scene.gravity().map_or(0.0, |g| g[D - 1]);
            let field = format!("effect[{i}].surface");
            let bodies = lattice.body_of_particles();
            let (top, bottom) = particles
                .x0
                .iter()
                .fold((f64::NEG_INFINITY, f64::INFINITY), |(top, bottom), x| {
                    (top.max(x[D - 1]), bottom.min(x[D - 1]))
                });
            let axis = if D == 1 { "x" } else { "y" };
            if *surface < top {
                return Err(SceneError::new(
                    field,
                    ErrorKind::Conflict,
                    format!(
                        "the free surface {axis} = {} lies below the highest particle ({axis} = {}): the particles above it would start without stress; give the top of the bodies, or a height above it for a load on them",
                        echo_number(*surface),
                        echo_number(top)
                    ),
                ));
            }
            for (p, &b) in bodies.iter().enumerate() {
                if particles.x0[p][D - 1] != bottom {
                    continue;
                }
                let material = scene.body_material(b);
                let stress = material.density * g.abs() * (surface - bottom);
                if stress.is_nan() || stress > material.young {
                    return Err(SceneError::new(
                        field,
                        ErrorKind::Value,
                        format!(
                            "the geostatic stress at the lowest particle ({axis} = {}), ρ g (surface − {axis}) = {}, exceeds the Young's modulus {} of body[{b}]: it would be crushed at once; is `surface` {} in the scene's units, and near the highest particle ({axis} = {})?",
                            echo_number(bottom),
                            crate::scene::limits::echo_fixed(stress, 1),
                            echo_number(material.young),
                            echo_number(*surface),
                            echo_number(top)
                        ),
                    ));
                }
            }
            for (p, b) in bodies.into_iter().enumerate() {
                let x0 = particles.x0[p];
                let depth = surface - x0[D - 1];
                // The mean density above the particle (its own body's when all are
                // one; Gmsh bodies have no region and keep their own).
                let density = if layered && depth > 0.0 && regions[b].is_some() {
                    let at = |height: f64| density_at(&x0, height);
                    weight_above(&at, x0[D - 1], *surface) / depth
                } else {
                    densities[b]
                };
                let state = Geostatic {
                    surface: *surface,
                    density,
                    gravity: g,
                    k0: *k0,
                };
                let s: SMatrix<f64, D, D> = state.sigma0(&x0);
                if particles.sigma0.is_empty() {
                    particles.sigma0 = vec![SMatrix::zeros(); particles.len()];
                }
                particles.sigma0[p] += s;
            }
        }
    }
    Ok(())
}
