//! Unstructured quality meshes of polygonal domains with holes: validation of the
//! domain, constrained Delaunay refinement (spade), tagging of the boundary edges by
//! the domain segment they lie on.

use super::{MeshError, TriMesh, Vec2};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

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

    /// Whether `p` lies inside the outer polygon and outside every hole (crossing
    /// number; a point exactly on the boundary may fall either way).
    pub fn contains(&self, p: Vec2) -> bool {
        inside_polygon(p, &self.outer) && !self.holes.iter().any(|(h, _)| inside_polygon(p, h))
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
    let orient = |p: Vec2, q: Vec2, r: Vec2| crate::mesh::signed_area(p, q, r);
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
        let (lo, hi) = crate::mesh::bounding_box(&self.outer);
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
        return Err(MeshError::EdgeLength(format!(
            "invalid mesh parameter: target_edge_length must be at least 1e-4 of the domain size {size}, got {target_edge_length}"
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
        return Err(MeshError::EdgeLength(format!(
            "mesher failed: refinement needed more than {MAX_STEINER_POINTS} points; increase target_edge_length"
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
mod contains_tests {
    use super::*;

    #[test]
    fn contains_is_inside_the_outline_and_outside_the_holes() {
        let mut d = PolygonDomain::rectangle(0.0, 4.0, 0.0, 4.0);
        d.holes.push((
            vec![
                Vec2::new(1.0, 1.0),
                Vec2::new(2.0, 1.0),
                Vec2::new(2.0, 2.0),
                Vec2::new(1.0, 2.0),
            ],
            "hole".into(),
        ));
        assert!(d.contains(Vec2::new(0.5, 0.5)));
        assert!(d.contains(Vec2::new(3.5, 1.5)));
        assert!(!d.contains(Vec2::new(1.5, 1.5)));
        assert!(!d.contains(Vec2::new(4.5, 1.5)));
        assert!(!d.contains(Vec2::new(-0.5, 1.5)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators::tests::{invalid_message, tag_count, total_area};

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
            match polygon_mesh(&square, h) {
                Err(MeshError::EdgeLength(m)) => assert!(m.contains("target_edge_length")),
                other => panic!("expected EdgeLength, got {other:?}"),
            }
        }
        // A valid hole still works.
        polygon_mesh(&with_hole(tri(0.2, 0.2, 0.4)), 0.2).unwrap();
    }
}
