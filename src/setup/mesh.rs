//! The geometry of a scene: its mesh (generated or read), the checks of its boundary
//! conditions against the mesh's tags, the normals of its slip walls, and the basis
//! on it.

use super::Domain;
use crate::bases::BasisKind;
use crate::contact::WallGeometry;
use crate::scene::limits::{echo_number, echo_significant};
use crate::scene::{
    BlockLayout, Component, EffectSpec, ErrorKind, Hole, MeshSpec, Scene, SceneError,
};
use crate::simulation::RunError;
use psmpm_basis::basis::bspline1d::QuadraticBSpline;
use psmpm_basis::basis::linear::Linear;
use psmpm_basis::basis::linear1d::Linear1d;
use psmpm_basis::basis::powell_sabin::PowellSabin;
use psmpm_basis::mesh::generators::{self, PolygonDomain, PolygonPart};
use psmpm_basis::mesh::MeshError;
use psmpm_basis::{Mesh1d, TriMesh, Vec2};

/// A slip wall is straight when the sine of the angle between any two of its edges
/// is below this.
const STRAIGHT_WALL: f64 = 1e-9;

/// The basis of a 2D scene, as the scene chose it.
pub(crate) enum Basis2d {
    /// Powell–Sabin splines.
    Ps(PowellSabin<f64>),
    /// Piecewise-linear.
    Linear(Linear<f64>),
}

/// The basis of a 1D scene, as the scene chose it.
pub(crate) enum Basis1d {
    /// Quadratic B-splines.
    Bspline(QuadraticBSpline<f64>),
    /// Piecewise-linear.
    Linear(Linear1d<f64>),
}

/// The mesh, basis and slip walls of a 2D scene (validated here).
pub(crate) fn domain_2d(scene: &Scene) -> Result<Domain<Basis2d>, RunError> {
    scene.validate()?;
    if scene.dim != 2 {
        return Err(conflict("dim", format!("the scene is {}D", scene.dim)).into());
    }
    if let Some(elements) = super::memory::generated_elements(scene) {
        super::memory::check(scene, &super::memory::Counts::from_scene(scene, elements))?;
    } else if let Some(fewest) = fewest_polygon_triangles(scene) {
        let mut counts = super::memory::Counts::from_scene(scene, fewest);
        counts.elements_at_least = true;
        super::memory::check(scene, &counts)?;
    }
    let mesh = triangulation(scene)?;
    // The basis is the larger part of a mesh's memory: checked before it is built.
    super::memory::check(
        scene,
        &super::memory::Counts::from_scene(scene, mesh.num_triangles()),
    )?;
    let h = smallest_edge(&mesh);
    check_tags(scene, mesh.tags())?;
    let walls = wall_normals(scene, &mesh)?;
    let (bends, bend_warning) = slip_bends(&mesh, &walls, scene.basis == BasisKind::Ps);
    let contacts = contact_walls(scene, &mesh)?;
    let small_obstacles = small_contact_obstacles(scene, &mesh);
    let slivers = sliver_warning(&mesh);
    let gap = narrow_gap_warning(scene, &mesh, h);
    let basis = match scene.basis {
        BasisKind::Ps => Basis2d::Ps(
            PowellSabin::<f64>::with_mirror(mesh, scene.split, scene.mirror_line)
                .map_err(|e| conflict("basis", e))?,
        ),
        BasisKind::Pl => Basis2d::Linear(Linear::<f64>::with_mirror(mesh, scene.mirror_line)),
        one_d @ (BasisKind::Bspline | BasisKind::Pl1d) => {
            return Err(conflict("basis", format!("`{}` is a 1D basis", one_d.name())).into())
        }
    };
    Ok(Domain {
        basis,
        h,
        walls,
        bends,
        contacts,
        warnings: bend_warning
            .into_iter()
            .chain(gap)
            .chain(small_obstacles)
            .chain(slivers)
            .collect(),
    })
}

/// The mesh, basis and walls of a 1D scene (validated here).
pub(crate) fn domain_1d(scene: &Scene) -> Result<Domain<Basis1d>, RunError> {
    scene.validate()?;
    let MeshSpec::Interval { x, elements } = scene.mesh else {
        return Err(conflict("mesh.kind", "a 1D scene needs an `interval` mesh").into());
    };
    let h = (x[1] - x[0]) / elements as f64;
    if let Some(error) = super::far_above_critical_1d(scene, h) {
        return Err(error.into());
    }
    super::memory::check(scene, &super::memory::Counts::from_scene(scene, elements))?;
    let mesh = Mesh1d::uniform(x[0], x[1], elements).map_err(|e| value("mesh", e))?;
    // In 1D the normal of a wall is the axis.
    check_tags(scene, &mesh.tags().map(String::from))?;
    let walls: Vec<(String, [f64; 2])> = scene
        .boundaries
        .iter()
        .filter(|bc| bc.fix.contains(&Component::Normal))
        .map(|bc| (bc.tag.clone(), [1.0, 0.0]))
        .collect();
    let basis = match scene.basis {
        BasisKind::Bspline => Basis1d::Bspline(QuadraticBSpline::<f64>::new(mesh)),
        BasisKind::Pl1d => Basis1d::Linear(Linear1d::<f64>::new(mesh)),
        two_d @ (BasisKind::Ps | BasisKind::Pl) => {
            return Err(conflict("basis", format!("`{}` is a 2D basis", two_d.name())).into())
        }
    };
    Ok(Domain {
        basis,
        h,
        walls,
        bends: Vec::new(),
        contacts: None,
        warnings: Vec::new(),
    })
}

/// The mesh of a 2D scene and its smallest edge length.
pub fn triangulation(scene: &Scene) -> Result<TriMesh, RunError> {
    let mesh = match &scene.mesh {
        MeshSpec::Blocks {
            x,
            y,
            blocks,
            layout,
        } => match layout {
            BlockLayout::FourTriangles => {
                generators::block_grid(x[0], x[1], y[0], y[1], blocks[0], blocks[1])
            }
            BlockLayout::Delaunay => {
                generators::block_delaunay(x[0], x[1], y[0], y[1], blocks[0], blocks[1])
            }
        }
        .map_err(|e| value("mesh", e))?,
        MeshSpec::Polygon {
            outline,
            tags,
            holes,
            edge_length,
        } => {
            let domain = polygon_domain(outline, tags, holes);
            // The domain's faults name the part at fault (a hole's outline, a tag).
            domain
                .check()
                .map_err(|f| value(&part_field(f.part), MeshError::from(f)))?;
            if let Some(gap) = domain.narrowest_gap(NARROW_GAP_REFUSED * edge_length) {
                return Err(value(
                    &part_field(gap.part),
                    format!(
                        "{} comes within {} of {}, {} of `mesh.edge_length` ({}): the mesher grades its triangles down to the gap (two holes 1e-5 apart at an edge length of 0.25 gave 66 000 triangles; closer, no mesh); {}",
                        gap.second,
                        echo_significant(gap.distance, 3),
                        gap.first,
                        echo_significant(gap.distance / edge_length, 2),
                        echo_number(*edge_length),
                        gap_fix(&gap, *edge_length),
                    ),
                )
                .into());
            }
            generators::polygon_mesh(&domain, *edge_length).map_err(|e| match e {
                MeshError::EdgeLength(_) => value("mesh.edge_length", e),
                _ => value("mesh.outline", e),
            })?
        }
        MeshSpec::Gmsh { file } => crate::scene::limits::read_mesh(file)
            .map_err(|e| SceneError::new("mesh.file", ErrorKind::File, e.to_string()))?,
        MeshSpec::Interval { .. } => {
            return Err(conflict("mesh.kind", "`interval` is a 1D mesh").into())
        }
    };
    Ok(mesh)
}

/// The field of a `polygon` scene that a part of its domain is written in.
fn part_field(part: PolygonPart) -> String {
    match part {
        PolygonPart::Outer => "mesh.outline".to_string(),
        PolygonPart::OuterTags => "mesh.tags".to_string(),
        PolygonPart::Hole(h) => format!("mesh.holes[{h}].outline"),
        PolygonPart::HoleTag(h) => format!("mesh.holes[{h}].tag"),
    }
}

/// Two boundary segments of a `polygon` mesh closer than this times
/// `mesh.edge_length` are refused before meshing: the mesher grades its
/// triangles down to their gap (two holes 1e-5 apart at an edge length of 0.25,
/// 4e-5 of it: 66 000 triangles, 198 126 PS functions, 10 s of meshing and 350 MB
/// for a body of 144 particles; 1e-6 apart, a degenerate triangle; 1e-8, more
/// points than the mesher allows).
pub const NARROW_GAP_REFUSED: f64 = 1e-3;

/// Two boundary segments closer than this times `mesh.edge_length` make the run
/// warn ([`narrow_gap_warning`]): the triangles there are graded down to about
/// their gap (two holes 1e-3 apart at an edge length of 0.25: 2 853 PS
/// functions, 1 233 with the holes 0.03 apart).
pub const NARROW_GAP_WARNED: f64 = 0.1;

/// What to do about a gap: two loops meant to touch are one loop; a slot or a
/// short segment of one loop is widened or removed.
fn gap_fix(gap: &generators::NarrowGap, edge_length: f64) -> String {
    let apart = echo_significant(NARROW_GAP_WARNED * edge_length, 2);
    let one_loop = gap.first.split(" of ").last() == gap.second.split(" of ").last();
    if one_loop {
        format!(
            "widen the slot (or lengthen the short segment) to {apart} or more, or close it; or give a smaller `mesh.edge_length` if the detail matters"
        )
    } else {
        format!(
            "if the two are meant to touch, write them as one (a hole whose outline is their union, or a notch of the outline); else move them {apart} or more apart (a tenth of the edge length)"
        )
    }
}

/// A warning when two boundary segments of a `polygon` mesh come closer than
/// [`NARROW_GAP_WARNED`] times `mesh.edge_length`: the mesh is graded down to
/// the gap there, its smallest triangles set the critical step where the bodies
/// reach them, and it holds more functions than the edge length suggests.
fn narrow_gap_warning(scene: &Scene, mesh: &TriMesh, smallest: f64) -> Option<String> {
    let (domain, edge_length) = scene_polygon(scene)?;
    let gap = domain.narrowest_gap(NARROW_GAP_WARNED * edge_length)?;
    Some(format!(
        "{} comes within {} of {}, {} of `mesh.edge_length` ({}): the mesher grades its triangles down to about that gap there (smallest edge {}, {} triangles), so the mesh holds more functions than the edge length suggests and its small triangles lower the critical step where the bodies reach them; {}",
        gap.second,
        echo_significant(gap.distance, 3),
        gap.first,
        echo_significant(gap.distance / edge_length, 2),
        echo_number(edge_length),
        echo_significant(smallest, 3),
        mesh.num_triangles(),
        gap_fix(&gap, edge_length),
    ))
}

/// The domain of a `polygon` mesh (untagged outer segments are `boundary`).
fn polygon_domain(outline: &[[f64; 2]], tags: &[String], holes: &[Hole]) -> PolygonDomain {
    let points = |o: &[[f64; 2]]| o.iter().map(|p| Vec2::new(p[0], p[1])).collect();
    PolygonDomain {
        outer: points(outline),
        outer_tags: if tags.is_empty() {
            vec!["boundary".to_string(); outline.len()]
        } else {
            tags.to_vec()
        },
        holes: holes
            .iter()
            .map(|h| (points(&h.outline), h.tag.clone()))
            .collect(),
    }
}

/// The fewest triangles the mesher can make of a `polygon` scene, known before
/// it runs (`None` for another mesh, or where the mesher will refuse the domain
/// or the edge length and name the fault): what the memory check counts before
/// meshing, so that a mesh too large for the memory allowed is refused before the
/// mesher allocates it.
fn fewest_polygon_triangles(scene: &Scene) -> Option<usize> {
    let (domain, edge_length) = scene_polygon(scene)?;
    generators::fewest_polygon_triangles(&domain, edge_length).map(|n| n as usize)
}

/// The domain and edge length of a `polygon` scene (`None` for another mesh).
fn scene_polygon(scene: &Scene) -> Option<(PolygonDomain, f64)> {
    let MeshSpec::Polygon {
        outline,
        tags,
        holes,
        edge_length,
    } = &scene.mesh
    else {
        return None;
    };
    Some((polygon_domain(outline, tags, holes), *edge_length))
}

/// The message for a tag `tag` the mesh (of tags `tags`) does not have, with the
/// closest tag where one is near, and for a Gmsh mesh where its tags come from (a
/// user's missing `Physical Curve` was told only the tags the file has).
fn unknown_tag(scene: &Scene, tag: &str, tags: &[String]) -> String {
    let message = if tags.is_empty() {
        format!(
            "unknown boundary tag `{}`; the mesh has no boundary tags",
            crate::scene::limits::echo(tag)
        )
    } else {
        crate::scene::names::did_you_mean(format!(
            "unknown boundary tag `{}`; the mesh has tags {}",
            crate::scene::limits::echo(tag),
            crate::scene::limits::echo_tags(tags)
        ))
    };
    match &scene.mesh {
        MeshSpec::Gmsh { file } if is_physical_surface(file, tag) => format!(
            "{message}: `{}` is a physical surface of `{file}` (a region of triangles, what a `gmsh` body's `surface` names), not a curve; a wall is on boundary edges, tagged by a physical curve: add `Physical Curve(\"{}-wall\") = {{...}};` for the wall's boundary curves to the .geo, mesh it again and give that tag",
            crate::scene::limits::echo(tag),
            crate::scene::limits::echo(tag)
        ),
        MeshSpec::Gmsh { file } => format!(
            "{message}: the tags of `{file}` are its physical curves (1D physical groups) on boundary edges, a physical curve on interior edges is none; add `Physical Curve(\"{}\") = {{...}};` for the wall's boundary curves to the .geo and mesh it again",
            crate::scene::limits::echo(tag)
        ),
        _ => message,
    }
}

/// `tag` names a physical surface of the Gmsh file `file` (read again: only on
/// the way to an error, a user's wall tagged with the domain's surface name).
fn is_physical_surface(file: &str, tag: &str) -> bool {
    let Ok(bytes) = crate::scene::limits::read_bounded(
        std::path::Path::new(file),
        crate::scene::limits::MAX_MESH_FILE_BYTES,
    ) else {
        return false;
    };
    psmpm_basis::mesh::gmsh::parse_msh_with_surfaces(&String::from_utf8_lossy(&bytes), file)
        .is_ok_and(|(_, surfaces)| surfaces.find(tag).is_some())
}

/// Every boundary condition names a tag of the mesh.
fn check_tags(scene: &Scene, tags: &[String]) -> Result<(), RunError> {
    for (b, bc) in scene.boundaries.iter().enumerate() {
        if !tags.contains(&bc.tag) {
            return Err(SceneError::new(
                format!("boundary[{b}].tag"),
                ErrorKind::Unknown,
                unknown_tag(scene, &bc.tag, tags),
            )
            .into());
        }
    }
    Ok(())
}

/// The unit normal of every slip wall (`fix = ["normal"]`): the boundary edges with
/// the wall's tag must all be parallel (a straight wall).
fn wall_normals(scene: &Scene, mesh: &TriMesh) -> Result<Vec<(String, [f64; 2])>, RunError> {
    let mut walls = Vec::new();
    for (b, bc) in scene.boundaries.iter().enumerate() {
        if !bc.fix.contains(&Component::Normal) {
            continue;
        }
        let id = mesh.tag_id(&bc.tag).map_err(|e| {
            SceneError::new(
                format!("boundary[{b}].tag"),
                ErrorKind::Unknown,
                e.to_string(),
            )
        })?;
        let mut normal: Option<Vec2> = None;
        for e in mesh.edges().iter().filter(|e| e.tag == Some(id)) {
            let d = mesh.vertices()[e.vertices[1]] - mesh.vertices()[e.vertices[0]];
            let n = Vec2::new(d[1], -d[0]).normalize();
            match normal {
                None => normal = Some(n),
                Some(m) if (m[0] * n[1] - m[1] * n[0]).abs() > STRAIGHT_WALL => {
                    return Err(conflict(
                        format!("boundary[{b}].fix"),
                        format!("`normal` needs a straight wall, but `{0}` bends (a hole's or a corner's edges share one tag): for a frictionless wall that bends, make it a contact wall (`[[effect]]` with `kind = \"contact-wall\"` and `tag = \"{0}\"`, in place of this `[[boundary]]`); for a sticking one, `fix = [\"x\", \"y\"]`; or give each straight side its own tag", bc.tag),
                    )
                    .into())
                }
                Some(_) => {}
            }
        }
        let n = normal.ok_or_else(|| {
            conflict(
                format!("boundary[{b}].tag"),
                format!("`{}` has no boundary edge", bc.tag),
            )
        })?;
        walls.push((bc.tag.clone(), [n[0], n[1]]));
    }
    Ok(walls)
}

/// Slip walls whose normals differ by at most this angle (radians) meet at a bend a
/// body is meant to slide over, not at a corner ([`slip_bends`]).
pub const SLIP_BEND: f64 = 80.0 * std::f64::consts::PI / 180.0;

/// Bends up to this angle (radians) are shared through the walls' mean normal
/// ([`slip_bends`]); sharper ones, up to [`SLIP_BEND`], keep their vertex still and
/// are warned about. The mean normal lets each wall through by `sin(θ/2)` of the
/// vertex's velocity (38 % at 45°): measured with a PS block sliding from a slope
/// onto a flat floor (`polygon` mesh of edge 0.15), at 21.8° it slides over the
/// bend and stays stable (drift 3.0e-2); at 25° it slid over but ended UNSTABLE
/// (6.4e-2), at 40° UNSTABLE (8.3e-2) where holding the vertex was stable, and PL
/// left the mesh through the bend.
pub const SLIP_BEND_SHARED: f64 = std::f64::consts::FRAC_PI_8;

/// Every vertex where two slip walls meet at a bend (their normals differ by more
/// than round-off and at most [`SLIP_BEND_SHARED`]), for the driver to share
/// through the walls' mean normal ([`crate::driver::Driver::average_slip_bends`]):
/// otherwise each holds the velocity along its own normal there, the vertex holds
/// still and a body sliding over the bend strikes it. With the warning for the
/// sharper bends up to [`SLIP_BEND`], whose vertex is held (the first named).
fn slip_bends(
    mesh: &TriMesh,
    walls: &[(String, [f64; 2])],
    smooth: bool,
) -> (Vec<Bend>, Option<String>) {
    let mut bends = Vec::new();
    let mut sharp: Vec<(String, String, [f64; 2], f64)> = Vec::new();
    for (a, (tag_a, na)) in walls.iter().enumerate() {
        for (tag_b, nb) in &walls[a + 1..] {
            let angle = (na[0] * nb[1] - na[1] * nb[0])
                .atan2(na[0] * nb[0] + na[1] * nb[1])
                .abs();
            if angle <= STRAIGHT_WALL || angle > SLIP_BEND {
                continue;
            }
            let (Ok(ia), Ok(ib)) = (mesh.tag_id(tag_a), mesh.tag_id(tag_b)) else {
                continue;
            };
            let at = |id: usize| -> Vec<usize> {
                let mut v: Vec<usize> = mesh
                    .edges()
                    .iter()
                    .filter(|e| e.tag == Some(id))
                    .flat_map(|e| e.vertices)
                    .collect();
                v.sort_unstable();
                v.dedup();
                v
            };
            let on_b = at(ib);
            for v in at(ia).into_iter().filter(|v| on_b.binary_search(v).is_ok()) {
                let p = mesh.vertices()[v];
                // A valley (the domain convex at the vertex): the other end of a
                // wall-b edge at the vertex lies on the domain's side of wall a.
                let valley = mesh
                    .edges()
                    .iter()
                    .filter(|e| e.tag == Some(ib) && e.vertices.contains(&v))
                    .any(|e| {
                        let w = if e.vertices[0] == v {
                            e.vertices[1]
                        } else {
                            e.vertices[0]
                        };
                        let d = mesh.vertices()[w] - p;
                        d[0] * na[0] + d[1] * na[1] < 0.0
                    });
                if angle <= SLIP_BEND_SHARED && valley && smooth {
                    bends.push(Bend {
                        tags: [tag_a.clone(), tag_b.clone()],
                        normals: [*na, *nb],
                        vertex: [p[0], p[1]],
                    });
                } else {
                    sharp.push((tag_a.clone(), tag_b.clone(), [p[0], p[1]], angle));
                }
            }
        }
    }
    let warning = sharp.first().map(|(tag_a, tag_b, p, angle)| {
        let more = match sharp.len() {
            1 => String::new(),
            n => format!(" (and {} more such bends)", n - 1),
        };
        format!(
            "slip walls `{tag_a}` and `{tag_b}` meet at [{}, {}] at a bend of {:.1}°{more}: each holds the velocity along its own normal there, so the vertex between them holds still and a body sliding over the bend strikes it (with PS, valleys up to {:.1}° share the vertex through the walls' mean normal; a crest, a sharper valley or PL's particles would go through the walls near it); for a floor a body slides over, make its walls contact walls (an `[[effect]]` with `kind = \"contact-wall\"` per `tag`, in place of the `[[boundary]]`s), which take bends",
            crate::scene::limits::echo_significant(p[0], 6),
            crate::scene::limits::echo_significant(p[1], 6),
            angle.to_degrees(),
            SLIP_BEND_SHARED.to_degrees(),
        )
    });
    (bends, warning)
}

/// Two slip walls meeting at a bend at `vertex` ([`slip_bends`]).
#[derive(Debug, Clone)]
pub(crate) struct Bend {
    pub tags: [String; 2],
    pub normals: [[f64; 2]; 2],
    pub vertex: [f64; 2],
}

/// The geometry of the scene's contact walls, all tags in one (`None` without a
/// contact wall): the wall items are listed for the elements within the mesh's
/// longest edge of them.
fn contact_walls(scene: &Scene, mesh: &TriMesh) -> Result<Option<WallGeometry>, RunError> {
    let longest = mesh
        .edges()
        .iter()
        .map(|e| (mesh.vertices()[e.vertices[0]] - mesh.vertices()[e.vertices[1]]).norm())
        .fold(0.0, f64::max);
    let mut walls = Vec::new();
    for (i, effect) in scene.effects.iter().enumerate() {
        let EffectSpec::ContactWall { tag, stiffness } = effect else {
            continue;
        };
        let field = format!("effect[{i}].tag");
        let id = mesh.tag_id(tag).map_err(|_| {
            SceneError::new(
                field.clone(),
                ErrorKind::Unknown,
                unknown_tag(scene, tag, mesh.tags()),
            )
        })?;
        if !mesh
            .edges()
            .iter()
            .any(|e| e.tag == Some(id) && e.is_boundary())
        {
            return Err(conflict(field, format!("`{tag}` has no boundary edge")).into());
        }
        walls.push((id, *stiffness));
    }
    Ok(WallGeometry::new(mesh, &walls, longest))
}

/// An obstacle (a contact wall whose edges close into a loop, such as a hole)
/// narrower than this many times the longest edge of the triangles along it makes
/// the run warn ([`small_contact_obstacles`]).
pub const SMALL_OBSTACLE: f64 = 1.5;

/// A warning for each contact wall that closes into a loop (an obstacle) spanning
/// less than [`SMALL_OBSTACLE`] times the longest edge of the triangles along it:
/// the functions around it reach past it, and a body pressing on it can pass
/// through. A user's disk (radius 0.25, E = 1e5, spacing 0.025) thrown at a square
/// post of side 0.2 at `courant = 0.25` held at `edge_length = 0.1` (the
/// triangles along it up to 0.113: 1.8 times) and went through at 0.25 (0.233:
/// 0.86 times; at 3 m/s) and 0.4 (0.456; at 1 m/s, a particle at 0.64 m/s).
fn small_contact_obstacles(scene: &Scene, mesh: &TriMesh) -> Vec<String> {
    let v = mesh.vertices();
    let mut warnings = Vec::new();
    for effect in &scene.effects {
        let EffectSpec::ContactWall { tag, .. } = effect else {
            continue;
        };
        let Ok(id) = mesh.tag_id(tag) else {
            continue;
        };
        let edges: Vec<&psmpm_basis::mesh::Edge> = mesh
            .edges()
            .iter()
            .filter(|e| e.tag == Some(id) && e.is_boundary())
            .collect();
        // A loop: every vertex of the wall starts one of its edges and ends one.
        let (mut starts, mut ends): (Vec<usize>, Vec<usize>) =
            edges.iter().map(|e| (e.vertices[0], e.vertices[1])).unzip();
        starts.sort_unstable();
        ends.sort_unstable();
        if edges.is_empty() || starts != ends {
            continue;
        }
        let (mut lo, mut hi) = (v[starts[0]], v[starts[0]]);
        for &a in &starts {
            lo = lo.inf(&v[a]);
            hi = hi.sup(&v[a]);
        }
        let span = (hi - lo).max();
        let longest = edges
            .iter()
            .flat_map(|e| {
                let t = mesh.triangles()[e.triangles.0];
                (0..3).map(move |k| (v[t[k]] - v[t[(k + 1) % 3]]).norm())
            })
            .fold(0.0, f64::max);
        if span < SMALL_OBSTACLE * longest {
            warnings.push(format!(
                "the contact wall `{tag}` closes around an obstacle {} across, less than {SMALL_OBSTACLE} times the longest edge of the triangles along it ({}): the basis functions around it reach past it, and a body pressed on it can pass through (a disk thrown at a post of 0.2 went through at an edge of 0.25 and 0.4, held at 0.1); refine the mesh to an `edge_length` of {} or less, or lower `time.courant` (0.125 held there)",
                echo_significant(span, 3),
                echo_significant(longest, 3),
                echo_significant(span / 2.0, 2),
            ));
        }
    }
    warnings
}

/// A triangle whose longest edge is this many times its height on it or more is
/// warned about as a sliver ([`sliver_warning`]): a right isosceles triangle's is
/// 2, an equilateral one's 1.15, and the PS pieces of a triangle of 10 reach
/// about 40 (their limit for naming a sliver in a failure is
/// [`crate::driver::SLIVER_ASPECT`]).
pub const SLIVER_TRIANGLE: f64 = 10.0;

/// Triangles whose longest edge is [`SLIVER_TRIANGLE`] times their height on it
/// or more: the critical step falls with the width of the elements
/// the particles are in, and a body landing on or sliding into such triangles
/// stiffens within a step (a block sliding into triangles 100 times longer than
/// high failed at `courant` 0.3 before the watch checked within split steps; a
/// block dropped on a floor of triangles 43 times longer than high fails at 0.1
/// and holds at 0.05). Says how many, the worst and where.
fn sliver_warning(mesh: &TriMesh) -> Option<String> {
    let v = mesh.vertices();
    let aspect = |t: &[usize; 3]| {
        let [a, b, c] = t.map(|i| [v[i].x, v[i].y]);
        crate::driver::triangle_aspect(a, b, c)
    };
    let mut count = 0;
    let mut worst: Option<(f64, usize)> = None;
    for (k, t) in mesh.triangles().iter().enumerate() {
        let a = aspect(t);
        if a >= SLIVER_TRIANGLE {
            count += 1;
            if worst.is_none_or(|(w, _)| a > w) {
                worst = Some((a, k));
            }
        }
    }
    let (a, k) = worst?;
    let t = mesh.triangles()[k];
    let centre = (v[t[0]] + v[t[1]] + v[t[2]]) / 3.0;
    Some(format!(
        "the mesh holds {} longer than {} times their height (the worst {a:.0} times, near ({}, {})): the critical step falls with the width of the elements the particles are in, and a body landing on or sliding into such triangles stiffens within a step, which the watch over the critical step follows by splitting steps but may not follow fast enough (a block dropped on a floor of triangles 43 times longer than high failed at `courant` 0.1 and held at 0.05); mesh without them where the bodies go (Gmsh: `Mesh.Optimize = 1`, `Mesh.OptimizeNetgen = 1`, a larger smallest edge), or lower `time.courant`",
        if count == 1 { "1 triangle".to_string() } else { format!("{count} triangles") },
        SLIVER_TRIANGLE,
        echo_significant(centre.x, 4),
        echo_significant(centre.y, 4),
    ))
}

fn smallest_edge(mesh: &TriMesh) -> f64 {
    mesh.edges()
        .iter()
        .map(|e| (mesh.vertices()[e.vertices[0]] - mesh.vertices()[e.vertices[1]]).norm())
        .fold(f64::INFINITY, f64::min)
}

/// A value the mesh or basis cannot be built from.
fn value(field: &str, e: impl ToString) -> SceneError {
    SceneError::new(field, ErrorKind::Value, e.to_string())
}

/// Values of the scene that do not fit together.
fn conflict(field: impl Into<String>, message: impl ToString) -> SceneError {
    SceneError::new(field, ErrorKind::Conflict, message.to_string())
}
