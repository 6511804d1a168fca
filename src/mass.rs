//! Mass strategies: how the system `M a = F` (paper eq. (17)) and the velocity
//! projection `M v̂ = P` (eq. (20)) are solved.
//!
//! A strategy is prepared once per mesh ([`MassStrategy::prepare`]: symbolic work),
//! factorises the assembled mass matrix once per step ([`MassStrategy::factorize`]:
//! numeric work, reused by both solves of the step), and solves one velocity
//! component at a time ([`MassStrategy::solve`]). Homogeneous Dirichlet conditions
//! come as a set of fixed coefficients per component: their rows and columns are
//! replaced by a diagonal entry, so the constrained system is solved exactly.
//! Functions with no particle in their support have an all-zero row; they are
//! decoupled the same way without changing the pattern.
//!
//! | [`MassKind`] | what is solved |
//! |---|---|
//! | `Consistent` | `M` itself, sparse Cholesky |
//! | `Lumped` | row sums `M_ii^L = Σ_j M_ij` |
//! | `Partial(rule)` | `M` with the rows chosen by `rule` lumped (thesis §5.3) |
//! | `Deactivate { threshold }` | `M` without the functions with `M_ii < threshold` (thesis §5.2) |
//!
//! Partial lumping moves every off-diagonal entry `M_ij` that touches a lumped row
//! onto both diagonals `M_ii` and `M_jj`: `M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ`.
//! Every row sum is kept, so total mass and momentum are conserved, and since
//! `M_ij ≥ 0` (non-negative bases) `M' ⪰ M` stays symmetric positive definite.
//! What a strategy did is returned as a [`MassReport`], never printed.

use crate::sparse::{NotPositiveDefinite, Scalar, SparseCholesky, SymmetricPattern};

/// Which rows a partially lumped strategy lumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LumpRule {
    /// The seeds' rule: rows whose function's support contains an element without
    /// particles (thesis §5.3).
    EmptyElement,
    /// Rows with `M_ii < threshold · max_j M_jj`.
    Threshold(f64),
}

/// How the mass systems are solved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassKind {
    /// Consistent mass matrix, sparse Cholesky.
    Consistent,
    /// Row-sum lumped mass.
    Lumped,
    /// Consistent with some rows lumped.
    Partial(LumpRule),
    /// Consistent without the functions whose `M_ii` is below `threshold`.
    Deactivate {
        /// Absolute threshold on `M_ii` (the thesis uses 1e-2).
        threshold: f64,
    },
}

impl MassKind {
    /// Parses `consistent`, `lumped`, `partial` (seed rule), `partial:TAU`
    /// (threshold rule), `deactivate` (threshold 1e-2) or `deactivate:THRESHOLD`.
    pub fn parse(name: &str) -> Result<Self, String> {
        let (head, arg) = match name.split_once(':') {
            Some((h, a)) => (h, Some(a)),
            None => (name, None),
        };
        let number = |a: &str| -> Result<f64, String> {
            a.parse::<f64>()
                .ok()
                .filter(|v| *v > 0.0 && v.is_finite())
                .ok_or_else(|| {
                    format!("`{name}`: the threshold must be a positive number, got `{a}`")
                })
        };
        match (head, arg) {
            ("consistent", None) => Ok(MassKind::Consistent),
            ("lumped", None) => Ok(MassKind::Lumped),
            ("partial", None) => Ok(MassKind::Partial(LumpRule::EmptyElement)),
            ("partial", Some(a)) => Ok(MassKind::Partial(LumpRule::Threshold(number(a)?))),
            ("deactivate", None) => Ok(MassKind::Deactivate { threshold: 1e-2 }),
            ("deactivate", Some(a)) => Ok(MassKind::Deactivate { threshold: number(a)? }),
            _ => Err(format!(
                "unknown mass strategy `{name}` (known: consistent, lumped, partial, partial:TAU, deactivate, deactivate:THRESHOLD)"
            )),
        }
    }

    /// The form [`MassKind::parse`] reads back (`partial:0.1`, `deactivate:0.01`).
    pub fn spec(self) -> String {
        match self {
            MassKind::Partial(LumpRule::Threshold(tau)) => format!("partial:{tau}"),
            MassKind::Deactivate { threshold } => format!("deactivate:{threshold}"),
            other => other.name().to_string(),
        }
    }

    /// Name for output.
    pub fn name(self) -> &'static str {
        match self {
            MassKind::Consistent => "consistent",
            MassKind::Lumped => "lumped",
            MassKind::Partial(_) => "partial",
            MassKind::Deactivate { .. } => "deactivate",
        }
    }
}

/// What a strategy did in one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MassReport {
    /// Functions with particles in their support that take part in the solve.
    pub active: usize,
    /// Rows replaced by their lumped value.
    pub lumped_rows: usize,
    /// Functions removed by deactivation.
    pub deactivated: usize,
}

/// Per-step information a strategy may use.
#[derive(Debug, Clone, Copy)]
pub struct StepContext<'a> {
    /// `touches_empty[i]`: the support of function `i` contains an element without particles.
    pub touches_empty: &'a [bool],
}

/// How to solve the mass systems of a step.
pub trait MassStrategy<T: Scalar> {
    /// Set-up once per mesh: `fixed[k][i]` says whether component `k` of coefficient
    /// `i` is held at zero by a Dirichlet condition.
    fn prepare(pattern: &SymmetricPattern, fixed: &[Vec<bool>], kind: MassKind) -> Self
    where
        Self: Sized;
    /// Numeric work for the matrix whose upper triangle has `values`
    /// (`M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)`, eq. (13)).
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, NotPositiveDefinite>;
    /// Solves component `k` in place: `rhs` becomes the coefficients, zero at fixed
    /// and inactive functions.
    fn solve(&mut self, k: usize, rhs: &mut [T]);
    /// An estimate of the spectral condition number of the systems last factorised
    /// (the largest over components): `λ_max` by 30 power iterations, `λ_min` by 30
    /// inverse iterations with the factorisation. Costs about 60 solves; call on request.
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64;
}

/// Number of power and inverse iterations of the condition estimate.
pub const CONDITION_ITERATIONS: usize = 30;

/// Consistent, partially lumped or deactivating: a sparse Cholesky solve of the
/// (modified) mass matrix, one factorisation per distinct set of fixed coefficients.
pub struct SparseMass<T: Scalar> {
    kind: MassKind,
    fixed: Vec<Vec<bool>>,
    /// `solver_of[k]`: index of the factorisation used by component `k`.
    solver_of: Vec<usize>,
    solvers: Vec<SparseCholesky<T>>,
    /// Modified values per distinct fixed set.
    modified: Vec<Vec<T>>,
    inactive: Vec<bool>,
    lumped: Vec<bool>,
    diagonal_add: Vec<T>,
    work: [Vec<T>; 2],
}

impl<T: Scalar> MassStrategy<T> for SparseMass<T> {
    fn prepare(pattern: &SymmetricPattern, fixed: &[Vec<bool>], kind: MassKind) -> Self {
        let mut distinct: Vec<&Vec<bool>> = Vec::new();
        let solver_of = fixed
            .iter()
            .map(|f| match distinct.iter().position(|d| *d == f) {
                Some(i) => i,
                None => {
                    distinct.push(f);
                    distinct.len() - 1
                }
            })
            .collect();
        let n = pattern.dim();
        SparseMass {
            kind,
            solvers: distinct
                .iter()
                .map(|_| SparseCholesky::new(pattern, 1))
                .collect(),
            modified: distinct
                .iter()
                .map(|_| vec![T::zero(); pattern.nnz()])
                .collect(),
            fixed: distinct.into_iter().cloned().collect(),
            solver_of,
            inactive: vec![false; n],
            lumped: vec![false; n],
            diagonal_add: vec![T::zero(); n],
            work: [vec![T::zero(); n], vec![T::zero(); n]],
        }
    }

    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, NotPositiveDefinite> {
        let n = pattern.dim();
        let diag = |i: usize| values[pattern.diagonal_position(i)];
        let max_diag = (0..n)
            .map(diag)
            .fold(T::zero(), |a, b| if b > a { b } else { a });
        let mut report = MassReport::default();
        let (mut scale, mut count) = (T::zero(), 0usize);
        for i in 0..n {
            let d = diag(i);
            let empty = d <= T::zero();
            let deactivated = match self.kind {
                MassKind::Deactivate { threshold } => !empty && d.to_f64() < threshold,
                _ => false,
            };
            self.inactive[i] = empty || deactivated;
            report.deactivated += deactivated as usize;
            self.lumped[i] = !self.inactive[i]
                && match self.kind {
                    MassKind::Partial(LumpRule::EmptyElement) => context.touches_empty[i],
                    MassKind::Partial(LumpRule::Threshold(tau)) => d < max_diag * T::of(tau),
                    _ => false,
                };
            report.lumped_rows += self.lumped[i] as usize;
            if !self.inactive[i] {
                report.active += 1;
                scale += d;
                count += 1;
            }
        }
        // Masked rows get the mean active diagonal: the value does not matter for the
        // solution (their right-hand side is zero) but keeps the condition estimate
        // about the active system.
        let scale = if count > 0 {
            scale / T::of(count as f64)
        } else {
            T::one()
        };
        let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
        for (s, fixed) in self.fixed.iter().enumerate() {
            let out = &mut self.modified[s];
            self.diagonal_add.iter_mut().for_each(|v| *v = T::zero());
            for c in 0..n {
                for k in ptr[c]..ptr[c + 1] {
                    let r = rows[k];
                    let masked = |i: usize| fixed[i] || self.inactive[i];
                    out[k] = if r == c {
                        if masked(r) {
                            scale
                        } else {
                            values[k]
                        }
                    } else if masked(r) || masked(c) {
                        T::zero()
                    } else if self.lumped[r] || self.lumped[c] {
                        self.diagonal_add[r] += values[k];
                        self.diagonal_add[c] += values[k];
                        T::zero()
                    } else {
                        values[k]
                    };
                }
            }
            for i in 0..n {
                out[pattern.diagonal_position(i)] += self.diagonal_add[i];
            }
            self.solvers[s].factorize(out)?;
        }
        Ok(report)
    }

    fn solve(&mut self, k: usize, rhs: &mut [T]) {
        let s = self.solver_of[k];
        for (i, r) in rhs.iter_mut().enumerate() {
            if self.fixed[s][i] || self.inactive[i] {
                *r = T::zero();
            }
        }
        self.solvers[s].solve_in_place(rhs, 1);
    }

    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        let mut worst = 0.0f64;
        for s in 0..self.solvers.len() {
            let [x, y] = &mut self.work;
            let norm = |v: &[T]| v.iter().map(|a| (*a * *a).to_f64()).sum::<f64>().sqrt();
            // λ_max: power iteration from a fixed start.
            x.iter_mut()
                .enumerate()
                .for_each(|(i, v)| *v = T::of(1.0 + (i % 7) as f64 * 0.1));
            let mut lambda_max = 0.0;
            for _ in 0..CONDITION_ITERATIONS {
                let nx = norm(x);
                x.iter_mut().for_each(|v| *v /= T::of(nx));
                pattern.mul_vec(&self.modified[s], x, y);
                lambda_max = x
                    .iter()
                    .zip(y.iter())
                    .map(|(a, b)| (*a * *b).to_f64())
                    .sum::<f64>();
                std::mem::swap(x, y);
            }
            // λ_min: inverse iteration with the factorisation.
            x.iter_mut()
                .enumerate()
                .for_each(|(i, v)| *v = T::of(1.0 + (i % 5) as f64 * 0.1));
            let mut mu = 0.0;
            for _ in 0..CONDITION_ITERATIONS {
                let nx = norm(x);
                x.iter_mut().for_each(|v| *v /= T::of(nx));
                y.copy_from_slice(x);
                self.solvers[s].solve_in_place(y, 1);
                mu = x
                    .iter()
                    .zip(y.iter())
                    .map(|(a, b)| (*a * *b).to_f64())
                    .sum::<f64>();
                std::mem::swap(x, y);
            }
            worst = worst.max(lambda_max * mu);
        }
        worst
    }
}

/// The lumped (row-sum) mass matrix `M_ii = Σ_j M_ij = Σ_p m_p phi_i(x_p)`.
pub struct Lumped<T: Scalar> {
    fixed: Vec<Vec<bool>>,
    diagonal: Vec<T>,
}

impl<T: Scalar> MassStrategy<T> for Lumped<T> {
    fn prepare(pattern: &SymmetricPattern, fixed: &[Vec<bool>], _kind: MassKind) -> Self {
        Lumped {
            fixed: fixed.to_vec(),
            diagonal: vec![T::zero(); pattern.dim()],
        }
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        _context: StepContext,
    ) -> Result<MassReport, NotPositiveDefinite> {
        pattern.row_sums(values, &mut self.diagonal);
        let active = self.diagonal.iter().filter(|&&m| m > T::zero()).count();
        Ok(MassReport {
            active,
            lumped_rows: active,
            deactivated: 0,
        })
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) {
        for (i, r) in rhs.iter_mut().enumerate() {
            let m = self.diagonal[i];
            *r = if self.fixed[k][i] || m <= T::zero() {
                T::zero()
            } else {
                *r / m
            };
        }
    }
    /// `max M_ii / min M_ii` over active rows.
    fn condition_estimate(&mut self, _pattern: &SymmetricPattern) -> f64 {
        let active = self
            .diagonal
            .iter()
            .filter(|&&m| m > T::zero())
            .map(|m| m.to_f64());
        let (lo, hi) = active.fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
            (lo.min(m), hi.max(m))
        });
        if hi > 0.0 {
            hi / lo
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    use psmpm_basis::{mesh::generators::block_grid, rng::SplitMix64};
    use psmpm_basis::{Basis, BasisEval};

    /// A PS mass matrix from random particles filling the lower 60 % of a 2 × 4 block
    /// grid (the top elements are empty), and the empty-element marks.
    fn column_mass() -> (PowellSabin<f64>, SymmetricPattern, Vec<f64>, Vec<bool>) {
        let ps = PowellSabin::<f64>::new(
            block_grid(0.0, 1.0, 0.0, 2.0, 2, 4).unwrap(),
            SplitPoint::Incentre,
        )
        .unwrap();
        let pattern = SymmetricPattern::new(&ps);
        let mut values = vec![0.0; pattern.nnz()];
        let mut eval = BasisEval::for_basis(&ps);
        let mut rng = SplitMix64(3);
        let mut occupied = vec![false; ps.num_elements()];
        for _ in 0..400 {
            let x = Vector2::new(rng.next_f64(), 1.2 * rng.next_f64());
            let e = ps.locate(&x, None).unwrap();
            occupied[e] = true;
            ps.eval(e, &x, &mut eval);
            let scatter = pattern.element_scatter(e);
            for a in 0..9 {
                for b in a..9 {
                    values[scatter[a * 9 + b]] += 0.01 * eval.phi[a] * eval.phi[b];
                }
            }
        }
        let mut touches_empty = vec![false; ps.num_functions()];
        for e in (0..ps.num_elements()).filter(|&e| !occupied[e]) {
            for &i in ps.element_functions(e) {
                touches_empty[i] = true;
            }
        }
        (ps, pattern, values, touches_empty)
    }

    /// Partial lumping keeps every row sum: `M' 1 = M 1`, so solving `M' y = M 1`
    /// returns `y = 1` on the active functions (mass and momentum are conserved),
    /// and the factorisation succeeds (`M'` is SPD).
    #[test]
    fn partial_lumping_keeps_row_sums_and_stays_spd() {
        let (ps, pattern, values, touches_empty) = column_mass();
        let n = ps.num_functions();
        let fixed = vec![vec![false; n]; 2];
        // The consistent matrix of this near-empty configuration is singular (three
        // PS functions of a top vertex see too few particles): reported, not a panic.
        let mut consistent = SparseMass::<f64>::prepare(&pattern, &fixed, MassKind::Consistent);
        let context = StepContext {
            touches_empty: &touches_empty,
        };
        assert!(consistent.factorize(&pattern, &values, context).is_err());
        for kind in [
            MassKind::Partial(LumpRule::EmptyElement),
            MassKind::Partial(LumpRule::Threshold(0.3)),
        ] {
            let mut m = SparseMass::<f64>::prepare(&pattern, &fixed, kind);
            let report = m
                .factorize(
                    &pattern,
                    &values,
                    StepContext {
                        touches_empty: &touches_empty,
                    },
                )
                .unwrap();
            assert!(report.lumped_rows > 0, "{kind:?} lumped nothing");
            let mut rhs = vec![0.0; n];
            pattern.row_sums(&values, &mut rhs);
            let active: Vec<bool> = rhs.iter().map(|&r| r > 0.0).collect();
            m.solve(0, &mut rhs);
            for i in 0..n {
                let expected = if active[i] { 1.0 } else { 0.0 };
                assert!(
                    (rhs[i] - expected).abs() < 1e-9,
                    "{kind:?}: y[{i}] = {}",
                    rhs[i]
                );
            }
            assert!(m.condition_estimate(&pattern) >= 1.0);
        }
    }

    #[test]
    fn deactivation_removes_small_rows_and_lumped_matches_row_sums() {
        let (ps, pattern, values, touches_empty) = column_mass();
        let n = ps.num_functions();
        let fixed = vec![vec![false; n]; 2];
        let context = StepContext {
            touches_empty: &touches_empty,
        };
        let active = (0..n)
            .filter(|&i| values[pattern.diagonal_position(i)] > 0.0)
            .count();
        // Particle masses 0.01: a threshold of 1e-4 on M_ii removes the nearly empty rows.
        let mut deact =
            SparseMass::<f64>::prepare(&pattern, &fixed, MassKind::Deactivate { threshold: 1e-4 });
        let r = deact.factorize(&pattern, &values, context).unwrap();
        assert!(r.deactivated > 0);
        assert_eq!(r.active + r.deactivated, active);
        let mut lumped = Lumped::<f64>::prepare(&pattern, &fixed, MassKind::Lumped);
        lumped.factorize(&pattern, &values, context).unwrap();
        let mut rhs = vec![0.0; n];
        pattern.row_sums(&values, &mut rhs);
        lumped.solve(1, &mut rhs);
        assert!(rhs.iter().all(|&y| y == 0.0 || (y - 1.0).abs() < 1e-14));
    }

    #[test]
    fn mass_kinds_parse() {
        assert_eq!(
            MassKind::parse("partial").unwrap(),
            MassKind::Partial(LumpRule::EmptyElement)
        );
        assert_eq!(
            MassKind::parse("partial:0.1").unwrap(),
            MassKind::Partial(LumpRule::Threshold(0.1))
        );
        assert_eq!(
            MassKind::parse("deactivate").unwrap(),
            MassKind::Deactivate { threshold: 1e-2 }
        );
        assert!(MassKind::parse("partial:-1").is_err());
        assert!(MassKind::parse("heavy").unwrap_err().contains("known:"));
    }
}
