//! Piecewise-linear Lagrange basis in 1D (PL 1D): one hat function per node.

use super::{Basis, BasisError, BasisEval, Constraint, Point, Quadratic};
use crate::mesh::Mesh1d;
use crate::scalar::Real;
use nalgebra::Vector1;

/// The 1D hat functions on a [`Mesh1d`]: on `[x_e, x_{e+1}]`,
/// `phi_e = (x_{e+1} − x)/h_e` and `phi_{e+1} = (x − x_e)/h_e`. C⁰, with derivative
/// jumps at the nodes.
#[derive(Debug, Clone)]
pub struct Linear1d<T: Real = f64> {
    mesh: Mesh1d,
    nodes: Vec<T>,
    element_functions: Vec<[usize; 2]>,
    support: Vec<Vec<usize>>,
}

impl<T: Real> Linear1d<T> {
    /// Builds the basis on `mesh`.
    pub fn new(mesh: Mesh1d) -> Self {
        let n = mesh.num_elements();
        let support = (0..=n)
            .map(|i| (i.saturating_sub(1)..(i + 1).min(n)).collect())
            .collect();
        Linear1d {
            nodes: mesh.nodes().iter().map(|&x| T::of(x)).collect(),
            element_functions: (0..n).map(|e| [e, e + 1]).collect(),
            support,
            mesh,
        }
    }
    /// The mesh.
    pub fn mesh(&self) -> &Mesh1d {
        &self.mesh
    }
}

impl<T: Real> Basis<T, 1> for Linear1d<T> {
    fn name(&self) -> &'static str {
        "pl1d"
    }
    fn num_functions(&self) -> usize {
        self.nodes.len()
    }
    fn num_elements(&self) -> usize {
        self.nodes.len() - 1
    }
    fn max_functions_per_element(&self) -> usize {
        2
    }
    fn locate(&self, x: &Point<T, 1>, hint: Option<usize>) -> Option<usize> {
        self.mesh.locate(x.x.to_f64(), hint)
    }
    fn other_elements_at(&self, element: usize, x: &Point<T, 1>, visit: &mut dyn FnMut(usize)) {
        if let Some(e) = self.mesh.other_element_at(element, x.x.to_f64()) {
            visit(e)
        }
    }
    #[inline]
    fn eval(&self, element: usize, x: &Point<T, 1>, out: &mut BasisEval<T, 1>) {
        let (a, b) = (self.nodes[element], self.nodes[element + 1]);
        let inv_h = T::one() / (b - a);
        out.index[0] = element;
        out.index[1] = element + 1;
        out.phi[0] = (b - x.x) * inv_h;
        out.phi[1] = (x.x - a) * inv_h;
        out.grad_phi[0] = Vector1::new(-inv_h);
        out.grad_phi[1] = Vector1::new(inv_h);
        out.set_len(2);
    }
    fn element_functions(&self, element: usize) -> &[usize] {
        &self.element_functions[element]
    }
    fn function_support(&self, function: usize) -> &[usize] {
        &self.support[function]
    }
    fn function_point(&self, function: usize) -> Point<f64, 1> {
        Vector1::new(self.mesh.nodes()[function])
    }
    fn boundary_tags(&self) -> Vec<String> {
        self.mesh.tags().map(String::from).to_vec()
    }
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, 1>,
    ) -> Result<Vec<Constraint<T, 1>>, BasisError> {
        end_constraint(tag, direction, self.nodes.len() - 1)
    }
    fn polynomial_pieces(&self, element: usize, out: &mut Vec<Point<f64, 1>>) {
        let (a, b) = self.mesh.element(element);
        out.push(Vector1::new(a));
        out.push(Vector1::new(b));
    }
    fn degree(&self) -> usize {
        1
    }
    /// `λ_i(p) = p(x_i)`, the nodal value (a linear `p`).
    fn dual_value(&self, function: usize, p: &Quadratic<1>) -> Option<f64> {
        Some(p.value(&Vector1::new(self.mesh.nodes()[function])))
    }
}

/// The homogeneous Dirichlet constraint at an end of a 1D basis whose only function
/// non-zero at `left` is the first and at `right` is `last` (both equal to one there).
pub(crate) fn end_constraint<T: Real>(
    tag: &str,
    direction: &Point<T, 1>,
    last: usize,
) -> Result<Vec<Constraint<T, 1>>, BasisError> {
    let f = match tag {
        "left" => 0,
        "right" => last,
        _ => {
            return Err(crate::mesh::MeshError::UnknownTag {
                tag: tag.into(),
                known: vec!["left".into(), "right".into()],
            }
            .into())
        }
    };
    Ok(vec![Constraint {
        direction: *direction,
        terms: vec![(f, T::one())],
    }])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::suite::{Claims, Continuity, Subject};

    /// PL 1D in the property suite ([`crate::check::suite`]): C⁰, linear.
    impl Subject<1> for Linear1d<f64> {
        type Mesh = Mesh1d;
        const CLAIMS: Claims = Claims {
            partition_of_unity: 1e-14,
            negative: 1e-15,
            linear: 1e-13,
            linear_per_size: 0.0,
            per_conditioning: 0.0,
            linear_gradient: 1e-13,
            quadratic: None,
            gradient: 1e-8,
            value_jump: 1e-14,
            continuity: Continuity::C0 {
                gradient_jump_above: 0.5,
            },
            dirichlet: 1e-14,
        };
        fn build(mesh: Mesh1d) -> Self {
            Linear1d::new(mesh)
        }
    }
}
