//! Delaunay triangulations of square vertex lattices, regular or randomly jittered
//! (with a seeded [`SplitMix64`]).

use super::delaunay::delaunay;
use super::{block_corners, check_box, check_counts, finish_box};
use super::{MeshError, TriMesh, Vec2};
use crate::rng::SplitMix64;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators::tests::{assert_box_tags, invalid_message, tag_count, total_area};

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
}
