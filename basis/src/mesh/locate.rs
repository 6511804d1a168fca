//! Point location: which triangle contains a point.
//!
//! PLACEHOLDER (being replaced): brute-force search.

use super::{TriMesh, Vec2};

/// Finds the triangle containing a point.
#[derive(Debug, Clone, Default)]
pub struct Locator {}

impl Locator {
    /// Builds the locator for `mesh`.
    pub fn new(_mesh: &TriMesh) -> Self {
        Locator {}
    }
    /// The triangle containing `p`, or `None` outside the mesh.
    pub fn locate(&self, mesh: &TriMesh, p: Vec2, _hint: Option<usize>) -> Option<usize> {
        (0..mesh.num_triangles()).find(|&t| mesh.barycentric(t, p).iter().all(|&l| l >= -1e-12))
    }
}
