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
//! line and column, and the field. `docs/scenes.md` documents every key (a test
//! checks it against this schema).
//!
//! ```toml
//! name = "column-small"
//! dim = 2
//! basis = "ps"               # ps, pl (2D); bspline, pl1d (1D)
//! mass = "consistent"        # optional: default (extended-hybrid), consistent, lumped, partial[:TAU], partial-coverage:C, deactivate[:M], extended[:C], extended-hybrid[:C1:C2], fmpm:K
//!
//! [mesh]
//! kind = "blocks"            # blocks, polygon, gmsh (2D); interval (1D)
//! x = [0.0, 2.0]
//! y = [0.0, 25.0]
//! blocks = [1, 8]
//!
//! [material]
//! model = "linear-elastic"   # the paper's law (not objective); corotational (the default), neo-hookean
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

//!
//! The module is split by concept: the schema (here), [`validate`](Scene::validate)
//! (validate.rs), locating errors in the TOML text (locate.rs), the form of each
//! table, one or an array of tables (table_forms.rs), the built-in scenes
//! (builtin.rs), the names of bases and split points in files (names.rs), values
//! derived from a scene (derived.rs) and changes made by comparisons and studies
//! (builders.rs).

use crate::bases::BasisKind;
use crate::mass::MassKind;
use psmpm_basis::basis::powell_sabin::{MirrorAxis, SplitPoint};
use serde::{Deserialize, Serialize};

mod annotate;
mod bodies;
mod builders;
mod builtin;
mod derived;
pub mod limits;
mod locate;
pub(crate) mod names;
mod table_forms;
mod validate;

pub use annotate::annotate;
pub use bodies::{region_polygon, DEFAULT_PER_TRIANGLE, MAX_SUBDIVIDE};
pub use builtin::BUILTIN;
pub use limits::{MAX_BLOCKS, MAX_PARTICLES};
pub use names::{mirror_line_to_str, parse_mirror_line, parse_split, split_to_str};

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
    #[serde(with = "names::basis_name")]
    pub basis: BasisKind,
    /// PS split points (ignored by the other bases).
    #[serde(default, with = "names::split_name")]
    pub split: SplitPoint,
    /// PS: the mirror line the control triangle keeps at a vertex whose PS points
    /// are mirror-symmetric about both axis-aligned lines through it (the interior
    /// vertices of the block grids), `vertical`, `horizontal`, `diagonal` or
    /// `anti-diagonal` (the 45° lines of a square grid): the scene's own
    /// mirror line, so that the mass strategies keep its symmetry
    /// ([`psmpm_basis::basis::powell_sabin::MirrorAxis`]). PL: with `horizontal`, a
    /// particle on an element edge is held by the triangle
    /// [`psmpm_basis::TriMesh::triangle_kept_at`] keeps. Ignored by the 1D bases.
    #[serde(
        default,
        with = "names::mirror_line_name",
        skip_serializing_if = "names::is_vertical"
    )]
    pub mirror_line: MirrorAxis,
    /// Mass strategy.
    /// The mass strategy; absent means [`MassKind::default`] (extension).
    #[serde(with = "names::mass_name", default)]
    pub mass: MassKind,
    /// The mesh.
    pub mesh: MeshSpec,
    /// The material of the bodies that do not give their own. A file may leave it
    /// out when every body has its own material; the scene then takes the first
    /// body's material here (see [`Scene::from_toml`]).
    pub material: MaterialSpec,
    /// Bodies: regions filled with particles.
    #[serde(rename = "body")]
    pub bodies: Vec<Body>,
    /// Initial velocity of the particles of the bodies that do not give their own.
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
    #[serde(with = "names::basis_name")]
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
/// `2^l` and divides a polygon's edge length by `2^l`. Along the axes whose element
/// size shrinks, body particle counts are multiplied and spacings divided by `2^l`,
/// keeping particles per element about constant. The time step and particles per
/// block stay.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Axes whose block counts are refined (absent: all; an empty list is an
    /// error, so is an axis listed twice).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refine: Option<Vec<Axis>>,
    /// The factor (1 to 4) by which each level also multiplies the particles per
    /// element along the axes whose element size shrinks (absent: 1, particles per
    /// element stay). PS's error at fixed particles per element is set by the
    /// particle quadrature and stops falling with `h`; with 2 its orders appear.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub particle_growth: Option<u32>,
}

/// A coordinate axis (`study.refine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// First axis.
    X,
    /// Second axis.
    Y,
}

impl Axis {
    /// Axis index: 0 for `x`, 1 for `y`.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
        }
    }
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
        #[serde(deserialize_with = "points::mesh_outline")]
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

/// The error for a mesh hole written as a body's (located at `holes` by
/// [`locate::parse_error`]).
pub(crate) const MESH_HOLE_AS_CORNERS: &str = "each hole of a mesh is a table with `outline` (its corners) and `tag` (its boundary's tag), written `[[mesh.holes]]`, not a list of corners as a body's `holes`";

/// A hole of a polygon mesh: a table (`[[mesh.holes]]`), never a list of corners
/// (the form of a body's `holes`, which have no tag), which is refused with a
/// message that says so.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Hole {
    /// Corners.
    pub outline: Vec<[f64; 2]>,
    /// Tag of its boundary.
    pub tag: String,
}

impl<'de> Deserialize<'de> for Hole {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Table {
            #[serde(deserialize_with = "points::mesh_hole")]
            outline: Vec<[f64; 2]>,
            tag: String,
        }
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = Hole;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table with `outline` and `tag`")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, _: A) -> Result<Hole, A::Error> {
                Err(serde::de::Error::custom(MESH_HOLE_AS_CORNERS))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Hole, A::Error> {
                let t = Table::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                Ok(Hole {
                    outline: t.outline,
                    tag: t.tag,
                })
            }
        }
        deserializer.deserialize_any(Visitor)
    }
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
    /// Model; absent means [`MaterialModel::default`] (co-rotational, objective).
    #[serde(default)]
    pub model: MaterialModel,
    /// Young's modulus `E > 0`.
    pub young: f64,
    /// Poisson's ratio `−1 < ν < 0.5`.
    #[serde(default)]
    pub poisson: f64,
    /// Reference density `ρ0 > 0`.
    pub density: f64,
}

/// Constitutive models (see [`crate::material`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialModel {
    /// The paper's linear elasticity on `sym(F) − I` (eqs. (25)–(26)), the law of
    /// the seeds' benchmarks: **not objective** (a rotating body builds spurious
    /// stress). `linear-elastic`, or `paper-linear`.
    #[serde(alias = "paper-linear")]
    LinearElastic,
    /// Co-rotational linear elasticity on the stretch `U − I` of `F = R U`:
    /// objective, the paper's law to first order. The default. `corotational`, or
    /// `corotated`.
    #[default]
    #[serde(alias = "corotated")]
    Corotational,
    /// Compressible neo-Hookean (paper eq. (27)).
    NeoHookean,
}

/// A body: a region filled with particles, with its own material and initial
/// velocity or the scene's.
///
/// The region is given by `shape` (a box when absent, the only shape in 1D):
/// - `box`: `[min, max]`;
/// - `polygon`: `outline`, with optional `holes`;
/// - `disk`: `centre`, `radius`;
/// - `gmsh`: the triangles of the physical surface `surface` of the mesh `file`.
///
/// Box, polygon and disk bodies are filled from a regular lattice over their
/// bounding box (spacing from `per_block`, `count` or `spacing`): a cell's particle,
/// at its centre, is kept when the centre lies inside the region, with the cell's
/// volume. A region whose boundary cuts cells is so approximated by whole cells: the
/// total volume differs from the region's area by at most the area of the cells the
/// boundary crosses (about `perimeter × spacing / 2` in the mean, going to zero with
/// the spacing). A Gmsh body gets `per_triangle` particles in each triangle, at the
/// points of a quadrature rule, each with volume weight × triangle area, so its total
/// volume is the surface's area exactly.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// The region's shape; absent means a box.
    #[serde(default, skip_serializing_if = "BodyShape::is_box")]
    pub shape: BodyShape,
    /// Box: lower corner (`dim` entries).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub min: Vec<f64>,
    /// Box: upper corner (`dim` entries).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub max: Vec<f64>,
    /// Polygon: corners of the outline (either orientation, closed implicitly).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    #[serde(deserialize_with = "points::list")]
    pub outline: Vec<[f64; 2]>,
    /// Polygon: holes, each a list of corners.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    #[serde(deserialize_with = "points::lists")]
    pub holes: Vec<Vec<[f64; 2]>>,
    /// Disk: centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "points::option")]
    pub centre: Option<[f64; 2]>,
    /// Disk: radius.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Gmsh: the `.msh` file (a relative path is relative to the scene file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// Gmsh: the physical surface, by name or by number.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<SurfaceRef>,
    /// Gmsh: particles per triangle, 1 (centroid) or 3 (the degree-2 rule; the
    /// default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_triangle: Option<usize>,
    /// Gmsh: split each triangle this many times into four (at its edge midpoints)
    /// before placing `per_triangle` particles in each piece: `4^subdivide` times as
    /// many particles, for a file whose triangles are coarse for the scene's mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subdivide: Option<u32>,
    /// Particles per mesh block along each axis (block and interval meshes): the
    /// lattice spacing is the block size divided by this.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_block: Option<Vec<usize>>,
    /// Particles along each axis of the box (of the bounding box for a polygon or
    /// a disk).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<Vec<usize>>,
    /// Lattice spacing along each axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spacing: Option<Vec<f64>>,
    /// Moves each particle off its cell centre by a uniform random offset of up to
    /// this fraction of the lattice cell along each axis (`0 ≤ jitter < 0.5`, so
    /// particles stay in their cells); 0: the regular lattice.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub jitter: f64,
    /// Seed of the jitter's random numbers ([`DEFAULT_JITTER_SEED`] when absent):
    /// the same seed gives the same particles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// The body's material; absent: the scene's `[material]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialSpec>,
    /// The body's initial velocity; absent: the scene's `[initial_velocity]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_velocity: Option<InitialVelocity>,
}

/// The shape of a body's region.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BodyShape {
    /// The box `[min, max]` (an interval in 1D).
    #[default]
    Box,
    /// A polygon with holes.
    Polygon,
    /// A disk.
    Disk,
    /// A physical surface of a Gmsh mesh.
    Gmsh,
}

impl BodyShape {
    /// Whether the shape is a box (the default, not written out).
    pub fn is_box(&self) -> bool {
        *self == BodyShape::Box
    }

    /// The name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            BodyShape::Box => "box",
            BodyShape::Polygon => "polygon",
            BodyShape::Disk => "disk",
            BodyShape::Gmsh => "gmsh",
        }
    }
}

/// A physical surface of a Gmsh file: its name, or its number.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum SurfaceRef {
    /// The name from `$PhysicalNames`.
    Name(String),
    /// The physical tag.
    Tag(i64),
}

/// Read by hand, so that a value of another type is named in the user's terms (a
/// derived untagged enum said "data did not match any variant of untagged enum").
impl<'de> Deserialize<'de> for SurfaceRef {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = SurfaceRef;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the name of a physical surface (a string, e.g. \"soil\") or its number (an integer, e.g. 7)")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<SurfaceRef, E> {
                Ok(SurfaceRef::Name(v.to_string()))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<SurfaceRef, E> {
                Ok(SurfaceRef::Tag(v))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<SurfaceRef, E> {
                i64::try_from(v)
                    .map(SurfaceRef::Tag)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Unsigned(v), &self))
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

impl SurfaceRef {
    /// As text: the name, or the tag's digits.
    pub fn text(&self) -> String {
        match self {
            SurfaceRef::Name(n) => n.clone(),
            SurfaceRef::Tag(t) => t.to_string(),
        }
    }
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
    /// `v_x = v0 sin(π (x − x_min) / L)` over the extent `[x_min, x_min + L]` along
    /// x of the body's region (the scene-level velocity: of the first body, whichever
    /// body it applies to).
    SineMode {
        /// Amplitude.
        v0: f64,
    },
    /// The velocity of the scene's reference solution at `t = 0`.
    Exact {},
    /// A rigid rotation with angular velocity `omega` (radians per unit time,
    /// counter-clockwise) about `centre`: `v = ω × (x − c) = ω (−(y − c_y), x − c_x)`.
    RigidRotation {
        /// Angular velocity `ω`.
        omega: f64,
        /// Centre of rotation `c`.
        centre: Vec<f64>,
    },
    /// A linear field `v = v0 + G (x − x0)`: `value` at `origin`, plus `gradient`.
    Linear {
        /// `v0` (`dim` entries).
        value: Vec<f64>,
        /// `x0` (`dim` entries).
        origin: Vec<f64>,
        /// `G` by rows, `G[i][j] = ∂v_i/∂x_j` (`dim` rows of `dim` entries).
        gradient: Vec<Vec<f64>>,
    },
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
    /// A frictionless contact wall on the boundary tagged `tag`, acting on the
    /// particles (a penalty; [`crate::contact`]): 2D only.
    ContactWall {
        /// The boundary tag of the wall.
        tag: String,
        /// `κ`: each particle's spring has frequency `κ / Δt`, in `(0, 1]`.
        #[serde(default = "default_contact_stiffness")]
        stiffness: f64,
    },
    /// Frictionless contact between the bodies: a velocity field per body, coupled
    /// where two bodies approach on the functions they share
    /// ([`crate::body_contact`]). Two or more bodies, at most
    /// [`crate::body_contact::MAX_CONTACT_BODIES`].
    BodyContact {},
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

fn default_contact_stiffness() -> f64 {
    crate::contact::DEFAULT_STIFFNESS
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
    /// Run with a fixed `dt` above the critical step estimated at the start (an
    /// error otherwise, naming both): for studies of what an unstable step does.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub allow_above_critical: bool,
    /// Estimate the critical step again as the bodies move and take a step in
    /// sub-steps where it fell below what the step needs
    /// (`Driver::watch_critical_step`; on by default, and off with
    /// `allow_above_critical`): `false` keeps every step whole, as a run of the
    /// seeds would.
    #[serde(default = "yes", skip_serializing_if = "Clone::clone")]
    pub watch: bool,
}

fn yes() -> bool {
    true
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
    /// Name of the error measure in `dim` dimensions (the column's stress is
    /// `σ_yy` in 2D and `σ_xx` in 1D, whose axis is x).
    pub fn error_measure(&self, dim: usize) -> &'static str {
        match self {
            Reference::VibratingBar { .. } | Reference::ColumnSelfWeight {} => "E_u",
            Reference::AxisAligned { .. } => "rms-position",
            Reference::ColumnEquilibrium {} if dim == 1 => "max-relative-sigma-xx",
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
    /// Bytes per particle the front end holds while it writes the run's output
    /// (particle frames, pictures), counted in the memory check of the set-up; not
    /// read from the file (0 for a run that writes none).
    #[serde(skip)]
    pub output_bytes_per_particle: f64,
}

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
    /// The field the error is about, when it is about one (a syntax error is not).
    pub field: Option<String>,
    /// What kind of error, when the scene parsed and a value was found wrong.
    pub kind: Option<ErrorKind>,
    /// What is wrong, starting with the field.
    pub message: String,
}

/// What kind of problem a scene value has; the message says it in words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ErrorKind {
    /// A value outside its range, not finite, or of the wrong shape.
    Value,
    /// A name the scene, the mesh or the program does not define (a boundary tag,
    /// a built-in scene, a benchmark).
    Unknown,
    /// Values that cannot hold together (a body outside the mesh, a wall that
    /// bends, an effect whose reference is missing).
    Conflict,
    /// A file the field names that cannot be read or is not valid.
    File,
}

/// A scene that is inconsistent: the field, the kind of problem and what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct SceneError {
    /// Dotted path of the field (`time.dt`, `body[0].per_block`).
    pub field: String,
    /// What kind of problem.
    pub kind: ErrorKind,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    /// An error of `kind` about `field`.
    pub fn new(field: impl Into<String>, kind: ErrorKind, message: impl Into<String>) -> Self {
        SceneError {
            field: field.into(),
            kind,
            message: message.into(),
        }
    }

    /// The error located in the scene file `text` (named `file`): the line and
    /// column of its field.
    pub fn in_file(&self, text: &str, file: &str) -> SceneFileError {
        let (line, column) = locate::line_column(text, locate::field_offset(text, &self.field));
        SceneFileError {
            file: file.to_string(),
            line,
            column,
            field: Some(self.field.clone()),
            kind: Some(self.kind),
            message: self.to_string(),
        }
    }
}

/// A value out of its range ([`ErrorKind::Value`]), the most common scene error.
fn bad(field: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::new(field, ErrorKind::Value, message)
}

/// Values that cannot hold together ([`ErrorKind::Conflict`]).
fn conflict(field: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::new(field, ErrorKind::Conflict, message)
}

impl Scene {
    /// Parses and validates a scene file (`file` names it in errors).
    ///
    /// A file without `[material]` must give every body its own `material` (the
    /// error names the first body without one); the scene then takes the first
    /// body's material as [`Scene::material`], which no body uses.
    ///
    /// A table written as an array of tables, or the reverse (`[[material]]`,
    /// `[body]`), is an error naming the field, at its header (before the file's
    /// other errors but its syntax errors).
    pub fn from_toml(text: &str, file: &str) -> Result<Self, SceneFileError> {
        if let Some(wrong) = table_forms::wrong_table_form(text) {
            let (line, column) = locate::line_column(text, wrong.at);
            return Err(SceneFileError {
                file: file.to_string(),
                line,
                column,
                field: Some(wrong.field),
                kind: None,
                message: wrong.message,
            });
        }
        let scene: Scene = match toml::from_str(text) {
            Ok(scene) => scene,
            // Missing fields are reported after every present field parsed, so the
            // rest of the file is valid here.
            Err(e) if e.message().trim() == "missing field `material`" => {
                match Self::with_first_body_material(text) {
                    Ok(Some(scene)) => scene,
                    Ok(None) => return Err(Self::parse_error(text, file, &e)),
                    Err(e) => return Err(e.in_file(text, file)),
                }
            }
            Err(e) => return Err(Self::parse_error(text, file, &e)),
        };
        scene.validate().map_err(|e| e.in_file(text, file))?;
        Ok(scene)
    }

    /// The scene of a file without `[material]` whose bodies all have their own,
    /// with the first body's material as the scene's; `None` when the file has no
    /// bodies (the missing `[material]` is then the error), an error naming the first
    /// body without a material.
    fn with_first_body_material(text: &str) -> Result<Option<Scene>, SceneError> {
        let Ok(mut table) = text.parse::<toml::Table>() else {
            return Ok(None);
        };
        let first = {
            let Some(bodies) = table.get("body").and_then(|b| b.as_array()) else {
                return Ok(None);
            };
            if let Some(b) = bodies
                .iter()
                .position(|b| b.as_table().is_none_or(|t| !t.contains_key("material")))
            {
                return Err(conflict(
                    format!("body[{b}].material"),
                    format!("the scene has no [material] for the bodies without their own, and body[{b}] has no `material` table: give it one, or add a scene-level [material]"),
                ));
            }
            match bodies.first().and_then(|b| b.get("material")) {
                Some(m) => m.clone(),
                None => return Ok(None),
            }
        };
        table.insert("material".into(), first);
        Ok(toml::Value::Table(table).try_into::<Scene>().ok())
    }

    /// A TOML parse error, located in the file.
    fn parse_error(text: &str, file: &str, e: &toml::de::Error) -> SceneFileError {
        let (at, field, message) = locate::parse_error(text, e);
        let (field, message) = match missing_sections(text, e.message().trim()) {
            Some((first, message)) => (Some(first), message),
            None => (field, message),
        };
        let (line, column) = locate::line_column(text, at);
        SceneFileError {
            file: file.to_string(),
            line,
            column,
            field,
            kind: None,
            message,
        }
    }

    /// The scene as TOML that [`Scene::from_toml`] reads back.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_else(|e| format!("# cannot serialise: {e}\n"))
    }
}

/// The top-level keys and sections every scene file gives, with what to write for
/// each (`docs/scenes.md` has them all).
const REQUIRED_TOP_LEVEL: [(&str, &str); 7] = [
    ("name", "`name = \"my-scene\"`"),
    ("dim", "`dim = 2` (or 1)"),
    (
        "basis",
        "`basis = \"ps\"` (2D: `ps`, `pl`; 1D: `bspline`, `pl1d`)",
    ),
    (
        "mesh",
        "a `[mesh]` section (`kind = \"blocks\"` with `x`, `y` and `blocks`; or `interval`, `polygon`, `gmsh`)",
    ),
    (
        "material",
        "a `[material]` section (`young`, `poisson`, `density`), or a `material` table in every `[[body]]`",
    ),
    (
        "body",
        "a `[[body]]` section per body (`min`, `max` and `per_block`, or a `shape`)",
    ),
    (
        "time",
        "a `[time]` section (`t_end`, and `courant = 0.5` or `dt`)",
    ),
];

/// Where the parser reports a missing top-level key or section (it names the first
/// only, at the top of the file): every missing one, each with what to write, and
/// the first as the field.
fn missing_sections(text: &str, message: &str) -> Option<(String, String)> {
    let reported = message.strip_prefix("missing field `")?.strip_suffix('`')?;
    let table = text.parse::<toml::Table>().ok()?;
    let missing: Vec<&(&str, &str)> = REQUIRED_TOP_LEVEL
        .iter()
        .filter(|(key, _)| !table.contains_key(*key))
        .collect();
    if !missing.iter().any(|(key, _)| *key == reported) {
        return None;
    }
    if missing.len() == REQUIRED_TOP_LEVEL.len() {
        return Some((
            "name".to_string(),
            "the file holds none of a scene's keys and sections (`name`, `dim`, `basis`, [mesh], [material], [[body]], [time]): start from a whole scene, `mpm-cli scene show column-small` (docs/scenes.md lists every key)".to_string(),
        ));
    }
    let names: Vec<String> = missing
        .iter()
        .map(|(key, _)| match *key {
            "mesh" | "material" | "time" => format!("[{key}]"),
            "body" => "[[body]]".to_string(),
            _ => format!("`{key}`"),
        })
        .collect();
    let adds: Vec<&str> = missing.iter().map(|(_, add)| *add).collect();
    Some((
        missing[0].0.to_string(),
        format!(
            "the scene has no {}: add {} (docs/scenes.md lists every key; `mpm-cli scene show column-small` prints a whole scene)",
            join_and(&names),
            adds.join("; ")
        ),
    ))
}

/// "a", "a and b", "a, b and c".
fn join_and(items: &[impl AsRef<str>]) -> String {
    match items {
        [] => String::new(),
        [one] => one.as_ref().to_string(),
        [init @ .., last] => format!(
            "{} and {}",
            init.iter()
                .map(|s| s.as_ref())
                .collect::<Vec<_>>()
                .join(", "),
            last.as_ref()
        ),
    }
}

#[cfg(test)]
mod tests;

/// Points of the plane read with their number of entries checked: a list of
/// numbers read into `[f64; 2]` took the first two of `[x, y, z]` without a word
/// in some tables (a disk's `centre = [0.8, 2.2, 0.0]`).
mod points {
    use serde::{de::Error, Deserialize, Deserializer};

    fn point<E: Error>(p: Vec<f64>) -> Result<[f64; 2], E> {
        match p[..] {
            [x, y] => Ok([x, y]),
            _ => Err(E::custom(format!(
                "a point has 2 entries, x and y, got {}",
                p.len()
            ))),
        }
    }

    pub fn option<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
        Option::<Vec<f64>>::deserialize(d)?.map(point).transpose()
    }

    pub fn list<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
        Vec::<Vec<f64>>::deserialize(d)?
            .into_iter()
            .map(point)
            .collect()
    }

    /// [`list`] for `mesh.outline`, named: a polygon mesh is read through its
    /// `kind`, and an error inside it is located at `[mesh]` without the key.
    pub fn mesh_outline<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
        list(d).map_err(|e| D::Error::custom(format!("mesh.outline: {e}")))
    }

    /// [`list`] for the outline of a `[[mesh.holes]]` table, named.
    pub fn mesh_hole<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
        list(d).map_err(|e| D::Error::custom(format!("mesh.holes outline: {e}")))
    }

    pub fn lists<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<[f64; 2]>>, D::Error> {
        Vec::<Vec<Vec<f64>>>::deserialize(d)?
            .into_iter()
            .map(|l| l.into_iter().map(point).collect())
            .collect()
    }
}
