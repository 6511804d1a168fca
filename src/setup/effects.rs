//! The effects a scene declares, built for its particles.

use super::Solution;
use crate::contact::{ContactWall, WallGeometry};
use crate::effect::{BodyForce, Effect, Gravity, LocalDamping, Traction};
use crate::particles::Particles;
use crate::scene::{EffectSpec, ErrorKind, Scene, SceneError};
use crate::simulation::RunError;
use nalgebra::SVector;
use psmpm_basis::basis::Basis;

/// The effects `scene` declares, built for `particles` (traction selects its
/// particles here; contact between bodies numbers the vertices of `basis`). Only
/// these are assembled in a run.
pub fn build_effects<const D: usize>(
    scene: &Scene,
    particles: &Particles<f64, D>,
    body_sizes: &[usize],
    contacts: Option<&WallGeometry>,
    basis: &dyn Basis<f64, D>,
) -> Result<Vec<Box<dyn Effect<f64, D>>>, RunError> {
    let solution = Solution::new(scene);
    // The contact walls are one effect, built at the first.
    let mut contacts = contacts;
    let mut effects: Vec<Box<dyn Effect<f64, D>>> = Vec::new();
    for (i, spec) in scene.effects.iter().enumerate() {
        match spec {
            EffectSpec::Gravity { g } => effects.push(Box::new(Gravity {
                g: SVector::<f64, D>::from_fn(|k, _| g[k]),
            })),
            EffectSpec::Damping { alpha } => effects.push(Box::new(LocalDamping { alpha: *alpha })),
            EffectSpec::Traction {
                min,
                max,
                traction,
                length,
                ramp,
            } => {
                let selected = traction_particles(particles, min, max);
                if selected.is_empty() {
                    // A body outside the mesh is the cause to name first (a
                    // user's body moved off the mesh was told only of its traction).
                    let extent = super::mesh_extent(basis);
                    if let Some(p) = (0..particles.len())
                        .find(|&p| basis.locate(&particles.x[p], None).is_none())
                    {
                        let position: Vec<f64> = particles.x[p].iter().copied().collect();
                        return Err(super::particle_outside(
                            scene, p, &position, extent, body_sizes,
                        )
                        .into());
                    }
                    return Err(SceneError::new(
                        format!("effect[{i}].min"),
                        ErrorKind::Conflict,
                        format!(
                            "the traction box {} to {} selects no particle: the particles' centres span {}; give `min` and `max` a box around the centres of the particles to load (the outer ones lie half a spacing inside the body's outline)",
                            crate::driver::point(min),
                            crate::driver::point(max),
                            particle_span(particles)
                        ),
                    )
                    .into());
                }
                let share = length / selected.len() as f64;
                effects.push(Box::new(Traction {
                    particles: selected,
                    force: SVector::<f64, D>::from_fn(|k, _| traction[k] * share),
                    ramp: *ramp,
                }));
            }
            EffectSpec::BodyForce { value } => effects.push(Box::new(BodyForce::Uniform(
                SVector::<f64, D>::from_fn(|k, _| value[k]),
            ))),
            EffectSpec::ManufacturedBodyForce {} => {
                let Some(Solution::AxisAligned(a)) = solution else {
                    return Err(SceneError::new(
                        format!("effect[{i}].kind"),
                        ErrorKind::Conflict,
                        "`manufactured-body-force` needs reference kind `axis-aligned`",
                    )
                    .into());
                };
                effects.push(Box::new(BodyForce::Manufactured(a)));
            }
            EffectSpec::ContactWall { .. } => {
                let Some(geometry) = contacts.take().cloned() else {
                    if scene.dim == 2 {
                        // Built with the first contact wall.
                        continue;
                    }
                    return Err(SceneError::new(
                        format!("effect[{i}].kind"),
                        ErrorKind::Conflict,
                        "a contact wall needs a 2D mesh",
                    )
                    .into());
                };
                let reach = geometry.reach();
                let distance = crate::contact::contact_distances(
                    particles,
                    body_sizes,
                    &crate::simulation::lattice_stretch(scene),
                );
                let coarsest = coarsest_body(&distance, body_sizes);
                let wall = ContactWall::new(geometry, particles, distance).map_err(|d| {
                    let tags: Vec<String> = scene
                        .effects
                        .iter()
                        .filter_map(|e| match e {
                            EffectSpec::ContactWall { tag, .. } => Some(format!("`{tag}`")),
                            _ => None,
                        })
                        .collect();
                    // The error points at the body whose lattice sets the distance,
                    // at the key that sets its lattice: that is what to change.
                    let (field, whose) = match coarsest.and_then(|b| scene.bodies.get(b).map(|body| (b, body))) {
                        Some((b, body)) => (
                            format!("body[{b}].{}", body.lattice_key()),
                            format!("the particles of body[{b}]"),
                        ),
                        None => (format!("effect[{i}].tag"), "the particles".to_string()),
                    };
                    SceneError::new(
                        field,
                        ErrorKind::Conflict,
                        format!(
                            "{whose} are coarser than the mesh for the contact wall on {} (effect[{i}]): their contact distance, half a particle spacing, is {d:.4e}, above the longest edge {reach:.4e}; give the body a spacing below {:.4e}, twice that edge (3 or more particles per element want far less: `per_block = [4, 4]` on block meshes), with `per_block`, `count` or `spacing`",
                            tags.join(", "),
                            2.0 * reach,
                        ),
                    )
                })?;
                effects.push(Box::new(wall));
            }
            EffectSpec::BodyContact {} => effects.push(Box::new(
                crate::body_contact::BodyContact::new(scene.bodies.len(), basis),
            )),
            // An initial state, not an effect: `particles::apply_initial_states`.
            EffectSpec::GeostaticStress { .. } => {}
        }
    }
    Ok(effects)
}

/// The body (index into `body_sizes`, the particles of each body in order) whose
/// particles have the largest contact distance; `None` when the sizes do not
/// cover the particles.
fn coarsest_body(distance: &[f64], body_sizes: &[usize]) -> Option<usize> {
    if body_sizes.iter().sum::<usize>() != distance.len() {
        return None;
    }
    let mut first = 0;
    let mut coarsest: Option<(usize, f64)> = None;
    for (b, &size) in body_sizes.iter().enumerate() {
        let largest = distance[first..first + size]
            .iter()
            .fold(0.0f64, |a, &d| a.max(d));
        if coarsest.is_none_or(|(_, d)| largest > d) {
            coarsest = Some((b, largest));
        }
        first += size;
    }
    coarsest.map(|(b, _)| b)
}

/// The particles a traction's box `[min, max]` loads: those inside it at the start.
pub(crate) fn traction_particles<const D: usize>(
    particles: &Particles<f64, D>,
    min: &[f64],
    max: &[f64],
) -> Vec<usize> {
    (0..particles.len())
        .filter(|&p| (0..D).all(|k| (min[k]..=max[k]).contains(&particles.x0[p][k])))
        .collect()
}

/// The bounding box of the particles' centres, for messages: `[x0, x1] × [y0, y1]`.
fn particle_span<const D: usize>(particles: &Particles<f64, D>) -> String {
    (0..D)
        .map(|k| {
            let (lo, hi) = particles
                .x
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x[k]), hi.max(x[k]))
                });
            format!(
                "[{}, {}]",
                crate::scene::limits::echo_significant(lo, 6),
                crate::scene::limits::echo_significant(hi, 6)
            )
        })
        .collect::<Vec<_>>()
        .join(" × ")
}
