//! Changes to a scene made by the command line, comparisons (a basis with its own
//! resolution) and refinement studies.

use super::{bad, conflict, BlockLayout, BodyShape, MeshSpec, Scene, SceneError};
use crate::bases::BasisKind;

impl Scene {
    /// Sets the block counts of a `blocks` mesh (`[n, 1]` sets the elements of an
    /// `interval` mesh).
    pub fn set_blocks(&mut self, nx: usize, ny: usize) -> Result<(), SceneError> {
        match &mut self.mesh {
            MeshSpec::Blocks { blocks, .. } => *blocks = [nx, ny],
            MeshSpec::Interval { elements, .. } => *elements = nx,
            MeshSpec::Polygon { .. } => {
                return Err(conflict(
                    "mesh.blocks",
                    "the scene's mesh is a `polygon` mesh, which has no blocks: refine or coarsen it with `mesh.edge_length` in the scene file (`converge` halves it per level)",
                ))
            }
            MeshSpec::Gmsh { .. } => {
                return Err(conflict(
                    "mesh.blocks",
                    "the scene's mesh is a Gmsh file, which has no blocks: make a finer or coarser mesh with Gmsh (its characteristic length) and give that file as `mesh.file`",
                ))
            }
        }
        Ok(())
    }

    /// Sets the block layout of a `blocks` mesh.
    pub fn set_layout(&mut self, new: BlockLayout) -> Result<(), SceneError> {
        match &mut self.mesh {
            MeshSpec::Blocks { layout, .. } => *layout = new,
            _ => return Err(conflict("mesh.layout", "the scene's mesh has no blocks")),
        }
        Ok(())
    }

    /// Sets the particles per block of every lattice body (the first `dim` entries
    /// of `p`; Gmsh bodies keep their particles).
    pub fn set_particles_per_block(&mut self, p: [usize; 2]) {
        for body in &mut self.bodies {
            if body.shape != BodyShape::Gmsh {
                body.per_block = Some(p[..self.dim].to_vec());
                body.count = None;
                body.spacing = None;
            }
        }
    }

    /// Takes the relative paths of the scene's files (the Gmsh mesh, Gmsh bodies)
    /// relative to `dir`, the directory of the scene file.
    pub fn resolve_paths(&mut self, dir: &std::path::Path) {
        let resolve = |file: &mut String| {
            let path = std::path::Path::new(file.as_str());
            if path.is_relative() {
                *file = dir.join(path).to_string_lossy().into_owned();
            }
        };
        if let MeshSpec::Gmsh { file } = &mut self.mesh {
            resolve(file);
        }
        for body in &mut self.bodies {
            if let Some(file) = &mut body.file {
                resolve(file);
            }
        }
    }

    /// Sets a fixed time step.
    pub fn set_dt(&mut self, dt: f64) {
        self.time.dt = Some(dt);
        self.time.courant = None;
    }

    /// Sets the time step to the fraction `courant` of the critical step estimated
    /// at the start ([`TimeSpec::courant`](super::TimeSpec::courant)).
    pub fn set_courant(&mut self, courant: f64) {
        self.time.courant = Some(courant);
        self.time.dt = None;
    }

    /// The scene for `basis`, with the resolution the scene gives that basis (see
    /// [`Scene::resolutions`]), validated.
    pub fn with_basis(&self, basis: BasisKind) -> Result<Scene, SceneError> {
        let mut s = self.clone();
        s.basis = basis;
        if let Some(r) = self.resolutions.iter().find(|r| r.basis == basis) {
            if let Some([nx, ny]) = r.blocks {
                s.set_blocks(nx, ny)?;
            }
            if let Some(h) = r.edge_length {
                match &mut s.mesh {
                    MeshSpec::Polygon { edge_length, .. } => *edge_length = h,
                    _ => {
                        return Err(conflict(
                            "resolution.edge_length",
                            "the mesh is not a polygon",
                        ))
                    }
                }
            }
            if let Some(p) = &r.per_block {
                for body in s.bodies.iter_mut().filter(|b| b.shape != BodyShape::Gmsh) {
                    body.per_block = Some(p.clone());
                    body.count = None;
                    body.spacing = None;
                }
            }
        }
        s.validate()?;
        Ok(s)
    }

    /// The scene refined `level` times as [`StudySpec`](super::StudySpec) says, validated.
    pub fn refined(&self, level: u32) -> Result<Scene, SceneError> {
        let mut s = self.clone();
        let factor = 1usize
            .checked_shl(level)
            .filter(|f| *f <= 4096)
            .ok_or_else(|| bad("study", format!("level {level} is too fine")))?;
        let listed = |axis: usize| {
            self.study
                .refine
                .as_ref()
                .is_none_or(|r| r.iter().any(|a| a.index() == axis))
        };
        // The axes along which the element size shrinks: a polygon mesh's edge
        // length shrinks along every axis, an interval's along its one axis.
        let mut axes = [false; 2];
        match &mut s.mesh {
            MeshSpec::Blocks { blocks, .. } => {
                for (axis, n) in blocks.iter_mut().enumerate() {
                    if listed(axis) {
                        *n = refine_count("mesh.blocks", *n, factor)?;
                        axes[axis] = true;
                    }
                }
            }
            MeshSpec::Interval { elements, .. } => {
                *elements = refine_count("mesh.elements", *elements, factor)?;
                axes[0] = true;
            }
            MeshSpec::Polygon { edge_length, .. } => {
                *edge_length /= factor as f64;
                axes = [true, true];
            }
            MeshSpec::Gmsh { .. } => {
                return Err(conflict(
                    "mesh.kind",
                    "a Gmsh mesh cannot be refined by a study: `converge` refines `blocks`, `polygon` and `interval` meshes (write the domain as a `polygon` mesh with its outline and `edge_length`), or make the finer meshes with Gmsh and `run` each one",
                ))
            }
        }
        // `particle_growth^level` more particles per element along those axes.
        let growth = (self.study.particle_growth.unwrap_or(1) as usize)
            .checked_pow(level)
            .filter(|g| *g <= 1 << 16)
            .ok_or_else(|| {
                bad(
                    "study.particle_growth",
                    format!("level {level} grows the particles too far"),
                )
            })?;
        for (i, body) in s.bodies.iter_mut().enumerate() {
            if let Some(c) = &mut body.count {
                for (axis, n) in c.iter_mut().enumerate() {
                    if axes[axis] {
                        *n = refine_count(&format!("body[{i}].count"), *n, factor * growth)?;
                    }
                }
            }
            if let Some(h) = &mut body.spacing {
                for (axis, h) in h.iter_mut().enumerate() {
                    if axes[axis] {
                        *h /= (factor * growth) as f64;
                    }
                }
            }
            if let Some(per) = &mut body.per_block {
                for (axis, n) in per.iter_mut().enumerate() {
                    if axes[axis] {
                        *n = refine_count(&format!("body[{i}].per_block"), *n, growth)?;
                    }
                }
            }
        }
        s.validate()?;
        Ok(s)
    }
}

/// `n` multiplied by a refinement `factor`, or an error naming `field` when the
/// product does not fit in a `usize` (the scene's limits reject large products).
fn refine_count(field: &str, n: usize, factor: usize) -> Result<usize, SceneError> {
    n.checked_mul(factor).ok_or_else(|| {
        bad(
            field,
            format!("{n} refined by a factor {factor} does not fit in a count"),
        )
    })
}
