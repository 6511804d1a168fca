//! The scene's reference solution, resolved from its parameters, in the scene's
//! dimension.

use crate::scene::{EffectSpec, MaterialModel, Reference, Scene};
use crate::studies::exact;

/// The scene's reference solution with its parameters resolved.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Solution {
    Bar(exact::VibratingBar),
    Column(exact::ColumnSelfWeight),
    AxisAligned(exact::AxisAligned),
    /// The column at rest under its weight: a static state, with no time history.
    Equilibrium {
        height: f64,
        density: f64,
        gravity: f64,
        young: f64,
        /// The column starts from a `geostatic-stress` initial state, or its law
        /// is not one whose uniaxial response is `σ = E (F − 1)` (neo-Hookean),
        /// so its equilibrium is measured at the particles' reference heights,
        /// the weight above them (see
        /// [`exact::column_equilibrium_stress_at_reference`]), which holds for
        /// any law; else at their current heights, the linear law's profile.
        at_reference: bool,
    },
}

impl Solution {
    pub(crate) fn new(scene: &Scene) -> Option<Self> {
        let m = scene.body_material(0);
        // The references are over the first body's box (validation requires one).
        let (min, max) = scene.bodies.first()?.bounds()?;
        let d = scene.dim;
        let gravity = scene.gravity().map_or(0.0, |g| g[d - 1]);
        Some(match scene.reference? {
            Reference::VibratingBar { v0 } => Solution::Bar(exact::VibratingBar {
                length: max[0] - min[0],
                young: m.young,
                density: m.density,
                v0,
            }),
            Reference::ColumnSelfWeight {} => Solution::Column(exact::ColumnSelfWeight {
                height: max[d - 1] - min[d - 1],
                young: m.young,
                density: m.density,
                gravity,
            }),
            Reference::AxisAligned { u0 } => Solution::AxisAligned(exact::AxisAligned {
                u0,
                young: m.young,
                poisson: m.poisson,
                density: m.density,
            }),
            Reference::ColumnEquilibrium {} => Solution::Equilibrium {
                height: max[d - 1] - min[d - 1],
                density: m.density,
                gravity,
                young: m.young,
                at_reference: scene
                    .effects
                    .iter()
                    .any(|e| matches!(e, EffectSpec::GeostaticStress { .. }))
                    || m.model == MaterialModel::NeoHookean,
            },
        })
    }

    /// Whether the solution is a motion in time, whose displacement and velocity
    /// the tracked particles are compared with (`tracked.csv`'s exact columns). The
    /// column's equilibrium is the state it settles to, not the motion on the way:
    /// it has none.
    pub(crate) fn has_history(&self) -> bool {
        !matches!(self, Solution::Equilibrium { .. })
    }

    /// Exact displacement at reference position `x0` (relative to the body's
    /// lower corner `origin`) and time `t`, in the scene's dimension.
    pub(crate) fn displacement(
        &self,
        x0: [f64; 2],
        origin: [f64; 2],
        dim: usize,
        t: f64,
    ) -> [f64; 2] {
        match self {
            Solution::Bar(bar) => [bar.displacement(x0[0] - origin[0], t), 0.0],
            Solution::Column(column) => {
                let u = column.displacement(x0[dim - 1] - origin[dim - 1], t);
                if dim == 1 {
                    [u, 0.0]
                } else {
                    [0.0, u]
                }
            }
            Solution::AxisAligned(a) => a.displacement(x0, t),
            Solution::Equilibrium { .. } => [0.0; 2],
        }
    }

    pub(crate) fn velocity(&self, x0: [f64; 2], origin: [f64; 2], dim: usize, t: f64) -> [f64; 2] {
        match self {
            Solution::Bar(bar) => [bar.velocity(x0[0] - origin[0], t), 0.0],
            Solution::AxisAligned(a) => a.velocity(x0, t),
            Solution::Column(column) => {
                let v = column.velocity(x0[dim - 1] - origin[dim - 1], t);
                if dim == 1 {
                    [v, 0.0]
                } else {
                    [0.0, v]
                }
            }
            Solution::Equilibrium { .. } => [0.0; 2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A neo-Hookean column is measured against the weight above each particle's
    /// reference height, which holds for any law; the linear laws against their
    /// own profile at the current height (the seeds' B5c).
    #[test]
    fn a_neo_hookean_column_is_measured_at_the_reference_heights() {
        let at_reference = |model: &str| {
            let mut scene = Scene::builtin("column-damped").unwrap();
            scene.material.model = match model {
                "neo-hookean" => MaterialModel::NeoHookean,
                "corotational" => MaterialModel::Corotational,
                _ => MaterialModel::LinearElastic,
            };
            match Solution::new(&scene) {
                Some(Solution::Equilibrium { at_reference, .. }) => at_reference,
                other => panic!("{other:?}"),
            }
        };
        assert!(at_reference("neo-hookean"));
        assert!(!at_reference("corotational"));
        assert!(!at_reference("linear-elastic"));
    }
}
