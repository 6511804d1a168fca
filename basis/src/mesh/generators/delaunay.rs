//! Delaunay triangulation of an arbitrary point set (spade), the building block of
//! the lattice and block Delaunay generators.

use super::{MeshError, TriMesh, Vec2};
use spade::{DelaunayTriangulation, Point2, Triangulation};

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
            "point {i} = {} is not finite",
            super::polygon::point(points[i])
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators::tests::invalid_message;
    use crate::rng::SplitMix64;

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
}
