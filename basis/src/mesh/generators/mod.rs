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
//!
//! One file per mesh family (`block.rs`, `delaunay.rs`, `lattice.rs`, `polygon.rs`);
//! this module holds the parameter checks they share and re-exports their public
//! items, so every generator is `psmpm_basis::mesh::generators::name`.

mod block;
mod delaunay;
mod lattice;
mod polygon;

pub use block::{block_delaunay, block_grid, two_triangle_grid, Diagonal};
pub use delaunay::delaunay;
pub use lattice::{jittered_lattice_delaunay, lattice_delaunay};
pub use polygon::{
    fewest_polygon_triangles, largest_triangle_area, polygon_mesh, NarrowGap, PolygonDomain,
    PolygonFault, PolygonPart, MAX_STEINER_POINTS, MIN_ANGLE_DEG,
};

use super::{MeshError, TriMesh, Vec2};

/// Checks that the box `[x0, x1] × [y0, y1]` is finite and not empty.
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

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn total_area(m: &TriMesh) -> f64 {
        (0..m.num_triangles()).map(|t| m.area(t)).sum()
    }

    pub(super) fn tag_count(m: &TriMesh, name: &str) -> usize {
        let id = m.tag_id(name).unwrap();
        m.edges().iter().filter(|e| e.tag == Some(id)).count()
    }

    /// Checks that every boundary edge of a box mesh is tagged with the side it lies on.
    pub(super) fn assert_box_tags(m: &TriMesh, (x0, x1, y0, y1): (f64, f64, f64, f64)) {
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

    pub(super) fn invalid_message<T: std::fmt::Debug>(r: Result<T, MeshError>) -> String {
        match r {
            Err(MeshError::InvalidParameter(m)) => m,
            other => panic!("expected InvalidParameter, got {other:?}"),
        }
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
