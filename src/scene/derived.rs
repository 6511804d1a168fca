//! Values derived from a scene: lattice spacing, gravity, time step and step count,
//! mesh size and block counts.

use super::{Body, EffectSpec, MeshSpec, Scene};

impl Scene {
    /// The lattice spacing of `body` along axis `k`: the box extent over `count`, or
    /// the mesh's block size over `per_block` (`None` when `per_block` is given on a
    /// mesh without blocks).
    pub fn lattice_spacing(&self, body: &Body, k: usize) -> Option<f64> {
        let extent = body.max[k] - body.min[k];
        match (&body.count, &body.per_block) {
            (Some(c), _) => Some(extent / c[k] as f64),
            (None, Some(per)) => {
                let blocks = self.blocks()?;
                let (lo, hi) = match (&self.mesh, k) {
                    (MeshSpec::Blocks { x, .. }, 0) | (MeshSpec::Interval { x, .. }, 0) => {
                        (x[0], x[1])
                    }
                    (MeshSpec::Blocks { y, .. }, _) => (y[0], y[1]),
                    _ => return None,
                };
                Some((hi - lo) / blocks[k] as f64 / per[k] as f64)
            }
            (None, None) => None,
        }
    }

    /// The gravity vector of the scene's gravity effect, if it has one.
    pub fn gravity(&self) -> Option<Vec<f64>> {
        self.effects.iter().find_map(|e| match e {
            EffectSpec::Gravity { g } => Some(g.clone()),
            _ => None,
        })
    }

    /// The time step `dt`, or with `courant` a mesh-based guess `C h / c` (P-wave
    /// speed `c`, `h` halved for PS) used to set a run up and to estimate its cost;
    /// the run itself takes `C Δt_crit` (see [`TimeSpec::courant`](super::TimeSpec::courant)).
    pub fn dt(&self, h: f64) -> f64 {
        match (self.time.dt, self.time.courant) {
            (Some(dt), _) => dt,
            (None, Some(c)) => {
                let m = &self.material;
                let e = crate::material::Elastic {
                    young: m.young,
                    poisson: m.poisson,
                    density: m.density,
                };
                let speed = (e.p_modulus(self.dim) / m.density).sqrt();
                c * self.basis.wave_length(h) / speed
            }
            (None, None) => f64::NAN,
        }
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
                let axis = self.study.refine.first().map_or(0, |c| c.index());
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
