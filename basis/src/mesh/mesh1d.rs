//! Node vectors on an interval: the 1D meshes.

/// A 1D mesh: strictly increasing nodes `x_0 < x_1 < … < x_n`; element `e` is `[x_e, x_{e+1}]`.
/// The end points carry the tags `left` and `right`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh1d {
    nodes: Vec<f64>,
}

impl Mesh1d {
    /// Nodes of the mesh.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }
}
