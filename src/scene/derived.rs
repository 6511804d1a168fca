//! Values derived from a scene: a body's bounding box, material and initial
//! velocity, lattice spacing, wave speed, gravity, time step and step count,
//! mesh size and block counts.

use super::{
    Body, BodyShape, Component, EffectSpec, InitialVelocity, MaterialSpec, MeshSpec, Scene,
};

impl Body {
    /// The key that sets the body's lattice, for messages that point at it:
    /// `per_block`, `count`, `spacing` (one at most: `Scene::validate`) or
    /// `per_triangle`, else `per_block`, the default.
    pub fn lattice_key(&self) -> &'static str {
        if self.per_block.is_some() {
            "per_block"
        } else if self.count.is_some() {
            "count"
        } else if self.spacing.is_some() {
            "spacing"
        } else if self.per_triangle.is_some() {
            "per_triangle"
        } else {
            "per_block"
        }
    }

    /// The bounding box `(min, max)` of the body's region (the second entries 0 in
    /// 1D); `None` for a Gmsh body (its box is known once the file is read) or an
    /// incomplete shape.
    pub fn bounds(&self) -> Option<([f64; 2], [f64; 2])> {
        match self.shape {
            BodyShape::Box => {
                let (mut lo, mut hi) = ([0.0; 2], [0.0; 2]);
                if self.min.is_empty() || self.min.len() > 2 || self.min.len() != self.max.len() {
                    return None;
                }
                lo[..self.min.len()].copy_from_slice(&self.min);
                hi[..self.max.len()].copy_from_slice(&self.max);
                Some((lo, hi))
            }
            BodyShape::Polygon => {
                let first = *self.outline.first()?;
                Some(self.outline.iter().fold((first, first), |(lo, hi), p| {
                    (
                        [lo[0].min(p[0]), lo[1].min(p[1])],
                        [hi[0].max(p[0]), hi[1].max(p[1])],
                    )
                }))
            }
            BodyShape::Disk => {
                let (c, r) = (self.centre?, self.radius?);
                Some(([c[0] - r, c[1] - r], [c[0] + r, c[1] + r]))
            }
            BodyShape::Gmsh => None,
        }
    }
}

impl Scene {
    /// The material of body `b`: its own, or the scene's.
    pub fn body_material(&self, b: usize) -> &MaterialSpec {
        self.bodies
            .get(b)
            .and_then(|body| body.material.as_ref())
            .unwrap_or(&self.material)
    }

    /// The initial velocity of body `b`: its own, or the scene's.
    pub fn body_velocity(&self, b: usize) -> &InitialVelocity {
        self.bodies
            .get(b)
            .and_then(|body| body.initial_velocity.as_ref())
            .unwrap_or(&self.initial_velocity)
    }

    /// The lattice spacing of `body` along axis `k`: `spacing`, the extent of the
    /// box (of the bounding box of a polygon or disk) over `count`, or the mesh's
    /// block size over `per_block` (`None` when `per_block` is given on a mesh without
    /// blocks, and for Gmsh bodies).
    pub fn lattice_spacing(&self, body: &Body, k: usize) -> Option<f64> {
        if let Some(h) = &body.spacing {
            return h.get(k).copied();
        }
        match (&body.count, &body.per_block) {
            (Some(c), _) => {
                let (lo, hi) = body.bounds()?;
                Some((hi[k] - lo[k]) / *c.get(k)? as f64)
            }
            (None, Some(per)) => {
                let blocks = self.blocks()?;
                let (lo, hi) = self.block_mesh_range(k)?;
                Some((hi - lo) / blocks[k] as f64 / *per.get(k)? as f64)
            }
            (None, None) => None,
        }
    }

    /// The range `[x0, x1]` (`k = 0`) or `[y0, y1]` (`k = 1`) of a `blocks` or
    /// `interval` mesh; `None` for other meshes.
    pub fn block_mesh_range(&self, k: usize) -> Option<(f64, f64)> {
        match (&self.mesh, k) {
            (MeshSpec::Blocks { x, .. }, 0) | (MeshSpec::Interval { x, .. }, 0) => {
                Some((x[0], x[1]))
            }
            (MeshSpec::Blocks { y, .. }, 1) => Some((y[0], y[1])),
            _ => None,
        }
    }

    /// The gravity vector of the scene's gravity effect, if it has one.
    pub fn gravity(&self) -> Option<Vec<f64>> {
        self.effects.iter().find_map(|e| match e {
            EffectSpec::Gravity { g } => Some(g.clone()),
            _ => None,
        })
    }

    /// The scene asks for contact between its bodies (a velocity field per body;
    /// [`crate::body_contact`]).
    pub fn body_contact(&self) -> bool {
        self.effects
            .iter()
            .any(|e| matches!(e, EffectSpec::BodyContact {}))
    }

    /// The scene has a contact wall (`[[effect]]` with `kind = "contact-wall"`).
    pub fn contact_walls(&self) -> bool {
        self.effects
            .iter()
            .any(|e| matches!(e, EffectSpec::ContactWall { .. }))
    }

    /// The bodies' densities differ (layers: a geostatic stress then integrates
    /// the weight of what lies above each particle).
    pub fn layered(&self) -> bool {
        let density = |b: usize| self.body_material(b).density;
        (1..self.bodies.len()).any(|b| density(b) != density(0))
    }

    /// The time step `dt`, or with `courant` a mesh-based guess `C h / c` (P-wave
    /// speed `c`, `h` halved for PS) used to set a run up and to estimate its cost;
    /// the run itself takes `C Δt_crit` (see [`TimeSpec::courant`](super::TimeSpec::courant)).
    pub fn dt(&self, h: f64) -> f64 {
        match (self.time.dt, self.time.courant) {
            (Some(dt), _) => dt,
            (None, Some(c)) => c * self.basis.wave_length(h) / self.wave_speed(),
            (None, None) => f64::NAN,
        }
    }

    /// The fastest P-wave speed `√((λ + 2μ) / ρ)` of the bodies' materials.
    pub fn wave_speed(&self) -> f64 {
        (0..self.bodies.len().max(1))
            .map(|b| self.body_wave_speed(b))
            .fold(0.0, f64::max)
    }

    /// The P-wave speed `√((λ + 2μ)/ρ)` of body `b`'s material.
    pub fn body_wave_speed(&self, b: usize) -> f64 {
        let m = self.body_material(b);
        let e = crate::material::Elastic {
            young: m.young,
            poisson: m.poisson,
            density: m.density,
        };
        (e.p_modulus(self.dim) / m.density).sqrt()
    }

    /// Steps to reach `t_end` with a fixed `dt` (rounded to the nearest integer); for
    /// a Courant-number scene, at least 1 (the mesh decides the count).
    pub fn steps(&self) -> usize {
        match self.time.dt {
            Some(dt) => (self.time.t_end / dt).round() as usize,
            None => 1,
        }
    }

    /// The mesh size `h` a refinement study reports: the block width along the
    /// first refined axis, the element length of an interval, the edge length of a
    /// polygon mesh (`None` for Gmsh meshes).
    pub fn mesh_size(&self) -> Option<f64> {
        match &self.mesh {
            MeshSpec::Blocks { x, y, blocks, .. } => {
                let axis = self
                    .study
                    .refine
                    .as_ref()
                    .and_then(|r| r.first())
                    .map_or(0, |a| a.index());
                let r = if axis == 0 { x } else { y };
                Some((r[1] - r[0]) / blocks[axis] as f64)
            }
            MeshSpec::Interval { x, elements } => Some((x[1] - x[0]) / *elements as f64),
            MeshSpec::Polygon { edge_length, .. } => Some(*edge_length),
            MeshSpec::Gmsh { .. } => None,
        }
    }

    /// Block counts of a `blocks` mesh (`[elements, 1]` for an interval).
    pub fn blocks(&self) -> Option<[usize; 2]> {
        match &self.mesh {
            MeshSpec::Blocks { blocks, .. } => Some(*blocks),
            MeshSpec::Interval { elements, .. } => Some([*elements, 1]),
            _ => None,
        }
    }
}

impl Scene {
    /// On a `blocks` or `interval` mesh, a wall on the side `tag` (`left`,
    /// `right`, `bottom`, `top`) holds the velocity component `axis`: it fixes
    /// `axis`, or the normal where the side's normal is along `axis`. `false` on
    /// other meshes, whose sides' names say nothing of where they are.
    pub fn side_holds(&self, tag: &str, axis: Component) -> bool {
        if !matches!(
            self.mesh,
            MeshSpec::Blocks { .. } | MeshSpec::Interval { .. }
        ) {
            return false;
        }
        let normal = match tag {
            "left" | "right" => Component::X,
            _ => Component::Y,
        };
        self.boundaries.iter().any(|b| {
            b.tag == tag
                && b.fix
                    .iter()
                    .any(|&c| c == axis || (c == Component::Normal && normal == axis))
        })
    }
}
