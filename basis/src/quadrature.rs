//! Gauss quadrature on intervals and triangles.
//!
//! - [`GaussLegendre`]: `n`-point Gauss–Legendre rule on `[0, 1]`, exact for
//!   polynomials of degree `2n − 1`; nodes by Newton iteration on the Legendre
//!   recurrence.
//! - [`TriangleRule`]: a collapsed (Duffy / conical-product) rule on the reference
//!   triangle, exact for polynomials of a requested total degree, in barycentric
//!   coordinates with weights summing to one (multiply by the triangle's area).

/// Gauss–Legendre rule on `[0, 1]`; weights sum to one.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussLegendre {
    /// Nodes in `(0, 1)`, increasing.
    pub points: Vec<f64>,
    /// Weights, summing to one.
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// The `n`-point rule (`n ≥ 1`), exact for degree `2n − 1`.
    ///
    /// # Panics
    /// If `n == 0`.
    pub fn new(n: usize) -> Self {
        assert!(n >= 1, "a Gauss rule needs at least one point");
        let mut points = vec![0.0; n];
        let mut weights = vec![0.0; n];
        for i in 0..n.div_ceil(2) {
            // Initial guess (Tricomi), then Newton on P_n.
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre(n, x);
                dp = d;
                let dx = p / d;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre(n, x);
            dp = if d != 0.0 { d } else { dp };
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            // Map from [-1, 1] to [0, 1].
            points[i] = 0.5 * (1.0 - x);
            points[n - 1 - i] = 0.5 * (1.0 + x);
            weights[i] = 0.5 * w;
            weights[n - 1 - i] = 0.5 * w;
        }
        GaussLegendre { points, weights }
    }

    /// The rule with the fewest points exact for polynomials of degree `degree`.
    pub fn with_degree(degree: usize) -> Self {
        Self::new(degree / 2 + 1)
    }
}

/// `(P_n(x), P_n'(x))` by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// A quadrature rule on a triangle in barycentric coordinates; weights sum to one.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleRule {
    /// Barycentric coordinates of the nodes.
    pub bary: Vec<[f64; 3]>,
    /// Weights, summing to one (the integral over a triangle of area `A` is
    /// `A Σ w_q f(x_q)`).
    pub weights: Vec<f64>,
}

impl TriangleRule {
    /// A collapsed Gauss rule exact for polynomials of total degree `degree`.
    ///
    /// With the Duffy map `(s, t) ↦ (s (1 − t), t)` from the unit square, a degree-`d`
    /// polynomial becomes degree `d` in `s` and `d + 1` in `t` (with the Jacobian
    /// `1 − t`), so Gauss–Legendre rules of those degrees in each direction are exact.
    pub fn with_degree(degree: usize) -> Self {
        let gs = GaussLegendre::with_degree(degree);
        let gt = GaussLegendre::with_degree(degree + 1);
        let mut bary = Vec::with_capacity(gs.points.len() * gt.points.len());
        let mut weights = Vec::with_capacity(bary.capacity());
        for (t, wt) in gt.points.iter().zip(&gt.weights) {
            for (s, ws) in gs.points.iter().zip(&gs.weights) {
                let (x, y) = (s * (1.0 - t), *t);
                bary.push([1.0 - x - y, x, y]);
                // Reference triangle has area 1/2; normalise weights to sum to one.
                weights.push(2.0 * ws * wt * (1.0 - t));
            }
        }
        TriangleRule { bary, weights }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// `true` for an empty rule.
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in 1..=12 {
            let g = GaussLegendre::new(n);
            for d in 0..2 * n {
                let q: f64 = g
                    .points
                    .iter()
                    .zip(&g.weights)
                    .map(|(x, w)| w * x.powi(d as i32))
                    .sum();
                let exact = 1.0 / (d as f64 + 1.0);
                assert!((q - exact).abs() < 1e-14, "n={n} d={d}: {q} vs {exact}");
            }
        }
        let g = GaussLegendre::new(2);
        assert!((g.points[0] - (0.5 - 0.5 / 3f64.sqrt())).abs() < 1e-15);
    }

    #[test]
    fn triangle_rule_is_exact_on_monomials() {
        // ∫_ref x^i y^j = i! j! / (i + j + 2)!, reference area 1/2.
        let fact = |k: usize| (1..=k).map(|v| v as f64).product::<f64>();
        for degree in [1, 2, 4, 7, 10, 14] {
            let rule = TriangleRule::with_degree(degree);
            for i in 0..=degree {
                for j in 0..=degree - i {
                    let q: f64 = rule
                        .bary
                        .iter()
                        .zip(&rule.weights)
                        .map(|(b, w)| 0.5 * w * b[1].powi(i as i32) * b[2].powi(j as i32))
                        .sum();
                    let exact = fact(i) * fact(j) / fact(i + j + 2);
                    assert!((q - exact).abs() < 1e-15, "deg {degree}, x^{i} y^{j}");
                }
            }
        }
    }
}
