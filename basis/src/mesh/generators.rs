//! Mesh generators: the seeds' block grids, lattice and point-set Delaunay
//! triangulations, and unstructured quality meshes of polygons.
//!
//! Rectangle generators tag their sides `left`, `right`, `bottom`, `top`.
//! Delaunay triangulations and constrained refinement come from the `spade` crate.

use super::{MeshError, TriMesh, Vec2};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, DelaunayTriangulation, Point2,
    RefinementParameters, Triangulation,
};

fn check_box(x0: f64, x1: f64, y0: f64, y1: f64) -> Result<(), MeshError> {
    if !(x0.is_finite() && x1.is_finite() && y0.is_finite() && y1.is_finite()) {
        return Err(MeshError::InvalidParameter(
            "box corners must be finite".into(),
        ));
    }
    if x0 >= x1 || y0 >= y1 {
        return Err(MeshError::InvalidParameter(format!(
            "box [{x0}, {x1}] × [{y0}, {y1}] is empty: need x0 < x1 and y0 < y1"
        )));
    }
    Ok(())
}

fn check_count(name: &str, n: usize, min: usize) -> Result<(), MeshError> {
    if n < min || n > 100_000 {
        return Err(MeshError::InvalidParameter(format!(
            "{name} must be between {min} and 100000, got {n}"
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
    check_count("nx", nx, 1)?;
    check_count("ny", ny, 1)?;
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
    check_count("nx", nx, 1)?;
    check_count("ny", ny, 1)?;
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
/// Errors on fewer than three points, duplicates and collinear sets.
pub fn delaunay(points: &[Vec2]) -> Result<TriMesh, MeshError> {
    if points.len() < 3 {
        return Err(MeshError::InvalidParameter(format!(
            "a triangulation needs at least 3 points, got {}",
            points.len()
        )));
    }
    let spade_points: Vec<Point2<f64>> = points.iter().map(|p| Point2::new(p.x, p.y)).collect();
    let dt = DelaunayTriangulation::<Point2<f64>>::bulk_load_stable(spade_points)
        .map_err(|e| MeshError::Mesher(format!("{e:?}")))?;
    if dt.num_vertices() != points.len() {
        return Err(MeshError::InvalidParameter(
            "the point set contains duplicate points".into(),
        ));
    }
    let triangles: Vec<[usize; 3]> = dt
        .inner_faces()
        .map(|f| {
            let [a, b, c] = f.vertices();
            [a.fix().index(), b.fix().index(), c.fix().index()]
        })
        .collect();
    if triangles.is_empty() {
        return Err(MeshError::InvalidParameter(
            "the points are collinear".into(),
        ));
    }
    TriMesh::new(points.to_vec(), triangles)
}

/// The Delaunay triangulation of the `n × n` vertex lattice of `[x0, x1] × [y0, y1]`
/// (benchmark B1's meshes). The lattice's squares are cocircular, so the diagonal of
/// each square is the mesher's deterministic choice.
pub fn lattice_delaunay(
    n: usize,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_count("n", n, 2)?;
    let points = block_corners(x0, x1, y0, y1, n - 1, n - 1);
    Ok(finish_box(delaunay(&points)?, x0, x1, y0, y1))
}

/// The Delaunay triangulation of the block corners and block centres of an
/// `nx × ny` block grid: equal to [`block_grid`] while blocks are wider than tall;
/// for narrower blocks some vertical block edges flip to centre–centre edges.
/// Used to reproduce the thesis' vibrating-bar tables.
pub fn block_delaunay(
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    nx: usize,
    ny: usize,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_count("nx", nx, 1)?;
    check_count("ny", ny, 1)?;
    let mut points = block_corners(x0, x1, y0, y1, nx, ny);
    points.extend(block_centres(x0, x1, y0, y1, nx, ny));
    Ok(finish_box(delaunay(&points)?, x0, x1, y0, y1))
}

/// A small deterministic generator (splitmix64) for jittered meshes.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Delaunay triangulation of an `nx × ny` vertex lattice of the box whose interior
/// points are moved by up to `jitter` times the spacing in each direction (boundary
/// points slide along their side only, corners stay), from `seed`.
pub fn jittered_lattice_delaunay(
    nx: usize,
    ny: usize,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    jitter: f64,
    seed: u64,
) -> Result<TriMesh, MeshError> {
    check_box(x0, x1, y0, y1)?;
    check_count("nx", nx, 2)?;
    check_count("ny", ny, 2)?;
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

/// An unstructured quality mesh of a polygon with holes: constrained Delaunay
/// triangulation refined (Ruppert-style, by spade) until every triangle has area below
/// that of an equilateral triangle of side `target_edge_length` and no angle below 25°.
/// Boundary edges are tagged by the segment of the domain they lie on.
pub fn polygon_mesh(domain: &PolygonDomain, target_edge_length: f64) -> Result<TriMesh, MeshError> {
    if domain.outer.len() < 3 {
        return Err(MeshError::InvalidParameter(format!(
            "the outer polygon needs at least 3 corners, got {}",
            domain.outer.len()
        )));
    }
    if domain.outer_tags.len() != domain.outer.len() {
        return Err(MeshError::InvalidParameter(format!(
            "the outer polygon has {} segments but {} tags",
            domain.outer.len(),
            domain.outer_tags.len()
        )));
    }
    for (hole, tag) in &domain.holes {
        if hole.len() < 3 {
            return Err(MeshError::InvalidParameter(format!(
                "hole `{tag}` needs at least 3 corners, got {}",
                hole.len()
            )));
        }
    }
    let segments = domain.segments();
    let (lo, hi) = super::bounding_box(&domain.outer);
    let size = (hi - lo).norm();
    if !(target_edge_length.is_finite() && target_edge_length > 0.0)
        || target_edge_length < size * 1e-4
    {
        return Err(MeshError::InvalidParameter(format!(
            "target edge length must be positive and at least 1e-4 of the domain size {size}, got {target_edge_length}"
        )));
    }
    for (a, b, tag) in &segments {
        if (b - a).norm() <= 1e-12 * size {
            return Err(MeshError::InvalidParameter(format!(
                "a segment tagged `{tag}` has zero length at ({}, {})",
                a.x, a.y
            )));
        }
    }
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut add_loop = |pts: &[Vec2]| -> Result<(), MeshError> {
        let handles = pts
            .iter()
            .map(|p| cdt.insert(Point2::new(p.x, p.y)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| MeshError::Mesher(format!("{e:?}")))?;
        for i in 0..handles.len() {
            let (a, b) = (handles[i], handles[(i + 1) % handles.len()]);
            if !cdt.can_add_constraint(a, b) {
                return Err(MeshError::InvalidParameter(
                    "the polygon's segments intersect each other".into(),
                ));
            }
            cdt.add_constraint(a, b);
        }
        Ok(())
    };
    add_loop(&domain.outer)?;
    for (hole, _) in &domain.holes {
        add_loop(hole)?;
    }
    let max_area = 3f64.sqrt() / 4.0 * target_edge_length * target_edge_length;
    let params = RefinementParameters::<f64>::new()
        .with_max_allowed_area(max_area)
        .with_angle_limit(AngleLimit::from_deg(25.0))
        .exclude_outer_faces(true)
        .with_max_additional_vertices(2_000_000);
    let result = cdt.refine(params);
    if !result.refinement_complete {
        return Err(MeshError::Mesher(
            "refinement stopped at its vertex limit; increase the target edge length".into(),
        ));
    }
    let excluded: std::collections::HashSet<usize> =
        result.excluded_faces.iter().map(|f| f.index()).collect();
    let mut map = vec![usize::MAX; cdt.num_vertices()];
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for f in cdt.inner_faces() {
        if excluded.contains(&f.fix().index()) {
            continue;
        }
        let mut tri = [0; 3];
        for (k, v) in f.vertices().iter().enumerate() {
            let i = v.fix().index();
            if map[i] == usize::MAX {
                map[i] = vertices.len();
                let p = v.position();
                vertices.push(Vec2::new(p.x, p.y));
            }
            tri[k] = map[i];
        }
        triangles.push(tri);
    }
    let mut mesh = TriMesh::new(vertices, triangles)?;
    let tol = 1e-9 * size;
    let on_segment = |p: Vec2, a: Vec2, b: Vec2| {
        let ab = b - a;
        let t = (p - a).dot(&ab) / ab.norm_squared();
        let d = (a + ab * t - p).norm();
        d <= tol && (-1e-9..=1.0 + 1e-9).contains(&t)
    };
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

    fn total_area(m: &TriMesh) -> f64 {
        (0..m.num_triangles()).map(|t| m.area(t)).sum()
    }

    fn tag_count(m: &TriMesh, name: &str) -> usize {
        let id = m.tag_id(name).unwrap();
        m.edges().iter().filter(|e| e.tag == Some(id)).count()
    }

    #[test]
    fn block_grid_counts_area_and_tags() {
        let m = block_grid(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
        assert_eq!(m.num_vertices(), 5 * 2 + 4);
        assert_eq!(m.num_triangles(), 16);
        assert!((total_area(&m) - 50.0).abs() < 1e-12);
        m.require_tagged_boundary().unwrap();
        assert_eq!(tag_count(&m, "bottom"), 4);
        assert_eq!(tag_count(&m, "left"), 1);
    }

    #[test]
    fn two_triangle_and_lattice_grids() {
        for d in [Diagonal::Left, Diagonal::Right] {
            let m = two_triangle_grid(0.0, 1.0, 0.0, 1.0, 3, 2, d).unwrap();
            assert_eq!(m.num_triangles(), 12);
            assert!((total_area(&m) - 1.0).abs() < 1e-12);
            m.require_tagged_boundary().unwrap();
        }
        let m = lattice_delaunay(5, 0.0, 1.0, 0.0, 1.0).unwrap();
        assert_eq!(m.num_vertices(), 25);
        assert_eq!(m.num_triangles(), 32);
        assert!((total_area(&m) - 1.0).abs() < 1e-12);
        m.require_tagged_boundary().unwrap();
    }

    #[test]
    fn block_delaunay_matches_block_grid_for_wide_blocks() {
        let a = block_delaunay(0.0, 25.0, 0.0, 2.0, 4, 1).unwrap();
        assert_eq!(a.num_triangles(), 16);
        // Every triangle has a block centre as a vertex.
        assert!(a.triangles().iter().all(|t| t.iter().any(|&v| v >= 10)));
        let narrow = block_delaunay(0.0, 25.0, 0.0, 2.0, 16, 1).unwrap();
        assert!((total_area(&narrow) - 50.0).abs() < 1e-9);
    }

    #[test]
    fn jittered_lattice_is_valid_and_deterministic() {
        let a = jittered_lattice_delaunay(6, 5, (0.0, 1.0, 0.0, 1.0), 0.3, 7).unwrap();
        let b = jittered_lattice_delaunay(6, 5, (0.0, 1.0, 0.0, 1.0), 0.3, 7).unwrap();
        assert_eq!(a.vertices(), b.vertices());
        assert_eq!(a.triangles(), b.triangles());
        assert!((total_area(&a) - 1.0).abs() < 1e-12);
        a.require_tagged_boundary().unwrap();
    }

    #[test]
    fn polygon_mesh_with_hole() {
        let mut domain = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        let hole: Vec<Vec2> = (0..12)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 12.0;
                Vec2::new(0.5 + 0.2 * a.cos(), 0.5 + 0.2 * a.sin())
            })
            .collect();
        let hole_area = 0.5 * 12.0 * 0.04 * (std::f64::consts::TAU / 12.0).sin();
        domain.holes.push((hole, "hole".into()));
        let m = polygon_mesh(&domain, 0.1).unwrap();
        assert!((total_area(&m) - (1.0 - hole_area)).abs() < 1e-12);
        assert!(tag_count(&m, "hole") >= 12);
        for e in m.edges() {
            let [a, b] = e.vertices;
            assert!((m.vertices()[a] - m.vertices()[b]).norm() <= 0.1 * 1.6);
        }
        // No angle below the 25° limit (some slack for boundary-constrained cases).
        for t in 0..m.num_triangles() {
            let p = m.triangle_points(t);
            for k in 0..3 {
                let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                let angle = (u.dot(&v) / (u.norm() * v.norm())).acos().to_degrees();
                assert!(angle > 20.0, "angle {angle}");
            }
        }
        assert!(polygon_mesh(&domain, -1.0).is_err());
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(matches!(
            block_grid(0.0, 1.0, 0.0, 1.0, 0, 1),
            Err(MeshError::InvalidParameter(_))
        ));
        assert!(matches!(
            block_grid(1.0, 0.0, 0.0, 1.0, 1, 1),
            Err(MeshError::InvalidParameter(_))
        ));
        assert!(delaunay(&[Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0)]).is_err());
        assert!(delaunay(&[
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(2.0, 0.0)
        ])
        .is_err());
    }
}
