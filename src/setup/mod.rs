//! Set-up: a scene becomes the pieces of its run. The mesh (generated or read,
//! [`triangulation`]) and its basis, checked against the scene's boundary conditions
//! (mesh.rs); the particles filling the bodies ([`particle_lattice`]) with their
//! initial states, velocity and initial stress (particles.rs); the effects the scene
//! declares ([`build_effects`], effects.rs); the reference solution (solution.rs);
//! and the one driver a scene runs on ([`SceneDriver`]), with the time step and the
//! number of steps (here).
//! [`crate::simulation`] runs what this builds.

mod effects;
pub(crate) mod memory;
mod mesh;
mod particles;
pub(crate) mod regions;
mod solution;

pub use effects::build_effects;
pub use mesh::triangulation;
pub use particles::{particle_lattice, Lattice};

pub(crate) use mesh::{domain_1d, domain_2d, Basis1d, Basis2d};
pub(crate) use solution::Solution;

use crate::driver::{Driver, Fix, SetupError, SlipBend};
use crate::effect::Effect;
use crate::mass::MassStrategy;
use crate::material::MaterialError;
use crate::material::{AnyMaterial, Corotational, Elastic, LinearElastic, NeoHookean};
use crate::materials::MaterialTable;
use crate::particles::Particles;
use crate::scene::limits::{echo_fixed, echo_number, echo_significant};
use crate::scene::{ErrorKind, MaterialModel, MaterialSpec, Scene, SceneError};
use crate::simulation::RunError;
use nalgebra::SVector;
use psmpm_basis::Basis;

/// The driver of a scene's run: the mass strategy and the materials (of its bodies)
/// are chosen by the scene, at run time.
pub type SceneDriver<const D: usize, B> =
    Driver<f64, D, B, Box<dyn MassStrategy<f64>>, MaterialTable>;

/// A scene's basis (in one of its typed choices, or chosen), its smallest mesh
/// length and the unit normals of its slip walls.
pub(crate) struct Domain<B> {
    /// The basis.
    pub basis: B,
    /// Smallest edge (2D) or element length (1D).
    pub h: f64,
    /// Tag and unit normal of every slip wall.
    pub walls: Vec<(String, [f64; 2])>,
    /// The vertices where two slip walls meet at a bend.
    pub bends: Vec<mesh::Bend>,
    /// The geometry of the contact walls, all tags in one.
    pub contacts: Option<crate::contact::WallGeometry>,
    /// What the mesh and walls make the run warn about.
    pub warnings: Vec<String>,
}

impl<B> Domain<B> {
    /// The basis, and the rest of the domain to give another basis
    /// ([`Domain::with_basis`]): a scene's basis is chosen at run time, its type
    /// per branch.
    pub fn take_basis(self) -> (B, Domain<()>) {
        let Domain {
            basis,
            h,
            walls,
            bends,
            contacts,
            warnings,
        } = self;
        (
            basis,
            Domain {
                basis: (),
                h,
                walls,
                bends,
                contacts,
                warnings,
            },
        )
    }
}

impl Domain<()> {
    /// This domain with `basis`.
    pub fn with_basis<C>(self, basis: C) -> Domain<C> {
        Domain {
            basis,
            h: self.h,
            walls: self.walls,
            bends: self.bends,
            contacts: self.contacts,
            warnings: self.warnings,
        }
    }
}

/// A run ready to step.
pub(crate) struct Prepared<const D: usize, B: Basis<f64, D>> {
    /// The driver, with particles, effects, fixes and walls.
    pub driver: SceneDriver<D, B>,
    /// The time step.
    pub dt: f64,
    /// Steps to take.
    pub steps: usize,
    /// The critical time step at the start, when it could be estimated.
    pub dt_critical: Option<f64>,
    /// Basis functions.
    pub functions: usize,
    /// The reference solution.
    pub solution: Option<Solution>,
    /// The lower corner of the first body's bounding box (the origin of the
    /// reference solutions).
    pub origin: [f64; 2],
    /// The number of particles of each body, in the order of the scene's bodies:
    /// the particles of body `b` follow those of the bodies before it.
    pub body_sizes: Vec<usize>,
    /// What the set-up saw that the run's summary should say
    /// ([`held_traction_warnings`]).
    pub warnings: Vec<String>,
}

/// Sets up the run of `scene` on `domain`: material, particles with their initial
/// states, effects, driver, time step.
pub(crate) fn set_up<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    domain: Domain<B>,
) -> Result<Prepared<D, B>, RunError> {
    // A Courant number of 1 or more is refused before anything is built.
    if let (Some(c), false) = (scene.time.courant, scene.time.allow_above_critical) {
        if c >= 1.0 {
            return Err(SceneError::new(
                "time.courant",
                ErrorKind::Value,
                format!(
                    "{} puts the time step at or above the critical step, where the explicit update is unstable: give a value below 1 (0.5 serves smooth motion, 0.25 impacts and large strains), or set `allow_above_critical = true` in `[time]` (`--allow-above-critical`) to run anyway",
                    echo_number(c)
                ),
            )
            .into());
        }
    }
    let solution = Solution::new(scene);
    let mut lattice = particle_lattice(scene)?;
    // The driver's arrays, checked against the memory the process may use.
    let copies = if scene.body_contact() {
        lattice.body_sizes.len().max(1)
    } else {
        1
    };
    memory::check(
        scene,
        &memory::Counts::placed(
            scene,
            &lattice.body_sizes,
            domain.basis.num_elements() / copies,
        ),
    )?;
    let material = materials::<D>(scene, &lattice)?;
    let mut origin = [0.0; 2];
    origin[..D].copy_from_slice(&lattice.bounds[0].0[..D]);
    let mut particles = particles::place::<D>(scene, &lattice);
    particles::apply_initial_states(scene, &lattice, solution, origin, &mut particles)?;
    let effects = build_effects(
        scene,
        &particles,
        &lattice.body_sizes,
        domain.contacts.as_ref(),
        &domain.basis,
    )?;
    // The lattice's positions and volumes are in `particles` now: free them before
    // the driver allocates (they would otherwise count in the run's peak memory).
    let body_sizes = std::mem::take(&mut lattice.body_sizes);
    drop(lattice);
    let Domain {
        basis,
        h,
        walls,
        bends,
        contacts,
        warnings: domain_warnings,
    } = domain;
    let functions = basis.num_functions();
    // With `courant` the step is fixed by `time_steps`, from the critical step; this
    // one (a mesh-based guess) only sets the driver up.
    let dt = scene.dt(h);
    if !(dt.is_normal() && dt > 0.0) {
        // A fixed `dt` is validated; this is the Courant-number guess `C h / c`.
        return Err(SceneError::new(
            "time.courant",
            ErrorKind::Conflict,
            format!(
                "the time step C h / c = {} from courant = {}, element size h = {} and P-wave speed c = {} (of the materials' young, poisson and density) is not a finite positive number: the element size and the materials' constants are too far apart",
                echo_number(dt),
                echo_number(scene.time.courant.unwrap_or(f64::NAN)),
                echo_number(h),
                echo_number(scene.wave_speed())
            ),
        )
        .into());
    }
    let mut driver = driver(
        scene,
        basis,
        particles,
        material,
        effects,
        dt,
        &walls,
        &bends,
        &body_sizes,
    )?;
    if scene.body_contact() {
        // Each body's particles in its own copy of the basis (`PerBody`): the
        // driver located them all in the first.
        let per_body = driver.basis.num_elements() / body_sizes.len().max(1);
        let mut first = 0;
        for (b, &n) in body_sizes.iter().enumerate() {
            for e in &mut driver.particles.element[first..first + n] {
                *e += b * per_body;
            }
            first += n;
        }
    }
    driver.set_body_sizes(&body_sizes);
    let mut warnings = domain_warnings;
    warnings.extend(reference_warnings(scene));
    warnings.extend(held_traction_warnings(scene, &driver));
    warnings.extend(held_motion_warnings(scene, &driver, &body_sizes));
    if let Some(walls) = &contacts {
        warnings.extend(started_close_warnings(
            scene,
            walls,
            &driver.particles,
            &body_sizes,
        ));
    }
    let (dt, steps, dt_critical, failed) = time_steps(scene, &mut driver, &body_sizes, dt)?;
    warnings.extend(failed);
    warnings.extend(soft_contact_warnings(
        scene,
        &driver.particles,
        &body_sizes,
        dt,
    ));
    if let (Some(critical), None, false) = (
        dt_critical,
        scene.time.courant,
        scene.time.allow_above_critical,
    ) {
        if dt > critical {
            // The lumped mass's step tells a nearly singular system from a step that
            // is simply too long.
            let lumped = driver.lumped_critical_time_step().ok();
            let cause = driver.singular_mass_cause_with(lumped.map(|l| (critical, l)));
            return Err(above_critical(scene, dt, critical, cause).into());
        }
    }
    if let (Some(critical), false, true) = (
        dt_critical,
        scene.time.allow_above_critical,
        scene.time.watch,
    ) {
        let (courant, trigger) = watch_thresholds(scene.time.courant, dt / critical);
        driver.watch_critical_step(courant, trigger);
    }
    Ok(Prepared {
        driver,
        dt,
        steps,
        dt_critical,
        functions,
        solution,
        origin,
        body_sizes,
        warnings,
    })
}

/// A warning for each contact wall whose springs, at the run's step `dt`, would let
/// a body resting on it under gravity sink by more than half its contact distance:
/// a particle's spring is `m_p (κ/Δt)²` stiff, the bottom particle of a body of
/// height `H` (along `g`) and spacing `h` carries about `ρ |g| H h`, so it sinks by
/// about `|g| H Δt² / (h κ²)` against a contact distance of `h / 2`; it holds for
/// `κ ≥ 2 Δt √(|g| H) / h`. A user's wall at `stiffness = 1e-3` was told after the
/// body went through to halve `courant`, and went through again: the springs were
/// about 1e5 times too soft. The first wall and the body that sinks most are named.
/// What a `[reference]` assumes and the scene does not give, on a `blocks` or
/// `interval` mesh (whose sides' names say where the walls are): the vibrating
/// bar is free vibration of a bar held along x at both ends, the columns are held
/// along their axis at their lower end (standing on it or hanging from it), and
/// the settling column (B5b) is undamped.
/// Otherwise the error measures another motion (a bar whose right wall was left
/// out scored `E_u` 2.8e-7, as good as the held bar's 1.4e-7, at the half period
/// of the fixed–free bar it became; a column hung from its top scored
/// `max-relative-sigma-yy` 1.05 while matching its own profile to 4.5 %).
fn reference_warnings(scene: &Scene) -> Vec<String> {
    use crate::scene::{Component, EffectSpec, MeshSpec, Reference};
    let Some(reference) = &scene.reference else {
        return Vec::new();
    };
    if !matches!(
        scene.mesh,
        MeshSpec::Blocks { .. } | MeshSpec::Interval { .. }
    ) {
        return Vec::new();
    }
    let one_d = scene.dim == 1;
    let holds = |tag: &str, axis: Component| scene.side_holds(tag, axis);
    let axis_name = |c: Component| if c == Component::X { "x" } else { "y" };
    let kind = |e: &EffectSpec| kind_of(e);
    let mut missing = Vec::new();
    let what = match reference {
        Reference::VibratingBar { .. } => {
            for side in ["left", "right"] {
                if !holds(side, Component::X) {
                    missing.push(format!("no wall holds x at `{side}`"));
                }
            }
            for (k, e) in scene.effects.iter().enumerate() {
                missing.push(format!("effect[{k}] (`{}`) acts on it", kind(e)));
            }
            "the free vibration of a bar held along x at both ends"
        }
        Reference::ColumnSelfWeight {} | Reference::ColumnEquilibrium {} => {
            let axis = if one_d { Component::X } else { Component::Y };
            // The end the references hold the column at, its lower end (`Y = 0`),
            // for either sign of `g`: with `g` toward it the column stands on it,
            // with `g` away from it the column hangs from it (a bar hanging from
            // `x = 0` with `g = [10]` was told to hold its free end).
            let end = if one_d { "left" } else { "bottom" };
            if !holds(end, axis) {
                missing.push(format!(
                    "no wall holds {} at `{end}`, the lower end the reference holds it at",
                    axis_name(axis)
                ));
            }
            if matches!(reference, Reference::ColumnSelfWeight {}) {
                for (k, e) in scene.effects.iter().enumerate() {
                    if matches!(e, EffectSpec::Damping { .. }) {
                        missing.push(format!("effect[{k}] (`damping`) slows its settling"));
                    }
                }
            }
            "a column held along its axis at its lower end (standing on it, or hanging from it when gravity points away)"
        }
        Reference::AxisAligned { .. } => return Vec::new(),
    };
    if missing.is_empty() {
        return Vec::new();
    }
    vec![format!(
        "the `[reference]` (`{}`) is {what}, but {}: its error measures another motion than this scene's; add what it assumes, or leave out [reference]",
        kind_of(reference),
        missing.join(", ")
    )]
}

/// The `kind` of a table a scene tags with it (an `[[effect]]`, the
/// `[reference]`), as the scene writes it.
fn kind_of(table: &impl serde::Serialize) -> String {
    serde_json::to_value(table)
        .ok()
        .and_then(|v| v.get("kind").and_then(|k| k.as_str()).map(String::from))
        .unwrap_or_default()
}

fn soft_contact_warnings<const D: usize>(
    scene: &Scene,
    particles: &crate::particles::Particles<f64, D>,
    body_sizes: &[usize],
    dt: f64,
) -> Vec<String> {
    use crate::scene::limits::echo_significant;
    let Some(g) = scene.gravity() else {
        return Vec::new();
    };
    let g_norm = g.iter().map(|c| c * c).sum::<f64>().sqrt();
    if g_norm <= 0.0 || dt.is_nan() || dt <= 0.0 {
        return Vec::new();
    }
    let sizes: Vec<usize> = if body_sizes.iter().sum::<usize>() == particles.len() {
        body_sizes.to_vec()
    } else {
        vec![particles.len()]
    };
    // Per body: its height along g and its mean spacing.
    let mut first = 0;
    let bodies: Vec<(f64, f64)> = sizes
        .iter()
        .map(|&n| {
            let range = first..first + n;
            first += n;
            let (mut low, mut high, mut spacing) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
            for p in range {
                let along: f64 = (0..D).map(|k| particles.x[p][k] * g[k] / g_norm).sum();
                low = low.min(along);
                high = high.max(along);
                spacing += particles.volume0[p].powf(1.0 / D as f64);
            }
            let h = spacing / n.max(1) as f64;
            (high - low + h, h)
        })
        .collect();
    let mut warnings = Vec::new();
    for effect in &scene.effects {
        let crate::scene::EffectSpec::ContactWall { tag, stiffness } = effect else {
            continue;
        };
        let sink =
            |(height, h): (f64, f64)| g_norm * height * dt * dt / (h * stiffness * stiffness);
        let Some((b, &(height, h))) = bodies
            .iter()
            .enumerate()
            .filter(|(_, &(_, h))| h > 0.0)
            .max_by(|a, c| (sink(*a.1) / a.1 .1).total_cmp(&(sink(*c.1) / c.1 .1)))
        else {
            continue;
        };
        let depth = sink((height, h));
        if depth <= 0.25 * h {
            continue;
        }
        let holds = 2.0 * dt * (g_norm * height).sqrt() / h;
        let who = if bodies.len() > 1 {
            format!("body[{b}]")
        } else {
            "the body".to_string()
        };
        warnings.push(format!(
            "contact wall `{tag}`: at `stiffness = {}` and the step {}, {who} resting on it under gravity would sink about {} into its springs (|g| H Δt² / (h κ²), H = {} its height, h = {} its spacing), more than half its contact distance ({}): it will be pressed through the wall. Its springs hold a resting body for `stiffness` of {} or more (at most 1), or with a step shorter by {:.1} times (`time.courant`); a body striking it needs more (an L body striking a wedge at 5.9 m/s went through at 0.02 and 0.1 and held at 0.25 and at the default 0.5)",
            echo_significant(*stiffness, 3),
            echo_significant(dt, 3),
            echo_significant(depth, 3),
            echo_significant(height, 3),
            echo_significant(h, 3),
            echo_significant(0.5 * h, 3),
            echo_significant(holds, 2),
            (depth / (0.25 * h)).sqrt(),
        ));
        break;
    }
    warnings
}

/// A warning for each body with particles that start in a contact wall's contact
/// layer ([`crate::contact::started_close`]).
fn started_close_warnings<const D: usize>(
    scene: &Scene,
    walls: &crate::contact::WallGeometry,
    particles: &crate::particles::Particles<f64, D>,
    body_sizes: &[usize],
) -> Vec<String> {
    let distances = crate::contact::contact_distances(
        particles,
        body_sizes,
        &crate::simulation::lattice_stretch(scene),
    );
    let close = crate::contact::started_close(walls, particles, &distances);
    let mut warnings = Vec::new();
    let mut first = 0;
    for (b, &n) in body_sizes.iter().enumerate() {
        let body: Vec<&(usize, f64)> = close
            .iter()
            .filter(|(p, _)| (first..first + n).contains(p))
            .collect();
        first += n;
        let Some(&&(p, distance)) = body.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
            continue;
        };
        let nominal = distances[p];
        let x = &particles.x[p];
        warnings.push(format!(
            "body[{b}]: {} particle{} start{} closer to a contact wall than {} of the distance at which it pushes (half a particle spacing, {}), the nearest (particle {p}) {} from it at [{}]: the body overlaps the wall's contact layer, so these particles' springs have that little room, and a step's small motion can take them through the wall; move the body off so that its particles start at least {} from the wall (a lattice not aligned with a slanted wall puts some particles closer than its outline: move such a body off by half a spacing)",
            body.len(),
            if body.len() == 1 { "" } else { "s" },
            if body.len() == 1 { "s" } else { "" },
            crate::driver::STARTED_CLOSE,
            echo_significant(nominal, 3),
            echo_significant(distance.max(0.0), 3),
            x.iter()
                .map(|c| echo_significant(*c, 5))
                .collect::<Vec<_>>()
                .join(", "),
            echo_significant(nominal, 3),
        ));
    }
    warnings
}

/// A warning for each traction whose load the walls take for the most part: the
/// share of its particles' force that falls on functions the walls (`fix`) hold
/// along it ([`crate::driver::Driver::share_held_by_walls`]) at least
/// [`HELD_TRACTION`]: a box on the particles next to a no-slip wall loads the wall
/// more than the body, which the run would not show otherwise.
fn held_traction_warnings<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    driver: &SceneDriver<D, B>,
) -> Vec<String> {
    scene
        .effects
        .iter()
        .enumerate()
        .filter_map(|(i, spec)| {
            let crate::scene::EffectSpec::Traction {
                min, max, traction, ..
            } = spec
            else {
                return None;
            };
            let loaded = effects::traction_particles(&driver.particles, min, max);
            let held = driver.share_held_by_walls(&loaded, traction);
            (held >= HELD_TRACTION).then(|| {
                format!(
                    "effect[{i}] (traction): {:.0} % of its load falls on functions the walls (`fix`) hold along it, so that part goes into the wall and moves nothing: the box (`min`, `max`) selects particles next to a wall that holds the load's direction; move it away from the wall, or let the wall slide along the load (`fix = [\"normal\"]`) if that is the physics",
                    100.0 * held
                )
            })
        })
        .collect()
}

/// A warning for each body whose initial motion the walls (`fix`) hold for
/// [`HELD_MOMENTUM`] of it or more ([`crate::driver::Driver::momentum_held_by_walls`]):
/// a wall holds its functions both ways, so a body started against it and moving
/// away stays stuck to it, and one moving into it stops dead; a motion that
/// vanishes at the walls (a bar vibrating between two) is not warned about
/// ([`HELD_SPEED`]). A user's L-shaped
/// body launched at (3, 3) m/s from the corner of two slip walls (`fix =
/// ["normal"]`) stayed in the corner, its centre at (0.31, 0.41) at t = 0.6
/// against (2.11, 0.45) in free flight, with no warning; with contact walls it
/// flew off as expected.
fn held_motion_warnings<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    driver: &SceneDriver<D, B>,
    body_sizes: &[usize],
) -> Vec<String> {
    let walls: Vec<String> = scene
        .boundaries
        .iter()
        .filter(|b| !b.fix.is_empty())
        .map(|b| format!("`{}`", b.tag))
        .collect();
    if walls.is_empty() {
        return Vec::new();
    }
    let sizes: Vec<usize> = if body_sizes.iter().sum::<usize>() == driver.particles.len() {
        body_sizes.to_vec()
    } else {
        vec![driver.particles.len()]
    };
    let mut first = 0;
    let mut warnings = Vec::new();
    for (b, &n) in sizes.iter().enumerate() {
        let held = driver
            .motion_held_by_walls(first..first + n)
            .iter()
            .filter(|&&(_, speed)| speed >= HELD_SPEED)
            .map(|&(share, _)| share)
            .fold(0.0, f64::max);
        first += n;
        if held >= HELD_MOMENTUM {
            // Contact walls are 2D; in 1D a body meant to strike the wall starts
            // an element away from it.
            let free_body_fix = if D == 1 {
                "a body that should strike the wall: start it at least an element away from it (it then rebounds from the fixed wall; contact walls are 2D)"
            } else {
                "a body that should strike or leave the wall: start it at least an element away from the walls (a body that reaches a fixed wall from there rebounds from it), or make the wall a contact wall (`[[effect]] kind = \"contact-wall\"` with its `tag`, in place of the `[[boundary]]`), which only pushes"
            };
            warnings.push(format!(
                "body[{b}]: {:.0} % of its initial momentum falls on functions the walls (`fix`: {}) hold, which they hold both ways: the particles near such a wall take its velocity at the first step, so a body started against it and moving away stays stuck to it, and one moving into it stops dead; {free_body_fix}; a body meant to be held there (fixed to the wall) keeps only the motion the wall allows: to start from such a motion, give an initial velocity that vanishes at the wall (`kind = \"linear\"`)",
                100.0 * held,
                walls.join(", ")
            ));
        }
    }
    warnings
}

/// The share of a body's initial momentum (in a component) held by the walls from
/// which the run warns ([`held_motion_warnings`]), if the speed there is
/// [`HELD_SPEED`] of the mean or more.
pub(crate) const HELD_MOMENTUM: f64 = 0.01;

/// The speed at the held functions over the body's mean speed (in a component)
/// from which a held share counts ([`held_motion_warnings`]): a motion the walls
/// allow vanishes at them. Measured: the vibrating bars (`vibrating-bar`,
/// `-thesis`, `-1d`, `docs/examples/student-bar-1d.toml`, `axis-aligned`): shares
/// 1.3–2.4 % at speeds of 0.16–0.30 of the mean; a user's L-shaped body launched
/// from the corner of two slip walls: 8 % at 1.0.
pub(crate) const HELD_SPEED: f64 = 0.5;

/// The share of a traction's load taken by the walls above which the run warns
/// ([`held_traction_warnings`]).
pub(crate) const HELD_TRACTION: f64 = 0.5;

/// The law of every particle of `lattice` in `D` dimensions: its body's material.
fn materials<const D: usize>(scene: &Scene, lattice: &Lattice) -> Result<MaterialTable, RunError> {
    let laws = (0..scene.bodies.len())
        .map(|b| {
            let field = if scene.bodies[b].material.is_some() {
                format!("body[{b}].material")
            } else {
                "material".to_string()
            };
            law::<D>(scene.body_material(b))
                .map_err(|e| SceneError::new(field, ErrorKind::Value, e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    MaterialTable::new(&laws, &lattice.body_of_particles())
        .map_err(|e| SceneError::new("body", ErrorKind::Value, e.to_string()).into())
}

/// The law a material declares, in `D` dimensions.
fn law<const D: usize>(m: &MaterialSpec) -> Result<AnyMaterial, MaterialError> {
    let elastic = Elastic::new(m.young, m.poisson, m.density)?;
    Ok(match m.model {
        MaterialModel::LinearElastic => AnyMaterial::Linear(LinearElastic::new(elastic, D)),
        MaterialModel::NeoHookean => AnyMaterial::NeoHookean(NeoHookean::new(elastic, D)),
        MaterialModel::Corotational => AnyMaterial::Corotational(Corotational::new(elastic, D)),
    })
}

/// The bounding box of the mesh of `basis`, for messages: `[x0, x1] × [y0, y1]`.
pub(crate) fn mesh_extent<const D: usize, B: Basis<f64, D> + ?Sized>(
    basis: &B,
) -> ([f64; D], [f64; D]) {
    let (mut lo, mut hi) = ([f64::INFINITY; D], [f64::NEG_INFINITY; D]);
    let mut pieces = Vec::new();
    for e in 0..basis.num_elements() {
        pieces.clear();
        basis.polynomial_pieces(e, &mut pieces);
        for p in &pieces {
            for k in 0..D {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (lo, hi)
}

/// Why a particle at `position` is in no element of a mesh whose bounding box is
/// `(lo, hi)`: in a hole or notch when it lies inside the box, outside otherwise.
fn outside_the_mesh<const D: usize>(position: &[f64], (lo, hi): ([f64; D], [f64; D])) -> String {
    let span = (0..D)
        .map(|k| {
            // Significant digits: a bound computed from the mesh's vertices carries
            // round-off (`0.6000000000000001`).
            format!(
                "[{}, {}]",
                crate::scene::limits::echo_significant(lo[k], 10),
                crate::scene::limits::echo_significant(hi[k], 10)
            )
        })
        .collect::<Vec<_>>()
        .join(" × ");
    let inside_box = (0..D).all(|k| position.get(k).is_some_and(|&x| lo[k] <= x && x <= hi[k]));
    if inside_box {
        let position = crate::driver::point(position);
        format!("the particle at {position} lies in a hole or notch of the mesh (inside its bounding box {span}, but in no element); the body must not overlap the mesh's holes (`[[mesh.holes]]`) or the parts of its outline cut away")
    } else {
        let position = crate::driver::point(position);
        format!("the particle at {position} lies outside the mesh, which spans {span}; the body must lie inside the meshed domain")
    }
}

/// The error for particle `particle` at `position` outside a mesh of bounding box
/// `extent`, named against its body (`body_sizes`, the bodies' particle counts in
/// order): a box past the mesh's low side is its `min`'s doing, past the high side
/// its `max`'s; in a hole, the whole body's.
pub(crate) fn particle_outside<const D: usize>(
    scene: &Scene,
    particle: usize,
    position: &[f64],
    extent: ([f64; D], [f64; D]),
    body_sizes: &[usize],
) -> SceneError {
    let mut first = 0;
    let body = body_sizes
        .iter()
        .position(|&n| {
            first += n;
            particle < first
        })
        .unwrap_or(0);
    let (lo, hi) = extent;
    let below = (0..D).any(|k| position.get(k).is_some_and(|&x| x < lo[k]));
    let above = (0..D).any(|k| position.get(k).is_some_and(|&x| x > hi[k]));
    let field = match scene.bodies.get(body) {
        Some(b) if b.shape.is_box() && below => format!("body[{body}].min"),
        Some(b) if b.shape.is_box() && above => format!("body[{body}].max"),
        _ => format!("body[{body}]"),
    };
    SceneError::new(
        field,
        ErrorKind::Conflict,
        outside_the_mesh(position, extent),
    )
}

/// The one place a scene's driver is built: fixes from the boundary conditions,
/// the scene's mass strategy, the condition estimate on request, slip walls. A
/// particle outside the mesh is reported against its body.
#[allow(clippy::too_many_arguments)]
fn driver<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    basis: B,
    particles: Particles<f64, D>,
    material: MaterialTable,
    effects: Vec<Box<dyn Effect<f64, D>>>,
    dt: f64,
    walls: &[(String, [f64; 2])],
    bends: &[mesh::Bend],
    body_sizes: &[usize],
) -> Result<SceneDriver<D, B>, RunError> {
    let mut fixes: Vec<Fix> = scene
        .boundaries
        .iter()
        .flat_map(|bc| {
            bc.fix.iter().filter_map(|c| {
                c.axis().map(|component| Fix {
                    tag: bc.tag.clone(),
                    component,
                })
            })
        })
        .collect();
    // A slip wall along an axis fixes one component of its functions: that is a
    // fixed set, eliminated from the system, not a general constraint projected
    // after the solve. Both give the same constrained minimiser, but the projection
    // of a reduced (extended) system, whose functions' values follow their
    // neighbours, pumped energy into a block bouncing on a slip floor (`docs/stability.md`,
    // "Slip walls along an axis").
    let mut oblique = Vec::new();
    for (tag, normal) in walls {
        let along: Vec<usize> = (0..D).filter(|&k| normal[k] != 0.0).collect();
        match along[..] {
            [component] => fixes.push(Fix {
                tag: tag.clone(),
                component,
            }),
            _ => oblique.push((tag, normal)),
        }
    }
    let extent = mesh_extent(&basis);
    let mut driver: SceneDriver<D, B> = Driver::new(
        basis,
        particles,
        material,
        scene.mass.build::<f64>(),
        &fixes,
        effects,
        dt,
    )
    .map_err(|e| match e {
        SetupError::ParticleOutside { particle, position } => {
            particle_outside(scene, particle, &position, extent, body_sizes)
        }
        SetupError::Boundary { tag, message } => SceneError::new(
            boundary_field(scene, &tag),
            ErrorKind::Conflict,
            format!("boundary condition on `{tag}`: {message}"),
        ),
        SetupError::Basis(e) => SceneError::new("basis", ErrorKind::Conflict, e.to_string()),
        e @ SetupError::TooManyFunctions { .. } => {
            SceneError::new("mesh", ErrorKind::Value, e.to_string())
        }
        e @ SetupError::TooManyParticles { .. } => {
            SceneError::new("body", ErrorKind::Value, e.to_string())
        }
    })?;
    driver.estimate_condition = scene.output.condition;
    for (tag, normal) in oblique {
        let n = SVector::<f64, D>::from_fn(|k, _| normal[k]);
        driver.add_slip_wall(tag, &n).map_err(|e| {
            SceneError::new(
                boundary_field(scene, tag),
                ErrorKind::Conflict,
                e.to_string(),
            )
        })?;
    }
    // Slip walls meeting at a bend share the vertex's value through their mean
    // normal (else the vertex holds still and a body sliding over it strikes it).
    let bends: Vec<SlipBend<f64, D>> = bends
        .iter()
        .map(|b| SlipBend {
            tags: b.tags.clone(),
            normals: b.normals.map(|n| SVector::<f64, D>::from_fn(|k, _| n[k])),
            vertex: SVector::<f64, D>::from_fn(|k, _| b.vertex[k]),
        })
        .collect();
    driver.average_slip_bends(&bends).map_err(|e| {
        SceneError::new(
            boundary_field(scene, &bends[0].tags[0]),
            ErrorKind::Conflict,
            e.to_string(),
        )
    })?;
    Ok(driver)
}

/// The Courant number of the sub-steps and the ratio `Δt / Δt_crit` above which a
/// step is split, for the watch over the critical step while the bodies move
/// ([`crate::driver::Driver::watch_critical_step`]), from the scene's `courant` or,
/// with a fixed `dt`, its ratio `start` to the critical step at the start.
///
/// With `courant = C` a step is split when it is above `min(1.25 C, (1 + C) / 2)` of
/// the current critical step (within a quarter of `C`, and halfway to 1), into
/// sub-steps at `C`: `courant` keeps its meaning as the bodies move over the mesh,
/// while the small changes of the estimate as a body at rest settles do not split
/// steps. With a fixed `dt` only a step near the limit is split (above 0.9 of the
/// critical step or, when the scene starts closer to it, above its ratio at the
/// start plus 3 %, up to 0.97: the estimate's own scatter, about 2 %, does not
/// split steps), into sub-steps at 0.7: the scene's step is kept wherever it is
/// stable. Once split, a step goes back to fewer sub-steps only below the middle of
/// the two thresholds ([`crate::driver::Driver::watch_critical_step`]).
pub(crate) fn watch_thresholds(courant: Option<f64>, start: f64) -> (f64, f64) {
    match courant {
        Some(c) => (c, (1.25 * c).min(0.5 * (1.0 + c))),
        None => (0.7, (1.03 * start).clamp(0.9, 0.97)),
    }
}

/// The time step, the number of steps and the critical step at the start: a fixed
/// `dt`, or with `courant` that fraction of the critical step, shortened so that a
/// whole number of steps ends at `t_end` (a failure of the estimate is the failure
/// of step 1, reported by the first step itself).
fn time_steps<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    driver: &mut SceneDriver<D, B>,
    body_sizes: &[usize],
    dt: f64,
) -> Result<(f64, usize, Option<f64>, Option<String>), RunError> {
    use crate::scene::limits::{echo_number, MAX_STEPS};
    let start = driver.critical_time_step();
    let mut dt_critical = start.as_ref().ok().copied().filter(|c| c.is_finite());
    let rigid = dt_critical.and_then(|c| rigid_bodies(scene, driver, body_sizes, c));
    if let Some((crossing, _)) = &rigid {
        dt_critical = Some(*crossing);
        driver.set_critical_step(*crossing);
    }
    let rigid = rigid
        .map(|(_, warning)| warning)
        .or_else(|| dt_critical.and_then(|c| unresolved_body(scene, driver, body_sizes, c)));
    match scene.time.courant {
        Some(c) => {
            let t_end = scene.time.t_end;
            let step = c * dt_critical.unwrap_or(dt / c);
            let ratio = t_end / step;
            // As for a fixed `dt` (whose count is rounded): an end time shorter than
            // half a step is shorter than one step.
            if ratio < 0.5 {
                return Err(SceneError::new(
                    "time.t_end",
                    ErrorKind::Conflict,
                    format!(
                        "is shorter than one time step (t_end = {}, courant = {} gives dt = {step:.3e}): give `t_end` of at least {}, or a fixed `dt` below it (the critical step grows as h √(ρ / E): E = {} here)",
                        echo_number(t_end),
                        echo_number(c),
                        crate::scene::limits::echo_significant(step, 3),
                        echo_number(scene.material.young)
                    ),
                )
                .into());
            }
            if ratio.is_nan() || ratio > MAX_STEPS as f64 {
                // A nearly singular mass system makes the step small (what
                // `above_critical` names for a fixed `dt`), else the waves do.
                let lumped = dt_critical.and_then(|_| driver.lumped_critical_time_step().ok());
                let cause = match driver
                    .singular_mass_cause_with(dt_critical.zip(lumped))
                {
                    Some(why) => format!(
                        "The critical step is that small because the mass matrix is nearly singular: {why}"
                    ),
                    None => wave_speed_hint(scene),
                };
                return Err(SceneError::new(
                    "time.t_end",
                    ErrorKind::Value,
                    format!(
                        "t_end = {} with courant = {} (dt = {}) takes {ratio:.3e} steps, above the limit of {MAX_STEPS}. {cause}",
                        echo_number(t_end),
                        echo_number(c),
                        crate::scene::limits::echo_significant(step, 4),
                    ),
                )
                .into());
            }
            let steps = ratio.ceil().max(1.0) as usize;
            crate::scene::limits::check_tracked_history(
                scene.output.tracked.len(),
                steps,
                "t_end / (courant × the critical step)",
            )
            .map_err(|m| SceneError::new("output.tracked", ErrorKind::Value, m))?;
            let dt = t_end / steps as f64;
            driver.set_dt(dt);
            let failed = start.err().map(|e| {
                format!(
                    "the critical step could not be estimated at the start ({e}); the run steps at {} = courant × h / c, a guess from the element size and the P-wave speed that knows neither the basis nor the mass strategy, so `courant` does not mean the share of the critical step it means elsewhere, and the step is not watched",
                    crate::scene::limits::echo_significant(dt, 3)
                )
            });
            Ok((dt, steps, dt_critical, failed.or(rigid)))
        }
        None => Ok((
            dt,
            (scene.time.t_end / dt).round().max(1.0) as usize,
            dt_critical,
            start
                .err()
                .map(|e| {
                    format!(
                        "the critical step could not be estimated at the start ({e}): the scene's `dt` is not checked against it, and the step is not watched"
                    )
                })
                .or(rigid),
        )),
    }
}

/// The critical step estimated at the start over the time the fastest P-wave
/// takes to cross the widest element holding particles, above which the system
/// solved holds almost no stiffness. Measured on every example and built-in
/// scene with PS and PL (1D: B-spline and PL): 0.09 to 1.03; for bodies smaller
/// than their elements whose functions a strategy extends into one or two (a
/// disk of radius 0.05 in blocks of 1, PS; radius 0.1 in blocks of 0.5, PL):
/// 1e12 to 5e15. Since 2026-12-07 the default keeps linear precision there
/// (`docs/stability.md`, "A body smaller than its elements") and `extended`,
/// which keeps its constant rows, is the strategy this still finds (that disk:
/// 1.5e16).
pub const RIGID_CRITICAL: f64 = 10.0;

/// When the critical step estimated at the start, `critical`, is more than
/// [`RIGID_CRITICAL`] times the time the fastest P-wave takes to cross the widest
/// element holding particles: that crossing time (the step `courant` then
/// measures) and the warning, naming the body smallest against its elements.
/// A system without stiffness moves its bodies rigidly: a disk of radius 0.05
/// in blocks of 1 (PS, default mass) had a critical step of 2.1e12 (`courant`
/// gave a step of 5e11), and at a fixed step of 1e-3 a strain energy of 1e-27.
fn rigid_bodies<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    driver: &SceneDriver<D, B>,
    body_sizes: &[usize],
    critical: f64,
) -> Option<(f64, String)> {
    use crate::scene::limits::echo_significant;
    let crossing = driver.widest_occupied_element() / scene.wave_speed();
    if !(crossing > 0.0 && crossing.is_finite() && critical > RIGID_CRITICAL * crossing) {
        return None;
    }
    let extents = driver.body_extents(body_sizes);
    let (b, &(extent, _, width)) = extents
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 .0 / a.1 .2).total_cmp(&(b.1 .0 / b.1 .2)))?;
    let who = if extents.len() > 1 {
        format!("body {} ", b + 1)
    } else {
        "the body ".to_string()
    };
    let mesh_key = match scene.mesh {
        crate::scene::MeshSpec::Polygon { .. } => "`mesh.edge_length`",
        crate::scene::MeshSpec::Blocks { .. } => "`mesh.blocks`",
        crate::scene::MeshSpec::Interval { .. } => "`mesh.elements`",
        crate::scene::MeshSpec::Gmsh { .. } => "a finer Gmsh mesh",
    };
    Some((
        crossing,
        format!(
            "the critical step used, {}, is the time the fastest P-wave takes to cross the widest element holding particles, not the step estimated for the mass strategy's system ({critical:.3e}, {:.1e} times longer): that system holds almost no stiffness, so the bodies move rigidly, without strain; {who}spans {} across, {} the width of the elements it lies in ({}), and a body within one or two elements gives its functions so few particles each that the strategy expresses them through one or two, which only translate. Refine the mesh so that the body spans at least three elements (elements about {} wide or less: {mesh_key})",
            echo_significant(crossing, 3),
            critical / crossing,
            echo_significant(extent, 3),
            if extent < width { "less than" } else { "about" },
            echo_significant(width, 3),
            echo_significant(extent / 3.0, 2),
        ),
    ))
}

/// The warning for a body the mesh does not resolve: the critical step
/// `critical` is longer than the time a P-wave takes to cross the body (its
/// extent over its material's P-wave speed), so that the body's own vibrations
/// are not represented. Measured as `critical c / extent` over every example and
/// built-in (PS and PL; 1D B-spline and PL): at most 0.35; a user's disk of
/// radius 0.075 in blocks of 1 (PS): 7.3, its first strain peak at 0.39 s
/// against 0.0043 s on a mesh that resolves it, with no warning.
///
/// Or a body whose largest extent is below the width of the elements it lies
/// in: since the default keeps linear precision for a body smaller than its
/// elements (`docs/stability.md`, "A body smaller than its elements") its
/// critical step is that of its own affine modes (that disk: 0.42 of the
/// crossing time) and the test above is silent, but one affine field is all the
/// basis gives it.
fn unresolved_body<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    driver: &SceneDriver<D, B>,
    body_sizes: &[usize],
    critical: f64,
) -> Option<String> {
    use crate::scene::limits::echo_significant;
    let extents = driver.body_extents(body_sizes);
    let who = |b: usize| {
        if extents.len() > 1 {
            format!("body {}", b + 1)
        } else {
            "the body".to_string()
        }
    };
    let Some((b, ratio, extent, width)) = extents
        .iter()
        .enumerate()
        .map(|(b, &(extent, _, width))| {
            let c = scene.body_wave_speed(b.min(scene.bodies.len().saturating_sub(1)));
            (b, critical * c / extent, extent, width)
        })
        .filter(|(_, r, _, _)| r.is_finite())
        .max_by(|a, c| a.1.total_cmp(&c.1))
        .filter(|&(_, ratio, _, _)| ratio > UNRESOLVED_BODY)
    else {
        // The body smallest against its elements, if within one.
        let (b, &(_, largest, width)) = extents
            .iter()
            .enumerate()
            .filter(|(_, &(_, largest, width))| largest < width)
            .min_by(|a, c| (a.1 .1 / a.1 .2).total_cmp(&(c.1 .1 / c.1 .2)))?;
        return Some(format!(
            "{} spans at most {} across, less than the width of the elements it lies in ({}): within one or two elements the basis gives it one affine field, a translation, a rotation and a uniform strain, and none of its bending or waves; refine the mesh so that the body spans at least three elements (elements about {} wide or less)",
            who(b),
            echo_significant(largest, 3),
            echo_significant(width, 3),
            echo_significant(largest / 3.0, 2),
        ));
    };
    let who = who(b);
    Some(format!(
        "the critical step, {}, is {:.1} times the time a P-wave takes to cross {who} ({} across, in elements {} wide): the mesh is too coarse to resolve its deformation, whose vibrations are faster than the step (a disk of radius 0.075 in blocks of 1 had its first strain peak at 0.39 s against 0.0043 s on a mesh that resolves it); refine the mesh so that the body spans at least three elements (elements about {} wide or less)",
        echo_significant(critical, 3),
        ratio,
        echo_significant(extent, 3),
        echo_significant(width, 3),
        echo_significant(extent / 3.0, 2),
    ))
}

/// The bound on `critical c / extent` above which a body is warned about as
/// unresolved by the mesh (`unresolved_body`: the critical step longer than a
/// P-wave takes to cross the body).
pub const UNRESOLVED_BODY: f64 = 1.0;

/// What sets a critical step too small for the run: the scene's fastest P-wave
/// speed ([`Scene::wave_speed`]), with the units to check (a modulus in Pa
/// beside a density in g/cm³ gives a wave 30 times too fast, a step 30 times too
/// short) and the fixes that keep the physics.
fn wave_speed_hint(scene: &Scene) -> String {
    format!(
        "The critical step is the time the fastest wave takes to cross the basis's smallest spacing, and here the materials' fastest P-wave speed √((λ + 2μ)/ρ) is {:.2e}: check that `young` and `density` are in one system of units (in SI, Pa and kg/m³: about 6e3 m/s for steel, 50 for rubber); if they are, shorten `t_end` or coarsen the mesh",
        scene.wave_speed()
    )
}

/// The most a 1D critical step reaches in element crossings `h / c` of the
/// fastest P-wave, over the 1D bases and mass strategies: measured 1.43 (`bspline`
/// with `lumped`; 0.59–1.02 for the others, on a bar filled and half filled,
/// `docs/stability.md`, "The critical time step"), with a margin.
pub(crate) const MOST_CROSSINGS_1D: f64 = 4.0;

/// Before a 1D mesh of spacing `h` and its basis are built: a fixed `dt` so far
/// above the critical step that no basis or mass strategy can take it
/// ([`MOST_CROSSINGS_1D`] crossings of an element by the fastest P-wave) is
/// refused at once. The check after the set-up estimates the critical step
/// itself; a user's bar of 1e6 elements with a step 700 times above it took 7 s
/// and 1.2 GB of set-up to be told so.
pub(crate) fn far_above_critical_1d(scene: &Scene, h: f64) -> Option<SceneError> {
    let dt = scene.time.dt?;
    let crossing = h / scene.wave_speed();
    let most = MOST_CROSSINGS_1D * crossing;
    if scene.time.allow_above_critical || !most.is_finite() || dt <= most {
        return None;
    }
    Some(SceneError::new(
        "time.dt",
        ErrorKind::Conflict,
        format!(
            "the time step {} is {} times the {} the fastest P-wave (√((λ + 2μ)/ρ) = {}) takes to cross an element of length {}, and no 1D basis or mass strategy has a critical step above {MOST_CROSSINGS_1D} such crossings ({}; `bspline` with `lumped` reaches 1.4, the others 0.6 to 1): lower `time.dt` below {} (the run estimates the critical step itself once set up), or give `courant = 0.5` instead of `dt`, or set `allow_above_critical = true` in `[time]` (`--allow-above-critical`) to run anyway",
            echo_number(dt),
            crate::scene::limits::echo_significant(dt / crossing, 3),
            crate::scene::limits::echo_significant(crossing, 3),
            crate::scene::limits::echo_significant(scene.wave_speed(), 3),
            crate::scene::limits::echo_significant(h, 3),
            crate::scene::limits::echo_significant(most, 3),
            crate::scene::limits::echo_significant(most, 3),
        ),
    ))
}

/// The error for a fixed `dt` above the critical step. The power iteration
/// approaches `λ_max(M⁻¹K)` from below, so its `Δt_crit` errs on the large side
/// (within 0.01 % of a dense eigenvalue computation after 40 iterations, test in
/// `driver::critical`): a step above it is unstable at the start.
///
/// When the driver sees why the mass matrix is nearly singular (`singular`: too few
/// particles, or a function with almost no particle support that the strategy
/// solves for), that is what makes the critical step small, and the fix that fits is
/// that cause's, not a smaller step.
fn above_critical(scene: &Scene, dt: f64, critical: f64, singular: Option<String>) -> SceneError {
    if let Some(why) = singular {
        return SceneError::new(
            "time.dt",
            ErrorKind::Conflict,
            format!(
                "the time step {} is above the critical step {critical:.3e} estimated at the start for this mesh, basis (`{}`) and mass strategy (`{}`) (Courant number {:.3e}) because the mass matrix is nearly singular: {why}",
                echo_number(dt),
                scene.basis.name(),
                scene.mass.spec(),
                dt / critical
            ),
        );
    }
    SceneError::new(
        "time.dt",
        ErrorKind::Conflict,
        format!(
            "the time step {} is above the critical step {critical:.3e} estimated at the start for this mesh, basis (`{}`) and mass strategy (`{}`): its Courant number is {}; lower `time.dt` below {critical:.3e}, or give `courant = 0.5` instead of `dt`, or set `allow_above_critical = true` in `[time]` (`--allow-above-critical`) to run anyway",
            echo_number(dt),
            scene.basis.name(),
            scene.mass.spec(),
            echo_fixed(dt / critical, 2)
        ),
    )
}

/// A point of the scene (`[f64; 2]`, the second entry ignored in 1D) as a vector.
pub(crate) fn to_vec<const D: usize>(p: [f64; 2]) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|k, _| p[k])
}

/// A vector as a point of the scene (the second entry 0 in 1D).
pub(crate) fn from_vec<const D: usize>(v: &SVector<f64, D>) -> [f64; 2] {
    let mut p = [0.0; 2];
    for k in 0..D {
        p[k] = v[k];
    }
    p
}

/// The field of the first boundary condition on `tag` (`boundary[i].tag`).
fn boundary_field(scene: &Scene, tag: &str) -> String {
    match scene.boundaries.iter().position(|bc| bc.tag == tag) {
        Some(i) => format!("boundary[{i}].tag"),
        None => "boundary".to_string(),
    }
}
