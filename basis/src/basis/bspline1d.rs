//! Quadratic B-splines in 1D on an open knot vector (thesis §2; the 1D basis of
//! B-spline MPM).
//!
//! On nodes `x_0 < … < x_n` the knot vector is
//! `t = (x_0, x_0, x_0, x_1, …, x_{n−1}, x_n, x_n, x_n)`, giving `n + 2` functions
//! `N_0 … N_{n+1}`, C¹ at every interior node, non-negative, a partition of unity.
//! Only `N_0` (`N_{n+1}`) is non-zero at `x_0` (`x_n`), where it equals one, so a
//! homogeneous Dirichlet condition fixes one coefficient. Linear precision holds with
//! the Greville abscissae `(t_{k+1} + t_{k+2}) / 2`.

use super::linear1d::end_constraint;
use super::{Basis, BasisError, BasisEval, Constraint, Point, Quadratic};
use crate::mesh::Mesh1d;
use crate::scalar::Real;
use nalgebra::Vector1;

/// Quadratic B-spline basis on a [`Mesh1d`]'s nodes as breakpoints.
#[derive(Debug, Clone)]
pub struct QuadraticBSpline<T: Real = f64> {
    mesh: Mesh1d,
    /// The open knot vector (length `n + 5`).
    knots: Vec<T>,
    greville: Vec<f64>,
    element_functions: Vec<[usize; 3]>,
    support: Vec<Vec<usize>>,
}

impl<T: Real> QuadraticBSpline<T> {
    /// Builds the basis on `mesh`.
    pub fn new(mesh: Mesh1d) -> Self {
        let x = mesh.nodes();
        let n = mesh.num_elements();
        let mut knots64 = vec![x[0], x[0]];
        knots64.extend_from_slice(x);
        knots64.extend([x[n], x[n]]);
        let greville = (0..n + 2)
            .map(|k| 0.5 * (knots64[k + 1] + knots64[k + 2]))
            .collect();
        let support = (0..n + 2)
            .map(|k| (k.saturating_sub(2)..k.min(n - 1) + 1).collect())
            .collect();
        QuadraticBSpline {
            knots: knots64.iter().map(|&v| T::of(v)).collect(),
            greville,
            element_functions: (0..n).map(|e| [e, e + 1, e + 2]).collect(),
            support,
            mesh,
        }
    }
    /// The mesh.
    pub fn mesh(&self) -> &Mesh1d {
        &self.mesh
    }
    /// The knot vector.
    pub fn knots(&self) -> &[T] {
        &self.knots
    }
}

impl<T: Real> Basis<T, 1> for QuadraticBSpline<T> {
    fn name(&self) -> &'static str {
        "bspline"
    }
    fn num_functions(&self) -> usize {
        self.mesh.num_elements() + 2
    }
    fn num_elements(&self) -> usize {
        self.mesh.num_elements()
    }
    fn max_functions_per_element(&self) -> usize {
        3
    }
    fn locate(&self, x: &Point<T, 1>, hint: Option<usize>) -> Option<usize> {
        self.mesh.locate(x.x.to_f64(), hint)
    }
    fn other_elements_at(&self, element: usize, x: &Point<T, 1>, visit: &mut dyn FnMut(usize)) {
        if let Some(e) = self.mesh.other_element_at(element, x.x.to_f64()) {
            visit(e)
        }
    }
    /// Cox–de Boor on knot span `i = e + 2` (The NURBS Book, A2.2), with
    /// `N'_{k,2} = 2/(t_{k+2} − t_k) N_{k,1} − 2/(t_{k+3} − t_{k+1}) N_{k+1,1}`.
    #[inline]
    fn eval(&self, element: usize, x: &Point<T, 1>, out: &mut BasisEval<T, 1>) {
        let t = &self.knots;
        let i = element + 2;
        let u = x.x;
        let two = T::one() + T::one();
        // Degree 1 on the span: N_{i−1,1}, N_{i,1}.
        let h = t[i + 1] - t[i];
        let n1 = [(t[i + 1] - u) / h, (u - t[i]) / h];
        // Degree 2.
        let (d0, d1) = (t[i + 1] - t[i - 1], t[i + 2] - t[i]);
        let phi = [
            (t[i + 1] - u) / d0 * n1[0],
            (u - t[i - 1]) / d0 * n1[0] + (t[i + 2] - u) / d1 * n1[1],
            (u - t[i]) / d1 * n1[1],
        ];
        let dphi = [
            -two / d0 * n1[0],
            two / d0 * n1[0] - two / d1 * n1[1],
            two / d1 * n1[1],
        ];
        for k in 0..3 {
            out.index[k] = element + k;
            out.phi[k] = phi[k];
            out.grad_phi[k] = Vector1::new(dphi[k]);
        }
        out.set_len(3);
    }
    fn element_functions(&self, element: usize) -> &[usize] {
        &self.element_functions[element]
    }
    fn function_support(&self, function: usize) -> &[usize] {
        &self.support[function]
    }
    fn function_point(&self, function: usize) -> Point<f64, 1> {
        Vector1::new(self.greville[function])
    }
    fn boundary_tags(&self) -> Vec<String> {
        self.mesh.tags().map(String::from).to_vec()
    }
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, 1>,
    ) -> Result<Vec<Constraint<T, 1>>, BasisError> {
        end_constraint(tag, direction, self.num_functions() - 1)
    }
    fn polynomial_pieces(&self, element: usize, out: &mut Vec<Point<f64, 1>>) {
        let (a, b) = self.mesh.element(element);
        out.push(Vector1::new(a));
        out.push(Vector1::new(b));
    }
    fn degree(&self) -> usize {
        2
    }
    /// The polar form (blossom) of `p` at the function's interior knots,
    /// `λ_k(p) = P(t_{k+1}, t_{k+2})` (Marsden's identity; `P(a, b) = ab` for `x²`).
    fn dual_value(&self, function: usize, p: &Quadratic<1>) -> Option<f64> {
        let t = |k: usize| Vector1::new(self.knots[k].to_f64());
        Some(p.polar(&t(function + 1), &t(function + 2)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check;
    use crate::check::suite::{Claims, Continuity, Subject};

    /// The B-spline in the property suite ([`crate::check::suite`]): C¹, quadratic
    /// precision with the polar form at the knots as coefficients.
    impl Subject<1> for QuadraticBSpline<f64> {
        type Mesh = Mesh1d;
        const CLAIMS: Claims = Claims {
            partition_of_unity: 1e-14,
            negative: 1e-15,
            linear: 1e-13,
            linear_per_size: 0.0,
            per_conditioning: 0.0,
            linear_gradient: 1e-13,
            quadratic: Some((1e-14, 1e-14)),
            gradient: 1e-8,
            value_jump: 1e-14,
            continuity: Continuity::C1 {
                gradient_jump_below: 1e-14,
            },
            dirichlet: 1e-14,
        };
        fn build(mesh: Mesh1d) -> Self {
            QuadraticBSpline::new(mesh)
        }
    }

    #[test]
    fn uniform_function_count_and_f32() {
        let mesh = Mesh1d::uniform(0.0, 25.0, 8).unwrap();
        let bs = QuadraticBSpline::<f64>::new(mesh.clone());
        assert_eq!(bs.num_functions(), 10);
        let f32_basis = QuadraticBSpline::<f32>::new(mesh);
        let mut ev = BasisEval::for_basis(&f32_basis);
        f32_basis.eval(3, &Vector1::new(11.0f32), &mut ev);
        assert!((ev.phi[..3].iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert!(check::partition_of_unity(&f32_basis) < 1e-6);
    }
}
