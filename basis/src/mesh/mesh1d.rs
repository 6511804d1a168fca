//! Node vectors on an interval: the 1D meshes.

use super::MeshError;

/// A 1D mesh: strictly increasing nodes `x_0 < x_1 < … < x_n`; element `e` is
/// `[x_e, x_{e+1}]`. The end points carry the tags `left` and `right`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh1d {
    nodes: Vec<f64>,
}

impl Mesh1d {
    /// A mesh on the given nodes: at least two, finite, strictly increasing.
    pub fn new(nodes: Vec<f64>) -> Result<Self, MeshError> {
        if nodes.len() < 2 {
            return Err(MeshError::InvalidParameter(format!(
                "a 1D mesh needs at least 2 nodes, got {}",
                nodes.len()
            )));
        }
        for (i, x) in nodes.iter().enumerate() {
            if !x.is_finite() {
                return Err(MeshError::NonFiniteVertex { vertex: i });
            }
        }
        for i in 1..nodes.len() {
            if nodes[i] <= nodes[i - 1] {
                return Err(MeshError::InvalidParameter(format!(
                    "1D nodes must be strictly increasing: node {} ({}) ≤ node {} ({})",
                    i,
                    nodes[i],
                    i - 1,
                    nodes[i - 1]
                )));
            }
        }
        Ok(Mesh1d { nodes })
    }

    /// `n_elements` equal elements on `[x0, x1]`.
    pub fn uniform(x0: f64, x1: f64, n_elements: usize) -> Result<Self, MeshError> {
        if n_elements == 0 || x0.partial_cmp(&x1) != Some(std::cmp::Ordering::Less) {
            return Err(MeshError::InvalidParameter(format!(
                "uniform 1D mesh needs x0 < x1 and at least one element, got [{x0}, {x1}] with {n_elements}"
            )));
        }
        Self::new(
            (0..=n_elements)
                .map(|i| x0 + (x1 - x0) * i as f64 / n_elements as f64)
                .collect(),
        )
    }

    /// Nodes of the mesh.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }
    /// Number of elements.
    pub fn num_elements(&self) -> usize {
        self.nodes.len() - 1
    }
    /// End points of element `e`.
    pub fn element(&self, e: usize) -> (f64, f64) {
        (self.nodes[e], self.nodes[e + 1])
    }
    /// Boundary tags, `left` and `right`.
    pub fn tags(&self) -> [&'static str; 2] {
        ["left", "right"]
    }

    /// The element containing `x` (checking `hint` first). A node belongs to the
    /// element on its right, the last node to the last element; `None` outside.
    pub fn locate(&self, x: f64, hint: Option<usize>) -> Option<usize> {
        let n = self.num_elements();
        if !(x >= self.nodes[0] && x <= self.nodes[n]) {
            return None;
        }
        if let Some(e) = hint.filter(|&e| e < n) {
            if x >= self.nodes[e] && (x < self.nodes[e + 1] || (e == n - 1 && x <= self.nodes[n])) {
                return Some(e);
            }
        }
        // Number of nodes ≤ x, minus one.
        let k = self.nodes.partition_point(|&v| v <= x);
        Some((k - 1).min(n - 1))
    }

    /// The element other than `e` whose closure holds `x` (which lies in `e`) up
    /// to `1e-9` element lengths: the neighbour beyond the node `x` lies on, if any
    /// (the 1D [`TriMesh::other_triangles_at`](super::TriMesh::other_triangles_at)).
    pub fn other_element_at(&self, e: usize, x: f64) -> Option<usize> {
        let (a, b) = self.element(e);
        let tol = super::locate::TOUCH_TOLERANCE * (b - a);
        if x - a <= tol && e > 0 {
            Some(e - 1)
        } else if b - x <= tol && e + 1 < self.num_elements() {
            Some(e + 1)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_and_location() {
        assert!(Mesh1d::new(vec![0.0]).is_err());
        assert!(Mesh1d::new(vec![0.0, 0.0]).is_err());
        assert!(Mesh1d::new(vec![0.0, f64::NAN]).is_err());
        assert!(Mesh1d::uniform(1.0, 0.0, 3).is_err());
        let m = Mesh1d::new(vec![0.0, 0.5, 0.7, 2.0]).unwrap();
        assert_eq!(m.locate(0.0, None), Some(0));
        assert_eq!(m.locate(0.5, None), Some(1));
        assert_eq!(m.locate(0.6, Some(2)), Some(1));
        assert_eq!(m.locate(2.0, None), Some(2));
        assert_eq!(m.locate(2.0 + 1e-12, None), None);
        assert_eq!(m.locate(-1e-12, Some(0)), None);
        assert_eq!(m.locate(f64::NAN, None), None);
    }
}
