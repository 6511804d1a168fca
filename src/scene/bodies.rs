//! Validation of the bodies: each body's shape and only that shape's fields, its
//! lattice, its material and initial velocity (its own or the scene's), and the
//! number of particles of all bodies, bounded before any is made.

use super::limits::{
    echo_number, plural, MAX_OUTLINE_CORNERS, MAX_PARTICLES, MAX_POLYGON_TESTS, MAX_SPEED,
};
use super::{
    bad, conflict, Body, BodyShape, ErrorKind, InitialVelocity, MaterialSpec, MeshSpec, Scene,
    SceneError,
};
use psmpm_basis::mesh::generators::{PolygonDomain, PolygonPart};
use psmpm_basis::mesh::MeshError;
use psmpm_basis::Vec2;

/// The fields each shape takes beyond the common ones (`shape`, `material`,
/// `initial_velocity`); the lattice fields belong to every shape but `gmsh`.
const LATTICE: [BodyShape; 3] = [BodyShape::Box, BodyShape::Polygon, BodyShape::Disk];

/// Particles a Gmsh body places per triangle when it does not say.
pub const DEFAULT_PER_TRIANGLE: usize = 3;

/// Most times a Gmsh body's triangles may be split into four (`4^8 = 65 536`
/// pieces per triangle).
pub const MAX_SUBDIVIDE: u32 = 8;

impl Scene {
    /// Checks every body; the error names the field (`body[1].radius`).
    pub(super) fn validate_bodies(&self) -> Result<(), SceneError> {
        if self.bodies.is_empty() {
            return Err(bad("body", "a scene needs at least one [[body]]"));
        }
        for (b, body) in self.bodies.iter().enumerate() {
            self.validate_shape(b, body)?;
            self.validate_lattice(b, body)?;
            if let Some(m) = &body.material {
                validate_material(&format!("body[{b}].material"), m, self.dim)?;
            }
            if let Some(v) = &body.initial_velocity {
                self.validate_velocity(&format!("body[{b}].initial_velocity"), v)?;
            }
        }
        let particles = self.estimated_particle_count();
        if particles.is_nan() || particles > MAX_PARTICLES as f64 {
            // The body with the most particles, and the key that sets its lattice.
            let (b, most) = self
                .bodies
                .iter()
                .map(|body| self.estimated_particles(body))
                .enumerate()
                .max_by(|a, c| a.1.total_cmp(&c.1))
                .unwrap_or((0, particles));
            let body = &self.bodies[b];
            let key = body.lattice_key();
            let fix = if key == "spacing" {
                "a larger `spacing`"
            } else if key == "per_block" {
                "fewer particles per block (`per_block` counts per block of the mesh, so a finer mesh multiplies them too: coarsen `mesh.blocks` or `mesh.elements` for the same particles per element)"
            } else {
                "a smaller `count`"
            };
            return Err(bad(
                format!("body[{b}].{key}"),
                format!(
                    "the bodies would hold about {particles:.3e} particles, above the limit of {MAX_PARTICLES} (body[{b}] about {most:.3e}): give {fix}"
                ),
            ));
        }
        // Each particle of the scene may be tested against every corner of a polygon
        // body (its own lattice cells when it is filled, the other bodies' particles
        // in its bounding box for the overlap check): bound the work before it starts.
        for (b, body) in self.bodies.iter().enumerate() {
            if body.shape != BodyShape::Polygon {
                continue;
            }
            let corners = body.outline.len() + body.holes.iter().map(Vec::len).sum::<usize>();
            let tests = corners as f64 * (particles + self.estimated_particles(body));
            if tests > MAX_POLYGON_TESTS {
                return Err(bad(
                    format!("body[{b}].outline"),
                    format!(
                        "{corners} corners against about {:.3e} lattice cells and particles take {tests:.3e} point-in-polygon tests, above the limit of {MAX_POLYGON_TESTS:e}: use fewer corners (a coarser outline) or a coarser lattice",
                        particles + self.estimated_particles(body)
                    ),
                ));
            }
        }
        for (b, body) in self.bodies.iter().enumerate() {
            if body.shape == BodyShape::Gmsh {
                continue;
            }
            // The particle mass is ρ0 times the lattice cell volume: reject a density
            // or a lattice so small that the product underflows to zero.
            let volume: f64 = (0..self.dim)
                .map(|k| self.lattice_spacing(body, k).unwrap_or(1.0))
                .product();
            let density = self.body_material(b).density;
            let mass = density * volume;
            if !(mass > 0.0 && mass.is_finite()) {
                let field = if !(volume > 0.0 && volume.is_finite()) {
                    // The lattice cell: the box's extent, or the lattice's field.
                    let lattice = if body.shape.is_box() {
                        "max"
                    } else {
                        body.lattice_key()
                    };
                    format!("body[{b}].{lattice}")
                } else if body.material.is_some() {
                    format!("body[{b}].material.density")
                } else {
                    "material.density".to_string()
                };
                return Err(bad(
                    field,
                    format!(
                        "the particles of body[{b}] would have mass {mass:e} (density {} times particle volume {volume:e}); it must be positive and finite",
                        echo_number(density)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The shape: allowed in the scene's dimension, its own fields given and valid,
    /// no field of another shape.
    fn validate_shape(&self, b: usize, body: &Body) -> Result<(), SceneError> {
        let d = self.dim;
        let field = |f: &str| format!("body[{b}].{f}");
        let shape = body.shape;
        if d == 1 && shape != BodyShape::Box {
            return Err(conflict(
                field("shape"),
                format!(
                    "a 1D scene has intervals only (`box` with `min`, `max`), got `{}`",
                    shape.name()
                ),
            ));
        }
        let present: [(&str, bool, &[BodyShape]); 15] = [
            ("min", !body.min.is_empty(), &[BodyShape::Box]),
            ("max", !body.max.is_empty(), &[BodyShape::Box]),
            ("outline", !body.outline.is_empty(), &[BodyShape::Polygon]),
            ("holes", !body.holes.is_empty(), &[BodyShape::Polygon]),
            ("centre", body.centre.is_some(), &[BodyShape::Disk]),
            ("radius", body.radius.is_some(), &[BodyShape::Disk]),
            ("file", body.file.is_some(), &[BodyShape::Gmsh]),
            ("surface", body.surface.is_some(), &[BodyShape::Gmsh]),
            (
                "per_triangle",
                body.per_triangle.is_some(),
                &[BodyShape::Gmsh],
            ),
            ("subdivide", body.subdivide.is_some(), &[BodyShape::Gmsh]),
            ("per_block", body.per_block.is_some(), &LATTICE),
            ("count", body.count.is_some(), &LATTICE),
            ("spacing", body.spacing.is_some(), &LATTICE),
            ("jitter", body.jitter != 0.0, &LATTICE),
            ("seed", body.seed.is_some(), &LATTICE),
        ];
        for (name, given, shapes) in present {
            if given && !shapes.contains(&shape) {
                let owners: Vec<&str> = shapes.iter().map(|s| s.name()).collect();
                return Err(conflict(
                    field(name),
                    format!(
                        "is not a field of a `{}` body (it belongs to {})",
                        shape.name(),
                        owners.join(", ")
                    ),
                ));
            }
        }
        let finite2 = |f: String, p: [f64; 2]| -> Result<(), SceneError> {
            if p.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(bad(f, format!("must be finite, got {p:?}")))
            }
        };
        match shape {
            BodyShape::Box => {
                for (name, v, corner) in [("min", &body.min, "lower"), ("max", &body.max, "upper")]
                {
                    if v.is_empty() {
                        return Err(bad(
                            field(name),
                            format!(
                                "is missing (or empty): a `box` body (the default shape) needs `{name}`, its {corner} corner ({d} {})",
                                if d == 1 { "number" } else { "numbers" }
                            ),
                        ));
                    }
                    if v.len() != d {
                        return Err(bad(
                            field(name),
                            format!("needs {}, got {}", plural(d, "entry", "entries"), v.len()),
                        ));
                    }
                    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                        return Err(bad(field(name), format!("must be finite, got {x}")));
                    }
                }
                if (0..d).any(|k| body.min[k] >= body.max[k]) {
                    return Err(bad(
                        field("max"),
                        format!(
                            "needs min < max on every axis, got min = {:?}, max = {:?}",
                            body.min, body.max
                        ),
                    ));
                }
            }
            BodyShape::Polygon => {
                if body.outline.len() < 3 {
                    return Err(bad(
                        field("outline"),
                        format!("needs at least 3 corners, got {}", body.outline.len()),
                    ));
                }
                let corners = body.outline.len() + body.holes.iter().map(Vec::len).sum::<usize>();
                if corners > MAX_OUTLINE_CORNERS {
                    return Err(bad(
                        field("outline"),
                        format!("{corners} corners (outline and holes) is above the limit of {MAX_OUTLINE_CORNERS}"),
                    ));
                }
                for (i, p) in body.outline.iter().enumerate() {
                    finite2(field(&format!("outline[{i}]")), *p)?;
                }
                for (h, hole) in body.holes.iter().enumerate() {
                    if hole.len() < 3 {
                        return Err(bad(
                            field(&format!("holes[{h}]")),
                            format!("needs at least 3 corners, got {}", hole.len()),
                        ));
                    }
                    for (i, p) in hole.iter().enumerate() {
                        finite2(field(&format!("holes[{h}][{i}]")), *p)?;
                    }
                }
                // The mesher's domain check: no crossing or touching segments, holes
                // inside the outline and not nested.
                region_polygon(body).check().map_err(|f| {
                    let name = match f.part {
                        PolygonPart::Hole(h) | PolygonPart::HoleTag(h) => format!("holes[{h}]"),
                        PolygonPart::Outer | PolygonPart::OuterTags => "outline".to_string(),
                    };
                    bad(field(&name), MeshError::from(f).to_string())
                })?;
            }
            BodyShape::Disk => {
                let Some(c) = body.centre else {
                    return Err(bad(field("centre"), "a `disk` body needs `centre`"));
                };
                finite2(field("centre"), c)?;
                match body.radius {
                    Some(r) if r > 0.0 && r.is_finite() => {}
                    Some(r) => {
                        return Err(bad(
                            field("radius"),
                            format!("must be positive and finite, got {}", echo_number(r)),
                        ))
                    }
                    None => return Err(bad(field("radius"), "a `disk` body needs `radius`")),
                }
            }
            BodyShape::Gmsh => {
                match &body.file {
                    Some(f) if !f.is_empty() => {}
                    Some(_) => return Err(bad(field("file"), "is empty")),
                    None => return Err(bad(field("file"), "a `gmsh` body needs `file`")),
                }
                if body.surface.is_none() {
                    return Err(bad(
                        field("surface"),
                        "a `gmsh` body needs `surface` (a physical surface's name or number)",
                    ));
                }
                if let Some(n) = body.per_triangle {
                    if !(n == 1 || n == 3) {
                        return Err(bad(
                            field("per_triangle"),
                            format!("must be 1 or 3, got {n}"),
                        ));
                    }
                }
                if let Some(k) = body.subdivide {
                    if k > MAX_SUBDIVIDE {
                        return Err(bad(
                            field("subdivide"),
                            format!("must be in 0..={MAX_SUBDIVIDE}, got {k}"),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The lattice of a box, polygon or disk body: exactly one of `per_block`,
    /// `count` and `spacing`, within range; `jitter` within a cell.
    fn validate_lattice(&self, b: usize, body: &Body) -> Result<(), SceneError> {
        if body.shape == BodyShape::Gmsh {
            return Ok(());
        }
        let d = self.dim;
        let field = |f: &str| format!("body[{b}].{f}");
        if !(0.0..0.5).contains(&body.jitter) {
            return Err(bad(
                field("jitter"),
                format!(
                    "must be in [0, 0.5) (a fraction of the lattice cell), got {}",
                    echo_number(body.jitter)
                ),
            ));
        }
        match (&body.per_block, &body.count, &body.spacing) {
            (Some(p), None, None) => {
                if p.len() != d || p.iter().any(|&n| n == 0 || n > 1000) {
                    return Err(bad(
                        field("per_block"),
                        format!(
                            "needs {d} {} in 1..=1000, got {p:?}",
                            if d == 1 { "count" } else { "counts" }
                        ),
                    ));
                }
                if !matches!(
                    self.mesh,
                    MeshSpec::Blocks { .. } | MeshSpec::Interval { .. }
                ) {
                    return Err(conflict(
                        field("per_block"),
                        "needs a `blocks` or `interval` mesh; use `count` or `spacing` on other meshes",
                    ));
                }
            }
            (None, Some(c), None) => {
                if c.len() != d || c.iter().any(|&n| n == 0 || n > 100_000) {
                    return Err(bad(
                        field("count"),
                        format!(
                            "needs {d} {} in 1..=100000, got {c:?}",
                            if d == 1 { "count" } else { "counts" }
                        ),
                    ));
                }
            }
            (None, None, Some(h)) => {
                if h.len() != d || h.iter().any(|&x| !(x > 0.0 && x.is_finite())) {
                    return Err(bad(
                        field("spacing"),
                        format!(
                            "needs {}, got {h:?}",
                            plural(d, "positive finite length", "positive finite lengths")
                        ),
                    ));
                }
            }
            (per_block, count, spacing) => {
                let given: Vec<&str> = [
                    ("per_block", per_block.is_some()),
                    ("count", count.is_some()),
                    ("spacing", spacing.is_some()),
                ]
                .into_iter()
                .filter_map(|(name, given)| given.then_some(name))
                .collect();
                return Err(match given.as_slice() {
                    [] => bad(
                        format!("body[{b}]"),
                        format!(
                            "a `{}` body needs a particle lattice and gives none: give one of `per_block` (particles per mesh block along each axis), `count` (particles along each axis of the body) and `spacing` (the lattice spacing along each axis)",
                            body.shape.name()
                        ),
                    ),
                    [.., last] => {
                        let names: Vec<String> = given.iter().map(|n| format!("`{n}`")).collect();
                        let (head, tail) = names.split_at(names.len() - 1);
                        conflict(
                            field(last),
                            format!(
                                "{} and {} are given together, but each sets the particle lattice alone: give one of them",
                                head.join(", "),
                                tail[0]
                            ),
                        )
                    }
                });
            }
        }
        Ok(())
    }

    /// An initial velocity (the scene's or a body's, `field` its path).
    pub(super) fn validate_velocity(
        &self,
        field: &str,
        v: &InitialVelocity,
    ) -> Result<(), SceneError> {
        let d = self.dim;
        let sub = |f: &str| format!("{field}.{f}");
        let vector = |f: String, v: &[f64]| -> Result<(), SceneError> {
            if v.len() != d {
                return Err(bad(
                    f,
                    format!("needs {}, got {}", plural(d, "entry", "entries"), v.len()),
                ));
            }
            match v.iter().find(|x| !x.is_finite()) {
                Some(x) => Err(bad(f, format!("must be finite, got {x}"))),
                None => Ok(()),
            }
        };
        // A speed no continuum moves at (its kinetic energy may not even be a
        // number): a unit slip, named before the run fails at its first step.
        let speed = |f: String, s: f64| -> Result<(), SceneError> {
            if s > MAX_SPEED {
                return Err(bad(
                    f,
                    format!(
                        "a speed of {} m/s is beyond continuum mechanics (the limit is {MAX_SPEED:e}, a third of the speed of light): give it in m/s",
                        echo_number(s)
                    ),
                ));
            }
            Ok(())
        };
        match v {
            InitialVelocity::Uniform { value } => {
                vector(sub("value"), value)?;
                speed(sub("value"), value.iter().fold(0.0f64, |a, c| a.hypot(*c)))?;
            }
            InitialVelocity::SineMode { v0 } if !v0.is_finite() => {
                return Err(bad(sub("v0"), format!("must be finite, got {v0}")));
            }
            InitialVelocity::SineMode { v0 } => speed(sub("v0"), v0.abs())?,
            InitialVelocity::Exact {} if self.reference.is_none() => {
                return Err(conflict(
                    sub("kind"),
                    "`exact` needs a [reference] solution",
                ))
            }
            InitialVelocity::RigidRotation { omega, centre } => {
                if d != 2 {
                    return Err(conflict(sub("kind"), "a rigid rotation needs a 2D scene"));
                }
                if !omega.is_finite() {
                    return Err(bad(sub("omega"), format!("must be finite, got {omega}")));
                }
                vector(sub("centre"), centre)?;
            }
            InitialVelocity::Linear {
                value,
                origin,
                gradient,
            } => {
                vector(sub("value"), value)?;
                vector(sub("origin"), origin)?;
                if gradient.len() != d {
                    return Err(bad(
                        sub("gradient"),
                        format!(
                            "needs {} of {}, got {}",
                            plural(d, "row", "rows"),
                            plural(d, "entry", "entries"),
                            plural(gradient.len(), "row", "rows")
                        ),
                    ));
                }
                for row in gradient {
                    vector(sub("gradient"), row)?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// About how many particles the bodies get together, computed from the scene
    /// without building anything (validation bounds it by [`MAX_PARTICLES`]; a Gmsh
    /// body counts as known only once its file is read).
    pub fn estimated_particle_count(&self) -> f64 {
        self.bodies
            .iter()
            .map(|b| self.estimated_particles(b))
            .sum()
    }

    /// About how many particles `body` gets: exact for boxes, the cells of the
    /// bounding box (an upper bound) for polygons and disks, 0 for a Gmsh body (its
    /// count is checked once the file is read).
    pub(crate) fn estimated_particles(&self, body: &Body) -> f64 {
        let Some((lo, hi)) = body.bounds() else {
            return 0.0;
        };
        (0..self.dim)
            .map(|k| {
                let cells = self
                    .lattice_spacing(body, k)
                    .map_or(1.0, |h| (hi[k] - lo[k]) / h);
                if body.shape == BodyShape::Box {
                    cells
                } else {
                    cells.ceil().max(1.0)
                }
            })
            .product()
    }
}

/// A material's constants in range; the error names `field.young` and so on. The
/// P-wave speed `√((λ + 2μ) / ρ)` in dimension `dim` they give must be a finite
/// positive normal number too (each constant in range, `young / density` can still
/// overflow or underflow): the critical time step is inversely proportional to it.
pub(super) fn validate_material(
    field: &str,
    m: &MaterialSpec,
    dim: usize,
) -> Result<(), SceneError> {
    let elastic = crate::material::Elastic::new(m.young, m.poisson, m.density).map_err(|e| {
        let name = match &e {
            crate::material::MaterialError::OutOfRange { name, .. } => name,
        };
        SceneError::new(format!("{field}.{name}"), ErrorKind::Value, e.to_string())
    })?;
    let c = (elastic.p_modulus(dim) / m.density).sqrt();
    if !(c.is_normal() && c > 0.0) {
        return Err(SceneError::new(
            format!("{field}.young"),
            ErrorKind::Conflict,
            format!(
                "young = {}, poisson = {} and density = {} give a P-wave speed √((λ + 2μ) / ρ) of {}, which sets no time step: `{field}.young`, `{field}.poisson` and `{field}.density` must give a speed between 1e-300 and 1e300 or so",
                echo_number(m.young),
                echo_number(m.poisson),
                echo_number(m.density),
                echo_number(c)
            ),
        ));
    }
    Ok(())
}

/// The region of a polygon body as the mesher's domain (its tags unused).
pub fn region_polygon(body: &Body) -> PolygonDomain {
    let corners = |c: &[[f64; 2]]| c.iter().map(|p| Vec2::new(p[0], p[1])).collect::<Vec<_>>();
    PolygonDomain {
        outer: corners(&body.outline),
        outer_tags: vec!["body".to_string(); body.outline.len()],
        holes: body
            .holes
            .iter()
            .enumerate()
            .map(|(h, hole)| (corners(hole), format!("holes[{h}]")))
            .collect(),
    }
}
