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
use super::{Basis, BasisError, BasisEval, Constraint, Point};
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::linear1d::Linear1d;
    use proptest::prelude::*;

    /// Values and derivatives of all functions (dense) at `x` evaluated in `element`.
    fn dense<B: Basis<f64, 1>>(b: &B, element: usize, x: f64) -> (Vec<f64>, Vec<f64>) {
        let mut ev = BasisEval::for_basis(b);
        b.eval(element, &Vector1::new(x), &mut ev);
        let (mut v, mut d) = (vec![0.0; b.num_functions()], vec![0.0; b.num_functions()]);
        for (i, phi, g) in ev.iter() {
            v[i] = phi;
            d[i] = g.x;
        }
        (v, d)
    }

    /// Partition of unity, non-negativity, linear precision, FD derivatives; returns
    /// the largest derivative jump at interior nodes.
    fn check_1d<B: Basis<f64, 1>>(b: &B, nodes: &[f64]) -> f64 {
        for e in 0..nodes.len() - 1 {
            let (a, c) = (nodes[e], nodes[e + 1]);
            for s in [0.0, 0.1, 0.37, 0.5, 0.9, 1.0] {
                let x = a + (c - a) * s;
                let (v, d) = dense(b, e, x);
                assert!((v.iter().sum::<f64>() - 1.0).abs() < 1e-14);
                assert!(v.iter().all(|&p| p >= -1e-15));
                let lin: f64 = v
                    .iter()
                    .enumerate()
                    .map(|(i, p)| p * b.function_point(i).x)
                    .sum();
                assert!((lin - x).abs() < 1e-13 * (1.0 + x.abs()));
                let dlin: f64 = d
                    .iter()
                    .enumerate()
                    .map(|(i, p)| p * b.function_point(i).x)
                    .sum();
                assert!((dlin - 1.0).abs() < 1e-11);
                if (0.05..0.95).contains(&s) {
                    let h = 1e-6 * (c - a);
                    let (vp, _) = dense(b, e, x + h);
                    let (vm, _) = dense(b, e, x - h);
                    for i in 0..v.len() {
                        let fd = (vp[i] - vm[i]) / (2.0 * h);
                        assert!(
                            (fd - d[i]).abs() < 1e-6 * (1.0 + d[i].abs()),
                            "fd {fd} vs {}",
                            d[i]
                        );
                    }
                }
            }
        }
        let mut jump = 0.0f64;
        for e in 1..nodes.len() - 1 {
            let (vl, dl) = dense(b, e - 1, nodes[e]);
            let (vr, dr) = dense(b, e, nodes[e]);
            for i in 0..vl.len() {
                assert!((vl[i] - vr[i]).abs() < 1e-14, "value jump at node {e}");
                jump = jump.max((dl[i] - dr[i]).abs() * (nodes[e + 1] - nodes[e - 1]));
            }
        }
        jump
    }

    fn dirichlet_vanishes<B: Basis<f64, 1>>(b: &B, nodes: &[f64]) {
        for (tag, x) in [("left", nodes[0]), ("right", *nodes.last().unwrap())] {
            let k = b.dirichlet(tag, &Vector1::new(1.0)).unwrap();
            let mut c: Vec<f64> = (0..b.num_functions()).map(|i| 1.0 + i as f64).collect();
            for con in &k {
                c[con.terms[0].0] = 0.0;
            }
            let e = b.locate(&Vector1::new(x), None).unwrap();
            let (v, _) = dense(b, e, x);
            let field: f64 = v.iter().zip(&c).map(|(p, c)| p * c).sum();
            assert!(field.abs() < 1e-14, "{tag}: {field}");
        }
        assert!(b.dirichlet("top", &Vector1::new(1.0)).is_err());
    }

    #[test]
    fn uniform_bspline_and_pl() {
        let mesh = Mesh1d::uniform(0.0, 25.0, 8).unwrap();
        let bs = QuadraticBSpline::<f64>::new(mesh.clone());
        assert_eq!(bs.num_functions(), 10);
        assert!(check_1d(&bs, mesh.nodes()) < 1e-12, "B-spline must be C¹");
        dirichlet_vanishes(&bs, mesh.nodes());
        let pl = Linear1d::<f64>::new(mesh.clone());
        assert!(check_1d(&pl, mesh.nodes()) > 0.5, "PL derivatives jump");
        dirichlet_vanishes(&pl, mesh.nodes());
        let f32_basis = QuadraticBSpline::<f32>::new(mesh);
        let mut ev = BasisEval::for_basis(&f32_basis);
        f32_basis.eval(3, &Vector1::new(11.0f32), &mut ev);
        assert!((ev.phi[..3].iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, rng_seed: proptest::test_runner::RngSeed::Fixed(20261122), .. ProptestConfig::default() })]
        #[test]
        fn non_uniform_nodes(steps in proptest::collection::vec(0.05f64..1.0, 1..12), start in -5.0f64..5.0) {
            let mut nodes = vec![start];
            for s in &steps {
                nodes.push(nodes.last().unwrap() + s);
            }
            let mesh = Mesh1d::new(nodes.clone()).unwrap();
            let bs = QuadraticBSpline::<f64>::new(mesh.clone());
            prop_assert!(check_1d(&bs, &nodes) < 1e-11);
            dirichlet_vanishes(&bs, &nodes);
            let pl = Linear1d::<f64>::new(mesh);
            check_1d(&pl, &nodes);
            dirichlet_vanishes(&pl, &nodes);
        }
    }
}
