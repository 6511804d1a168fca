//! Mesh generators: the seeds' block grids, lattice and point-set Delaunay
//! triangulations, and unstructured quality meshes of polygons.
//!
//! - [`block_grid`], [`two_triangle_grid`]: structured grids of rectangular blocks
//!   cut into 4 (centre vertex) or 2 (one diagonal) triangles;
//! - [`block_delaunay`], [`lattice_delaunay`], [`jittered_lattice_delaunay`],
//!   [`delaunay`]: Delaunay triangulations of block corners and centres, of a square
//!   lattice, of a randomly perturbed lattice, of any point set;
//! - [`polygon_mesh`]: a quality mesh of a [`PolygonDomain`] (with holes), boundary
//!   edges tagged by the domain segment they lie on.
//!
//! Rectangle generators tag their sides `left`, `right`, `bottom`, `top`. All
//! output is deterministic (vertex numbering is documented per generator) and
//! counter-clockwise. Parameters are checked first: a bad one gives
//! [`MeshError::InvalidParameter`] naming it and its allowed range. Delaunay
//! triangulations and constrained refinement come from the `spade` crate.

use super::{MeshError, TriMesh, Vec2};
use crate::rng::SplitMix64;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, DelaunayTriangulation, Point2,
    RefinementParameters, Triangulation,
};

fn check_box(x0: f64, x1: f64, y0: f64, y1: f64) -> Result<(), MeshError> {
    for (name, v) in [("x0", x0), ("x1", x1), ("y0", y0), ("y1", y1)] {
        if !v.is_finite() {
            return Err(MeshError::InvalidParameter(format!(
                "{name} must be a finite number, got {v}"
            )));
        }
    }
    if x0 >= x1 {
        return Err(MeshError::InvalidParameter(format!(
            "x0 must be less than x1, got x0 = {x0}, x1 = {x1}"
        )));
    }
    if y0 >= y1 {
        return Err(MeshError::InvalidParameter(format!(
            "y0 must be less than y1, got y0 = {y0}, y1 = {y1}"
        )));
    }
    Ok(())
}

/// Largest number of blocks (or lattice points) along one side.
pub const MAX_PER_SIDE: usize = 100_000;

/// Largest total number of blocks (or lattice points) of a generated grid, which
/// keeps a mistyped parameter from exhausting memory.
pub const MAX_TOTAL: usize = 10_000_000;

/// Checks the counts `(name, value, minimum)` along each side, and their product.
fn check_counts(counts: &[(&str, usize, usize)]) -> Result<(), MeshError> {
    for &(name, n, min) in counts {
        if n < min || n > MAX_PER_SIDE {
            return Err(MeshError::InvalidParameter(format!(
                "{name} must be between {min} and {MAX_PER_SIDE}, got {n}"
            )));
        }
    }
    let total: usize = counts.iter().map(|c| c.1).product();
    if total > MAX_TOTAL {
        let names: Vec<&str> = counts.iter().map(|c| c.0).collect();
        return Err(MeshError::InvalidParameter(format!(
            "{} = {total} exceeds the limit of {MAX_TOTAL}",
            names.join(" × ")
        )));
    }
    Ok(())
}

fn finish_box(mut mesh: TriMesh, x0: f64, x1: f64, y0: f64, y1: f64) -> TriMesh {
    mesh.tag_box_sides(x0, x1, y0, y1);
    mesh
}

/// Corner vertices of an `nx × ny` block grid, row-major with y outer.
fn block_corners(x0: f64, x1: f64, y0: f64, y1: f64, nx: usize, ny: usize) -> Vec<Vec2> {
    let mut v = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            v.push(Vec2::new(
                x0 + (x1 - x0) * i as f64 / nx as f64,
                y0 + (y1 - y0) * j as f64 / ny as f64,
            ));
        }
    }
    v
}

/// Block centres, row-major with y outer.
fn block_centres(x0: f64, x1: f64, y0: f64, y1: f64, nx: usize, ny: usize) -> Vec<Vec2> {
    let mut v = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            v.push(Vec2::new(
                x0 + (x1 - x0) * (i as f64 + 0.5) / nx as f64,
                y0 + (y1 - y0) * (j as f64 + 0.5) / ny as f64,
            ));
        }
    }
    v
}

/// The seeds' block grid (thesis Fig. 4.2): `[x0, x1] × [y0, y1]` cut into `nx × ny`
/// rectangular blocks, each split into 4 triangles by a vertex at its centre.
///
/// Vertices: the `(nx + 1)(ny + 1)` block corners (row-major, y outer), then the
/// `nx · ny` centres. Triangles: 4 per block, counter-clockwise.
pub fn block_grid(
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    nx: usize,
    ny: usize,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_counts(&[("nx", nx, 1), ("ny", ny, 1)])?;
    let mut vertices = block_corners(x0, x1, y0, y1, nx, ny);
    let first_centre = vertices.len();
    vertices.extend(block_centres(x0, x1, y0, y1, nx, ny));
    let corner = |i: usize, j: usize| j * (nx + 1) + i;
    let mut triangles = Vec::with_capacity(4 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let c = first_centre + j * nx + i;
            let (sw, se, ne, nw) = (
                corner(i, j),
                corner(i + 1, j),
                corner(i + 1, j + 1),
                corner(i, j + 1),
            );
            triangles.push([sw, se, c]);
            triangles.push([se, ne, c]);
            triangles.push([ne, nw, c]);
            triangles.push([nw, sw, c]);
        }
    }
    Ok(finish_box(
        TriMesh::new(vertices, triangles)?,
        x0,
        x1,
        y0,
        y1,
    ))
}

/// Direction of the diagonal cutting each block of a [`two_triangle_grid`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Diagonal {
    /// From the lower-left to the upper-right corner (`/`).
    Right,
    /// From the lower-right to the upper-left corner (`\`).
    Left,
}

/// `nx × ny` blocks, each cut into 2 triangles along `diagonal`.
pub fn two_triangle_grid(
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    nx: usize,
    ny: usize,
    diagonal: Diagonal,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_counts(&[("nx", nx, 1), ("ny", ny, 1)])?;
    let vertices = block_corners(x0, x1, y0, y1, nx, ny);
    let corner = |i: usize, j: usize| j * (nx + 1) + i;
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (sw, se, ne, nw) = (
                corner(i, j),
                corner(i + 1, j),
                corner(i + 1, j + 1),
                corner(i, j + 1),
            );
            match diagonal {
                Diagonal::Right => {
                    triangles.push([sw, se, ne]);
                    triangles.push([sw, ne, nw]);
                }
                Diagonal::Left => {
                    triangles.push([sw, se, nw]);
                    triangles.push([se, ne, nw]);
                }
            }
        }
    }
    Ok(finish_box(
        TriMesh::new(vertices, triangles)?,
        x0,
        x1,
        y0,
        y1,
    ))
}

/// Delaunay triangulation of a point set (vertex `i` is `points[i]`), boundary untagged.
///
/// The triangulation covers the convex hull of the points. Where four or more points
/// are cocircular the diagonal is spade's choice, which is deterministic.
///
/// Errors: fewer than three points or non-finite coordinates
/// ([`MeshError::InvalidParameter`]), two equal points ([`MeshError::DuplicateVertex`],
/// instead of spade's silent merge), all points collinear, and whatever
/// [`TriMesh::new`] rejects (e.g. nearly coincident points).
pub fn delaunay(points: &[Vec2]) -> Result<TriMesh, MeshError> {
    if points.len() < 3 {
        return Err(MeshError::InvalidParameter(format!(
            "a triangulation needs at least 3 points, got {}",
            points.len()
        )));
    }
    if let Some(i) = points
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite()))
    {
        return Err(MeshError::InvalidParameter(format!(
            "point {i} = ({}, {}) is not finite",
            points[i].x, points[i].y
        )));
    }
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        let (p, q) = (points[a], points[b]);
        p.x.total_cmp(&q.x)
            .then(p.y.total_cmp(&q.y))
            .then(a.cmp(&b))
    });
    for w in order.windows(2) {
        if points[w[0]] == points[w[1]] {
            let (a, b) = (w[0].min(w[1]), w[0].max(w[1]));
            return Err(MeshError::DuplicateVertex {
                a,
                b,
                x: points[a].x,
                y: points[a].y,
            });
        }
    }
    let spade_points: Vec<Point2<f64>> = points.iter().map(|p| Point2::new(p.x, p.y)).collect();
    // `bulk_load_stable` keeps the input order: spade's vertex i is points[i].
    let dt = DelaunayTriangulation::<Point2<f64>>::bulk_load_stable(spade_points)
        .map_err(|e| MeshError::Mesher(format!("{e:?}")))?;
    if dt.num_vertices() != points.len() {
        return Err(MeshError::Mesher(format!(
            "the Delaunay triangulation kept {} of {} points",
            dt.num_vertices(),
            points.len()
        )));
    }
    let triangles: Vec<[usize; 3]> = dt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .collect();
    if triangles.is_empty() {
        return Err(MeshError::InvalidParameter(
            "the points are collinear: no triangle can be formed".into(),
        ));
    }
    TriMesh::new(points.to_vec(), triangles)
}

/// The Delaunay triangulation of the `n × n` vertex lattice of `[x0, x1] × [y0, y1]`
/// (benchmark B1's meshes): `n²` vertices, row-major with y outer, `2 (n − 1)²`
/// triangles. The lattice's squares are cocircular, so the diagonal of each square is
/// the mesher's deterministic choice. Requires `n ≥ 2`.
pub fn lattice_delaunay(
    n: usize,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_counts(&[("n", n, 2), ("n", n, 2)])?;
    let points = block_corners(x0, x1, y0, y1, n - 1, n - 1);
    Ok(finish_box(delaunay(&points)?, x0, x1, y0, y1))
}

/// The Delaunay triangulation of the block corners and block centres of an
/// `nx × ny` block grid (same vertices, same numbering as [`block_grid`]).
///
/// Across an interior block edge of length `a`, between blocks of depth `b`
/// (perpendicular to it), the two triangles on the edge have opposite angles
/// `2 atan(a / b)` each at the centres, so they are Delaunay iff `a ≤ b`; for
/// `a > b` the block edge flips to the centre–centre edge. So with one row of blocks
/// (`ny = 1`, horizontal block edges all on the boundary) the result equals
/// [`block_grid`] while blocks are at least as wide as tall, and for narrower blocks
/// the vertical block edges flip (in general: vertical edges flip for blocks
/// taller than wide, horizontal ones for blocks wider than tall; square blocks
/// are cocircular and the choice is spade's). Used to reproduce the thesis'
/// vibrating-bar tables.
pub fn block_delaunay(
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    nx: usize,
    ny: usize,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_counts(&[("nx", nx, 1), ("ny", ny, 1)])?;
    let mut points = block_corners(x0, x1, y0, y1, nx, ny);
    points.extend(block_centres(x0, x1, y0, y1, nx, ny));
    Ok(finish_box(delaunay(&points)?, x0, x1, y0, y1))
}

/// Delaunay triangulation of an `nx × ny` vertex lattice of the box `(x0, x1, y0, y1)`
/// whose interior points are moved by up to `jitter` times the spacing in each
/// direction (boundary points slide along their side only, corners stay), drawn
/// from a [`SplitMix64`] seeded with `seed`: the same arguments give the same mesh.
///
/// Vertices row-major with y outer, as in [`lattice_delaunay`]. Requires `nx, ny ≥ 2`
/// and `0 ≤ jitter < 0.5` (so that points cannot pass each other).
pub fn jittered_lattice_delaunay(
    nx: usize,
    ny: usize,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    jitter: f64,
    seed: u64,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_counts(&[("nx", nx, 2), ("ny", ny, 2)])?;
    if !(0.0..0.5).contains(&jitter) {
        return Err(MeshError::InvalidParameter(format!(
            "jitter must be in [0, 0.5), got {jitter}"
        )));
    }
    let (hx, hy) = ((x1 - x0) / (nx - 1) as f64, (y1 - y0) / (ny - 1) as f64);
    let mut rng = SplitMix64(seed);
    let mut points = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let mut p = Vec2::new(x0 + i as f64 * hx, y0 + j as f64 * hy);
            let (dx, dy) = (
                (2.0 * rng.next_f64() - 1.0) * jitter * hx,
                (2.0 * rng.next_f64() - 1.0) * jitter * hy,
            );
            let (x_free, y_free) = (i > 0 && i + 1 < nx, j > 0 && j + 1 < ny);
            if x_free {
                p.x += dx;
            }
            if y_free {
                p.y += dy;
            }
            points.push(p);
        }
    }
    Ok(finish_box(delaunay(&points)?, x0, x1, y0, y1))
}

/// A polygonal domain: an outer boundary with one tag per segment, and holes with one
/// tag each. Polygons are lists of corners (either orientation), closed implicitly.
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonDomain {
    /// Outer boundary corners.
    pub outer: Vec<Vec2>,
    /// Tag of segment `i → i + 1` of `outer`.
    pub outer_tags: Vec<String>,
    /// Holes: corners and a tag for all their segments.
    pub holes: Vec<(Vec<Vec2>, String)>,
}

impl PolygonDomain {
    /// The rectangle `[x0, x1] × [y0, y1]` with sides tagged `bottom`, `right`, `top`, `left`.
    pub fn rectangle(x0: f64, x1: f64, y0: f64, y1: f64) -> Self {
        PolygonDomain {
            outer: vec![
                Vec2::new(x0, y0),
                Vec2::new(x1, y0),
                Vec2::new(x1, y1),
                Vec2::new(x0, y1),
            ],
            outer_tags: ["bottom", "right", "top", "left"]
                .map(String::from)
                .to_vec(),
            holes: Vec::new(),
        }
    }

    /// All segments with their tags.
    fn segments(&self) -> Vec<(Vec2, Vec2, &str)> {
        let mut s = Vec::new();
        let n = self.outer.len();
        for i in 0..n {
            s.push((
                self.outer[i],
                self.outer[(i + 1) % n],
                self.outer_tags[i].as_str(),
            ));
        }
        for (hole, tag) in &self.holes {
            let m = hole.len();
            for i in 0..m {
                s.push((hole[i], hole[(i + 1) % m], tag.as_str()));
            }
        }
        s
    }
}

/// Smallest angle the refinement of [`polygon_mesh`] aims for, in degrees (spade's
/// default is 30°; 25° leaves margin for termination near small input angles).
pub const MIN_ANGLE_DEG: f64 = 25.0;

/// Most points [`polygon_mesh`] lets the refinement add before it gives up.
pub const MAX_STEINER_POINTS: usize = 2_000_000;

/// Distance between the closed segments `[a, b]` and `[c, d]` (0 when they cross).
fn segment_distance(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> f64 {
    let orient = |p: Vec2, q: Vec2, r: Vec2| super::signed_area(p, q, r);
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return 0.0;
    }
    point_segment_distance(a, c, d)
        .min(point_segment_distance(b, c, d))
        .min(point_segment_distance(c, a, b))
        .min(point_segment_distance(d, a, b))
}

/// Distance from `p` to the closed segment `[a, b]`.
fn point_segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (a + ab * t - p).norm()
}

/// Whether `p` is inside the polygon `poly` (crossing number; `p` off its boundary).
fn inside_polygon(p: Vec2, poly: &[Vec2]) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

impl PolygonDomain {
    /// Checks the domain: at least 3 finite corners per polygon, one non-empty tag per
    /// outer segment, segments of positive length that neither cross nor touch
    /// (except consecutive ones at their shared corner), holes inside the outer
    /// polygon and not inside each other. Returns the diameter of the outer polygon's
    /// bounding box. Costs `O(N²)` in the total number `N` of corners.
    pub fn validate(&self) -> Result<f64, MeshError> {
        let invalid = |m: String| Err(MeshError::InvalidParameter(m));
        if self.outer.len() < 3 {
            return invalid(format!(
                "the outer polygon needs at least 3 corners, got {}",
                self.outer.len()
            ));
        }
        if self.outer_tags.len() != self.outer.len() {
            return invalid(format!(
                "the outer polygon has {} segments but {} tags (one per segment i → i + 1)",
                self.outer.len(),
                self.outer_tags.len()
            ));
        }
        for (hole, tag) in &self.holes {
            if hole.len() < 3 {
                return invalid(format!(
                    "hole `{tag}` needs at least 3 corners, got {}",
                    hole.len()
                ));
            }
        }
        let loops = self.loops();
        for (corners, name) in &loops {
            if let Some(p) = corners
                .iter()
                .find(|p| !(p.x.is_finite() && p.y.is_finite()))
            {
                return invalid(format!("{name} has a non-finite corner ({}, {})", p.x, p.y));
            }
        }
        let segments = self.segments();
        if segments.iter().any(|s| s.2.is_empty()) {
            return invalid("boundary tags must not be empty".into());
        }
        let (lo, hi) = super::bounding_box(&self.outer);
        let size = (hi - lo).norm();
        let tol = 1e-9 * size;
        for (a, b, tag) in &segments {
            if (b - a).norm() <= tol {
                return invalid(format!(
                    "a segment tagged `{tag}` has zero length at ({}, {})",
                    a.x, a.y
                ));
            }
        }
        // Pairs of segments: (loop, index in loop) identifies each one.
        let mut ids = Vec::new();
        for (l, (corners, _)) in loops.iter().enumerate() {
            for i in 0..corners.len() {
                ids.push((l, i));
            }
        }
        let ends = |(l, i): (usize, usize)| {
            let c = &loops[l].0;
            (c[i], c[(i + 1) % c.len()])
        };
        for (m, &s) in ids.iter().enumerate() {
            let (a, b) = ends(s);
            for &u in &ids[m + 1..] {
                let (c, d) = ends(u);
                let n = loops[s.0].0.len();
                let distance = if s.0 != u.0 {
                    segment_distance(a, b, c, d)
                } else if (s.1 + 1) % n == u.1 {
                    // u starts where s ends: they must not fold back onto each other.
                    point_segment_distance(a, c, d).min(point_segment_distance(d, a, b))
                } else if (u.1 + 1) % n == s.1 {
                    point_segment_distance(b, c, d).min(point_segment_distance(c, a, b))
                } else {
                    segment_distance(a, b, c, d)
                };
                if distance <= tol {
                    return invalid(format!(
                        "the boundary intersects itself: segment ({}, {})–({}, {}) of {} meets segment ({}, {})–({}, {}) of {}",
                        a.x, a.y, b.x, b.y, loops[s.0].1, c.x, c.y, d.x, d.y, loops[u.0].1
                    ));
                }
            }
        }
        for (h, (hole, tag)) in self.holes.iter().enumerate() {
            if !inside_polygon(hole[0], &self.outer) {
                return invalid(format!("hole `{tag}` lies outside the outer polygon"));
            }
            for (other, other_tag) in self.holes.iter().take(h) {
                if inside_polygon(hole[0], other) || inside_polygon(other[0], hole) {
                    return invalid(format!(
                        "holes `{other_tag}` and `{tag}` are nested (one lies inside the other)"
                    ));
                }
            }
        }
        Ok(size)
    }

    /// The polygons (outer first) with a name for messages.
    fn loops(&self) -> Vec<(&[Vec2], String)> {
        let mut loops = vec![(self.outer.as_slice(), "the outer polygon".to_string())];
        for (hole, tag) in &self.holes {
            loops.push((hole.as_slice(), format!("hole `{tag}`")));
        }
        loops
    }
}

/// An unstructured quality mesh of a polygon with holes: the constrained Delaunay
/// triangulation of the boundary, refined by spade (Delaunay refinement, boundary
/// segments split where needed) until every triangle has an area below that of the
/// equilateral triangle of side `target_edge_length`, `√3/4 · h²`, and no angle below
/// [`MIN_ANGLE_DEG`]; triangles outside the outer polygon and inside holes are dropped.
///
/// Boundary edges are tagged by the domain segment they lie on. Vertex order: the
/// outer corners, then the hole corners (in the order given), then the points added by
/// the refinement, in spade's (deterministic) order.
///
/// Errors: an invalid domain (see [`PolygonDomain::validate`]), `target_edge_length`
/// not positive or below `1e-4` times the domain size, or a refinement that needs
/// more than [`MAX_STEINER_POINTS`] points ([`MeshError::Mesher`]).
pub fn polygon_mesh(domain: &PolygonDomain, target_edge_length: f64) -> Result<TriMesh, MeshError> {
    let size = domain.validate()?;
    if !(target_edge_length.is_finite() && target_edge_length >= size * 1e-4) {
        return Err(MeshError::InvalidParameter(format!(
            "target_edge_length must be at least 1e-4 of the domain size {size}, got {target_edge_length}"
        )));
    }
    let segments = domain.segments();
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut num_corners = 0;
    for (corners, name) in domain.loops() {
        let handles = corners
            .iter()
            .map(|p| cdt.insert(Point2::new(p.x, p.y)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| MeshError::Mesher(format!("{e:?}")))?;
        num_corners += corners.len();
        if cdt.num_vertices() != num_corners {
            return Err(MeshError::Mesher(format!(
                "two corners of {name} coincide for the mesher"
            )));
        }
        for i in 0..handles.len() {
            let (a, b) = (handles[i], handles[(i + 1) % handles.len()]);
            if !cdt.can_add_constraint(a, b) {
                return Err(MeshError::Mesher(format!(
                    "segment {i} of {name} crosses another segment"
                )));
            }
            cdt.add_constraint(a, b);
        }
    }
    let max_area = 3f64.sqrt() / 4.0 * target_edge_length * target_edge_length;
    let params = RefinementParameters::<f64>::new()
        .with_max_allowed_area(max_area)
        .with_angle_limit(AngleLimit::from_deg(MIN_ANGLE_DEG))
        .exclude_outer_faces(true)
        .with_max_additional_vertices(MAX_STEINER_POINTS);
    let result = cdt.refine(params);
    if !result.refinement_complete {
        return Err(MeshError::Mesher(format!(
            "refinement needed more than {MAX_STEINER_POINTS} points; increase target_edge_length"
        )));
    }
    let excluded: std::collections::HashSet<usize> =
        result.excluded_faces.iter().map(|f| f.index()).collect();
    let kept: Vec<[usize; 3]> = cdt
        .inner_faces()
        .filter(|f| !excluded.contains(&f.fix().index()))
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .collect();
    // Number the used vertices in spade's order (corners first, as inserted).
    let mut used = vec![false; cdt.num_vertices()];
    for &v in kept.iter().flatten() {
        used[v] = true;
    }
    let mut map = vec![usize::MAX; cdt.num_vertices()];
    let mut vertices = Vec::new();
    for v in cdt.vertices() {
        let i = v.fix().index();
        if used[i] {
            map[i] = vertices.len();
            let p = v.position();
            vertices.push(Vec2::new(p.x, p.y));
        }
    }
    let triangles = kept.iter().map(|t| t.map(|v| map[v])).collect();
    let mut mesh = TriMesh::new(vertices, triangles)?;
    let tol = 1e-9 * size;
    let on_segment = |p: Vec2, a: Vec2, b: Vec2| point_segment_distance(p, a, b) <= tol;
    mesh.tag_boundary(|p, q| {
        segments
            .iter()
            .find(|(a, b, _)| on_segment(p, *a, *b) && on_segment(q, *a, *b))
            .map(|(_, _, tag)| tag.to_string())
    });
    mesh.require_tagged_boundary()?;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    fn total_area(m: &TriMesh) -> f64 {
        (0..m.num_triangles()).map(|t| m.area(t)).sum()
    }

    fn tag_count(m: &TriMesh, name: &str) -> usize {
        let id = m.tag_id(name).unwrap();
        m.edges().iter().filter(|e| e.tag == Some(id)).count()
    }

    /// Checks that every boundary edge of a box mesh is tagged with the side it lies on.
    fn assert_box_tags(m: &TriMesh, (x0, x1, y0, y1): (f64, f64, f64, f64)) {
        m.require_tagged_boundary().unwrap();
        for e in m.edges().iter().filter(|e| e.is_boundary()) {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            let expected = if a.x == x0 && b.x == x0 {
                "left"
            } else if a.x == x1 && b.x == x1 {
                "right"
            } else if a.y == y0 && b.y == y0 {
                "bottom"
            } else if a.y == y1 && b.y == y1 {
                "top"
            } else {
                panic!("boundary edge {a:?}–{b:?} off the box sides")
            };
            assert_eq!(m.tags()[e.tag.unwrap()], expected);
        }
    }

    /// The triangles as sets of vertices, independent of rotation and order.
    fn triangle_set(m: &TriMesh) -> BTreeSet<[usize; 3]> {
        m.triangles()
            .iter()
            .map(|t| {
                let mut t = *t;
                t.sort();
                t
            })
            .collect()
    }

    fn min_angle_deg(m: &TriMesh) -> f64 {
        let mut min: f64 = 180.0;
        for t in 0..m.num_triangles() {
            let p = m.triangle_points(t);
            for k in 0..3 {
                let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                min = min.min((u.dot(&v) / (u.norm() * v.norm())).acos().to_degrees());
            }
        }
        min
    }

    fn circle(centre: Vec2, r: f64, n: usize) -> Vec<Vec2> {
        (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                centre + Vec2::new(a.cos(), a.sin()) * r
            })
            .collect()
    }

    fn invalid_message<T: std::fmt::Debug>(r: Result<T, MeshError>) -> String {
        match r {
            Err(MeshError::InvalidParameter(m)) => m,
            other => panic!("expected InvalidParameter, got {other:?}"),
        }
    }

    #[test]
    fn block_grid_counts_numbering_area_and_tags() {
        for (nx, ny) in [(1, 1), (4, 1), (3, 5)] {
            let b = (0.0, 25.0, -1.0, 2.0);
            let m = block_grid(b.0, b.1, b.2, b.3, nx, ny).unwrap();
            assert_eq!(m.num_vertices(), (nx + 1) * (ny + 1) + nx * ny);
            assert_eq!(m.num_triangles(), 4 * nx * ny);
            assert!((total_area(&m) - 75.0).abs() < 1e-12);
            assert_box_tags(&m, b);
            assert_eq!(tag_count(&m, "bottom"), nx);
            assert_eq!(tag_count(&m, "top"), nx);
            assert_eq!(tag_count(&m, "left"), ny);
            assert_eq!(tag_count(&m, "right"), ny);
            // Corners row-major with y outer, then centres.
            let (hx, hy) = (25.0 / nx as f64, 3.0 / ny as f64);
            let v = m.vertices();
            assert_eq!(v[nx], Vec2::new(25.0, -1.0));
            assert_eq!(v[nx + 1], Vec2::new(0.0, -1.0 + hy));
            let c0 = (nx + 1) * (ny + 1);
            assert!((v[c0] - Vec2::new(hx / 2.0, -1.0 + hy / 2.0)).norm() < 1e-12);
            // Each triangle: one block side and the block's centre.
            for t in m.triangles() {
                assert_eq!(t.iter().filter(|&&i| i >= c0).count(), 1);
            }
        }
    }

    #[test]
    fn two_triangle_grids_cut_along_the_chosen_diagonal() {
        for d in [Diagonal::Left, Diagonal::Right] {
            let m = two_triangle_grid(0.0, 3.0, 0.0, 2.0, 3, 2, d).unwrap();
            assert_eq!(m.num_vertices(), 12);
            assert_eq!(m.num_triangles(), 12);
            assert!((total_area(&m) - 6.0).abs() < 1e-12);
            assert_box_tags(&m, (0.0, 3.0, 0.0, 2.0));
            let diagonals: Vec<Vec2> = m
                .edges()
                .iter()
                .map(|e| m.vertices()[e.vertices[1]] - m.vertices()[e.vertices[0]])
                .filter(|v| v.x != 0.0 && v.y != 0.0)
                .collect();
            assert_eq!(diagonals.len(), 6);
            let slope_up = d == Diagonal::Right;
            assert!(diagonals.iter().all(|v| (v.x * v.y > 0.0) == slope_up));
        }
    }

    #[test]
    fn lattice_delaunay_is_the_square_lattice_cut_in_halves() {
        let m = lattice_delaunay(5, 0.0, 1.0, 0.0, 2.0).unwrap();
        assert_eq!(m.num_vertices(), 25);
        assert_eq!(m.num_triangles(), 32);
        assert!((total_area(&m) - 2.0).abs() < 1e-12);
        for t in 0..m.num_triangles() {
            assert!((m.area(t) - 0.25 * 0.5 / 2.0).abs() < 1e-14);
        }
        assert_box_tags(&m, (0.0, 1.0, 0.0, 2.0));
        assert_eq!(tag_count(&m, "left"), 4);
        // Deterministic.
        let again = lattice_delaunay(5, 0.0, 1.0, 0.0, 2.0).unwrap();
        assert_eq!(m.triangles(), again.triangles());
    }

    #[test]
    fn block_delaunay_equals_block_grid_for_wide_blocks_and_flips_narrow_ones() {
        // The vibrating bar: 4 blocks of 6.25 × 2 in one row.
        let grid = block_grid(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
        let dt = block_delaunay(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
        assert_eq!(dt.vertices(), grid.vertices());
        assert_eq!(triangle_set(&dt), triangle_set(&grid));
        assert_box_tags(&dt, (0.0, 25.0, 0.0, 2.0));

        let centre_centre = |m: &TriMesh, first_centre: usize| {
            m.edges()
                .iter()
                .filter(|e| e.vertices.iter().all(|&v| v >= first_centre))
                .count()
        };
        // 16 blocks of 1.5625 × 2: the 15 interior vertical edges flip.
        let narrow = block_delaunay(0.0, 25.0, 0.0, 2.0, 16, 1).unwrap();
        assert_eq!(narrow.num_triangles(), 64);
        assert!((total_area(&narrow) - 50.0).abs() < 1e-9);
        assert_eq!(centre_centre(&narrow, 34), 15);
        assert_box_tags(&narrow, (0.0, 25.0, 0.0, 2.0));
        // 2 × 2 blocks of 2 × 1: the 2 interior horizontal edges flip.
        let wide = block_delaunay(0.0, 4.0, 0.0, 2.0, 2, 2).unwrap();
        assert_eq!(wide.num_triangles(), 16);
        assert_eq!(centre_centre(&wide, 9), 2);
    }

    #[test]
    fn delaunay_keeps_the_input_order_and_names_bad_point_sets() {
        let mut rng = SplitMix64(5);
        let points: Vec<Vec2> = (0..40)
            .map(|_| Vec2::new(rng.next_f64(), rng.next_f64()))
            .collect();
        let m = delaunay(&points).unwrap();
        assert_eq!(m.vertices(), &points[..]);
        // Boundary untagged: a clear error where tags are required.
        assert!(m.tags().is_empty());
        assert!(matches!(
            m.require_tagged_boundary(),
            Err(MeshError::UntaggedBoundary { .. })
        ));

        let mut dup = points.clone();
        dup.push(points[7]);
        assert!(matches!(
            delaunay(&dup),
            Err(MeshError::DuplicateVertex { a: 7, b: 40, .. })
        ));
        let line: Vec<Vec2> = (0..5)
            .map(|i| Vec2::new(i as f64, 2.0 * i as f64))
            .collect();
        assert!(invalid_message(delaunay(&line)).contains("collinear"));
        assert!(invalid_message(delaunay(&points[..2])).contains("at least 3"));
        let mut nan = points.clone();
        nan[3].y = f64::NAN;
        assert!(invalid_message(delaunay(&nan)).contains("point 3"));
    }

    #[test]
    fn jittered_lattice_is_valid_deterministic_and_keeps_the_box() {
        let b = (0.0, 1.0, 0.0, 2.0);
        let a = jittered_lattice_delaunay(6, 5, b, 0.3, 7).unwrap();
        let again = jittered_lattice_delaunay(6, 5, b, 0.3, 7).unwrap();
        let other = jittered_lattice_delaunay(6, 5, b, 0.3, 8).unwrap();
        assert_eq!(a.vertices(), again.vertices());
        assert_eq!(a.triangles(), again.triangles());
        assert_ne!(a.vertices(), other.vertices());
        assert_eq!(a.num_vertices(), 30);
        assert!((total_area(&a) - 2.0).abs() < 1e-12);
        assert_box_tags(&a, b);
        let (hx, hy) = (0.2, 0.5);
        for (k, p) in a.vertices().iter().enumerate() {
            let (i, j) = (k % 6, k / 6);
            assert!((p.x - i as f64 * hx).abs() <= 0.3 * hx + 1e-15);
            assert!((p.y - j as f64 * hy).abs() <= 0.3 * hy + 1e-15);
            if i == 0 || i == 5 {
                assert_eq!(p.x, i as f64 * hx);
            }
            if j == 0 || j == 4 {
                assert_eq!(p.y, j as f64 * hy);
            }
        }
        // No jitter: the lattice itself.
        let zero = jittered_lattice_delaunay(5, 5, (0.0, 1.0, 0.0, 1.0), 0.0, 1).unwrap();
        let lattice = lattice_delaunay(5, 0.0, 1.0, 0.0, 1.0).unwrap();
        assert_eq!(zero.vertices(), lattice.vertices());
        assert!(invalid_message(jittered_lattice_delaunay(5, 5, b, 0.5, 1)).contains("jitter"));
        assert!(
            invalid_message(jittered_lattice_delaunay(5, 5, b, f64::NAN, 1)).contains("jitter")
        );
    }

    #[test]
    fn polygon_mesh_of_a_square_with_a_hole() {
        let h = 0.1;
        let mut domain = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        let hole = circle(Vec2::new(0.5, 0.5), 0.2, 12);
        let hole_area = 0.5 * 12.0 * 0.04 * (std::f64::consts::TAU / 12.0).sin();
        domain.holes.push((hole.clone(), "hole".into()));
        let m = polygon_mesh(&domain, h).unwrap();
        assert!((total_area(&m) - (1.0 - hole_area)).abs() < 1e-12);
        // Corners first, in order.
        assert_eq!(&m.vertices()[..4], &domain.outer[..]);
        assert_eq!(&m.vertices()[4..16], &hole[..]);
        // Every boundary edge carries the tag of the segment it lies on.
        m.require_tagged_boundary().unwrap();
        assert!(tag_count(&m, "hole") >= 12);
        for e in m.edges().iter().filter(|e| e.is_boundary()) {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            let tag = m.tags()[e.tag.unwrap()].as_str();
            let mid = (a + b) * 0.5;
            let expected = if (mid - Vec2::new(0.5, 0.5)).norm() < 0.25 {
                "hole"
            } else if mid.x < 1e-12 {
                "left"
            } else if mid.x > 1.0 - 1e-12 {
                "right"
            } else if mid.y < 1e-12 {
                "bottom"
            } else {
                "top"
            };
            assert_eq!(tag, expected, "edge {a:?}–{b:?}");
        }
        // Quality: edge lengths near the target, no angle below the limit.
        for e in m.edges() {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            assert!(
                (a - b).norm() <= 1.5 * h,
                "edge of length {}",
                (a - b).norm()
            );
        }
        assert!(min_angle_deg(&m) >= MIN_ANGLE_DEG - 1e-9);
        // Finer target, finer mesh; deterministic.
        let fine = polygon_mesh(&domain, h / 2.0).unwrap();
        assert!(fine.num_triangles() > 3 * m.num_triangles());
        let again = polygon_mesh(&domain, h).unwrap();
        assert_eq!(m.vertices(), again.vertices());
        assert_eq!(m.triangles(), again.triangles());
    }

    #[test]
    fn polygon_mesh_of_a_clockwise_l_shape_with_two_holes() {
        let outer: Vec<Vec2> = [
            (0.0, 0.0),
            (0.0, 2.0),
            (1.0, 2.0),
            (1.0, 1.0),
            (2.0, 1.0),
            (2.0, 0.0),
        ]
        .map(|(x, y)| Vec2::new(x, y))
        .to_vec();
        let domain = PolygonDomain {
            outer,
            outer_tags: ["w", "top", "w", "w", "right", "bottom"]
                .map(String::from)
                .to_vec(),
            holes: vec![
                (circle(Vec2::new(0.5, 0.5), 0.2, 8), "a".into()),
                (circle(Vec2::new(0.5, 1.5), 0.2, 6), "b".into()),
            ],
        };
        let m = polygon_mesh(&domain, 0.2).unwrap();
        let polygon_area = |n: f64| 0.5 * n * 0.04 * (std::f64::consts::TAU / n).sin();
        let area = 3.0 - polygon_area(8.0) - polygon_area(6.0);
        assert!((total_area(&m) - area).abs() < 1e-12);
        m.require_tagged_boundary().unwrap();
        let mut tags = m.tags().to_vec();
        tags.sort();
        assert_eq!(tags, ["a", "b", "bottom", "right", "top", "w"]);
        assert!(tag_count(&m, "b") >= 6);
        assert!(min_angle_deg(&m) >= MIN_ANGLE_DEG - 1e-9);
    }

    #[test]
    fn polygon_mesh_rejects_bad_domains() {
        let square = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        let with_hole = |hole: Vec<Vec2>| {
            let mut d = square.clone();
            d.holes.push((hole, "hole".into()));
            d
        };
        let pts = |c: &[(f64, f64)]| c.iter().map(|&(x, y)| Vec2::new(x, y)).collect::<Vec<_>>();
        let msg = |d: &PolygonDomain| invalid_message(polygon_mesh(d, 0.2));

        let mut d = square.clone();
        d.outer.truncate(2);
        d.outer_tags.truncate(2);
        assert!(msg(&d).contains("at least 3 corners"));
        let mut d = square.clone();
        d.outer_tags.pop();
        assert!(msg(&d).contains("4 segments but 3 tags"));
        let mut d = square.clone();
        d.outer_tags[2] = String::new();
        assert!(msg(&d).contains("empty"));
        let mut d = square.clone();
        d.outer[2].x = f64::INFINITY;
        assert!(msg(&d).contains("non-finite"));
        let mut d = square.clone();
        d.outer.insert(1, Vec2::new(0.0, 0.0));
        d.outer_tags.insert(1, "x".into());
        assert!(msg(&d).contains("zero length"));
        // A bow tie.
        let mut d = square.clone();
        d.outer.swap(1, 2);
        assert!(msg(&d).contains("intersects itself"));
        // A spike folding back along its own segment.
        let mut d = square.clone();
        d.outer.insert(2, Vec2::new(1.0, -0.5));
        d.outer_tags.insert(2, "x".into());
        assert!(msg(&d).contains("intersects itself"));
        // Holes: crossing, touching, outside, nested, too small.
        let tri = |x: f64, y: f64, r: f64| pts(&[(x, y), (x + r, y), (x, y + r)]);
        assert!(msg(&with_hole(tri(0.8, 0.5, 0.4))).contains("intersects itself"));
        assert!(msg(&with_hole(tri(0.6, 0.5, 0.4))).contains("intersects itself"));
        assert!(msg(&with_hole(tri(2.0, 2.0, 0.4))).contains("outside"));
        let mut nested = with_hole(tri(0.1, 0.1, 0.6));
        nested.holes.push((tri(0.15, 0.15, 0.1), "inner".into()));
        assert!(msg(&nested).contains("nested"));
        assert!(msg(&with_hole(tri(0.1, 0.1, 0.3)[..2].to_vec())).contains("at least 3"));
        // Target edge length.
        for h in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-6] {
            assert!(invalid_message(polygon_mesh(&square, h)).contains("target_edge_length"));
        }
        // A valid hole still works.
        polygon_mesh(&with_hole(tri(0.2, 0.2, 0.4)), 0.2).unwrap();
    }

    #[test]
    fn bad_parameters_name_the_parameter_and_its_range() {
        assert!(
            invalid_message(block_grid(0.0, 1.0, 0.0, 1.0, 0, 1)).contains("nx must be between 1")
        );
        assert!(
            invalid_message(block_grid(0.0, 1.0, 0.0, 1.0, 1, 0)).contains("ny must be between 1")
        );
        assert!(invalid_message(block_grid(1.0, 0.0, 0.0, 1.0, 1, 1))
            .contains("x0 must be less than x1"));
        assert!(invalid_message(block_grid(0.0, 1.0, 1.0, 1.0, 1, 1))
            .contains("y0 must be less than y1"));
        assert!(invalid_message(block_grid(0.0, f64::NAN, 0.0, 1.0, 1, 1))
            .contains("x1 must be a finite"));
        assert!(
            invalid_message(block_grid(0.0, 1.0, 0.0, 1.0, 50_000, 50_000)).contains("exceeds")
        );
        assert!(invalid_message(block_delaunay(0.0, 1.0, 0.0, 1.0, 1, 200_000)).contains("ny"));
        assert!(
            invalid_message(two_triangle_grid(0.0, 1.0, 0.0, -1.0, 1, 1, Diagonal::Left))
                .contains("y0")
        );
        assert!(invalid_message(lattice_delaunay(1, 0.0, 1.0, 0.0, 1.0))
            .contains("n must be between 2"));
        assert!(invalid_message(jittered_lattice_delaunay(
            1,
            3,
            (0.0, 1.0, 0.0, 1.0),
            0.1,
            0
        ))
        .contains("nx"));
    }
}
