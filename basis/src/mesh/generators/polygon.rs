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

    /// The area inside the outer polygon and outside the holes (shoelace formula;
    /// meaningful for a domain [`PolygonDomain::validate`] accepts, whose holes lie
    /// inside the outer polygon and apart).
    pub fn area(&self) -> f64 {
        let enclosed = |poly: &[Vec2]| {
            let n = poly.len();
            let twice: f64 = (0..n)
                .map(|i| {
                    let (a, b) = (poly[i], poly[(i + 1) % n]);
                    a.x * b.y - b.x * a.y
                })
                .sum();
            0.5 * twice.abs()
        };
        enclosed(&self.outer) - self.holes.iter().map(|(h, _)| enclosed(h)).sum::<f64>()
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

/// The part of a [`PolygonDomain`] a [`PolygonFault`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PolygonPart {
    /// The outer polygon's corners.
    Outer,
    /// The outer polygon's segment tags.
    OuterTags,
    /// The corners of hole `i`.
    Hole(usize),
    /// The tag of hole `i`.
    HoleTag(usize),
}

/// Two boundary segments of a [`PolygonDomain`] closer than asked
/// ([`PolygonDomain::narrowest_gap`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NarrowGap {
    /// Their distance.
    pub distance: f64,
    /// The part the later segment belongs to (a hole rather than the outer
    /// polygon, the second of two holes), as [`PolygonFault`] names it.
    pub part: PolygonPart,
    /// The earlier segment, for messages (`segment (x, y)–(x, y) of hole `a``).
    pub first: String,
    /// The later segment, likewise.
    pub second: String,
}

/// Why a [`PolygonDomain`] cannot be meshed, and the part at fault: of two loops that
/// meet or nest, the later one (a hole rather than the outer polygon, the second
/// hole rather than the first).
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonFault {
    /// The part at fault.
    pub part: PolygonPart,
    /// What is wrong.
    pub message: String,
}

impl From<PolygonFault> for MeshError {
    fn from(f: PolygonFault) -> Self {
        MeshError::InvalidParameter(f.message)
    }
}

impl PolygonDomain {
    /// Checks the domain: at least 3 finite corners per polygon, one non-empty tag per
    /// outer segment, segments of positive length that neither cross nor touch
    /// (except consecutive ones at their shared corner), holes inside the outer
    /// polygon and not inside each other. Returns the diameter of the outer polygon's
    /// bounding box. Segments are paired through a grid of about `N` cells (`N` the
    /// total number of corners), so the cost is about `O(N)` for corners spread along
    /// the boundary, and `O(N²)` only when most segments cross most cells.
    pub fn validate(&self) -> Result<f64, MeshError> {
        Ok(self.check()?)
    }

    /// [`PolygonDomain::validate`] with the part at fault.
    pub fn check(&self) -> Result<f64, PolygonFault> {
        let invalid = |part: PolygonPart, message: String| Err(PolygonFault { part, message });
        // Loop `l` of `loops()` (0 the outer polygon) as a part.
        let part_of = |l: usize| match l {
            0 => PolygonPart::Outer,
            h => PolygonPart::Hole(h - 1),
        };
        if self.outer.len() < 3 {
            return invalid(
                PolygonPart::Outer,
                format!(
                    "the outer polygon needs at least 3 corners, got {}",
                    self.outer.len()
                ),
            );
        }
        if self.outer_tags.len() != self.outer.len() {
            return invalid(
                PolygonPart::OuterTags,
                format!(
                    "the outer polygon has {} segments but {} (one per segment i → i + 1)",
                    self.outer.len(),
                    match self.outer_tags.len() {
                        1 => "1 tag".to_string(),
                        n => format!("{n} tags"),
                    }
                ),
            );
        }
        for (h, (hole, tag)) in self.holes.iter().enumerate() {
            if hole.len() < 3 {
                return invalid(
                    PolygonPart::Hole(h),
                    format!("hole `{tag}` needs at least 3 corners, got {}", hole.len()),
                );
            }
        }
        let loops = self.loops();
        for (l, (corners, name)) in loops.iter().enumerate() {
            if let Some(p) = corners
                .iter()
                .find(|p| !(p.x.is_finite() && p.y.is_finite()))
            {
                return invalid(
                    part_of(l),
                    format!("{name} has a non-finite corner {}", point(*p)),
                );
            }
        }
        if self.outer_tags.iter().any(String::is_empty) {
            return invalid(
                PolygonPart::OuterTags,
                "boundary tags must not be empty".into(),
            );
        }
        if let Some(h) = self.holes.iter().position(|(_, tag)| tag.is_empty()) {
            return invalid(
                PolygonPart::HoleTag(h),
                "boundary tags must not be empty".into(),
            );
        }
        let (lo, hi) = crate::mesh::bounding_box(&self.outer);
        let size = (hi - lo).norm();
        let tol = 1e-9 * size;
        for (l, (corners, name)) in loops.iter().enumerate() {
            let n = corners.len();
            for i in 0..n {
                let (a, b) = (corners[i], corners[(i + 1) % n]);
                if (b - a).norm() <= tol {
                    return invalid(
                        part_of(l),
                        format!("a segment of {name} has zero length at {}", point(a)),
                    );
                }
            }
            // Corners on one line: the loop folds onto itself and encloses nothing
            // (said so, rather than that it intersects itself).
            let far = corners
                .iter()
                .map(|c| c - corners[0])
                .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
                .unwrap_or_default();
            let on_line = corners.iter().all(|c| {
                let v = c - corners[0];
                (v.x * far.y - v.y * far.x).abs() <= tol * far.norm()
            });
            if on_line {
                return invalid(
                    part_of(l),
                    format!("{name} encloses no area (its corners lie on one line)"),
                );
            }
        }
        // Pairs of segments: (loop, index in loop) identifies each one. Only pairs
        // whose boxes (grown by `tol`) overlap can be within `tol`: a grid of cells
        // finds them, and the first pair in (m, u) order that meets is reported.
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
        let all: Vec<(Vec2, Vec2)> = ids.iter().map(|&s| ends(s)).collect();
        let grid = SegmentGrid::new(&all, tol);
        let mut first: Option<(usize, usize)> = None;
        grid.for_each_close_pair(|m, u| {
            let (s, t) = (ids[m], ids[u]);
            let ((a, b), (c, d)) = (all[m], all[u]);
            let n = loops[s.0].0.len();
            let distance = if s.0 != t.0 {
                segment_distance(a, b, c, d)
            } else if (s.1 + 1) % n == t.1 {
                // t starts where s ends: they must not fold back onto each other.
                point_segment_distance(a, c, d).min(point_segment_distance(d, a, b))
            } else if (t.1 + 1) % n == s.1 {
                point_segment_distance(b, c, d).min(point_segment_distance(c, a, b))
            } else {
                segment_distance(a, b, c, d)
            };
            if distance <= tol && first.is_none_or(|f| (m, u) < f) {
                first = Some((m, u));
            }
        });
        if let Some((m, u)) = first {
            let ((a, b), (c, d)) = (all[m], all[u]);
            return invalid(
                part_of(ids[u].0),
                format!(
                    "the boundary intersects itself: segment {}–{} of {} meets segment {}–{} of {}",
                    point(a),
                    point(b),
                    loops[ids[m].0].1,
                    point(c),
                    point(d),
                    loops[ids[u].0].1
                ),
            );
        }
        // No two segments meet, so a loop lies inside another exactly when its first
        // corner does: the parity of the crossings of a ray from it, per loop.
        for (h, (hole, tag)) in self.holes.iter().enumerate() {
            let parity = grid.crossings(hole[0], |m| ids[m].0, loops.len());
            if !parity[0] {
                return invalid(
                    PolygonPart::Hole(h),
                    format!("hole `{tag}` lies outside the outer polygon"),
                );
            }
            for (other, (_, other_tag)) in self.holes.iter().enumerate() {
                if other != h && parity[other + 1] {
                    let (first, second) = if other < h {
                        (other_tag, tag)
                    } else {
                        (tag, other_tag)
                    };
                    return invalid(
                        PolygonPart::Hole(h.max(other)),
                        format!(
                            "holes `{first}` and `{second}` are nested (one lies inside the other)"
                        ),
                    );
                }
            }
        }
        Ok(size)
    }

    /// The narrowest gap of the boundary below `within`: the closest two segments
    /// that are not neighbours on their loop (of two loops, or across a slot or
    /// around a short segment of one), if any comes closer than `within`. The mesher
    /// grades its triangles down to about this gap around it, so a gap far below the
    /// target edge length makes a mesh far larger than that length alone gives (two
    /// holes 1e-5 apart at an edge length of 0.25: 198 126 PS functions and 10 s of
    /// meshing; 1e-6 apart, a degenerate triangle; 1e-8, more than
    /// [`MAX_STEINER_POINTS`] points). Call on a domain that passes [`Self::check`].
    pub fn narrowest_gap(&self, within: f64) -> Option<NarrowGap> {
        let loops = self.loops();
        let part_of = |l: usize| match l {
            0 => PolygonPart::Outer,
            h => PolygonPart::Hole(h - 1),
        };
        let mut ids = Vec::new();
        let mut all = Vec::new();
        for (l, (corners, _)) in loops.iter().enumerate() {
            let n = corners.len();
            for i in 0..n {
                ids.push((l, i));
                all.push((corners[i], corners[(i + 1) % n]));
            }
        }
        let grid = SegmentGrid::new(&all, within);
        let mut best: Option<(f64, usize, usize)> = None;
        grid.for_each_close_pair(|m, u| {
            let (s, t) = (ids[m], ids[u]);
            let n = loops[s.0].0.len();
            if s.0 == t.0 && ((s.1 + 1) % n == t.1 || (t.1 + 1) % n == s.1) {
                return;
            }
            let ((a, b), (c, d)) = (all[m], all[u]);
            let distance = segment_distance(a, b, c, d);
            // The closest pair, the first in (m, u) order among equals.
            if distance < within && best.is_none_or(|(w, bm, bu)| (distance, m, u) < (w, bm, bu)) {
                best = Some((distance, m, u));
            }
        });
        let (distance, m, u) = best?;
        let describe = |k: usize| {
            let (a, b) = all[k];
            format!("segment {}–{} of {}", point(a), point(b), loops[ids[k].0].1)
        };
        Some(NarrowGap {
            distance,
            part: part_of(ids[u].0),
            first: describe(m),
            second: describe(u),
        })
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

/// The largest triangle [`polygon_mesh`] leaves at `target_edge_length` `h`: the
/// equilateral triangle of side `h`, of area `√3/4 · h²`.
pub fn largest_triangle_area(target_edge_length: f64) -> f64 {
    3f64.sqrt() / 4.0 * target_edge_length * target_edge_length
}

/// The fewest triangles [`polygon_mesh`] can make of `domain` at
/// `target_edge_length`, known before it runs: every triangle is smaller than
/// [`largest_triangle_area`], so there are at least the domain's area over that
/// (the refinement's minimum angle and boundary splits make about 1.5 times as
/// many). For a memory check before meshing; `None` where [`polygon_mesh`] would
/// refuse the domain or the edge length (it names the fault).
pub fn fewest_polygon_triangles(domain: &PolygonDomain, target_edge_length: f64) -> Option<f64> {
    let size = domain.check().ok()?;
    (target_edge_length.is_finite() && target_edge_length >= size * 1e-4)
        .then(|| (domain.area() / largest_triangle_area(target_edge_length)).floor())
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
    let max_area = largest_triangle_area(target_edge_length);
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

/// A point in a message, `(x, y)`, each coordinate in its shortest form and in
/// exponent notation outside `1e-4 ≤ |x| < 1e16` (`1e300`, not 301 digits).
pub(crate) fn point(p: Vec2) -> String {
    format!("({}, {})", number(p.x), number(p.y))
}

/// A number in a message: see [`point`].
pub(crate) fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
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

    /// The narrowest gap names the two segments and their distance: two holes
    /// side by side, a slot of the outline, and none where every pair of
    /// non-neighbouring segments is farther apart than asked (the corners of a
    /// square are neighbours' meeting points, not gaps).
    #[test]
    fn the_narrowest_gap_is_between_segments_that_are_not_neighbours() {
        let square = |x0: f64, y0: f64, side: f64| {
            [
                (x0, y0),
                (x0 + side, y0),
                (x0 + side, y0 + side),
                (x0, y0 + side),
            ]
            .map(|(x, y)| Vec2::new(x, y))
            .to_vec()
        };
        let mut domain = PolygonDomain::rectangle(0.0, 4.0, 0.0, 3.0);
        assert_eq!(domain.narrowest_gap(0.5), None);
        domain.holes = vec![
            (square(2.5, 0.5, 0.5), "a".into()),
            (square(3.0 + 1e-5, 0.5, 0.5), "b".into()),
        ];
        domain.check().unwrap();
        let gap = domain.narrowest_gap(0.025).unwrap();
        assert!((gap.distance - 1e-5).abs() < 1e-12, "{gap:?}");
        assert_eq!(gap.part, PolygonPart::Hole(1));
        assert!(
            gap.first.contains("hole `a`") && gap.second.contains("hole `b`"),
            "{gap:?}"
        );
        // Nothing closer than asked: none; the hole alone is 0.5 from the floor.
        assert_eq!(domain.narrowest_gap(1e-6), None);
        domain.holes.truncate(1);
        assert_eq!(domain.narrowest_gap(0.45), None);
        let floor = domain.narrowest_gap(0.6).unwrap();
        assert!((floor.distance - 0.5).abs() < 1e-12, "{floor:?}");
        assert!(floor.first.contains("outer polygon"), "{floor:?}");
        // A slot 0.01 wide cut into the outline from the top.
        let mut slot = PolygonDomain::rectangle(0.0, 2.0, 0.0, 1.0);
        slot.outer = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.01, 1.0),
            (1.01, 0.5),
            (1.0, 0.5),
            (1.0, 1.0),
            (0.0, 1.0),
        ]
        .map(|(x, y)| Vec2::new(x, y))
        .to_vec();
        slot.outer_tags = vec!["wall".into(); 8];
        slot.check().unwrap();
        let gap = slot.narrowest_gap(0.1).unwrap();
        assert!((gap.distance - 0.01).abs() < 1e-12, "{gap:?}");
        assert_eq!(gap.part, PolygonPart::Outer);
    }

    /// The count known before meshing is a lower bound of the mesh's, and not a
    /// loose one (a memory check before the mesher relies on both): on a square,
    /// an L-shape with a round hole and a thin strip, at several edge lengths.
    #[test]
    fn the_fewest_triangles_bound_the_mesh_from_below_and_closely() {
        let mut l_shape = PolygonDomain::rectangle(0.0, 2.0, 0.0, 2.0);
        l_shape.outer = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .map(|(x, y)| Vec2::new(x, y))
        .to_vec();
        l_shape.outer_tags = vec!["wall".into(); 6];
        l_shape.holes = vec![(circle(Vec2::new(0.5, 0.5), 0.2, 24), "hole".into())];
        for (domain, h) in [
            (PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0), 0.1),
            (PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0), 0.03),
            (l_shape.clone(), 0.15),
            (l_shape, 0.05),
            (PolygonDomain::rectangle(0.0, 4.0, 0.0, 0.1), 0.05),
        ] {
            let fewest = fewest_polygon_triangles(&domain, h).unwrap();
            let mesh = polygon_mesh(&domain, h).unwrap();
            assert!((total_area(&mesh) - domain.area()).abs() < 1e-2 * domain.area());
            let made = mesh.num_triangles() as f64;
            assert!(
                fewest <= made && made < 4.0 * fewest,
                "{fewest} against {made} at h = {h}"
            );
        }
        // Refused where the mesher refuses: an edge length below 1e-4 of the size,
        // a domain of two corners.
        let square = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        assert_eq!(fewest_polygon_triangles(&square, 1e-5), None);
        assert_eq!(fewest_polygon_triangles(&square, f64::NAN), None);
        let mut segment = square;
        segment.outer.truncate(2);
        segment.outer_tags.truncate(2);
        assert_eq!(fewest_polygon_triangles(&segment, 0.1), None);
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
        d.outer_tags.truncate(1);
        assert!(msg(&d).contains("4 segments but 1 tag ("), "{}", msg(&d));
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
        // Corners on one line enclose no area.
        let mut d = square.clone();
        d.outer = pts(&[(0.0, 0.0), (2.0, 0.0), (4.0, 0.0)]);
        d.outer_tags.truncate(3);
        assert!(msg(&d).contains("the outer polygon encloses no area"));
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
        // The part at fault: of two loops that meet or nest, the later one.
        let part = |d: &PolygonDomain| d.check().unwrap_err().part;
        assert_eq!(part(&with_hole(tri(0.8, 0.5, 0.4))), PolygonPart::Hole(0));
        assert_eq!(part(&with_hole(tri(2.0, 2.0, 0.4))), PolygonPart::Hole(0));
        assert_eq!(part(&nested), PolygonPart::Hole(1));
        let mut crossing = with_hole(tri(0.1, 0.1, 0.2));
        crossing.holes.push((tri(0.2, 0.15, 0.2), "second".into()));
        assert_eq!(part(&crossing), PolygonPart::Hole(1));
        let mut untagged = with_hole(tri(0.1, 0.1, 0.2));
        untagged.holes[0].1.clear();
        assert_eq!(part(&untagged), PolygonPart::HoleTag(0));
        let mut d = square.clone();
        d.outer_tags[2] = String::new();
        assert_eq!(part(&d), PolygonPart::OuterTags);
        d.outer.swap(1, 2);
        d.outer_tags[2] = "top".into();
        assert_eq!(part(&d), PolygonPart::Outer);
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

/// Segments binned in a uniform grid over their bounding box: each segment in every
/// cell its box (grown by `tol`) covers, with about one cell per segment, coarsened
/// until the segments cover at most [`SegmentGrid::MAX_COVER`] cells each on average.
struct SegmentGrid<'a> {
    segments: &'a [(Vec2, Vec2)],
    tol: f64,
    lo: Vec2,
    cell: f64,
    dims: [usize; 2],
    /// Segments of cell `c`: `items[start[c]..start[c + 1]]`.
    start: Vec<usize>,
    items: Vec<usize>,
}

impl<'a> SegmentGrid<'a> {
    /// Average cells per segment above which the grid is coarsened.
    const MAX_COVER: usize = 32;

    fn new(segments: &'a [(Vec2, Vec2)], tol: f64) -> Self {
        let n = segments.len().max(1);
        let mut lo = Vec2::new(f64::INFINITY, f64::INFINITY);
        let mut hi = Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for (a, b) in segments {
            lo = lo.inf(a).inf(b);
            hi = hi.sup(a).sup(b);
        }
        let pad = Vec2::new(tol, tol);
        let (lo, hi) = (lo - pad, hi + pad);
        let extent = (hi - lo).max().max(f64::MIN_POSITIVE);
        let mut cell = extent / (n as f64).sqrt().max(1.0);
        loop {
            let dims = [
                (((hi.x - lo.x) / cell).floor() as usize + 1).min(n),
                (((hi.y - lo.y) / cell).floor() as usize + 1).min(n),
            ];
            let mut grid = SegmentGrid {
                segments,
                tol,
                lo,
                cell,
                dims,
                start: Vec::new(),
                items: Vec::new(),
            };
            let cover: usize = (0..segments.len())
                .map(|m| {
                    let [i0, j0, i1, j1] = grid.box_cells(m);
                    (i1 - i0 + 1) * (j1 - j0 + 1)
                })
                .sum();
            if cover <= Self::MAX_COVER * n || dims == [1, 1] {
                grid.fill();
                return grid;
            }
            cell *= 2.0;
        }
    }

    /// `[i0, j0, i1, j1]`: the cell columns and rows of segment `m`'s grown box.
    fn box_cells(&self, m: usize) -> [usize; 4] {
        let (a, b) = self.segments[m];
        let index = |v: f64, lo: f64, dim: usize| -> usize {
            (((v - lo) / self.cell).floor().max(0.0) as usize).min(dim - 1)
        };
        [
            index(a.x.min(b.x) - self.tol, self.lo.x, self.dims[0]),
            index(a.y.min(b.y) - self.tol, self.lo.y, self.dims[1]),
            index(a.x.max(b.x) + self.tol, self.lo.x, self.dims[0]),
            index(a.y.max(b.y) + self.tol, self.lo.y, self.dims[1]),
        ]
    }

    fn fill(&mut self) {
        let cells = self.dims[0] * self.dims[1];
        let mut count = vec![0usize; cells + 1];
        for m in 0..self.segments.len() {
            let [i0, j0, i1, j1] = self.box_cells(m);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    count[i + self.dims[0] * j + 1] += 1;
                }
            }
        }
        for c in 0..cells {
            count[c + 1] += count[c];
        }
        let mut next = count.clone();
        self.items = vec![0; count[cells]];
        for m in 0..self.segments.len() {
            let [i0, j0, i1, j1] = self.box_cells(m);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let c = i + self.dims[0] * j;
                    self.items[next[c]] = m;
                    next[c] += 1;
                }
            }
        }
        self.start = count;
    }

    /// Calls `f(m, u)`, `m < u`, once for every pair of segments whose grown boxes
    /// overlap (in the cell holding the lower corner of the overlap).
    fn for_each_close_pair(&self, mut f: impl FnMut(usize, usize)) {
        for j in 0..self.dims[1] {
            for i in 0..self.dims[0] {
                let c = i + self.dims[0] * j;
                let here = &self.items[self.start[c]..self.start[c + 1]];
                for (k, &m) in here.iter().enumerate() {
                    let bm = self.box_cells(m);
                    for &u in &here[k + 1..] {
                        let bu = self.box_cells(u);
                        // The pair meets in the cell of its overlap's lower corner only.
                        if bm[0].max(bu[0]) != i || bm[1].max(bu[1]) != j {
                            continue;
                        }
                        if !self.boxes_overlap(m, u) {
                            continue;
                        }
                        let (a, b) = if m < u { (m, u) } else { (u, m) };
                        f(a, b);
                    }
                }
            }
        }
    }

    fn boxes_overlap(&self, m: usize, u: usize) -> bool {
        let ((a, b), (c, d)) = (self.segments[m], self.segments[u]);
        let t = self.tol;
        a.x.min(b.x) - t <= c.x.max(d.x) + t
            && c.x.min(d.x) - t <= a.x.max(b.x) + t
            && a.y.min(b.y) - t <= c.y.max(d.y) + t
            && c.y.min(d.y) - t <= a.y.max(b.y) + t
    }

    /// Per loop (`loop_of(m)` names each segment's, of `loops`), whether a ray from
    /// `p` towards +x crosses its segments an odd number of times: whether `p` lies
    /// inside it (the rule of `inside_polygon`). Walks only the cells of `p`'s row.
    fn crossings(&self, p: Vec2, loop_of: impl Fn(usize) -> usize, loops: usize) -> Vec<bool> {
        let mut parity = vec![false; loops];
        let j = (((p.y - self.lo.y) / self.cell).floor().max(0.0) as usize).min(self.dims[1] - 1);
        let i0 = (((p.x - self.lo.x) / self.cell).floor().max(0.0) as usize).min(self.dims[0] - 1);
        let mut seen = std::collections::BTreeSet::new();
        for i in i0..self.dims[0] {
            let c = i + self.dims[0] * j;
            for &m in &self.items[self.start[c]..self.start[c + 1]] {
                if !seen.insert(m) {
                    continue;
                }
                let (a, b) = self.segments[m];
                if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)
                {
                    let l = loop_of(m);
                    parity[l] = !parity[l];
                }
            }
        }
        parity
    }
}

#[cfg(test)]
mod grid_tests {
    use super::*;

    /// A star polygon of `n` corners (radius `1 + wobble(k)`), tagged `side`.
    fn star(n: usize, wobble: impl Fn(usize) -> f64) -> PolygonDomain {
        star_turned(n, wobble, |_| 0.0)
    }

    /// [`star`] with corner `k` turned by `turn(k)` corner spacings (more than half
    /// a spacing lets segments cross).
    fn star_turned(
        n: usize,
        wobble: impl Fn(usize) -> f64,
        turn: impl Fn(usize) -> f64,
    ) -> PolygonDomain {
        let outer = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * (k as f64 + turn(k)) / n as f64;
                let r = 1.0 + wobble(k);
                Vec2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        PolygonDomain {
            outer,
            outer_tags: vec!["side".into(); n],
            holes: Vec::new(),
        }
    }

    /// What `validate` decided before the grid: every pair of segments tested.
    fn brute_force_meets(d: &PolygonDomain, tol: f64) -> Option<(usize, usize)> {
        let all: Vec<(Vec2, Vec2, usize, usize)> = d
            .loops()
            .iter()
            .enumerate()
            .flat_map(|(l, (c, _))| (0..c.len()).map(move |i| (c[i], c[(i + 1) % c.len()], l, i)))
            .collect();
        for m in 0..all.len() {
            for u in m + 1..all.len() {
                let ((a, b, l, i), (c, e, l2, j)) = (all[m], all[u]);
                let n = d.loops()[l].0.len();
                let distance = if l != l2 {
                    segment_distance(a, b, c, e)
                } else if (i + 1) % n == j {
                    point_segment_distance(a, c, e).min(point_segment_distance(e, a, b))
                } else if (j + 1) % n == i {
                    point_segment_distance(b, c, e).min(point_segment_distance(c, a, b))
                } else {
                    segment_distance(a, b, c, e)
                };
                if distance <= tol {
                    return Some((m, u));
                }
            }
        }
        None
    }

    /// The grid finds exactly the crossings the all-pairs test finds, on stars whose
    /// corners are pushed in and out at random (many of them cross).
    #[test]
    fn the_grid_agrees_with_all_pairs_on_random_stars() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut crossing, mut simple) = (0, 0);
        for case in 0..300 {
            let n = 5 + case % 40;
            let amplitude = [0.05, 0.5, 1.5][case % 3];
            let radii: Vec<f64> = (0..n).map(|_| amplitude * (random() - 0.5)).collect();
            let turns: Vec<f64> = (0..n).map(|_| 2.0 * amplitude * (random() - 0.5)).collect();
            let d = star_turned(n, |k| radii[k], |k| turns[k]);
            let tol = 1e-9 * {
                let (lo, hi) = crate::mesh::bounding_box(&d.outer);
                (hi - lo).norm()
            };
            let expected = brute_force_meets(&d, tol);
            let got = d.validate();
            match expected {
                Some(_) => {
                    crossing += 1;
                    let message = format!("{:?}", got.unwrap_err());
                    assert!(message.contains("intersects itself"), "{message}");
                }
                None => {
                    simple += 1;
                    assert!(got.is_ok(), "case {case}: {got:?}");
                }
            }
        }
        assert!(
            crossing > 20 && simple > 20,
            "{crossing} crossing, {simple} simple"
        );
    }

    /// 100 000 corners validate in about linear time (the all-pairs test took
    /// minutes), and one crossing among them is still found.
    #[test]
    fn a_large_polygon_validates_and_a_crossing_in_it_is_found() {
        let n = 100_000;
        assert!(star(n, |_| 0.0).validate().is_ok());
        let mut d = star(n, |_| 0.0);
        d.outer.swap(40_000, 40_001);
        let message = format!("{:?}", d.validate().unwrap_err());
        assert!(message.contains("intersects itself"), "{message}");
        // A hole inside, one outside, and two nested.
        let square = |x: f64, y: f64, s: f64| {
            vec![
                Vec2::new(x, y),
                Vec2::new(x + s, y),
                Vec2::new(x + s, y + s),
                Vec2::new(x, y + s),
            ]
        };
        let mut d = star(n, |_| 0.0);
        d.holes.push((square(-0.2, -0.2, 0.4), "a".into()));
        assert!(d.validate().is_ok());
        d.holes.push((square(2.0, 2.0, 0.1), "out".into()));
        let message = format!("{:?}", d.validate().unwrap_err());
        assert!(message.contains("hole `out` lies outside"), "{message}");
        d.holes.pop();
        d.holes.push((square(-0.1, -0.1, 0.2), "in".into()));
        let message = format!("{:?}", d.validate().unwrap_err());
        assert!(message.contains("nested"), "{message}");
    }
}
