//! Point location: which triangle contains a point.
//!
//! Two stages. First a walk from a hint triangle (a particle's previous triangle):
//! from the current triangle step across the edge whose barycentric coordinate is
//! most negative, up to [`MAX_WALK_STEPS`] steps, which finds the answer in a few
//! steps for a particle that moved a little. If the walk leaves the mesh (a hole or a
//! concave boundary may lie between) or runs out of steps, a global search in a
//! uniform bucket grid over the triangles' bounding boxes decides. A point is inside
//! triangle `t` when all its barycentric coordinates are at least `−INSIDE_TOLERANCE`;
//! a point inside no triangle is outside the mesh, and is reported as such.
//! Everything is deterministic: ties go to the lowest triangle index in a bucket.

use super::{TriMesh, Vec2};

/// Barycentric tolerance for "inside": points within about `1e-12` relative
/// distance of a triangle count as inside it.
pub const INSIDE_TOLERANCE: f64 = 1e-12;

/// Longest walk before falling back to the global search.
pub const MAX_WALK_STEPS: usize = 64;

/// Finds the triangle containing a point (walk from a hint, then bucket grid).
#[derive(Debug, Clone, Default)]
pub struct Locator {
    origin: Vec2,
    cell: Vec2,
    nx: usize,
    ny: usize,
    /// CSR: triangles whose bounding box touches each bucket.
    offsets: Vec<usize>,
    triangles: Vec<usize>,
}

impl Locator {
    /// Builds the bucket grid for `mesh` (about one triangle per bucket).
    pub fn new(mesh: &TriMesh) -> Self {
        let (lo, hi) = mesh.bounding_box();
        let n = mesh.num_triangles().max(1) as f64;
        let extent = (hi - lo).map(|v| v.max(f64::MIN_POSITIVE));
        let aspect = extent.x / extent.y;
        let nx = ((n * aspect).sqrt().ceil() as usize).clamp(1, 4096);
        let ny = ((n / aspect).sqrt().ceil() as usize).clamp(1, 4096);
        let cell = Vec2::new(extent.x / nx as f64, extent.y / ny as f64);
        let mut locator = Locator {
            origin: lo,
            cell,
            nx,
            ny,
            offsets: Vec::new(),
            triangles: Vec::new(),
        };
        let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); nx * ny];
        for t in 0..mesh.num_triangles() {
            let p = mesh.triangle_points(t);
            let (a, b) = super::bounding_box(&p);
            let (i0, j0) = locator.bucket(a);
            let (i1, j1) = locator.bucket(b);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    buckets[j * nx + i].push(t);
                }
            }
        }
        locator.offsets.push(0);
        for b in buckets {
            locator.triangles.extend(b);
            locator.offsets.push(locator.triangles.len());
        }
        locator
    }

    /// Bucket indices of a point, clamped to the grid (points outside the bounding
    /// box go to an edge bucket, where no triangle will contain them).
    fn bucket(&self, p: Vec2) -> (usize, usize) {
        let f = |v: f64, o: f64, c: f64, n: usize| -> usize {
            let k = ((v - o) / c).floor();
            if k.is_nan() || k < 0.0 {
                0
            } else {
                (k as usize).min(n - 1)
            }
        };
        (
            f(p.x, self.origin.x, self.cell.x, self.nx),
            f(p.y, self.origin.y, self.cell.y, self.ny),
        )
    }

    /// The triangle containing `p`, or `None` when `p` is outside the mesh.
    pub fn locate(&self, mesh: &TriMesh, p: Vec2, hint: Option<usize>) -> Option<usize> {
        if !(p.x.is_finite() && p.y.is_finite()) {
            return None;
        }
        if let Some(mut t) = hint.filter(|&t| t < mesh.num_triangles()) {
            for _ in 0..MAX_WALK_STEPS {
                let l = mesh.barycentric(t, p);
                // Local edge k is opposite vertex (k + 2) % 3.
                let (k_min, l_min) = (0..3).map(|k| (k, l[k])).fold((0, f64::INFINITY), |a, b| {
                    if b.1 < a.1 {
                        b
                    } else {
                        a
                    }
                });
                if l_min >= -INSIDE_TOLERANCE {
                    return Some(t);
                }
                let edge = (k_min + 1) % 3;
                match mesh.neighbours()[t][edge] {
                    Some(n) => t = n,
                    None => break,
                }
            }
        }
        let (lo, hi) = (
            self.origin,
            self.origin + Vec2::new(self.cell.x * self.nx as f64, self.cell.y * self.ny as f64),
        );
        let margin = 1e-9 * (hi - lo).norm();
        if p.x < lo.x - margin || p.y < lo.y - margin || p.x > hi.x + margin || p.y > hi.y + margin
        {
            return None;
        }
        let (i, j) = self.bucket(p);
        let b = j * self.nx + i;
        self.triangles[self.offsets[b]..self.offsets[b + 1]]
            .iter()
            .copied()
            .find(|&t| {
                mesh.barycentric(t, p)
                    .iter()
                    .all(|&l| l >= -INSIDE_TOLERANCE)
            })
    }
}

#[cfg(test)]
mod tests {
    use crate::mesh::generators::{self, PolygonDomain, SplitMix64};
    use crate::mesh::{TriMesh, Vec2};

    fn contains(m: &TriMesh, t: usize, p: Vec2) -> bool {
        m.barycentric(t, p).iter().all(|&l| l >= -1e-12)
    }

    fn check_mesh(m: &TriMesh, outside: &[Vec2]) {
        let mut rng = SplitMix64(42);
        let far_hint = Some(m.num_triangles() - 1);
        for t in 0..m.num_triangles() {
            let [a, b, c] = m.triangle_points(t);
            let (u, v) = (rng.next_f64(), rng.next_f64());
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            // Interior point, edge midpoints and vertices.
            for p in [
                a + (b - a) * u + (c - a) * v,
                (a + b) * 0.5,
                (b + c) * 0.5,
                a,
                b,
                c,
            ] {
                for hint in [None, Some(t), Some(0), far_hint] {
                    let found = m.locate(p, hint).expect("point inside the mesh");
                    assert!(contains(m, found, p), "{p:?} not in {found}");
                }
            }
        }
        for &p in outside {
            for hint in [None, Some(0), far_hint] {
                assert_eq!(m.locate(p, hint), None, "{p:?} should be outside");
            }
        }
    }

    #[test]
    fn locates_on_every_generator() {
        let box_outside = [
            Vec2::new(-1e-9, 0.5),
            Vec2::new(1.0 + 1e-9, 0.5),
            Vec2::new(0.5, -1e-9),
            Vec2::new(0.3, 1.0 + 1e-9),
            Vec2::new(5.0, 5.0),
            Vec2::new(f64::NAN, 0.5),
        ];
        check_mesh(
            &generators::block_grid(0.0, 1.0, 0.0, 1.0, 4, 3).unwrap(),
            &box_outside,
        );
        check_mesh(
            &generators::two_triangle_grid(0.0, 1.0, 0.0, 1.0, 3, 3, generators::Diagonal::Left)
                .unwrap(),
            &box_outside,
        );
        check_mesh(
            &generators::lattice_delaunay(7, 0.0, 1.0, 0.0, 1.0).unwrap(),
            &box_outside,
        );
        check_mesh(
            &generators::jittered_lattice_delaunay(8, 6, (0.0, 1.0, 0.0, 1.0), 0.3, 9).unwrap(),
            &box_outside,
        );
        let mut domain = PolygonDomain::rectangle(0.0, 1.0, 0.0, 1.0);
        domain.holes.push((
            vec![
                Vec2::new(0.4, 0.4),
                Vec2::new(0.6, 0.4),
                Vec2::new(0.6, 0.6),
                Vec2::new(0.4, 0.6),
            ],
            "hole".into(),
        ));
        let mut outside = box_outside.to_vec();
        outside.extend([Vec2::new(0.5, 0.5), Vec2::new(0.4 + 1e-9, 0.5)]);
        check_mesh(&generators::polygon_mesh(&domain, 0.1).unwrap(), &outside);
    }
}
