//! Control (PS) triangles: for each vertex `V_i`, a triangle containing all its PS
//! points (`ps-splines.md` §2, thesis §3.5.2). Containment makes the basis
//! non-negative; a smaller area conditions it better.
//!
//! Candidates are built from the lines of the convex hull of the PS points:
//! - every pair of hull lines meeting at an apex, closed by a third line orthogonal
//!   to the bisector of the wedge and pushed out to the farthest PS point;
//! - every triple of hull lines whose half-planes bound a triangle.
//!
//! The candidate of smallest area wins. On a straight stretch of boundary only
//! candidates with an edge on the boundary line are allowed; at a convex corner the
//! apex is `V_i` with edges along both boundary lines. With these choices the
//! homogeneous Dirichlet condition on a straight boundary fixes exactly the
//! coefficients of the control points on it (`ps-splines.md` §5).

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

/// The triangle cut from the wedge `{a, b}` (apex `a ∩ b`) by the line orthogonal to
/// its bisector through the farthest point. `None` if the lines are parallel or the
/// wedge is not a proper angle.
fn wedge_candidate(a: &HalfPlane, b: &HalfPlane, points: &[Vec2]) -> Option<[Vec2; 3]> {
    let apex = intersect(a, b)?;
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

/// The control triangle of a vertex at `vertex` with PS points `points`, counter-
/// clockwise; for a [`VertexKind::Corner`] the first point is the vertex itself.
/// `None` if no candidate contains the points (cannot happen on a valid mesh).
pub fn control_triangle(vertex: Vec2, points: &[Vec2], kind: VertexKind) -> Option<[Vec2; 3]> {
    let scale = points
        .iter()
        .fold(0.0f64, |m, p| m.max((p - vertex).norm()));
    let tol = 1e-9 * scale;
    let orient = |t: [Vec2; 3]| {
        if area(&t) < 0.0 {
            [t[0], t[2], t[1]]
        } else {
            t
        }
    };
    if let VertexKind::Corner(a, b) = kind {
        let t = orient(wedge_candidate(&a, &b, points)?);
        // Put the apex (the vertex) first, keeping the orientation.
        let k =
            (0..3).min_by(|&i, &j| (t[i] - vertex).norm().total_cmp(&(t[j] - vertex).norm()))?;
        let t = [t[k], t[(k + 1) % 3], t[(k + 2) % 3]];
        return contains_all(&t, points, tol).then_some(t);
    }
    let hull = convex_hull(points);
    // The hull is counter-clockwise, so the points lie left of every edge.
    let mut lines: Vec<HalfPlane> = (0..hull.len())
        .map(|k| HalfPlane::left_of(hull[k], hull[(k + 1) % hull.len()]))
        .collect();
    let required: Option<usize> = match kind {
        VertexKind::Straight(h) => {
            let found = lines
                .iter()
                .position(|l| (l.n - h.n).norm() < 1e-9 && (l.c - h.c).abs() <= tol);
            match found {
                Some(i) => Some(i),
                None => {
                    lines.push(h);
                    Some(lines.len() - 1)
                }
            }
        }
        _ => None,
    };
    let allowed = |ids: &[usize]| required.is_none_or(|r| ids.contains(&r));
    let mut best: Option<([Vec2; 3], f64)> = None;
    let mut consider = |t: [Vec2; 3]| {
        let t = orient(t);
        let a = area(&t);
        if a <= tol * tol || !contains_all(&t, points, tol) {
            return;
        }
        if best.is_none_or(|(_, b)| a < b * (1.0 - 1e-12)) {
            best = Some((t, a));
        }
    };
    let n = lines.len();
    for i in 0..n {
        for j in i + 1..n {
            if allowed(&[i, j]) {
                if let Some(t) = wedge_candidate(&lines[i], &lines[j], points) {
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
    best.map(|(t, _)| t)
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
        assert!(contains_all(&t, &pts, 1e-12));
        // The smallest triangle around a regular hexagon has 1.5× its area.
        let hex = 1.5 * 3f64.sqrt();
        assert!((area(&t) - 1.5 * hex).abs() < 1e-9, "area {}", area(&t));
    }
}
