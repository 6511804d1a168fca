//! The rows of the extension matrix `E`: for an under-supported function, the
//! nearest well-covered functions (rings of neighbours) and the minimum-norm
//! weights that keep the polynomials the basis reproduces.

use super::{Extended, Role, EXTENSION_RINGS, MAX_EXTENSION_TERMS, MAX_EXTENSION_WEIGHT};
use crate::sparse::Scalar;

/// The moment matrix of a ring is singular (its functions cannot reproduce the
/// polynomials) when a Cholesky pivot falls below this fraction of its largest
/// diagonal; the ring is then widened.
const SINGULAR_MOMENTS: f64 = 1e-12;

/// Largest error of the kept moments `Σ_k w_k λ_k(q_α) − λ_j(q_α)` (the local
/// monomials are of order one on the candidates), per unit of `1 + Σ_k |w_k|`:
/// a row missing it is refused as a singular ring is.
const MOMENT_RESIDUAL: f64 = 1e-9;

/// Relative slack of the weight bound [`MAX_EXTENSION_WEIGHT`]: on grids of
/// cocircular points (`layout = "delaunay"`) a weight is often exactly the bound, and
/// without the slack round-off decided, differently for a function and its mirror
/// image, whether the next ring was added: a symmetric scene lost its symmetry
/// (mirror error 2.45e-3 with the default, 3.9e-2 with `extended`; 1.8e-13 and
/// 3.6e-12 with the slack; `tests/symmetry.rs`).
const WEIGHT_BOUND_SLACK: f64 = 1e-9;

impl<T: Scalar> Extended<T> {
    /// Collects the solved functions of the next ring around the current search
    /// front into `candidates`; returns `false` when the front is exhausted.
    fn next_ring(&mut self) -> bool {
        std::mem::swap(&mut self.front, &mut self.queue);
        self.queue.clear();
        for idx in 0..self.front.len() {
            let f = self.front[idx];
            for &g in self.support.neighbours_of(f) {
                let g = g as usize;
                if self.mark[g] == self.stamp {
                    continue;
                }
                self.mark[g] = self.stamp;
                self.queue.push(g);
                if self.role[g] == Role::Solved && self.candidates.len() < MAX_EXTENSION_TERMS {
                    self.candidates.push(g);
                }
            }
        }
        !self.queue.is_empty()
    }

    /// Minimum-norm weights expressing function `j` through `candidates` with
    /// polynomial precision of the first `terms` monomials; `None` when the
    /// candidates cannot reproduce them or need too large weights.
    fn weights_for(&mut self, j: usize, terms: usize) -> Option<()> {
        let facts = &self.support;
        let nm = facts.exponents.len();
        let m = self.candidates.len();
        if m < terms {
            return None;
        }
        // Local monomials q_α = ((ξ − c) / h)^α around X_j, h the farthest candidate.
        let c = facts.points[j];
        let h = self
            .candidates
            .iter()
            .map(|&i| {
                let p = facts.points[i];
                ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt()
            })
            .fold(0.0f64, f64::max);
        if h <= 0.0 {
            return None;
        }
        // λ(q_α) = Σ_β T_αβ λ(m_β) with the binomial expansion of (ξ − c)^α / h^|α|.
        let mut t = [0.0f64; 36];
        for (a, alpha) in facts.exponents[..terms].iter().enumerate() {
            let scale = h.powi((alpha[0] + alpha[1]) as i32);
            for r0 in 0..=alpha[0] {
                for r1 in 0..=alpha[1] {
                    let beta = facts
                        .exponents
                        .iter()
                        .position(|e| *e == [r0, r1])
                        .expect("lower monomials are listed");
                    t[a * 6 + beta] += binomial(alpha[0], r0)
                        * (-c[0]).powi((alpha[0] - r0) as i32)
                        * binomial(alpha[1], r1)
                        * (-c[1]).powi((alpha[1] - r1) as i32)
                        / scale;
                }
            }
        }
        let expansion = |a: usize, coeffs: &[f64]| -> f64 {
            (0..nm).map(|beta| t[a * 6 + beta] * coeffs[beta]).sum()
        };
        // A (terms × m) row-major, target (terms).
        self.local.clear();
        for a in 0..terms {
            for &i in &self.candidates {
                self.local
                    .push(expansion(a, &facts.coefficients[i * nm..(i + 1) * nm]));
            }
        }
        let mut target = [0.0; 6];
        for (a, value) in target.iter_mut().enumerate().take(terms) {
            *value = expansion(a, &facts.coefficients[j * nm..(j + 1) * nm]);
        }
        // G = A Aᵀ, Cholesky, y = G⁻¹ t, e = Aᵀ y.
        let mut g = [0.0; 36];
        for a in 0..terms {
            for b in 0..=a {
                let s: f64 = (0..m)
                    .map(|k| self.local[a * m + k] * self.local[b * m + k])
                    .sum();
                g[a * 6 + b] = s;
            }
        }
        let max_diag = (0..terms).map(|a| g[a * 6 + a]).fold(0.0f64, f64::max);
        for a in 0..terms {
            for b in 0..=a {
                let mut s = g[a * 6 + b];
                for k in 0..b {
                    s -= g[a * 6 + k] * g[b * 6 + k];
                }
                if a == b {
                    if s.is_nan() || s <= SINGULAR_MOMENTS * max_diag {
                        return None;
                    }
                    g[a * 6 + a] = s.sqrt();
                } else {
                    g[a * 6 + b] = s / g[b * 6 + b];
                }
            }
        }
        let mut y = target;
        for a in 0..terms {
            for k in 0..a {
                y[a] -= g[a * 6 + k] * y[k];
            }
            y[a] /= g[a * 6 + a];
        }
        for a in (0..terms).rev() {
            for k in a + 1..terms {
                y[a] -= g[k * 6 + a] * y[k];
            }
            y[a] /= g[a * 6 + a];
        }
        self.weights.clear();
        for k in 0..m {
            let e: f64 = (0..terms).map(|a| self.local[a * m + k] * y[a]).sum();
            self.weights.push(e);
        }
        // The moments the weights keep, checked: a ring whose functions cannot
        // reproduce the polynomials has a singular `G` in exact arithmetic, and
        // round-off can leave its pivots just above `SINGULAR_MOMENTS` (six PS
        // functions of two vertices for the six quadratics, with the closed-form
        // dual values): weights missing the constants by 0.1 were taken, and a
        // ball in free flight lost 3e-5 of its momentum.
        let tolerance = MOMENT_RESIDUAL * (1.0 + self.weights.iter().map(|w| w.abs()).sum::<f64>());
        for (a, &goal) in target.iter().enumerate().take(terms) {
            let kept: f64 = (0..m)
                .map(|k| self.local[a * m + k] * self.weights[k])
                .sum();
            if (kept - goal).abs() > tolerance || kept.is_nan() {
                return None;
            }
        }
        let largest = self.weights.iter().fold(0.0f64, |a, w| a.max(w.abs()));
        (largest <= MAX_EXTENSION_WEIGHT * (1.0 + WEIGHT_BOUND_SLACK) && largest.is_finite())
            .then_some(())
    }

    /// Builds the row of `E` for the under-supported function `j`; returns `false`
    /// when no well-covered function can carry it.
    pub(super) fn extend(&mut self, j: usize) -> bool {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.stamp = 1;
        }
        self.mark[j] = self.stamp;
        self.queue.clear();
        self.queue.push(j);
        self.candidates.clear();
        let full = self.support.exponents.len();
        let mut found = false;
        for _ in 0..EXTENSION_RINGS {
            if !self.next_ring() && self.candidates.is_empty() {
                break;
            }
            if self.weights_for(j, full).is_some() {
                found = true;
                break;
            }
        }
        if !found {
            // Lower precision with every candidate found: linear, then (without
            // lumped rows) constant. The hybrid keeps a function that only a
            // constant can carry as an unknown with a lumped row instead
            // (`extend` fails): a body smaller than its elements has one or two
            // functions covered above `C1`, and rows of `E` through them alone
            // carry no rotation (a disk of radius 0.05 spinning at ω = 3 in
            // triangles of edge 1 stopped turning: `docs/stability.md`, "A body
            // smaller than its elements"). Without lumping such an unknown's
            // consistent row is nearly singular (`extended` then inverts an
            // element), so there the constant is kept.
            let linear = 1 + self.support.dim;
            let lower: &[usize] = if self.lumps_rows() {
                &[linear]
            } else {
                &[linear, 1]
            };
            found = lower
                .iter()
                .filter(|&&t| t < full)
                .any(|&t| self.weights_for(j, t).is_some());
        }
        if !found {
            return false;
        }
        for (k, &i) in self.candidates.iter().enumerate() {
            self.ext_idx.push(i);
            self.ext_w.push(T::of(self.weights[k]));
        }
        true
    }
}

fn binomial(n: usize, k: usize) -> f64 {
    match (n, k) {
        (_, 0) => 1.0,
        (n, k) if k == n => 1.0,
        (2, 1) => 2.0,
        (n, k) => (1..=k).fold(1.0, |acc, i| acc * (n + 1 - i) as f64 / i as f64),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::{MassSetup, MassStrategy, SupportFacts};
    use crate::sparse::SymmetricPattern;
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    use psmpm_basis::mesh::generators::{polygon_mesh, PolygonDomain};
    use psmpm_basis::Basis;

    /// The six PS functions of two vertices cannot reproduce the quadratics (on
    /// the line through the vertices their dual values are four functionals of a
    /// quadratic of three coefficients): for every function of a third vertex
    /// and every pair of vertices of its support, no quadratic weights are
    /// given, although round-off leaves some such `G` with pivots above the
    /// singular threshold; the constants and lines, which they can reproduce,
    /// are kept exactly.
    #[test]
    fn a_ring_that_cannot_reproduce_the_quadratics_gives_no_quadratic_weights() {
        let domain = PolygonDomain::rectangle(0.0, 4.0, 0.0, 3.0);
        let ps = PowellSabin::<f64>::new(polygon_mesh(&domain, 0.2).unwrap(), SplitPoint::Incentre)
            .unwrap();
        let pattern = SymmetricPattern::new(&ps);
        let facts = std::sync::Arc::new(SupportFacts::new(&ps, &pattern, true));
        let mut extended = Extended::<f64>::new(0.5);
        let fixed = vec![vec![false; ps.num_functions()]; 2];
        extended.prepare(&MassSetup {
            pattern: &pattern,
            fixed: &fixed,
            support: Some(&facts),
        });
        let (mut tried, mut linear) = (0, 0);
        for j in (0..ps.num_functions()).step_by(7) {
            let mut vertices: Vec<usize> = facts
                .neighbours_of(j)
                .iter()
                .map(|&g| g as usize / 3)
                .collect();
            vertices.dedup();
            vertices.retain(|&v| v != j / 3);
            for pair in vertices.windows(2) {
                extended.candidates.clear();
                extended
                    .candidates
                    .extend((0..6).map(|k| 3 * pair[k / 3] + k % 3));
                tried += 1;
                assert!(
                    extended.weights_for(j, 6).is_none(),
                    "function {j}, vertices {pair:?}"
                );
                if extended.weights_for(j, 3).is_some() {
                    linear += 1;
                    let sum: f64 = extended.weights.iter().sum();
                    assert!(
                        (sum - 1.0).abs() < 1e-9,
                        "function {j}: weights sum to {sum}"
                    );
                }
            }
        }
        assert!(
            tried > 500 && linear > tried / 2,
            "{tried} pairs, {linear} linear"
        );
    }
}
