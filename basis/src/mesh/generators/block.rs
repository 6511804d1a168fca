//! Structured grids of rectangular blocks: the seeds' block grid (4 triangles per
//! block around its centre), two-triangle grids (one diagonal per block), and the
//! Delaunay triangulation of the block grid's vertices.

use super::delaunay::delaunay;
use super::{block_corners, check_box, check_counts, finish_box};
use super::{MeshError, TriMesh, Vec2};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators::tests::{assert_box_tags, tag_count, total_area};
    use std::collections::BTreeSet;

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
}
