//! Facts of a basis that the stabilised strategies use, computed once per mesh:
//! the integral of each function (to measure how much of its support the
//! particles cover), which functions share an element (neighbours), and the
//! coefficients of the low-degree polynomials in the basis (the dual values
//! `λ_i(p)` with `p = Σ_i λ_i(p) phi_i`), from which extension weights are built.
//!
//! The coefficients come from an L² projection with exact quadrature on every
//! polynomial piece: a polynomial the basis reproduces is projected exactly, so
//! `λ_i(p)` are its spline coefficients up to round-off.

use crate::sparse::{Scalar, SparseCholesky, SymmetricPattern};
use nalgebra::SVector;
use psmpm_basis::quadrature::{GaussLegendre, TriangleRule};
use psmpm_basis::{Basis, BasisEval, Quadratic};

/// Per-function facts of a basis on its mesh.
#[derive(Debug, Clone, Default)]
pub struct SupportFacts {
    /// `∫ phi_i dΩ`.
    pub volume: Vec<f64>,
    /// Neighbours of `i` (functions sharing an element with it, `i` excluded):
    /// `neighbours[neighbour_ptr[i]..neighbour_ptr[i + 1]]`, ascending.
    pub neighbour_ptr: Vec<usize>,
    /// See [`neighbour_ptr`](Self::neighbour_ptr); 32-bit (the driver refuses a
    /// basis of 2³¹ functions or more).
    pub neighbours: Vec<u32>,
    /// Dimension of the mesh.
    pub dim: usize,
    /// Degree of the polynomials the basis reproduces (0 when not computed).
    pub degree: usize,
    /// Exponents of the monomials `ξ^a η^b` of degree ≤ [`degree`](Self::degree),
    /// in normalised coordinates `ξ = (x − origin) / scale`.
    pub exponents: Vec<[usize; 2]>,
    /// `λ_i(m_β)` at `coefficients[i · exponents.len() + β]`.
    pub coefficients: Vec<f64>,
    /// Function points `X_i` in normalised coordinates.
    pub points: Vec<[f64; 2]>,
    /// Lower corner of the mesh's bounding box.
    pub origin: [f64; 2],
    /// Largest side of the mesh's bounding box.
    pub scale: f64,
}

impl SupportFacts {
    /// The integrals and neighbours of `basis`; with `polynomials`, also the
    /// polynomial coefficients.
    ///
    /// The coefficients are the basis's closed forms ([`Basis::dual_value`]) where
    /// it has them (every basis of psmpm-basis), else an L² projection: on a PS
    /// mesh of 200² blocks the projection (a Gram matrix of 241 203 functions and
    /// its factorisation) took 4 of the 6.4 s of the set-up.
    pub fn new<T: Scalar, const D: usize, B: Basis<T, D> + ?Sized>(
        basis: &B,
        pattern: &SymmetricPattern,
        polynomials: bool,
    ) -> Self {
        Self::with_closed_forms(basis, pattern, polynomials, true)
    }

    /// [`SupportFacts::new`], with `closed_forms = false` projecting whatever the
    /// basis offers (to check the one against the other).
    fn with_closed_forms<T: Scalar, const D: usize, B: Basis<T, D> + ?Sized>(
        basis: &B,
        pattern: &SymmetricPattern,
        polynomials: bool,
        closed_forms: bool,
    ) -> Self {
        let n = basis.num_functions();
        // Neighbours from the element lists.
        let mut lists: Vec<Vec<usize>> = vec![Vec::new(); n];
        for e in 0..basis.num_elements() {
            let f = basis.element_functions(e);
            for &i in f {
                lists[i].extend(f.iter().copied().filter(|&j| j != i));
            }
        }
        let mut neighbour_ptr = Vec::with_capacity(n + 1);
        neighbour_ptr.push(0);
        for list in &mut lists {
            list.sort_unstable();
            list.dedup();
        }
        let mut neighbours = Vec::with_capacity(lists.iter().map(Vec::len).sum());
        for list in &lists {
            neighbours
                .extend(list.iter().map(|&j| {
                    u32::try_from(j).expect("the driver bounds the functions below 2³¹")
                }));
            neighbour_ptr.push(neighbours.len());
        }
        drop(lists);
        // Bounding box of the function points, for normalised coordinates.
        let points_raw: Vec<SVector<f64, D>> = (0..n).map(|i| basis.function_point(i)).collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &points_raw {
            for k in 0..D {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let mut origin = [0.0; 2];
        origin[..D].copy_from_slice(&lo[..D]);
        let scale = (0..D)
            .map(|k| hi[k] - lo[k])
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let normalise = |x: &SVector<f64, D>| {
            let mut xi = [0.0; 2];
            for k in 0..D {
                xi[k] = (x[k] - origin[k]) / scale;
            }
            xi
        };
        let points = points_raw.iter().map(normalise).collect();
        let degree = if polynomials { basis.degree() } else { 0 };
        let exponents = monomial_exponents(D, degree);
        let nm = exponents.len();
        // The bases' closed forms where every function has one (every basis of
        // psmpm-basis): no Gram matrix, no factorisation.
        let mut coefficients = Vec::new();
        if polynomials && closed_forms {
            let monomials: Vec<Quadratic<D>> = exponents
                .iter()
                .map(|ex| monomial_polynomial(ex, &origin, scale))
                .collect();
            coefficients = Vec::with_capacity(n * nm);
            'functions: for i in 0..n {
                for m in &monomials {
                    match basis.dual_value(i, m) {
                        Some(c) => coefficients.push(c),
                        None => {
                            coefficients.clear();
                            break 'functions;
                        }
                    }
                }
            }
        }
        let project = polynomials && coefficients.is_empty();
        // The integrals, and where a basis gives no closed form the Gram matrix
        // and right-hand sides `∫ phi_i m_β` of the L² projection.
        let mut gram = vec![T::zero(); if project { pattern.nnz() } else { 0 }];
        let mut rhs = vec![T::zero(); if project { n * nm } else { 0 }];
        let mut volume = vec![0.0; n];
        let mut eval = BasisEval::for_basis(basis);
        let rule = if project { 2 } else { 1 } * basis.degree().max(1);
        for_each_quadrature_point(basis, rule, |e, x, w| {
            let xt = SVector::<T, D>::from_fn(|k, _| T::of(x[k]));
            basis.eval(e, &xt, &mut eval);
            let m = eval.len();
            let xi = normalise(&x);
            let scatter = pattern.element_scatter(e);
            for a in 0..m {
                let (i, phi) = (eval.index[a], eval.phi[a].to_f64());
                volume[i] += w * phi;
                if !project {
                    continue;
                }
                for b in a..m {
                    gram[scatter[a * m + b] as usize] += T::of(w * phi * eval.phi[b].to_f64());
                }
                for (beta, ex) in exponents.iter().enumerate() {
                    rhs[beta * n + i] += T::of(w * phi * monomial(ex, &xi));
                }
            }
        });
        if project {
            let mut solver = SparseCholesky::new(pattern, nm);
            // A Gram matrix of a basis on its whole mesh is positive definite.
            if solver.factorize(&gram).is_ok() {
                solver.solve_in_place(&mut rhs, nm);
                coefficients = vec![0.0; n * nm];
                for i in 0..n {
                    for beta in 0..nm {
                        coefficients[i * nm + beta] = rhs[beta * n + i].to_f64();
                    }
                }
            }
        }
        let degree = if coefficients.is_empty() { 0 } else { degree };
        SupportFacts {
            volume,
            neighbour_ptr,
            neighbours,
            dim: D,
            degree,
            exponents: if coefficients.is_empty() {
                Vec::new()
            } else {
                exponents
            },
            coefficients,
            points,
            origin,
            scale,
        }
    }

    /// The neighbours of function `i`.
    pub fn neighbours_of(&self, i: usize) -> &[u32] {
        &self.neighbours[self.neighbour_ptr[i]..self.neighbour_ptr[i + 1]]
    }

    /// Coverage of a function: `Σ_p V_p phi_i(x_p) / ∫ phi_i` (0 for a function
    /// without support volume).
    pub fn coverage_of(particle_volume: f64, support_volume: f64) -> f64 {
        if support_volume > 0.0 {
            particle_volume / support_volume
        } else {
            0.0
        }
    }
}

/// Exponents `(a, b)` of the monomials `ξ^a η^b` with `a + b ≤ degree` (`b = 0` in 1D),
/// by total degree.
pub fn monomial_exponents(dim: usize, degree: usize) -> Vec<[usize; 2]> {
    let mut out = Vec::new();
    for total in 0..=degree {
        if dim == 1 {
            out.push([total, 0]);
        } else {
            for b in 0..=total {
                out.push([total - b, b]);
            }
        }
    }
    out
}

/// `ξ^a η^b`.
pub fn monomial(exponent: &[usize; 2], xi: &[f64; 2]) -> f64 {
    xi[0].powi(exponent[0] as i32) * xi[1].powi(exponent[1] as i32)
}

/// The monomial `ξ^a η^b` of degree at most two in the normalised coordinates
/// `ξ = (x − origin) / scale` as a polynomial in `x` about `origin`.
fn monomial_polynomial<const D: usize>(
    exponent: &[usize; 2],
    origin: &[f64; 2],
    scale: f64,
) -> Quadratic<D> {
    let mut q = Quadratic {
        centre: SVector::<f64, D>::from_fn(|k, _| origin[k]),
        c: 0.0,
        g: SVector::zeros(),
        a: nalgebra::SMatrix::zeros(),
    };
    // The axes the monomial's factors run along (`[1, 1]`: ξ η).
    let axes: Vec<usize> = (0..2)
        .flat_map(|k| std::iter::repeat_n(k, exponent[k]))
        .collect();
    match axes[..] {
        [] => q.c = 1.0,
        [k] => q.g[k] = 1.0 / scale,
        [k, l] => {
            q.a[(k, l)] += 0.5 / (scale * scale);
            q.a[(l, k)] += 0.5 / (scale * scale);
        }
        _ => unreachable!("monomials of degree at most two"),
    }
    q
}

/// Visits every quadrature point of every polynomial piece of `basis` with a rule
/// exact for polynomials of `degree`: `visit(element, x, weight)`, the weights of
/// a piece summing to its length (1D) or area (2D).
pub fn for_each_quadrature_point<T: Scalar, const D: usize, B: Basis<T, D> + ?Sized>(
    basis: &B,
    degree: usize,
    mut visit: impl FnMut(usize, SVector<f64, D>, f64),
) {
    let line = GaussLegendre::with_degree(degree);
    let triangle = TriangleRule::with_degree(degree);
    let mut pieces: Vec<SVector<f64, D>> = Vec::with_capacity(6 * (D + 1));
    for e in 0..basis.num_elements() {
        pieces.clear();
        basis.polynomial_pieces(e, &mut pieces);
        for piece in pieces.chunks_exact(D + 1) {
            if D == 1 {
                let (a, b) = (piece[0], piece[1]);
                let length = (b - a).norm();
                for (t, w) in line.points.iter().zip(&line.weights) {
                    visit(e, a + (b - a) * *t, w * length);
                }
            } else {
                let (a, b, c) = (piece[0], piece[1], piece[2]);
                let (u, v) = (b - a, c - a);
                let area = 0.5 * (u[0] * v[1] - v[0] * u[1]).abs();
                for (bary, w) in triangle.bary.iter().zip(&triangle.weights) {
                    visit(e, a * bary[0] + b * bary[1] + c * bary[2], w * area);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    use psmpm_basis::mesh::generators::block_grid;

    /// The closed forms of the bases give the coefficients the L² projection
    /// gives, up to the projection's round-off: PS on a jittered Delaunay mesh,
    /// PL, and the 1D bases.
    #[test]
    fn closed_forms_agree_with_the_projection() {
        fn agree<const D: usize, B: Basis<f64, D>>(basis: &B, tolerance: f64) {
            let pattern = SymmetricPattern::new(basis);
            let closed = SupportFacts::with_closed_forms(basis, &pattern, true, true);
            let projected = SupportFacts::with_closed_forms(basis, &pattern, true, false);
            assert_eq!(closed.degree, basis.degree());
            assert_eq!(closed.coefficients.len(), projected.coefficients.len());
            let worst = closed
                .coefficients
                .iter()
                .zip(&projected.coefficients)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst < tolerance, "{}: {worst:e}", basis.name());
            for (a, b) in closed.volume.iter().zip(&projected.volume) {
                assert!((a - b).abs() < 1e-14 * b.abs().max(1.0), "{a} {b}");
            }
        }
        let mesh = psmpm_basis::mesh::generators::jittered_lattice_delaunay(
            5,
            4,
            (0.0, 2.0, 0.0, 1.0),
            0.3,
            7,
        )
        .unwrap();
        agree(
            &PowellSabin::<f64>::new(mesh.clone(), SplitPoint::Incentre).unwrap(),
            1e-11,
        );
        agree(&psmpm_basis::basis::linear::Linear::<f64>::new(mesh), 1e-12);
        let line = psmpm_basis::Mesh1d::uniform(0.0, 3.0, 7).unwrap();
        agree(
            &psmpm_basis::basis::bspline1d::QuadraticBSpline::<f64>::new(line.clone()),
            1e-12,
        );
        agree(
            &psmpm_basis::basis::linear1d::Linear1d::<f64>::new(line),
            1e-12,
        );
    }

    /// The coefficients reproduce every quadratic: `Σ_i λ_i(m_β) phi_i(x) = m_β(x)`
    /// at points inside the mesh, and the integrals sum to the area.
    #[test]
    fn ps_coefficients_reproduce_quadratics() {
        let ps = PowellSabin::<f64>::new(
            block_grid(0.0, 2.0, 0.0, 1.0, 3, 2).unwrap(),
            SplitPoint::Incentre,
        )
        .unwrap();
        let pattern = SymmetricPattern::new(&ps);
        let facts = SupportFacts::new(&ps, &pattern, true);
        assert_eq!(facts.degree, 2);
        assert_eq!(facts.exponents.len(), 6);
        assert!((facts.volume.iter().sum::<f64>() - 2.0).abs() < 1e-12);
        let mut eval = BasisEval::for_basis(&ps);
        for x in [[0.3, 0.2], [1.7, 0.9], [1.01, 0.5]] {
            let p = nalgebra::Vector2::new(x[0], x[1]);
            let e = ps.locate(&p, None).unwrap();
            ps.eval(e, &p, &mut eval);
            let xi = [
                (x[0] - facts.origin[0]) / facts.scale,
                (x[1] - facts.origin[1]) / facts.scale,
            ];
            for (beta, ex) in facts.exponents.iter().enumerate() {
                let s: f64 = (0..eval.len())
                    .map(|a| facts.coefficients[eval.index[a] * 6 + beta] * eval.phi[a])
                    .sum();
                assert!(
                    (s - monomial(ex, &xi)).abs() < 1e-11,
                    "{ex:?} at {x:?}: {s}"
                );
            }
        }
    }
}
