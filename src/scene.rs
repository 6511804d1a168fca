//! Scenes: a run declared as data. A scene is a TOML file (and the same struct built
//! in code) that says everything a run needs and nothing more: the mesh (a generator
//! or a Gmsh file), the basis and mass strategy, the material, the bodies and how
//! particles fill them, the initial velocity, boundary conditions per boundary tag,
//! the effects (gravity, damping, traction, body forces, initial stress), time
//! stepping, the reference solution that errors are measured against, and outputs.
//!
//! A run simulates only the effects its scene lists: a scene without gravity never
//! evaluates it. [`crate::simulation`] turns a scene into a driver and runs it.
//!
//! The built-in scenes are TOML files under `scenes/` compiled into the library
//! ([`BUILTIN`], [`Scene::builtin`]); `mpm-cli scene show NAME` prints them and
//! `mpm-cli run FILE.toml` reads a file back. Every error in a file names the file,
//! line and column, and the field.
//!
//! ```toml
//! name = "column-small"
//! dim = 2
//! basis = "ps"               # ps, pl (2D); bspline, pl1d (1D)
//! mass = "consistent"        # optional: default (extended), consistent, lumped, partial[:TAU], partial-coverage:C, deactivate[:M], extended[:C], fmpm:K
//!
//! [mesh]
//! kind = "blocks"            # blocks, polygon, gmsh (2D); interval (1D)
//! x = [0.0, 2.0]
//! y = [0.0, 25.0]
//! blocks = [1, 8]
//!
//! [material]
//! model = "linear-elastic"   # or neo-hookean
//! young = 5e4
//! poisson = 0.0
//! density = 1.0
//!
//! [[body]]
//! min = [0.0, 0.0]
//! max = [2.0, 25.0]
//! per_block = [6, 8]         # or count = [NX, NY] over the body
//! # jitter = 0.3             # optional: random offsets, a fraction of the cell
//!
//! [[boundary]]
//! tag = "bottom"
//! fix = ["x", "y"]
//!
//! [[effect]]
//! kind = "gravity"
//! g = [0.0, -9.81]
//!
//! [time]
//! dt = 1e-4                  # or courant = 0.5 (fraction of the critical step)
//! t_end = 1.0
//!
//! [reference]
//! kind = "column-self-weight"
//! ```

use crate::bases::BasisKind;
use crate::mass::MassKind;
use psmpm_basis::basis::powell_sabin::SplitPoint;
use serde::{Deserialize, Serialize};

/// A fully declared run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// One line saying what the scene is.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// 1 or 2.
    pub dim: usize,
    /// Basis.
    #[serde(with = "basis_name")]
    pub basis: BasisKind,
    /// PS split points (ignored by the other bases).
    #[serde(default, with = "split_name")]
    pub split: SplitPoint,
    /// Mass strategy.
    /// The mass strategy; absent means [`MassKind::default`] (extension).
    #[serde(with = "mass_name", default)]
    pub mass: MassKind,
    /// The mesh.
    pub mesh: MeshSpec,
    /// The material.
    pub material: MaterialSpec,
    /// Bodies: boxes filled with particles.
    #[serde(rename = "body")]
    pub bodies: Vec<Body>,
    /// Initial velocity of the particles.
    #[serde(default)]
    pub initial_velocity: InitialVelocity,
    /// Homogeneous Dirichlet conditions per boundary tag.
    #[serde(default, rename = "boundary", skip_serializing_if = "Vec::is_empty")]
    pub boundaries: Vec<BoundaryCondition>,
    /// Effects beyond elasticity; only these are assembled.
    #[serde(default, rename = "effect", skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<EffectSpec>,
    /// Time stepping.
    pub time: TimeSpec,
    /// The exact or reference solution the error is measured against.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<Reference>,
    /// What to record.
    #[serde(default)]
    pub output: OutputSpec,
    /// The resolution each basis gets when bases are compared (`mpm-cli compare`),
    /// chosen so that they have about the same number of functions.
    #[serde(default, rename = "resolution", skip_serializing_if = "Vec::is_empty")]
    pub resolutions: Vec<Resolution>,
    /// How refinement studies refine the scene (`mpm-cli converge`).
    #[serde(default)]
    pub study: StudySpec,
}

/// The resolution of one basis in comparisons: every field given replaces the
/// scene's value when the scene is switched to `basis`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resolution {
    /// The basis this resolution is for.
    #[serde(with = "basis_name")]
    pub basis: BasisKind,
    /// Blocks of a `blocks` mesh (`[elements, 1]` for an interval).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<[usize; 2]>,
    /// Target edge length of a `polygon` mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_length: Option<f64>,
    /// Particles per block of every body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_block: Option<Vec<usize>>,
}

/// How a refinement study refines a scene: level `l` multiplies the block counts
/// along the `refine` axes (all axes by default) and the elements of an interval by
/// `2^l`, divides a polygon's edge length by `2^l` (and multiplies particle counts
/// along every axis by `2^l`, keeping particles per element about constant). The
/// time step and particles per block stay.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Axes whose block counts are refined (empty: all).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refine: Vec<Component>,
}

/// The mesh of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum MeshSpec {
    /// `[x0, x1] × [y0, y1]` cut into `blocks = [nx, ny]` rectangular blocks (sides
    /// tagged `bottom`, `right`, `top`, `left`).
    Blocks {
        /// `[x0, x1]`.
        x: [f64; 2],
        /// `[y0, y1]`.
        y: [f64; 2],
        /// `[nx, ny]`.
        blocks: [usize; 2],
        /// How each block is triangulated.
        #[serde(default)]
        layout: BlockLayout,
    },
    /// A quality triangulation of a polygon (with holes) by the project's mesher.
    Polygon {
        /// Corners of the outer boundary.
        outline: Vec<[f64; 2]>,
        /// Tag of each outline segment `i → i + 1` (default: all `boundary`).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        tags: Vec<String>,
        /// Holes.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        holes: Vec<Hole>,
        /// Target edge length.
        edge_length: f64,
    },
    /// A Gmsh `.msh` file (ASCII 2.2 or 4.1; physical names become boundary tags);
    /// a relative path is relative to the scene file.
    Gmsh {
        /// Path.
        file: String,
    },
    /// 1D: `[x0, x1]` cut into `elements` equal elements (ends tagged `left`, `right`).
    Interval {
        /// `[x0, x1]`.
        x: [f64; 2],
        /// Number of elements.
        elements: usize,
    },
}

/// A hole of a polygon mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hole {
    /// Corners.
    pub outline: Vec<[f64; 2]>,
    /// Tag of its boundary.
    pub tag: String,
}

/// How a block is triangulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BlockLayout {
    /// Four triangles around a centre vertex (the seeds' grid).
    #[default]
    FourTriangles,
    /// Delaunay triangulation of block corners and centres (the thesis' tables).
    Delaunay,
}

/// The constitutive model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Model.
    pub model: MaterialModel,
    /// Young's modulus `E > 0`.
    pub young: f64,
    /// Poisson's ratio `−1 < ν < 0.5`.
    #[serde(default)]
    pub poisson: f64,
    /// Reference density `ρ0 > 0`.
    pub density: f64,
}

/// Constitutive models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialModel {
    /// Linear elasticity on `F` (paper eqs. (25)–(26)).
    LinearElastic,
    /// Compressible neo-Hookean (paper eq. (27)).
    NeoHookean,
}

/// A body: the box `[min, max]` filled with particles at the cell centres of a
/// regular lattice; the particle volume is the cell volume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Lower corner (`dim` entries).
    pub min: Vec<f64>,
    /// Upper corner (`dim` entries).
    pub max: Vec<f64>,
    /// Particles per mesh block along each axis (block and interval meshes): the
    /// lattice spacing is the block size divided by this.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_block: Option<Vec<usize>>,
    /// Particles along each axis of the box.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<Vec<usize>>,
    /// Moves each particle off its cell centre by a uniform random offset of up to
    /// this fraction of the lattice cell along each axis (`0 ≤ jitter < 0.5`, so
    /// particles stay in their cells); 0: the regular lattice.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub jitter: f64,
    /// Seed of the jitter's random numbers ([`DEFAULT_JITTER_SEED`] when absent):
    /// the same seed gives the same particles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// The seed of a body's jitter when the scene gives none.
pub const DEFAULT_JITTER_SEED: u64 = 1;

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Initial velocity.
///
/// (Variants without parameters are written `Rest {}` so that a stray key next to
/// their `kind` is rejected as an unknown field.)
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum InitialVelocity {
    /// At rest.
    Rest {},
    /// The same velocity everywhere.
    Uniform {
        /// Velocity (`dim` entries).
        value: Vec<f64>,
    },
    /// `v_x = v0 sin(π (x − x_min) / L)` over the first body's extent `L` along x.
    SineMode {
        /// Amplitude.
        v0: f64,
    },
    /// The velocity of the scene's reference solution at `t = 0`.
    Exact {},
}

impl Default for InitialVelocity {
    fn default() -> Self {
        InitialVelocity::Rest {}
    }
}

/// A homogeneous Dirichlet condition on the boundary with tag `tag`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundaryCondition {
    /// Boundary tag.
    pub tag: String,
    /// Velocity components held at zero: `x`, `y`, or `normal` (a slip wall: the
    /// component along the wall's normal; the wall must be straight).
    pub fix: Vec<Component>,
}

/// A velocity component.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Component {
    /// First axis.
    X,
    /// Second axis.
    Y,
    /// The normal of a straight wall (a slip wall, oblique or not).
    Normal,
}

impl Component {
    /// Axis index (`None` for the wall normal).
    pub fn axis(self) -> Option<usize> {
        match self {
            Component::X => Some(0),
            Component::Y => Some(1),
            Component::Normal => None,
        }
    }

    /// Axis index of `x` and `y`; the normal counts as axis 0 (for `study.refine`,
    /// where only axes are meaningful and validation rejects `normal`).
    pub fn index(self) -> usize {
        self.axis().unwrap_or(0)
    }
}

/// An effect a scene declares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum EffectSpec {
    /// Uniform gravity (conservative: its potential energy is in the total).
    Gravity {
        /// Acceleration (`dim` entries).
        g: Vec<f64>,
    },
    /// Local damping, paper eq. (49).
    Damping {
        /// Damping factor `0 ≤ α < 1`.
        alpha: f64,
    },
    /// A traction on the particles in the box `[min, max]`: force per unit length
    /// `traction` over the boundary length `length`, shared by those particles.
    Traction {
        /// Lower corner of the box selecting particles.
        min: Vec<f64>,
        /// Upper corner.
        max: Vec<f64>,
        /// Traction (force per unit length, `dim` entries).
        traction: Vec<f64>,
        /// Loaded boundary length.
        length: f64,
        /// Linear ramp time (0: sudden).
        #[serde(default)]
        ramp: f64,
    },
    /// A uniform body force per unit mass (non-conservative bookkeeping: its work
    /// is accumulated).
    BodyForce {
        /// Force per unit mass (`dim` entries).
        value: Vec<f64>,
    },
    /// The body force that makes the reference solution exact (paper eqs. (42)–(46)
    /// for `axis-aligned`).
    ManufacturedBodyForce {},
    /// Geostatic initial stress: `σ_yy = ρ g (surface − y)`, `σ_xx = k0 σ_yy`, with
    /// the density of the material and `g` of the gravity effect.
    GeostaticStress {
        /// Height of the free surface.
        surface: f64,
        /// Lateral coefficient.
        #[serde(default)]
        k0: f64,
    },
}

/// Time stepping: a fixed `dt`, or one from a Courant number.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Time step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// Courant number `C` (in `(0, 1)` to be stable): `Δt = C Δt_crit`, the critical
    /// step of the basis, mass strategy and material estimated at the start of the run
    /// (power iteration on `M⁻¹K`, see `Driver::critical_time_step`), shortened so that
    /// a whole number of steps ends exactly at `t_end`. The same `C` means the same
    /// margin for PL and PS and for every mass strategy.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub courant: Option<f64>,
    /// End time.
    pub t_end: f64,
}

/// The exact or reference solution of a scene, and so its error measure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Reference {
    /// B2: first-mode vibration of a bar fixed at both ends (thesis eq. (4.2)), over
    /// the first body's length; error `E_u` (thesis eq. (4.4)) at the end.
    VibratingBar {
        /// Velocity amplitude.
        v0: f64,
    },
    /// B5a: column settling under self-weight from rest (thesis eq. (4.6),
    /// corrected), height of the first body, `g` of the gravity effect; error `E_u`.
    ColumnSelfWeight {},
    /// B4: the neo-Hookean manufactured solution (paper §4.2); error: the
    /// time-averaged RMS position error of paper eq. (47).
    AxisAligned {
        /// Displacement amplitude.
        u0: f64,
    },
    /// B5c: the static stress profile of a column under self-weight; error: the
    /// largest `|σ_yy − σ_yy^exact| / |σ_yy(0)|` over particles at the end. The
    /// exact profile is that of the project's linear law `σ = E (F − 1)`
    /// ([`crate::studies::exact::column_equilibrium_stress_linear`]); paper eq. (48) belongs
    /// to a slightly different law and differs by about `κ² |σ_yy(0)|`.
    ColumnEquilibrium {},
}

impl Reference {
    /// Name of the error measure.
    pub fn error_measure(&self) -> &'static str {
        match self {
            Reference::VibratingBar { .. } | Reference::ColumnSelfWeight {} => "E_u",
            Reference::AxisAligned { .. } => "rms-position",
            Reference::ColumnEquilibrium {} => "max-relative-sigma-yy",
        }
    }
}

/// What a run records.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Points whose nearest particles are tracked every step.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tracked: Vec<Vec<f64>>,
    /// Print diagnostics every this many steps (0: about 20 rows per run).
    #[serde(default)]
    pub diagnostics_every: usize,
    /// Estimate the condition number of the solved mass system every step (about 60
    /// solves for the factorising strategies, 30 products for `extended`).
    #[serde(default)]
    pub condition: bool,
}

mod basis_name {
    use crate::bases::BasisKind;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(b: &BasisKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(b.name())
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<BasisKind, D::Error> {
        let name = String::deserialize(d)?;
        BasisKind::parse(&name).map_err(serde::de::Error::custom)
    }
}

mod mass_name {
    use crate::mass::MassKind;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(m: &MassKind, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&m.spec())
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<MassKind, D::Error> {
        let name = String::deserialize(d)?;
        MassKind::parse(&name).map_err(serde::de::Error::custom)
    }
}

mod split_name {
    use psmpm_basis::basis::powell_sabin::SplitPoint;
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(p: &SplitPoint, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(super::split_to_str(*p))
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<SplitPoint, D::Error> {
        let name = String::deserialize(d)?;
        super::parse_split(&name).map_err(serde::de::Error::custom)
    }
}

/// `incentre` or `centroid`.
pub fn split_to_str(p: SplitPoint) -> &'static str {
    match p {
        SplitPoint::Centroid => "centroid",
        _ => "incentre",
    }
}

/// Parses `incentre` or `centroid`.
pub fn parse_split(name: &str) -> Result<SplitPoint, String> {
    match name {
        "incentre" => Ok(SplitPoint::Incentre),
        "centroid" => Ok(SplitPoint::Centroid),
        other => Err(format!(
            "unknown split point `{other}` (known: incentre, centroid)"
        )),
    }
}

/// Most blocks a `blocks` mesh may have.
pub const MAX_BLOCKS: usize = 1_000_000;
/// Most particles a scene may have.
pub const MAX_PARTICLES: usize = 10_000_000;

/// The built-in scenes: name, one line, TOML text.
pub const BUILTIN: [(&str, &str, &str); 10] = [
    (
        "vibrating-bar",
        "B2: elastic bar L = 25, H = 2 vibrating in its first mode (v0 = 0.1)",
        include_str!("../scenes/vibrating-bar.toml"),
    ),
    (
        "vibrating-bar-thesis",
        "B2 as the thesis computed its tables (centroids, Delaunay blocks, 1999 steps)",
        include_str!("../scenes/vibrating-bar-thesis.toml"),
    ),
    (
        "column-small",
        "B5a: elastic column H = 25, W = 2 settling under self-weight",
        include_str!("../scenes/column-small.toml"),
    ),
    (
        "axis-aligned",
        "B4: neo-Hookean manufactured solution on an unstructured unit square",
        include_str!("../scenes/axis-aligned.toml"),
    ),
    (
        "bar-large",
        "B3: bar L = 1, W = 0.05 in its first mode at 7 % strain (the paper's variant), to t = 20",
        include_str!("../scenes/bar-large.toml"),
    ),
    (
        "bar-large-thesis",
        "B3 as in the thesis: L = 25, H = 2, PS 8 x 1 blocks (78 functions, 20 ppe), to t = 20",
        include_str!("../scenes/bar-large-thesis.toml"),
    ),
    (
        "column-large",
        "B5b: column H = 1, W = 0.1 at 18 % strain, one empty block row above, to t = 2.5",
        include_str!("../scenes/column-large.toml"),
    ),
    (
        "column-damped",
        "B5c: the B5b column with local damping (alpha = 0.6) settling to equilibrium, to t = 10",
        include_str!("../scenes/column-damped.toml"),
    ),
    (
        "vibrating-bar-1d",
        "B2 in 1D (quadratic B-spline or 1D PL)",
        include_str!("../scenes/vibrating-bar-1d.toml"),
    ),
    (
        "column-small-1d",
        "B5a in 1D (quadratic B-spline or 1D PL)",
        include_str!("../scenes/column-small-1d.toml"),
    ),
];

/// An error in a scene, located in its file when it came from one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SceneFileError {
    /// File name.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong, starting with the field.
    pub message: String,
}

/// A scene that is inconsistent: the field and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct SceneError {
    /// Dotted path of the field (`time.dt`, `body[0].per_block`).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

fn bad(field: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError {
        field: field.into(),
        message: message.into(),
    }
}

/// 1-based line and column of byte offset `at` in `text`.
fn line_column(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    // Columns count characters, not bytes.
    let column = before[before.rfind('\n').map_or(0, |i| i + 1)..]
        .chars()
        .count()
        + 1;
    (line, column)
}

/// Byte offset of the first line at or after `from` that sets `key`.
fn key_line_after(text: &str, from: usize, key: &str) -> Option<usize> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        if offset + line.len() > from
            && line
                .split_once('=')
                .is_some_and(|(k, _)| k.trim() == key && !line.trim_start().starts_with('#'))
        {
            return Some(offset + line.len() - line.trim_start().len());
        }
        offset += line.len();
    }
    None
}

/// Byte offset of the first value at or after `from` (in a `key = value` line, before
/// the next table header but one) that contains `value`.
fn value_after(text: &str, from: usize, value: &str) -> Option<usize> {
    let mut offset = 0;
    let mut headers = 0;
    for line in text.split_inclusive('\n') {
        if offset >= from {
            if line.trim_start().starts_with('[') {
                headers += 1;
                if headers > 1 {
                    return None;
                }
            } else if let Some(eq) = line.find('=') {
                if let Some(i) = line[eq..].find(value) {
                    return Some(offset + eq + i);
                }
            }
        }
        offset += line.len();
    }
    None
}

/// The dotted field (`mesh.blocks`, `effect[1].kind`, `basis`) set on the line of
/// byte offset `at`, if that line is a `key = value` line.
fn field_at(text: &str, at: usize) -> Option<String> {
    let mut table: Option<String> = None;
    let mut counts = std::collections::HashMap::<String, usize>::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim();
        if let Some(name) = trimmed.strip_prefix("[[").and_then(|r| r.split_once("]]")) {
            let name = name.0.trim().to_string();
            let count = counts.entry(name.clone()).or_insert(0);
            table = Some(format!("{name}[{count}]"));
            *count += 1;
        } else if let Some(name) = trimmed.strip_prefix('[').and_then(|r| r.split_once(']')) {
            table = Some(name.0.trim().to_string());
        }
        if at < offset + line.len() {
            let (key, _) = line.split_once('=')?;
            let key = key.trim();
            if key.is_empty()
                || key.starts_with('#')
                || !key
                    .chars()
                    .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
            {
                return None;
            }
            return Some(match table {
                Some(t) => format!("{t}.{key}"),
                None => key.to_string(),
            });
        }
        offset += line.len();
    }
    None
}

/// Byte offset of the value of field `path` (`time.dt`, `body[1].count`, `mesh`) in
/// the TOML `text`, found by walking its tables; the start of the file if not found.
fn field_offset(text: &str, path: &str) -> usize {
    // A whole array-of-tables entry (`body[1]`) or table (`body`): its header.
    if !path.contains('.') {
        let (name, index) = match path.split_once('[') {
            Some((n, i)) => (n, i.trim_end_matches(']').parse::<usize>().unwrap_or(0)),
            None => (path, 0),
        };
        let mut offset = 0;
        let mut seen = 0;
        for line in text.split_inclusive('\n') {
            let t = line.trim();
            if t == format!("[[{name}]]") || t == format!("[{name}]") {
                if seen == index {
                    return offset;
                }
                seen += 1;
            }
            offset += line.len();
        }
    }
    // Split `body[1].count` into table `body`, index 1, key `count`.
    let (table, index, key) = match path.split_once('.') {
        Some((head, key)) => {
            let (name, index) = match head.split_once('[') {
                Some((n, i)) => (n, i.trim_end_matches(']').parse::<usize>().unwrap_or(0)),
                None => (head, 0),
            };
            (Some(name), index, key)
        }
        None => {
            let (name, _) = path.split_once('[').unwrap_or((path, ""));
            (None, 0, name)
        }
    };
    let mut offset = 0;
    let mut current: Option<String> = None;
    let mut seen = std::collections::HashMap::<String, usize>::new();
    let mut current_index = 0;
    let mut table_start = None;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim();
        if let Some(name) = trimmed
            .strip_prefix("[[")
            .and_then(|r| r.split_once("]]"))
            .map(|(n, _)| n.trim().to_string())
        {
            let count = seen.entry(name.clone()).or_insert(0);
            current_index = *count;
            *count += 1;
            current = Some(name);
            if table.is_some_and(|t| Some(t.to_string()) == current && current_index == index) {
                table_start = Some(offset);
            }
        } else if let Some(name) = trimmed
            .strip_prefix('[')
            .and_then(|r| r.split_once(']'))
            .map(|(n, _)| n.trim().to_string())
        {
            current = Some(name);
            current_index = 0;
            if table.is_some_and(|t| Some(t.to_string()) == current) && index == 0 {
                table_start = Some(offset);
            }
        } else {
            let in_table = match table {
                Some(t) => current.as_deref() == Some(t) && current_index == index,
                None => current.is_none(),
            };
            let key_here = trimmed
                .split_once('=')
                .map(|(k, _)| k.trim() == key)
                .unwrap_or(false);
            if in_table && key_here {
                let eq = line.find('=').unwrap_or(0);
                let after = &line[eq + 1..];
                return offset + eq + 1 + (after.len() - after.trim_start().len());
            }
            // An inline table: `reference = { kind = ... }`.
            if table.is_some()
                && current.is_none()
                && trimmed
                    .split_once('=')
                    .is_some_and(|(k, _)| Some(k.trim()) == table)
            {
                if let Some(at) = line.find(&format!("{key} ")).or_else(|| line.find(key)) {
                    return offset + at;
                }
            }
        }
        offset += line.len();
    }
    table_start.unwrap_or(0)
}

/// `message` located in the scene file `text` (named `file`) when it starts with a
/// field path (`body[0].max: ...`, `boundary[1].tag: ...`): `file:line:column: message`.
/// For errors found while a run is built, after the file parsed.
pub fn locate_message(text: &str, file: &str, message: &str) -> String {
    let Some((field, _)) = message.split_once(':') else {
        return message.to_string();
    };
    let is_path = !field.is_empty()
        && field
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_[].".contains(c));
    if !is_path {
        return message.to_string();
    }
    let (line, column) = line_column(text, field_offset(text, field));
    format!("{file}:{line}:{column}: {message}")
}

impl Scene {
    /// The built-in scene `name`. The error lists the known scenes.
    pub fn builtin(name: &str) -> Result<Self, String> {
        let (_, _, text) = BUILTIN.iter().find(|(n, _, _)| *n == name).ok_or_else(|| {
            let known: Vec<&str> = BUILTIN.iter().map(|(n, _, _)| *n).collect();
            format!("unknown scene `{name}` (known: {})", known.join(", "))
        })?;
        Scene::from_toml(text, &format!("scenes/{name}.toml")).map_err(|e| e.to_string())
    }

    /// Parses and validates a scene file (`file` names it in errors).
    pub fn from_toml(text: &str, file: &str) -> Result<Self, SceneFileError> {
        let locate = |at: usize, message: String| {
            let (line, column) = line_column(text, at);
            SceneFileError {
                file: file.to_string(),
                line,
                column,
                message,
            }
        };
        let scene: Scene = toml::from_str(text).map_err(|e| {
            let mut at = e.span().map_or(0, |s| s.start);
            let message = e.message().trim().to_string();
            // An unknown field is reported at its table's header: find its line.
            if let Some(name) = message
                .strip_prefix("unknown field `")
                .and_then(|r| r.split_once('`'))
                .map(|(n, _)| n)
            {
                if let Some(offset) = key_line_after(text, at, name) {
                    at = offset;
                }
            } else if text[at.min(text.len())..].starts_with('[')
                && [
                    "invalid type",
                    "invalid value",
                    "unknown variant",
                    "invalid length",
                ]
                .iter()
                .any(|m| message.starts_with(m))
            {
                // A value error inside a tagged table is reported at its header: find
                // the value the message quotes.
                if let Some(value) = message.split('`').nth(1) {
                    if let Some(offset) = value_after(text, at, value) {
                        at = offset;
                    }
                }
            }
            // Name the field when the error is about a key or a value (not about the
            // syntax between them).
            let about_value = {
                let line_start = text[..at.min(text.len())].rfind('\n').map_or(0, |i| i + 1);
                text[line_start..at.min(text.len())].contains('=')
            };
            let about_key =
                message.starts_with("unknown field") || message.starts_with("duplicate key");
            let message = match field_at(text, at) {
                Some(field) if (about_value || about_key) && !message.starts_with(&field) => {
                    format!("{field}: {message}")
                }
                _ => message,
            };
            locate(at, message)
        })?;
        scene
            .validate()
            .map_err(|e| locate(field_offset(text, &e.field), e.to_string()))?;
        Ok(scene)
    }

    /// The scene as TOML that [`Scene::from_toml`] reads back.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_else(|e| format!("# cannot serialise: {e}\n"))
    }

    /// Checks that the scene is consistent; the error names the field.
    pub fn validate(&self) -> Result<(), SceneError> {
        let d = self.dim;
        if !(d == 1 || d == 2) {
            return Err(bad("dim", format!("must be 1 or 2, got {d}")));
        }
        if self.basis.dim() != d {
            return Err(bad(
                "basis",
                format!(
                    "`{}` is a {}D basis but the scene is {d}D (2D: ps, pl; 1D: bspline, pl1d)",
                    self.basis.name(),
                    self.basis.dim()
                ),
            ));
        }
        let finite = |field: &str, v: f64| -> Result<(), SceneError> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(bad(field, format!("must be finite, got {v}")))
            }
        };
        let positive = |field: &str, v: f64| -> Result<(), SceneError> {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(bad(field, format!("must be positive and finite, got {v}")))
            }
        };
        let vector = |field: &str, v: &[f64]| -> Result<(), SceneError> {
            if v.len() != d {
                return Err(bad(field, format!("needs {d} entries, got {}", v.len())));
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
                    format!("needs min < max, got [{}, {}]", r[0], r[1]),
                ))
            }
        };
        match &self.mesh {
            MeshSpec::Blocks { x, y, blocks, .. } => {
                if d != 2 {
                    return Err(bad(
                        "mesh.kind",
                        "`blocks` is a 2D mesh; use `interval` in 1D",
                    ));
                }
                interval("mesh.x", *x)?;
                interval("mesh.y", *y)?;
                if blocks.iter().any(|&n| n == 0 || n > 4096) {
                    return Err(bad(
                        "mesh.blocks",
                        format!("each count must be in 1..=4096, got {blocks:?}"),
                    ));
                }
                if blocks[0] * blocks[1] > MAX_BLOCKS {
                    return Err(bad(
                        "mesh.blocks",
                        format!(
                            "{} blocks in all is above the limit of {MAX_BLOCKS}",
                            blocks[0] * blocks[1]
                        ),
                    ));
                }
            }
            MeshSpec::Polygon {
                outline,
                tags,
                edge_length,
                ..
            } => {
                if d != 2 {
                    return Err(bad("mesh.kind", "`polygon` is a 2D mesh"));
                }
                if outline.len() < 3 {
                    return Err(bad("mesh.outline", "needs at least 3 corners"));
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
            }
            MeshSpec::Gmsh { file } => {
                if d != 2 {
                    return Err(bad("mesh.kind", "`gmsh` meshes are 2D"));
                }
                if file.is_empty() {
                    return Err(bad("mesh.file", "is empty"));
                }
            }
            MeshSpec::Interval { x, elements } => {
                if d != 1 {
                    return Err(bad(
                        "mesh.kind",
                        "`interval` is a 1D mesh; use `blocks` in 2D",
                    ));
                }
                interval("mesh.x", *x)?;
                if *elements == 0 || *elements > 1_000_000 {
                    return Err(bad(
                        "mesh.elements",
                        format!("must be in 1..=1000000, got {elements}"),
                    ));
                }
            }
        }
        crate::material::Elastic::new(
            self.material.young,
            self.material.poisson,
            self.material.density,
        )
        .map_err(|e| {
            let field = match &e {
                crate::material::MaterialError::OutOfRange { name, .. } => {
                    format!("material.{name}")
                }
            };
            bad(field, e.to_string())
        })?;
        if self.bodies.is_empty() {
            return Err(bad("body", "a scene needs at least one [[body]]"));
        }
        for (b, body) in self.bodies.iter().enumerate() {
            let field = |f: &str| format!("body[{b}].{f}");
            vector(&field("min"), &body.min)?;
            vector(&field("max"), &body.max)?;
            for k in 0..d {
                if body.min[k] >= body.max[k] {
                    return Err(bad(
                        field("max"),
                        format!(
                            "needs min < max on every axis, got min = {:?}, max = {:?}",
                            body.min, body.max
                        ),
                    ));
                }
            }
            if !(0.0..0.5).contains(&body.jitter) {
                return Err(bad(
                    field("jitter"),
                    format!(
                        "must be in [0, 0.5) (a fraction of the lattice cell), got {}",
                        body.jitter
                    ),
                ));
            }
            match (&body.per_block, &body.count) {
                (Some(p), None) => {
                    if p.len() != d || p.iter().any(|&n| n == 0 || n > 1000) {
                        return Err(bad(
                            field("per_block"),
                            format!("needs {d} counts in 1..=1000, got {p:?}"),
                        ));
                    }
                    if !matches!(
                        self.mesh,
                        MeshSpec::Blocks { .. } | MeshSpec::Interval { .. }
                    ) {
                        return Err(bad(
                            field("per_block"),
                            "needs a `blocks` or `interval` mesh; use `count` on other meshes",
                        ));
                    }
                }
                (None, Some(c)) => {
                    if c.len() != d || c.iter().any(|&n| n == 0 || n > 100_000) {
                        return Err(bad(
                            field("count"),
                            format!("needs {d} counts in 1..=100000, got {c:?}"),
                        ));
                    }
                }
                _ => {
                    return Err(bad(
                        field("per_block"),
                        "give exactly one of `per_block` and `count`",
                    ))
                }
            }
        }
        let particles: f64 = self
            .bodies
            .iter()
            .map(|b| self.estimated_particles(b))
            .sum();
        if particles > MAX_PARTICLES as f64 {
            return Err(bad(
                "body[0]",
                format!(
                    "the bodies would hold about {particles:.3e} particles, above the limit of {MAX_PARTICLES}"
                ),
            ));
        }
        match &self.initial_velocity {
            InitialVelocity::Uniform { value } => vector("initial_velocity.value", value)?,
            InitialVelocity::SineMode { v0 } => finite("initial_velocity.v0", *v0)?,
            InitialVelocity::Exact {} if self.reference.is_none() => {
                return Err(bad(
                    "initial_velocity.kind",
                    "`exact` needs a [reference] solution",
                ))
            }
            _ => {}
        }
        for (i, bc) in self.boundaries.iter().enumerate() {
            if bc.fix.is_empty() {
                return Err(bad(format!("boundary[{i}].fix"), "lists no component"));
            }
            if bc.fix.contains(&Component::Normal) && bc.fix.len() > 1 {
                return Err(bad(
                    format!("boundary[{i}].fix"),
                    "`normal` fixes the normal component alone; list it on its own",
                ));
            }
            if let Some(c) = bc.fix.iter().find(|c| c.axis().is_some_and(|a| a >= d)) {
                return Err(bad(
                    format!("boundary[{i}].fix"),
                    format!(
                        "component `{}` does not exist in {d}D",
                        format!("{c:?}").to_lowercase()
                    ),
                ));
            }
        }
        let gravity = self.gravity();
        for (i, effect) in self.effects.iter().enumerate() {
            let field = |f: &str| format!("effect[{i}].{f}");
            match effect {
                EffectSpec::Gravity { g } => vector(&field("g"), g)?,
                EffectSpec::Damping { alpha } => {
                    if !(0.0..1.0).contains(alpha) {
                        return Err(bad(
                            field("alpha"),
                            format!("must be in [0, 1), got {alpha}"),
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
                    vector(&field("traction"), traction)?;
                    positive(&field("length"), *length)?;
                    if !(*ramp >= 0.0 && ramp.is_finite()) {
                        return Err(bad(field("ramp"), format!("must be ≥ 0, got {ramp}")));
                    }
                }
                EffectSpec::BodyForce { value } => vector(&field("value"), value)?,
                EffectSpec::ManufacturedBodyForce {} => {
                    if !matches!(self.reference, Some(Reference::AxisAligned { .. })) {
                        return Err(bad(
                            field("kind"),
                            "`manufactured-body-force` needs reference kind `axis-aligned`",
                        ));
                    }
                }
                EffectSpec::GeostaticStress { surface, k0 } => {
                    finite(&field("surface"), *surface)?;
                    finite(&field("k0"), *k0)?;
                    if gravity.is_none() {
                        return Err(bad(
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
            _ => return Err(bad("time.dt", "give exactly one of `dt` and `courant`")),
        }
        positive("time.t_end", self.time.t_end)?;
        if self.study.refine.contains(&Component::Normal) {
            return Err(bad("study.refine", "lists axes, `x` or `y`"));
        }
        for (i, t) in self.output.tracked.iter().enumerate() {
            vector(&format!("output.tracked[{i}]"), t)?;
        }
        match self.reference {
            Some(Reference::VibratingBar { v0 }) => finite("reference.v0", v0)?,
            Some(Reference::ColumnSelfWeight {}) | Some(Reference::ColumnEquilibrium {})
                if gravity.is_none() =>
            {
                return Err(bad(
                    "reference.kind",
                    "a column reference needs a gravity effect",
                ));
            }
            Some(Reference::AxisAligned { u0 }) => {
                finite("reference.u0", u0)?;
                if d != 2 || self.material.model != MaterialModel::NeoHookean {
                    return Err(bad(
                        "reference.kind",
                        "`axis-aligned` is a 2D neo-Hookean solution",
                    ));
                }
            }
            _ => {}
        }
        if self.steps() == 0 {
            return Err(bad("time.t_end", "is shorter than one time step"));
        }
        Ok(())
    }

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

    /// About how many particles `body` gets (exact for aligned boxes).
    fn estimated_particles(&self, body: &Body) -> f64 {
        (0..self.dim)
            .map(|k| {
                self.lattice_spacing(body, k)
                    .map_or(1.0, |h| (body.max[k] - body.min[k]) / h)
            })
            .product()
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
    /// the run itself takes `C Δt_crit` (see [`TimeSpec::courant`]).
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
                let h = if self.basis == BasisKind::Ps {
                    0.5 * h
                } else {
                    h
                };
                c * h / speed
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

    /// Sets the block counts of a `blocks` mesh (`[n, 1]` sets the elements of an
    /// `interval` mesh).
    pub fn set_blocks(&mut self, nx: usize, ny: usize) -> Result<(), SceneError> {
        match &mut self.mesh {
            MeshSpec::Blocks { blocks, .. } => *blocks = [nx, ny],
            MeshSpec::Interval { elements, .. } => *elements = nx,
            _ => return Err(bad("mesh.blocks", "the scene's mesh has no blocks")),
        }
        Ok(())
    }

    /// Sets the block layout of a `blocks` mesh.
    pub fn set_layout(&mut self, new: BlockLayout) -> Result<(), SceneError> {
        match &mut self.mesh {
            MeshSpec::Blocks { layout, .. } => *layout = new,
            _ => return Err(bad("mesh.layout", "the scene's mesh has no blocks")),
        }
        Ok(())
    }

    /// Sets the particles per block of every body (the first `dim` entries of `p`).
    pub fn set_particles_per_block(&mut self, p: [usize; 2]) {
        for body in &mut self.bodies {
            body.per_block = Some(p[..self.dim].to_vec());
            body.count = None;
        }
    }

    /// Sets a fixed time step.
    pub fn set_dt(&mut self, dt: f64) {
        self.time.dt = Some(dt);
        self.time.courant = None;
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
                    _ => return Err(bad("resolution.edge_length", "the mesh is not a polygon")),
                }
            }
            if let Some(p) = &r.per_block {
                for body in &mut s.bodies {
                    body.per_block = Some(p.clone());
                    body.count = None;
                }
            }
        }
        s.validate()?;
        Ok(s)
    }

    /// The scene refined `level` times as [`StudySpec`] says, validated.
    pub fn refined(&self, level: u32) -> Result<Scene, SceneError> {
        let mut s = self.clone();
        let factor = 1usize
            .checked_shl(level)
            .filter(|f| *f <= 4096)
            .ok_or_else(|| bad("study", format!("level {level} is too fine")))?;
        let refine = |axis: usize| {
            self.study.refine.is_empty() || self.study.refine.iter().any(|c| c.index() == axis)
        };
        match &mut s.mesh {
            MeshSpec::Blocks { blocks, .. } => {
                for (axis, n) in blocks.iter_mut().enumerate() {
                    if refine(axis) {
                        *n *= factor;
                    }
                }
            }
            MeshSpec::Interval { elements, .. } => *elements *= factor,
            MeshSpec::Polygon { edge_length, .. } => {
                *edge_length /= factor as f64;
                for body in &mut s.bodies {
                    if let Some(c) = &mut body.count {
                        c.iter_mut().for_each(|n| *n *= factor);
                    }
                }
            }
            MeshSpec::Gmsh { .. } => {
                return Err(bad("mesh.kind", "a Gmsh mesh cannot be refined by a study"))
            }
        }
        s.validate()?;
        Ok(s)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_scene_parses_and_round_trips() {
        for (name, _, _) in BUILTIN {
            let scene = Scene::builtin(name).unwrap();
            let text = scene.to_toml();
            let back =
                Scene::from_toml(&text, "shown.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(scene, back, "{name}");
        }
    }

    #[test]
    fn jitter_is_validated_and_moves_particles_inside_their_cells_deterministically() {
        let text = Scene::builtin("column-small").unwrap().to_toml();
        let jittered = text.replace("per_block = [6, 8]", "per_block = [6, 8]\njitter = 0.3");
        let scene = Scene::from_toml(&jittered, "j.toml").unwrap();
        assert_eq!(
            Scene::from_toml(&scene.to_toml(), "back.toml").unwrap(),
            scene
        );
        for bad_value in ["0.5", "-0.1", "nan"] {
            let broken = text.replace(
                "per_block = [6, 8]",
                &format!("per_block = [6, 8]\njitter = {bad_value}"),
            );
            let e = Scene::from_toml(&broken, "j.toml").unwrap_err();
            assert!(
                e.message.starts_with("body[0].jitter: must be in [0, 0.5)"),
                "{e}"
            );
        }
        let regular =
            crate::simulation::particle_lattice(&Scene::builtin("column-small").unwrap()).unwrap();
        let moved = crate::simulation::particle_lattice(&scene).unwrap();
        assert_eq!(moved, crate::simulation::particle_lattice(&scene).unwrap());
        let (hx, hy) = (2.0 / 6.0, 25.0 / 8.0 / 8.0);
        let mut largest: f64 = 0.0;
        for (p, q) in regular.positions.iter().zip(&moved.positions) {
            let (dx, dy) = ((q[0] - p[0]) / hx, (q[1] - p[1]) / hy);
            assert!(dx.abs() <= 0.3 && dy.abs() <= 0.3, "{p:?} -> {q:?}");
            largest = largest.max(dx.abs()).max(dy.abs());
        }
        assert!(largest > 0.25, "{largest}");
        let mut other = scene.clone();
        other.bodies[0].seed = Some(7);
        assert_ne!(crate::simulation::particle_lattice(&other).unwrap(), moved);
    }

    #[test]
    fn errors_name_line_column_and_field() {
        let text = Scene::builtin("column-small").unwrap().to_toml();
        let broken = text.replace("t_end = 1.0", "t_end = -1.0");
        let e = Scene::from_toml(&broken, "c.toml").unwrap_err();
        let line = broken.lines().position(|l| l.starts_with("t_end")).unwrap() + 1;
        assert_eq!((e.file.as_str(), e.line), ("c.toml", line), "{e}");
        assert!(e.message.starts_with("time.t_end: must be positive"), "{e}");
    }
}
