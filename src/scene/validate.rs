//! Validation: a scene is consistent, or the error names the field.

use super::limits::{
    check_tracked_history, echo, echo_number, plural, MAX_BLOCKS, MAX_BLOCKS_PER_AXIS,
    MAX_DESCRIPTION_CHARS, MAX_ELEMENTS_1D, MAX_NAME_CHARS, MAX_OUTLINE_CORNERS, MAX_STEPS,
    MAX_TRACKED, MAX_TRIANGLES,
};
use super::{
    bad, conflict, Axis, BodyShape, Component, EffectSpec, InitialVelocity, MaterialModel,
    MeshSpec, Reference, Scene, SceneError,
};

/// Largest lateral coefficient `k0` of a geostatic stress.
pub const MAX_K0: f64 = 10.0;

/// Largest `study.particle_growth`.
pub const MAX_PARTICLE_GROWTH: u32 = 4;

impl Scene {
    /// Checks that the scene is consistent; the error names the field.
    pub fn validate(&self) -> Result<(), SceneError> {
        let d = self.dim;
        if !(d == 1 || d == 2) {
            return Err(bad("dim", format!("must be 1 or 2, got {d}")));
        }
        if self.basis.dim() != d {
            return Err(conflict(
                "basis",
                format!(
                    "`{}` is a {}D basis but the scene is {d}D (2D: ps, pl; 1D: bspline, pl1d)",
                    self.basis.name(),
                    self.basis.dim()
                ),
            ));
        }
        // Names and descriptions are printed and written into SVG and JSON files.
        if self.name.trim().is_empty() {
            return Err(bad(
                "name",
                "is empty: the scene's name is printed and names its output files",
            ));
        }
        for (field, text, limit) in [
            ("name", &self.name, MAX_NAME_CHARS),
            ("description", &self.description, MAX_DESCRIPTION_CHARS),
        ] {
            let chars = text.chars().count();
            if chars > limit {
                return Err(bad(
                    field,
                    format!("is {chars} characters long, above the limit of {limit}"),
                ));
            }
            if let Some(c) = text.chars().find(|c| c.is_control()) {
                return Err(bad(
                    field,
                    format!(
                        "contains the control character {:?} (U+{:04X}): it is printed and written into the output files; use printable text",
                        c,
                        c as u32
                    ),
                ));
            }
        }
        let finite = |field: &str, v: f64| -> Result<(), SceneError> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(bad(
                    field,
                    format!("must be finite, got {}", echo_number(v)),
                ))
            }
        };
        let positive = |field: &str, v: f64| -> Result<(), SceneError> {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(bad(
                    field,
                    format!("must be positive and finite, got {}", echo_number(v)),
                ))
            }
        };
        let vector = |field: &str, v: &[f64]| -> Result<(), SceneError> {
            if v.len() != d {
                return Err(bad(
                    field,
                    format!("needs {}, got {}", plural(d, "entry", "entries"), v.len()),
                ));
            }
            v.iter().try_for_each(|&x| finite(field, x))
        };
        let interval = |field: &str, r: [f64; 2]| -> Result<(), SceneError> {
            finite(field, r[0])?;
            finite(field, r[1])?;
            if r[0] < r[1] {
                Ok(())
            } else {
                Err(bad(
                    field,
                    format!(
                        "needs min < max, got [{}, {}]",
                        echo_number(r[0]),
                        echo_number(r[1])
                    ),
                ))
            }
        };
        match &self.mesh {
            MeshSpec::Blocks { x, y, blocks, .. } => {
                if d != 2 {
                    return Err(conflict(
                        "mesh.kind",
                        "`blocks` is a 2D mesh; use `interval` in 1D",
                    ));
                }
                interval("mesh.x", *x)?;
                interval("mesh.y", *y)?;
                check_blocks("mesh.blocks", *blocks)?;
            }
            MeshSpec::Polygon {
                outline,
                tags,
                edge_length,
                holes,
            } => {
                if d != 2 {
                    return Err(conflict("mesh.kind", "`polygon` is a 2D mesh"));
                }
                if outline.len() < 3 {
                    return Err(bad("mesh.outline", "needs at least 3 corners"));
                }
                let corners = outline.len() + holes.iter().map(|h| h.outline.len()).sum::<usize>();
                if corners > MAX_OUTLINE_CORNERS {
                    return Err(bad(
                        "mesh.outline",
                        format!(
                            "{corners} corners (outline and holes) is above the limit of {MAX_OUTLINE_CORNERS}"
                        ),
                    ));
                }
                for (i, p) in outline.iter().enumerate() {
                    finite(&format!("mesh.outline[{i}]"), p[0])?;
                    finite(&format!("mesh.outline[{i}]"), p[1])?;
                }
                if !tags.is_empty() && tags.len() != outline.len() {
                    return Err(bad(
                        "mesh.tags",
                        format!(
                            "needs one tag per outline segment ({}), got {}",
                            outline.len(),
                            tags.len()
                        ),
                    ));
                }
                positive("mesh.edge_length", *edge_length)?;
                check_triangles("mesh.edge_length", outline, *edge_length)?;
            }
            MeshSpec::Gmsh { file } => {
                if d != 2 {
                    return Err(conflict("mesh.kind", "`gmsh` meshes are 2D"));
                }
                if file.is_empty() {
                    return Err(bad("mesh.file", "is empty"));
                }
            }
            MeshSpec::Interval { x, elements } => {
                if d != 1 {
                    return Err(conflict(
                        "mesh.kind",
                        "`interval` is a 1D mesh; use `blocks` in 2D",
                    ));
                }
                interval("mesh.x", *x)?;
                check_elements("mesh.elements", *elements)?;
            }
        }
        super::bodies::validate_material("material", &self.material, self.dim)?;
        self.validate_bodies()?;
        self.validate_velocity("initial_velocity", &self.initial_velocity)?;
        for (i, bc) in self.boundaries.iter().enumerate() {
            if bc.fix.is_empty() {
                return Err(bad(format!("boundary[{i}].fix"), "lists no component"));
            }
            if let Some((k, c)) = bc
                .fix
                .iter()
                .enumerate()
                .find(|(k, c)| bc.fix[..*k].contains(c))
            {
                return Err(bad(
                    format!("boundary[{i}].fix"),
                    format!(
                        "`{}` is listed twice (entries {} and {k})",
                        format!("{c:?}").to_lowercase(),
                        bc.fix.iter().position(|b| b == c).unwrap_or(0)
                    ),
                ));
            }
            if let Some(j) = self.boundaries[..i].iter().position(|o| o.tag == bc.tag) {
                // In 1D an end has one component, the axis (`x`, or `normal`).
                let fix = if d == 1 {
                    "(in 1D `fix = [\"normal\"]`: the axis, an end's only component)"
                } else {
                    "listing all it holds (`fix = [\"x\", \"y\"]`, or `[\"normal\"]` alone)"
                };
                return Err(conflict(
                    format!("boundary[{i}].tag"),
                    format!(
                        "`{}` is already held by boundary[{j}]: give each tag one [[boundary]] {fix}",
                        echo(&bc.tag)
                    ),
                ));
            }
            if bc.fix.contains(&Component::Normal) && bc.fix.len() > 1 {
                return Err(conflict(
                    format!("boundary[{i}].fix"),
                    "`normal` fixes the normal component alone; list it on its own",
                ));
            }
            if let Some(c) = bc.fix.iter().find(|c| c.axis().is_some_and(|a| a >= d)) {
                return Err(conflict(
                    format!("boundary[{i}].fix"),
                    format!(
                        "component `{}` does not exist in {d}D: {}",
                        format!("{c:?}").to_lowercase(),
                        if d == 1 {
                            "a 1D bar moves along x only; hold its end with `fix = [\"x\"]` (or `[\"normal\"]`, the same in 1D)"
                        } else {
                            "use `x` and `y` (or `normal` for a slip wall)"
                        }
                    ),
                ));
            }
        }
        let gravity = self.gravity();
        for (i, effect) in self.effects.iter().enumerate() {
            let field = |f: &str| format!("effect[{i}].{f}");
            // The physics sums two gravity (or damping) effects, but the references
            // and the geostatic stress take the first gravity alone, and two dampings
            // may add up to α ≥ 1, which pushes along the velocity: one of each.
            let once = match effect {
                EffectSpec::Gravity { .. } => Some((
                    "gravity",
                    "`g` (the references and the geostatic stress use the first gravity alone)",
                )),
                EffectSpec::Damping { .. } => Some((
                    "damping",
                    "`alpha`, below 1 (the damping of two is that of their sum, and from 1 on it pushes along the velocity)",
                )),
                _ => None,
            };
            if let Some((kind, what)) = once {
                let same =
                    |e: &EffectSpec| std::mem::discriminant(e) == std::mem::discriminant(effect);
                if let Some(j) = self.effects[..i].iter().position(same) {
                    return Err(conflict(
                        field("kind"),
                        format!(
                            "`{kind}` is already declared by effect[{j}]; give one `{kind}` effect with the sum of their {what}"
                        ),
                    ));
                }
            }
            match effect {
                EffectSpec::Gravity { g } => vector(&field("g"), g)?,
                EffectSpec::Damping { alpha } => {
                    if !(0.0..1.0).contains(alpha) {
                        return Err(bad(
                            field("alpha"),
                            format!("must be in [0, 1), got {}", echo_number(*alpha)),
                        ));
                    }
                }
                EffectSpec::Traction {
                    min,
                    max,
                    traction,
                    length,
                    ramp,
                } => {
                    vector(&field("min"), min)?;
                    vector(&field("max"), max)?;
                    if min.iter().zip(max.iter()).any(|(a, b)| a > b) {
                        return Err(bad(
                            field("max"),
                            format!(
                                "the traction box needs min ≤ max on every axis, got min = {:?}, max = {:?}",
                                min, max
                            ),
                        ));
                    }
                    vector(&field("traction"), traction)?;
                    positive(&field("length"), *length)?;
                    if !traction.iter().all(|t| (t * length).is_finite()) {
                        return Err(bad(
                            field("length"),
                            format!(
                                "the force `traction × length` overflows (traction {:?}, length {})",
                                traction,
                                echo_number(*length)
                            ),
                        ));
                    }
                    if self.dim == 1 && *length != 1.0 {
                        return Err(conflict(
                            field("length"),
                            format!(
                                "in 1D the loaded boundary is a point: give `length = 1` (the force is `traction × length`, and `traction` is the force per unit cross-section); got {}",
                                echo_number(*length)
                            ),
                        ));
                    }
                    if !(*ramp >= 0.0 && ramp.is_finite()) {
                        return Err(bad(
                            field("ramp"),
                            format!("must be ≥ 0, got {}", echo_number(*ramp)),
                        ));
                    }
                }
                EffectSpec::BodyForce { value } => vector(&field("value"), value)?,
                EffectSpec::ManufacturedBodyForce {} => {
                    if !matches!(self.reference, Some(Reference::AxisAligned { .. })) {
                        return Err(conflict(
                            field("kind"),
                            "`manufactured-body-force` needs reference kind `axis-aligned`",
                        ));
                    }
                }
                EffectSpec::ContactWall { tag, stiffness } => {
                    if self.dim != 2 {
                        // In 1D the wall's normal is the axis: a slip wall holds it.
                        return Err(conflict(
                            field("kind"),
                            format!(
                                "a contact wall needs a 2D scene; in 1D hold the end with a `[[boundary]]` in place of this effect: `tag = \"{}\"` and `fix = [\"normal\"]` (in 1D the normal is the axis)",
                                echo(tag)
                            ),
                        ));
                    }
                    if !(*stiffness > 0.0 && *stiffness <= 1.0) {
                        return Err(bad(
                            field("stiffness"),
                            format!("must be in (0, 1], got {}", echo_number(*stiffness)),
                        ));
                    }
                    if let Some(j) = self.effects[..i].iter().position(
                        |e| matches!(e, EffectSpec::ContactWall { tag: t, .. } if t == tag),
                    ) {
                        return Err(conflict(
                            field("tag"),
                            format!(
                                "`{}` already has a contact wall (effect[{j}]): a second one would double its springs; keep one",
                                crate::scene::limits::echo(tag)
                            ),
                        ));
                    }
                    if let Some(b) = self.boundaries.iter().position(|bc| &bc.tag == tag) {
                        if !self.boundaries[b].fix.is_empty() {
                            return Err(conflict(
                                field("tag"),
                                format!(
                                    "`{}` is also held by boundary[{b}] (`fix`): a contact wall replaces the condition on the functions; remove that `[[boundary]]`",
                                    crate::scene::limits::echo(tag)
                                ),
                            ));
                        }
                    }
                }
                EffectSpec::BodyContact {} => {
                    use crate::body_contact::MAX_CONTACT_BODIES;
                    let n = self.bodies.len();
                    if n < 2 {
                        return Err(conflict(
                            field("kind"),
                            format!("contact between bodies needs two or more `[[body]]` tables, this scene has {n}: add the other body, or remove this effect"),
                        ));
                    }
                    if n > MAX_CONTACT_BODIES {
                        return Err(conflict(
                            field("kind"),
                            format!("contact between bodies copies the basis once per body, and this scene has {n} bodies, above the limit of {MAX_CONTACT_BODIES}: join the bodies that need no contact between them into one (a `polygon` body with holes, or one material)"),
                        ));
                    }
                    if let Some(j) = self.effects[..i]
                        .iter()
                        .position(|e| matches!(e, EffectSpec::BodyContact {}))
                    {
                        return Err(conflict(
                            field("kind"),
                            format!(
                                "effect[{j}] already asks for contact between bodies; keep one"
                            ),
                        ));
                    }
                }
                EffectSpec::GeostaticStress { surface, k0 } => {
                    finite(&field("surface"), *surface)?;
                    finite(&field("k0"), *k0)?;
                    if !(0.0..=MAX_K0).contains(k0) {
                        return Err(bad(
                            field("k0"),
                            format!(
                                "must be in [0, {MAX_K0}] (σ_xx / σ_yy at rest: about 0.3–1 in most soils, up to about 3 when overconsolidated), got {}",
                                echo_number(*k0)
                            ),
                        ));
                    }
                    if gravity.is_none() {
                        return Err(conflict(
                            field("kind"),
                            "geostatic stress needs a gravity effect",
                        ));
                    }
                }
            }
        }
        match (self.time.dt, self.time.courant) {
            (Some(dt), None) => positive("time.dt", dt)?,
            (None, Some(c)) => positive("time.courant", c)?,
            _ => {
                return Err(conflict(
                    "time.dt",
                    "give exactly one of `dt` and `courant`",
                ))
            }
        }
        positive("time.t_end", self.time.t_end)?;
        if let Some(dt) = self.time.dt {
            let steps = self.time.t_end / dt;
            if steps > MAX_STEPS as f64 {
                return Err(bad(
                    "time.dt",
                    format!(
                        "t_end / dt = {} / {} = {} steps is above the limit of {MAX_STEPS}",
                        crate::scene::limits::echo_number(self.time.t_end),
                        crate::scene::limits::echo_number(dt),
                        if steps < 1e9 {
                            format!("{}", steps.round())
                        } else {
                            format!("{steps:.3e}")
                        }
                    ),
                ));
            }
        }
        if let Some(growth) = self.study.particle_growth {
            if !(1..=MAX_PARTICLE_GROWTH).contains(&growth) {
                return Err(bad(
                    "study.particle_growth",
                    format!(
                        "must be a whole number from 1 to {MAX_PARTICLE_GROWTH} (the factor on the particles per element along each refined axis per level), got {growth}"
                    ),
                ));
            }
        }
        if let Some(refine) = &self.study.refine {
            if refine.is_empty() {
                return Err(bad(
                    "study.refine",
                    "lists no axis: list `x`, `y` or both, or leave `refine` out to refine every axis",
                ));
            }
            if let Some((i, a)) = refine
                .iter()
                .enumerate()
                .find(|(i, a)| refine[..*i].contains(a))
            {
                return Err(bad(
                    "study.refine",
                    format!(
                        "`{}` is listed twice (entries {} and {i})",
                        format!("{a:?}").to_lowercase(),
                        refine.iter().position(|b| b == a).unwrap_or(0)
                    ),
                ));
            }
            if d == 1 && refine.contains(&Axis::Y) {
                return Err(bad(
                    "study.refine",
                    "`y` does not exist in a 1D scene (refine `x` or leave it out)",
                ));
            }
        }
        self.validate_resolutions()?;
        let tracked = self.output.tracked.len();
        if tracked > MAX_TRACKED {
            return Err(bad(
                "output.tracked",
                format!(
                    "lists {tracked} points, above the limit of {MAX_TRACKED}: each is recorded every step; track fewer points, or write the particle frames (`run --out DIR`, every particle at every `--out-every` steps)"
                ),
            ));
        }
        for (i, t) in self.output.tracked.iter().enumerate() {
            vector(&format!("output.tracked[{i}]"), t)?;
        }
        if let (Some(dt), true) = (self.time.dt, tracked > 0) {
            // (With `courant` the run checks it once it knows its step.)
            let steps = (self.time.t_end / dt).round().max(1.0) as usize;
            check_tracked_history(tracked, steps, "t_end / dt")
                .map_err(|m| bad("output.tracked", m))?;
        }
        match self.reference {
            Some(Reference::VibratingBar { v0 }) => {
                finite("reference.v0", v0)?;
                self.validate_vibrating_bar(v0)?;
            }
            Some(Reference::ColumnSelfWeight {}) | Some(Reference::ColumnEquilibrium {})
                if gravity.is_none() =>
            {
                return Err(conflict(
                    "reference.kind",
                    "a column reference needs a gravity effect",
                ));
            }
            Some(Reference::ColumnSelfWeight {}) => {
                // The settling motion starts stress-free; a geostatic initial stress
                // holds the column at rest instead.
                if let Some(k) = self
                    .effects
                    .iter()
                    .position(|e| matches!(e, EffectSpec::GeostaticStress { .. }))
                {
                    return Err(conflict(
                        "reference.kind",
                        format!(
                            "`column-self-weight` is the column settling from a stress-free start, but effect[{k}] gives it a geostatic initial stress, which holds it at rest: use `column-equilibrium` (whose error is then measured against the geostatic profile), or leave out the geostatic stress"
                        ),
                    ));
                }
            }
            Some(Reference::AxisAligned { u0 }) => {
                finite("reference.u0", u0)?;
                if d != 2
                    || (0..self.bodies.len())
                        .any(|b| self.body_material(b).model != MaterialModel::NeoHookean)
                {
                    return Err(conflict(
                        "reference.kind",
                        "`axis-aligned` is a 2D neo-Hookean solution",
                    ));
                }
            }
            _ => {}
        }
        if self.reference.is_some() && !self.bodies[0].shape.is_box() {
            return Err(conflict(
                "body[0].shape",
                "a [reference] solution is over the first body's box: body[0] must be a `box`",
            ));
        }
        if let (Some(dt), 0) = (self.time.dt, self.steps()) {
            // `t_end / dt` rounds to no step: the step is what does not fit (with
            // `courant` the run checks it once it knows its step).
            return Err(conflict(
                "time.dt",
                format!(
                    "{} exceeds t_end = {}: the run takes t_end / dt steps, rounded, and that is none; give a `dt` of at most t_end, or a longer `t_end`",
                    echo_number(dt),
                    echo_number(self.time.t_end)
                ),
            ));
        }
        Ok(())
    }

    /// The vibrating-bar reference (thesis eq. (4.2)) is the first mode of a bar fixed
    /// at both ends: the first body starts in that mode with the reference's `v0`,
    /// and on a block or interval mesh it spans the mesh along x (whose ends carry
    /// the walls). Otherwise its error would measure another motion.
    fn validate_vibrating_bar(&self, v0: f64) -> Result<(), SceneError> {
        let (field, start) = match &self.bodies[0].initial_velocity {
            Some(v) => ("body[0].initial_velocity", Some(v)),
            None => ("initial_velocity", Some(&self.initial_velocity)),
        };
        match start {
            Some(InitialVelocity::Exact {}) => {}
            Some(InitialVelocity::SineMode { v0: w }) if *w == v0 => {}
            Some(InitialVelocity::SineMode { v0: w }) => {
                return Err(conflict(
                    "reference.v0",
                    format!(
                        "is {}, but the bar starts in the sine mode with v0 = {} \
                         ([{field}]): the reference would be another motion; give both the \
                         same v0, or `kind = \"exact\"` in [{field}] to start from the \
                         reference",
                        echo_number(v0),
                        echo_number(*w)
                    ),
                ));
            }
            _ => {
                return Err(conflict(
                    "reference.kind",
                    format!(
                        "`vibrating-bar` is the first mode of a bar started with \
                         v_x = v0 sin(π x / L), but the bar starts otherwise: give \
                         [{field}] `kind = \"exact\"` (or `kind = \"sine-mode\"` with the \
                         reference's v0)"
                    ),
                ));
            }
        }
        let mesh_x = match &self.mesh {
            MeshSpec::Blocks { x, .. } | MeshSpec::Interval { x, .. } => *x,
            _ => return Ok(()),
        };
        let body = &self.bodies[0];
        if let (Some(&lo), Some(&hi)) = (body.min.first(), body.max.first()) {
            let tolerance = 1e-9 * (mesh_x[1] - mesh_x[0]).abs();
            if (lo - mesh_x[0]).abs() > tolerance || (hi - mesh_x[1]).abs() > tolerance {
                return Err(conflict(
                    "body[0].max",
                    format!(
                        "the `vibrating-bar` reference is a bar fixed at both ends, but body[0] \
                         spans [{}, {}] along x and the mesh, whose ends carry the walls, \
                         [{}, {}]: make the body span the mesh, or leave out [reference]",
                        echo_number(lo),
                        echo_number(hi),
                        echo_number(mesh_x[0]),
                        echo_number(mesh_x[1])
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The `[[resolution]]` tables: each names a basis of the scene's dimension and
    /// changes only what the scene's mesh has, within the limits.
    fn validate_resolutions(&self) -> Result<(), SceneError> {
        let d = self.dim;
        for (i, r) in self.resolutions.iter().enumerate() {
            let field = |f: &str| format!("resolution[{i}].{f}");
            if let Some(j) = self.resolutions[..i]
                .iter()
                .position(|o| o.basis == r.basis)
            {
                return Err(conflict(
                    field("basis"),
                    format!(
                        "`{}` already has a resolution (resolution[{j}]): give each basis one [[resolution]]",
                        r.basis.name()
                    ),
                ));
            }
            if r.basis.dim() != d {
                return Err(bad(
                    field("basis"),
                    format!(
                        "`{}` is a {}D basis but the scene is {d}D",
                        r.basis.name(),
                        r.basis.dim()
                    ),
                ));
            }
            if let Some(blocks) = r.blocks {
                match &self.mesh {
                    MeshSpec::Blocks { .. } => check_blocks(&field("blocks"), blocks)?,
                    MeshSpec::Interval { .. } => {
                        if blocks[1] != 1 {
                            return Err(bad(
                                field("blocks"),
                                format!(
                                    "a 1D scene has one count of elements: the second number must be 1, got {blocks:?}"
                                ),
                            ));
                        }
                        check_elements(&field("blocks"), blocks[0])?;
                    }
                    _ => return Err(bad(field("blocks"), "the scene's mesh has no blocks")),
                }
            }
            if let Some(h) = r.edge_length {
                let MeshSpec::Polygon { outline, .. } = &self.mesh else {
                    return Err(bad(
                        field("edge_length"),
                        "the scene's mesh is not a polygon",
                    ));
                };
                if !(h > 0.0 && h.is_finite()) {
                    return Err(bad(
                        field("edge_length"),
                        format!("must be positive and finite, got {}", echo_number(h)),
                    ));
                }
                check_triangles(&field("edge_length"), outline, h)?;
            }
            if let Some(p) = &r.per_block {
                if p.len() != d || p.iter().any(|&n| n == 0 || n > 1000) {
                    return Err(bad(
                        field("per_block"),
                        format!(
                            "needs {d} {} in 1..=1000, got {p:?}",
                            if d == 1 { "count" } else { "counts" }
                        ),
                    ));
                }
                if self.blocks().is_none() {
                    return Err(bad(
                        field("per_block"),
                        "needs a `blocks` or `interval` mesh",
                    ));
                }
                if self.bodies.iter().all(|b| b.shape == BodyShape::Gmsh) {
                    return Err(conflict(
                        field("per_block"),
                        "every body is a Gmsh body (`shape = \"gmsh\"`), whose particles `per_triangle` and `subdivide` set: `per_block` would change none",
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Block counts of a `blocks` mesh within [`MAX_BLOCKS_PER_AXIS`] and [`MAX_BLOCKS`].
fn check_blocks(field: &str, blocks: [usize; 2]) -> Result<(), SceneError> {
    if blocks.iter().any(|&n| n == 0 || n > MAX_BLOCKS_PER_AXIS) {
        return Err(bad(
            field,
            format!("each count must be in 1..={MAX_BLOCKS_PER_AXIS}, got {blocks:?}"),
        ));
    }
    let all = blocks[0] * blocks[1];
    if all > MAX_BLOCKS {
        return Err(bad(
            field,
            format!("{all} blocks in all is above the limit of {MAX_BLOCKS}"),
        ));
    }
    Ok(())
}

/// Elements of an interval within [`MAX_ELEMENTS_1D`].
fn check_elements(field: &str, elements: usize) -> Result<(), SceneError> {
    if elements == 0 || elements > MAX_ELEMENTS_1D {
        return Err(bad(
            field,
            format!("must be in 1..={MAX_ELEMENTS_1D}, got {elements}"),
        ));
    }
    Ok(())
}

/// The triangles of a polygon mesh with edge length `h`, estimated from the area of
/// the outline's bounding box (an equilateral triangle of side `h` has area
/// `√3/4 h²`), within [`MAX_TRIANGLES`].
fn check_triangles(field: &str, outline: &[[f64; 2]], h: f64) -> Result<(), SceneError> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in outline {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    let triangles = area / (0.25 * 3f64.sqrt() * h * h);
    if triangles.is_nan() || triangles > MAX_TRIANGLES as f64 {
        return Err(bad(
            field,
            format!(
                "edge length {} on an outline of extent {} × {} gives about {triangles:.3e} triangles, above the limit of {MAX_TRIANGLES}",
                echo_number(h),
                echo_number(hi[0] - lo[0]),
                echo_number(hi[1] - lo[1])
            ),
        ));
    }
    Ok(())
}
