//! Control (PS) triangles: for each vertex `V_i`, a triangle containing all its PS
//! points (`ps-splines.md` §2, thesis §3.5.2). Containment makes the basis
//! non-negative; a smaller area conditions it better.
//!
//! Candidates are built from the lines of the convex hull of the PS points:
//! - every pair of hull lines meeting at an apex, closed by a third line orthogonal
//!   to the bisector of the wedge and pushed out to the farthest PS point;
//! - every triple of hull lines whose half-planes bound a triangle.
//!
//! The candidate of smallest area wins, except where the PS points are
//! mirror-symmetric about the vertical or the horizontal line through `V_i` (or a
//! diagonal one, where the scene asks for it):
//! there the smallest candidate with the same mirror symmetry wins (the
//! [`MirrorAxis`] asked for where the points have both), so that a mesh
//! symmetric about a line gets a basis symmetric about it (the smallest triangle of
//! a symmetric point set is often not symmetric, and which way it points would
//! otherwise be decided by the order of the hull). On a straight stretch of boundary only
//! candidates with an edge on the boundary line are allowed; at a convex corner the
//! apex is `V_i` with edges along both boundary lines. With these choices the
//! homogeneous Dirichlet condition on a straight boundary fixes exactly the
//! coefficients of the control points on it (`ps-splines.md` §5).

pub use crate::mesh::MirrorAxis;
use crate::mesh::Vec2;

/// A line `n · x = c` bounding the half-plane `n · x ≤ c` (`n` a unit outward normal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfPlane {
    /// Unit outward normal.
    pub n: Vec2,
    /// Offset.
    pub c: f64,
}

impl HalfPlane {
    /// The half-plane bounded by the line through `a` and `b`, containing the points
    /// to the left of `a → b`.
    pub fn left_of(a: Vec2, b: Vec2) -> Self {
        let d = (b - a).normalize();
        let n = Vec2::new(d.y, -d.x);
        HalfPlane { n, c: n.dot(&a) }
    }
}

/// Where a vertex sits, for the choice of its control triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VertexKind {
    /// Interior vertex: free choice.
    Interior,
    /// Boundary vertex on a straight stretch: one edge on this line.
    Straight(HalfPlane),
    /// Convex boundary corner: apex at the vertex, edges on both lines.
    Corner(HalfPlane, HalfPlane),
}

fn cross(u: Vec2, v: Vec2) -> f64 {
    u.x * v.y - u.y * v.x
}

/// Intersection of two lines, `None` when (nearly) parallel.
fn intersect(a: &HalfPlane, b: &HalfPlane) -> Option<Vec2> {
    let det = cross(a.n, b.n);
    if det.abs() < 1e-12 {
        return None;
    }
    Some(Vec2::new(
        (a.c * b.n.y - b.c * a.n.y) / det,
        (a.n.x * b.c - b.n.x * a.c) / det,
    ))
}

/// Convex hull (counter-clockwise, no collinear points) by Andrew's monotone chain.
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<Vec2> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup_by(|a, b| (*a - *b).norm() <= 1e-14 * (1.0 + a.norm()));
    if p.len() < 3 {
        return p;
    }
    let scale = p.iter().fold(0.0f64, |m, q| m.max((q - p[0]).norm()));
    let turn = |o: Vec2, a: Vec2, b: Vec2| cross(a - o, b - o) > 1e-12 * scale * scale;
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2 && !turn(hull[hull.len() - 2], hull[hull.len() - 1], q) {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Signed area of a triangle.
fn area(t: &[Vec2; 3]) -> f64 {
    0.5 * cross(t[1] - t[0], t[2] - t[0])
}

/// The triangle cut from the wedge `{a, b}` by the line orthogonal to its bisector
/// through the farthest point. The apex is `a ∩ b`, or `apex` when given (a boundary
/// corner, whose apex is known exactly). `None` if the lines are parallel or the
/// wedge is not a proper angle.
fn wedge_candidate(
    a: &HalfPlane,
    b: &HalfPlane,
    apex: Option<Vec2>,
    points: &[Vec2],
) -> Option<[Vec2; 3]> {
    let apex = match apex {
        Some(p) => p,
        None => intersect(a, b)?,
    };
    let sum = a.n + b.n;
    if sum.norm() < 1e-12 {
        return None;
    }
    let d = -sum.normalize(); // opening direction of the wedge
    let reach = points
        .iter()
        .map(|p| d.dot(&(p - apex)))
        .fold(f64::NEG_INFINITY, f64::max);
    if reach <= 0.0 {
        return None;
    }
    let cut = HalfPlane {
        n: d,
        c: d.dot(&apex) + reach,
    };
    let pa = intersect(a, &cut)?;
    let pb = intersect(b, &cut)?;
    Some([apex, pa, pb])
}

/// The triangle bounded by three half-planes, if bounded.
fn triple_candidate(l: [&HalfPlane; 3], tol: f64) -> Option<[Vec2; 3]> {
    let p01 = intersect(l[0], l[1])?;
    let p12 = intersect(l[1], l[2])?;
    let p20 = intersect(l[2], l[0])?;
    let inside = |p: Vec2, h: &HalfPlane| h.n.dot(&p) <= h.c + tol;
    if inside(p01, l[2]) && inside(p12, l[0]) && inside(p20, l[1]) {
        Some([p01, p12, p20])
    } else {
        None
    }
}

/// `true` when every point lies in triangle `t` (counter-clockwise) up to `tol`.
fn contains_all(t: &[Vec2; 3], points: &[Vec2], tol: f64) -> bool {
    points.iter().all(|p| {
        (0..3).all(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            cross(b - a, p - a) / (b - a).norm() >= -tol
        })
    })
}

/// A convex boundary corner takes the apex construction `Q¹ = V_i` (edges on both
/// boundary lines) only while its area is at most this multiple of the smallest
/// candidate with an edge on one of the two lines. A nearly straight corner (interior
/// angle close to π) would otherwise get a very flat control triangle whose far
/// corners run off along the boundary: its two basis functions `φ²`, `φ³` become
/// nearly equal (ill-conditioned mass matrix) and round-off in its triplets breaks
/// non-negativity. The fallback keeps Dirichlet conditions exact (single-term on the
/// chosen line, general constraints on the other; see `dirichlet` of
/// [`super::PowellSabin`]). At a right angle the ratio is about 1.
pub const CORNER_AREA_RATIO: f64 = 4.0;

/// The control triangle of a vertex at `vertex` with PS points `points`, counter-
/// clockwise (thesis §3.5.2, `ps-splines.md` §2):
/// - [`VertexKind::Interior`]: the smallest candidate from the hull lines;
/// - [`VertexKind::Straight`]: the smallest candidate having the boundary line as one
///   of its lines;
/// - [`VertexKind::Corner`]: the wedge with apex `vertex` on the two boundary lines,
///   closed orthogonally to its bisector; `vertex` is returned first (`Q¹ = V_i`).
///   Falls back to the best `Straight` candidate on either line when the wedge is
///   more than [`CORNER_AREA_RATIO`] times larger.
///
/// Where the PS points are mirror-symmetric about the vertical line through
/// `vertex` (else about the horizontal one), only candidates with that symmetry
/// compete, when there is one (the private `Mirror` says why); where they are
/// symmetric about both, [`control_triangle_with`] chooses which.
///
/// Ties between candidates of equal area go to the first one found (hull lines in
/// counter-clockwise order from the lowest-leftmost point), so the choice is
/// deterministic. `None` if no candidate contains the points (cannot happen on a
/// valid mesh).
pub fn control_triangle(vertex: Vec2, points: &[Vec2], kind: VertexKind) -> Option<[Vec2; 3]> {
    control_triangle_with(vertex, points, kind, MirrorAxis::Vertical)
}

/// [`control_triangle`], keeping the line `axis` where the PS points are
/// symmetric about both axis-aligned lines through `vertex`.
pub fn control_triangle_with(
    vertex: Vec2,
    points: &[Vec2],
    kind: VertexKind,
    axis: MirrorAxis,
) -> Option<[Vec2; 3]> {
    let t = choose(vertex, points, kind, axis)?;
    // Enlarge about the vertex (see CONTROL_TRIANGLE_MARGIN).
    Some(t.map(|q| vertex + (q - vertex) * (1.0 + CONTROL_TRIANGLE_MARGIN)))
}

/// The chosen triangle is enlarged by the factor `1 + CONTROL_TRIANGLE_MARGIN` about
/// the vertex. A PS point on one of its edges would get Bézier ordinates that are
/// zero up to round-off of either sign, and round-off is amplified by `|∇L_q|`, the
/// inverse height of the triangle (large for thin ones): this margin moves such
/// points inside by `ε · dist(V_i, edge)`, so that every ordinate, hence every basis
/// function, is non-negative in floating point too. Lines through `V_i` do not move:
/// the boundary lines of aligned control triangles stay exact (Dirichlet conditions),
/// and at a corner `Q¹ = V_i` stays. Partition of unity and linear precision hold for
/// any control triangle and are unaffected.
pub const CONTROL_TRIANGLE_MARGIN: f64 = 1e-11;

/// The unenlarged choice of [`control_triangle`].
fn choose(vertex: Vec2, points: &[Vec2], kind: VertexKind, axis: MirrorAxis) -> Option<[Vec2; 3]> {
    match kind {
        VertexKind::Interior => smallest_candidate(vertex, points, None, axis),
        VertexKind::Straight(h) => smallest_candidate(vertex, points, Some(h), axis),
        VertexKind::Corner(a, b) => {
            let corner = corner_candidate(vertex, points, &a, &b);
            let along = [a, b]
                .iter()
                .filter_map(|h| smallest_candidate(vertex, points, Some(*h), axis))
                .min_by(|s, t| area(s).total_cmp(&area(t)));
            match (corner, along) {
                (Some(c), Some(s)) if area(&c) > CORNER_AREA_RATIO * area(&s) => Some(s),
                (Some(c), _) => Some(c),
                (None, s) => s,
            }
        }
    }
}

/// Containment tolerance: round-off relative to the spread of the PS points.
fn tolerance(vertex: Vec2, points: &[Vec2]) -> f64 {
    1e-9 * points
        .iter()
        .fold(0.0f64, |m, p| m.max((p - vertex).norm()))
}

/// Counter-clockwise orientation of `t`.
fn orient(t: [Vec2; 3]) -> [Vec2; 3] {
    if area(&t) < 0.0 {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// The wedge on the two boundary lines of a convex corner with apex at the vertex,
/// the vertex first.
fn corner_candidate(
    vertex: Vec2,
    points: &[Vec2],
    a: &HalfPlane,
    b: &HalfPlane,
) -> Option<[Vec2; 3]> {
    let t = orient(wedge_candidate(a, b, Some(vertex), points)?);
    let t = if t[1] == vertex {
        [t[1], t[2], t[0]]
    } else if t[2] == vertex {
        [t[2], t[0], t[1]]
    } else {
        t
    };
    contains_all(&t, points, tolerance(vertex, points)).then_some(t)
}

/// A mirror line through a vertex, axis-aligned. A mesh symmetric about a line
/// (a box, a column, the block grids) has a symmetric basis only if each vertex on
/// the line gets a triangle symmetric about it and each pair of mirrored vertices
/// gets mirrored triangles. The smallest triangle around a symmetric point set is
/// often not symmetric (around the octagon of PS points of a `four-triangles` grid
/// vertex of valence 8 the smallest ones lean left or right), so where the points
/// are symmetric the choice is made among symmetric candidates: the basis of a
/// block dropped onto the middle of a floor is then mirror-symmetric, and the block
/// does not come back turning. Where the points have both mirrors, the
/// [`MirrorAxis`] asked for (vertical by default: the mirror of a scene under
/// gravity along `y`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mirror {
    /// The line `x = vertex.x`.
    Vertical,
    /// The line `y = vertex.y`.
    Horizontal,
    /// The line `y − vertex.y = x − vertex.x`.
    Diagonal,
    /// The line `y − vertex.y = −(x − vertex.x)`.
    AntiDiagonal,
}

impl Mirror {
    fn reflect(self, vertex: Vec2, p: Vec2) -> Vec2 {
        let d = p - vertex;
        match self {
            Mirror::Vertical => Vec2::new(2.0 * vertex.x - p.x, p.y),
            Mirror::Horizontal => Vec2::new(p.x, 2.0 * vertex.y - p.y),
            Mirror::Diagonal => vertex + Vec2::new(d.y, d.x),
            Mirror::AntiDiagonal => vertex - Vec2::new(d.y, d.x),
        }
    }

    /// The unit direction of a diagonal line (`None` for the axis-aligned ones).
    fn diagonal_direction(self) -> Option<Vec2> {
        let r = std::f64::consts::FRAC_1_SQRT_2;
        match self {
            Mirror::Diagonal => Some(Vec2::new(r, r)),
            Mirror::AntiDiagonal => Some(Vec2::new(r, -r)),
            _ => None,
        }
    }

    /// `true` when the reflection maps `points` onto themselves, up to `tol`.
    fn maps_onto_itself(self, vertex: Vec2, points: &[Vec2], tol: f64) -> bool {
        points.iter().all(|p| {
            let r = self.reflect(vertex, *p);
            points.iter().any(|q| (q - r).norm() <= tol)
        })
    }

    /// The mirror of the vertex's PS points, if they have one; `axis` first. The
    /// diagonal lines are tried only where the scene asks for one (the other
    /// scenes keep the triangles they had); a vertex whose points have no
    /// diagonal mirror (on a boundary along an axis) keeps an axis-aligned one,
    /// which a diagonal mirror of the mesh maps onto its partner's.
    fn of(vertex: Vec2, points: &[Vec2], tol: f64, axis: MirrorAxis) -> Option<Mirror> {
        use Mirror::{AntiDiagonal, Diagonal, Horizontal, Vertical};
        let order: &[Mirror] = match axis {
            MirrorAxis::Vertical => &[Vertical, Horizontal],
            MirrorAxis::Horizontal => &[Horizontal, Vertical],
            MirrorAxis::Diagonal => &[Diagonal, AntiDiagonal, Vertical, Horizontal],
            MirrorAxis::AntiDiagonal => &[AntiDiagonal, Diagonal, Vertical, Horizontal],
        };
        order
            .iter()
            .copied()
            .find(|m| m.maps_onto_itself(vertex, points, tol))
    }
}

/// The smallest isosceles triangles symmetric about the line through `vertex`
/// along the unit vector `a` that contain `points`, one pointing each way along
/// it, with its base orthogonal to the line on the farthest point behind. The
/// hull lines give no symmetric candidate about a diagonal around a square of PS
/// points whose corners lie on the axes (the valence-4 block centres of the
/// `blocks` grids): its edges mirrored about the diagonal are parallel. With `u`
/// along the line and `w` across it, the apex at `u_A` beyond every point and the
/// base at `u_b`, the half-width grows as `s (u_A − u)`, `s = max |w_p| / (u_A −
/// u_p)`, and the area `s (u_A − u_b)²` is convex in `u_A`: its minimum is at a
/// stationary point of one point's term (`u_A = 2 u_p − u_b`) or where two terms
/// cross, all of which are tried.
fn isosceles_candidates(vertex: Vec2, a: Vec2, points: &[Vec2]) -> Vec<[Vec2; 3]> {
    let b = Vec2::new(-a.y, a.x);
    let mut out = Vec::new();
    for sign in [1.0, -1.0] {
        let (a, b) = (a * sign, b * sign);
        let uw: Vec<(f64, f64)> = points
            .iter()
            .map(|p| ((p - vertex).dot(&a), (p - vertex).dot(&b).abs()))
            .collect();
        let base = uw.iter().fold(f64::INFINITY, |m, &(u, _)| m.min(u));
        let top = uw.iter().fold(f64::NEG_INFINITY, |m, &(u, _)| m.max(u));
        let scale = top - base;
        if scale <= 0.0 {
            continue;
        }
        let slope = |apex: f64| {
            uw.iter()
                .filter(|&&(_, w)| w > 0.0)
                .fold(0.0f64, |m, &(u, w)| m.max(w / (apex - u)))
        };
        let mut apexes: Vec<f64> = uw.iter().map(|&(u, _)| 2.0 * u - base).collect();
        for (i, &(ui, wi)) in uw.iter().enumerate() {
            for &(uj, wj) in &uw[i + 1..] {
                if (wi - wj).abs() > 1e-12 * scale {
                    apexes.push((wi * uj - wj * ui) / (wi - wj));
                }
            }
        }
        let best = apexes
            .into_iter()
            .filter(|&apex| apex > top + 1e-9 * scale)
            .map(|apex| (apex, slope(apex) * (apex - base) * (apex - base)))
            .filter(|&(_, area)| area > 0.0 && area.is_finite())
            .min_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((apex, _)) = best {
            let half = slope(apex) * (apex - base);
            out.push([
                vertex + a * apex,
                vertex + a * base + b * half,
                vertex + a * base - b * half,
            ]);
        }
    }
    out
}

/// The smallest candidate (wedge or triple of hull lines) containing `points`; with
/// `required`, only candidates having that line as one of theirs. Where the points
/// have a [`Mirror`], the smallest candidate with the same symmetry, if any (`axis`
/// where they have both).
fn smallest_candidate(
    vertex: Vec2,
    points: &[Vec2],
    required: Option<HalfPlane>,
    axis: MirrorAxis,
) -> Option<[Vec2; 3]> {
    let tol = tolerance(vertex, points);
    let hull = convex_hull(points);
    // The hull is counter-clockwise, so the points lie left of every edge.
    let mut lines: Vec<HalfPlane> = (0..hull.len())
        .map(|k| HalfPlane::left_of(hull[k], hull[(k + 1) % hull.len()]))
        .collect();
    let required: Option<usize> = required.map(|h| {
        let found = lines
            .iter()
            .position(|l| (l.n - h.n).norm() < 1e-9 && (l.c - h.c).abs() <= tol);
        found.unwrap_or_else(|| {
            lines.push(h);
            lines.len() - 1
        })
    });
    let allowed = |ids: &[usize]| required.is_none_or(|r| ids.contains(&r));
    let mirror = Mirror::of(vertex, points, tol, axis);
    let mut best: Option<([Vec2; 3], f64)> = None;
    let mut best_mirrored: Option<([Vec2; 3], f64)> = None;
    let mut consider = |t: [Vec2; 3]| {
        let t = orient(t);
        let a = area(&t);
        if a <= tol * tol || !contains_all(&t, points, tol) {
            return;
        }
        if best.is_none_or(|(_, b)| a < b * (1.0 - 1e-12)) {
            best = Some((t, a));
        }
        if mirror.is_some_and(|m| m.maps_onto_itself(vertex, &t, tol))
            && best_mirrored.is_none_or(|(_, b)| a < b * (1.0 - 1e-12))
        {
            best_mirrored = Some((t, a));
        }
    };
    // About a diagonal line the hull lines may give no symmetric candidate.
    if let (None, Some(a)) = (required, mirror.and_then(Mirror::diagonal_direction)) {
        for t in isosceles_candidates(vertex, a, points) {
            consider(t);
        }
    }
    let n = lines.len();
    for i in 0..n {
        for j in i + 1..n {
            if allowed(&[i, j]) {
                if let Some(t) = wedge_candidate(&lines[i], &lines[j], None, points) {
                    consider(t);
                }
            }
            for k in j + 1..n {
                if allowed(&[i, j, k]) {
                    if let Some(t) = triple_candidate([&lines[i], &lines[j], &lines[k]], tol) {
                        consider(t);
                    }
                }
            }
        }
    }
    best_mirrored.or(best).map(|(t, _)| t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_interior_points() {
        let pts = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.5, 0.5),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(0.5, 0.0),
        ];
        let h = convex_hull(&pts);
        assert_eq!(h.len(), 4);
        for k in 0..4 {
            assert!(cross(h[(k + 1) % 4] - h[k], h[(k + 2) % 4] - h[(k + 1) % 4]) > 0.0);
        }
    }

    /// Smallest barycentric coordinate of the points in `t`.
    fn margin(t: &[Vec2; 3], points: &[Vec2]) -> f64 {
        points
            .iter()
            .flat_map(|p| crate::mesh::barycentric(t[0], t[1], t[2], *p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Number of corners of `t` on the line of `h`.
    fn on_line(t: &[Vec2; 3], h: &HalfPlane) -> usize {
        t.iter()
            .filter(|q| (h.n.dot(q) - h.c).abs() < 1e-15)
            .count()
    }

    #[test]
    fn control_triangle_of_a_regular_hexagon_contains_it() {
        let pts: Vec<Vec2> = (0..6)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 6.0;
                Vec2::new(a.cos(), a.sin())
            })
            .chain([Vec2::zeros()])
            .collect();
        let t = control_triangle(Vec2::zeros(), &pts, VertexKind::Interior).unwrap();
        // Strictly inside, by the margin: the hexagon's corners touching the edges
        // are at distance 1e-11 × (distance of the centre to the edge, 1).
        let m = margin(&t, &pts);
        assert!(m > 0.0 && m < 1e-10, "margin {m:e}");
        // The smallest triangle around a regular hexagon has 1.5× its area.
        let hex = 1.5 * 3f64.sqrt();
        assert!((area(&t) - 1.5 * hex).abs() < 1e-9, "area {}", area(&t));
    }

    /// The PS points of a valence-8 vertex of the `four-triangles` grid (unit
    /// blocks, incentre split): a regular octagon, whose eight smallest triangles
    /// tie. Two of them are symmetric about the vertical through the vertex; the
    /// choice is one of those.
    #[test]
    fn a_mirror_symmetric_point_set_gets_a_mirror_symmetric_triangle() {
        let v = Vec2::new(2.0, 1.0);
        // The incentre of the triangle (0, 0), (1, 0), (½, ½), halfway to the vertex.
        let r = Vec2::new(0.25, 0.25 * (2f64.sqrt() - 1.0)).norm();
        let mut pts = vec![v];
        for k in 0..8 {
            let a = std::f64::consts::FRAC_PI_4 * k as f64;
            // Edge points at ¼ along the axes and ⅛ along the diagonals (the block
            // centres at ½), the triangles' points between them.
            let e = if k % 2 == 0 {
                0.25
            } else {
                0.125 * 2f64.sqrt()
            };
            pts.push(v + e * Vec2::new(a.cos(), a.sin()));
            let b = a + std::f64::consts::FRAC_PI_8;
            pts.push(v + r * Vec2::new(b.cos(), b.sin()));
        }
        let t = control_triangle(v, &pts, VertexKind::Interior).unwrap();
        for q in &t {
            let image = Vec2::new(2.0 * v.x - q.x, q.y);
            assert!(
                t.iter().any(|p| (p - image).norm() < 1e-12),
                "{t:?} not symmetric"
            );
        }
        assert!(margin(&t, &pts) > 0.0);
        // As small as the smallest candidate of all (a regular octagon's smallest
        // triangle, flush with edges 0, 3 and 5 of the eight).
        let octagon =
            8.0 * r * r * std::f64::consts::FRAC_PI_8.sin() * std::f64::consts::FRAC_PI_8.cos();
        let smallest = {
            let tol = tolerance(v, &pts);
            let hull = convex_hull(&pts);
            let lines: Vec<HalfPlane> = (0..hull.len())
                .map(|k| HalfPlane::left_of(hull[k], hull[(k + 1) % hull.len()]))
                .collect();
            let mut best = f64::INFINITY;
            for i in 0..lines.len() {
                for j in i + 1..lines.len() {
                    for k in j + 1..lines.len() {
                        if let Some(c) = triple_candidate([&lines[i], &lines[j], &lines[k]], tol) {
                            let c = orient(c);
                            if contains_all(&c, &pts, tol) {
                                best = best.min(area(&c));
                            }
                        }
                    }
                }
            }
            best
        };
        assert!(smallest > octagon);
        assert!(
            (area(&t) / smallest - 1.0).abs() < 1e-9,
            "{} {smallest}",
            area(&t)
        );
    }

    #[test]
    fn the_choice_does_not_depend_on_the_order_of_the_points() {
        let mut pts: Vec<Vec2> = [
            (0.0, 0.0),
            (0.4, 0.1),
            (0.1, 0.5),
            (-0.3, 0.2),
            (-0.2, -0.4),
            (0.3, -0.3),
            (0.45, -0.05),
        ]
        .map(|(x, y)| Vec2::new(x, y))
        .to_vec();
        let t = control_triangle(Vec2::zeros(), &pts, VertexKind::Interior).unwrap();
        assert!(margin(&t, &pts) > 0.0);
        pts.reverse();
        pts.swap(1, 4);
        assert_eq!(
            control_triangle(Vec2::zeros(), &pts, VertexKind::Interior),
            Some(t)
        );
    }

    #[test]
    fn straight_boundary_gives_an_edge_on_the_boundary_line() {
        // Boundary along the x-axis, domain above: the PS points of a boundary vertex.
        let pts: Vec<Vec2> = [
            (0.0, 0.0),
            (0.5, 0.0),
            (-0.4, 0.0),
            (0.35, 0.3),
            (-0.1, 0.45),
            (-0.35, 0.2),
            (0.1, 0.4),
        ]
        .map(|(x, y)| Vec2::new(x, y))
        .to_vec();
        let h = HalfPlane::left_of(Vec2::zeros(), Vec2::new(1.0, 0.0));
        let t = control_triangle(Vec2::zeros(), &pts, VertexKind::Straight(h)).unwrap();
        assert_eq!(on_line(&t, &h), 2);
        assert!(margin(&t, &pts) > -1e-15);
        // Never smaller than the unconstrained choice.
        let free = control_triangle(Vec2::zeros(), &pts, VertexKind::Interior).unwrap();
        assert!(area(&t) >= area(&free) * (1.0 - 1e-12));
    }

    #[test]
    fn convex_corner_gets_its_apex_at_the_vertex() {
        // Right-angled corner at the origin, domain in the first quadrant.
        let (a, b) = (Vec2::new(0.0, 1.0), Vec2::new(1.0, 0.0));
        let la = HalfPlane::left_of(a, Vec2::zeros());
        let lb = HalfPlane::left_of(Vec2::zeros(), b);
        let pts: Vec<Vec2> = [(0.0, 0.0), (0.0, 0.4), (0.5, 0.0), (0.3, 0.25), (0.1, 0.3)]
            .map(|(x, y)| Vec2::new(x, y))
            .to_vec();
        let t = control_triangle(Vec2::zeros(), &pts, VertexKind::Corner(la, lb)).unwrap();
        assert_eq!(t[0], Vec2::zeros());
        assert_eq!((on_line(&t, &la), on_line(&t, &lb)), (2, 2));
        assert!(area(&t) > 0.0 && margin(&t, &pts) > -1e-15);
        // The cut is orthogonal to the bisector: an isosceles right triangle.
        assert!(((t[1] - t[0]).norm() - (t[2] - t[0]).norm()).abs() < 1e-14);
    }

    #[test]
    fn nearly_flat_convex_corner_falls_back_to_one_boundary_line() {
        // Interior angle 176°: the apex wedge would be ~30 times too large.
        let turn = 4f64.to_radians();
        let a = Vec2::new(-1.0, (turn / 2.0).tan());
        let b = Vec2::new(1.0, (turn / 2.0).tan());
        let la = HalfPlane::left_of(a, Vec2::zeros());
        let lb = HalfPlane::left_of(Vec2::zeros(), b);
        let pts: Vec<Vec2> = [
            Vec2::zeros(),
            a * 0.3,
            b * 0.25,
            Vec2::new(0.1, 0.3),
            Vec2::new(-0.15, 0.25),
        ]
        .to_vec();
        let t = control_triangle(Vec2::zeros(), &pts, VertexKind::Corner(la, lb)).unwrap();
        let wedge = corner_candidate(Vec2::zeros(), &pts, &la, &lb).unwrap();
        assert!(area(&wedge) > CORNER_AREA_RATIO * area(&t));
        assert_ne!(t[0], Vec2::zeros());
        assert!(on_line(&t, &la) == 2 || on_line(&t, &lb) == 2);
        assert!(margin(&t, &pts) > -1e-15);
    }
}
