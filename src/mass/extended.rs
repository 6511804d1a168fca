//! Extension (aggregation) of under-supported functions: the default strategy.
//!
//! A function whose support is covered by particle volume below a fraction `C`
//! of its integral (`Σ_p V_p phi_j(x_p) < C ∫ phi_j`) is not solved for. It is
//! expressed through well-covered neighbours, `phi_j → Σ_i e_ji phi_i`, with
//! weights that keep every polynomial the basis reproduces (degree 2 for PS, 1 for
//! PL): with `λ_i(p)` the spline coefficients of a polynomial `p`,
//! `Σ_{i ∈ S_j} e_ji λ_i(p) = λ_j(p)` for all `p` of that degree, the minimum-norm
//! solution over the nearest well-covered functions `S_j` (by rings of
//! neighbours). This is the extended B-spline idea (Höllig; Yamaguchi, Moriguchi
//! and Terada for MPM) on any basis with dual values.
//!
//! With the extension matrix `E` (identity on the well-covered functions, the rows
//! `e_j` on the extended ones) the solved system is `Eᵀ M E ã = Eᵀ F` and
//! `a = E ã`. Every row of `E` sums to one (constants are reproduced), so the
//! total mass `1ᵀ Eᵀ M E 1 = 1ᵀ M 1` and the momentum are conserved, and the
//! polynomial precision (hence the order) of the basis is kept. Where every
//! function is well covered `E = I` and the strategy is the consistent mass.
//!
//! The reduced system changes pattern whenever the set of extended functions
//! does, so it is solved matrix-free by conjugate gradients with a Jacobi
//! preconditioner (`Eᵀ M E` applied as three sparse products over the functions
//! with particles); it needs no factorisation and its condition is bounded by the
//! coverage threshold. In a step where nothing is extended the system is `M` and
//! is solved exactly as the consistent strategy solves it (sparse Cholesky).

use super::condition::lanczos_estimate;
use super::masked::MaskedCholesky;
use super::{
    distinct_fixed_sets, MassError, MassReport, MassSetup, MassStrategy, Needs, StepContext,
    SupportFacts,
};
use crate::sparse::{Scalar, SymmetricPattern};

/// Default coverage threshold `C` of [`Extended`].
pub const DEFAULT_COVERAGE: f64 = 0.5;
/// Rings of neighbours searched for the functions an extended function is
/// expressed through.
pub const EXTENSION_RINGS: usize = 3;
/// Largest number of functions one extended function is expressed through.
pub const MAX_EXTENSION_TERMS: usize = 48;
/// Largest acceptable extension weight; a larger one means the neighbourhood is too
/// small to extrapolate well, and the next ring is added.
pub const MAX_EXTENSION_WEIGHT: f64 = 2.0;
/// Relative residual at which the conjugate-gradient solve stops.
pub const CG_TOLERANCE: f64 = 1e-11;
/// Iteration limit of the conjugate-gradient solve.
pub const CG_MAX_ITERATIONS: usize = 2000;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// No particle in the support: held at zero.
    Inactive,
    /// Well covered: an unknown of the reduced system.
    Solved,
    /// Under-supported: expressed through its row of `E`.
    Extended,
}

/// The reduced operator `Eᵀ M E` restricted to the free functions of one fixed set.
struct Reduced<'a, T> {
    col_ptr: &'a [usize],
    row_idx: &'a [usize],
    values: &'a [T],
    role: &'a [Role],
    ext_ptr: &'a [usize],
    ext_idx: &'a [usize],
    ext_w: &'a [T],
    fixed: &'a [bool],
    /// Functions with particles (solved or extended), ascending.
    active: &'a [usize],
    /// Extended functions, ascending.
    extended: &'a [usize],
}

impl<T: Scalar> Reduced<'_, T> {
    fn free(&self, i: usize) -> bool {
        self.role[i] == Role::Solved && !self.fixed[i]
    }
    /// `(E x)_i` for an active function `i`.
    #[inline]
    fn expanded(&self, x: &[T], i: usize) -> T {
        match self.role[i] {
            Role::Solved if !self.fixed[i] => x[i],
            Role::Extended if !self.fixed[i] => {
                let mut s = T::zero();
                for t in self.ext_ptr[i]..self.ext_ptr[i + 1] {
                    s += self.ext_w[t] * x[self.ext_idx[t]];
                }
                s
            }
            _ => T::zero(),
        }
    }
    /// `u = E x` on the active functions (the others stay zero).
    fn expand(&self, x: &[T], u: &mut [T]) {
        for &i in self.active {
            u[i] = self.expanded(x, i);
        }
    }
    /// `u = E x` on every function.
    fn expand_all(&self, x: &[T], u: &mut [T]) {
        for i in 0..u.len() {
            u[i] = self.expanded(x, i);
        }
    }
    /// `y = Eᵀ w`, zero off the free functions (written on the active ones).
    fn restrict(&self, w: &[T], y: &mut [T]) {
        for &i in self.active {
            y[i] = if self.free(i) { w[i] } else { T::zero() };
        }
        for &j in self.extended {
            if !self.fixed[j] {
                for t in self.ext_ptr[j]..self.ext_ptr[j + 1] {
                    let i = self.ext_idx[t];
                    if self.free(i) {
                        y[i] += self.ext_w[t] * w[j];
                    }
                }
            }
        }
    }
    /// `w = M u` over the active columns: `M_ij = 0` as soon as `i` or `j` has no
    /// particle, so the other entries contribute nothing.
    fn mass_product(&self, u: &[T], w: &mut [T]) {
        for &c in self.active {
            w[c] = T::zero();
        }
        for &c in self.active {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                let r = self.row_idx[k];
                let a = self.values[k];
                w[r] += a * u[c];
                if r != c {
                    w[c] += a * u[r];
                }
            }
        }
    }
    /// `y = Eᵀ M E x`.
    fn apply(&self, x: &[T], y: &mut [T], u: &mut [T], w: &mut [T]) {
        self.expand(x, u);
        self.mass_product(u, w);
        self.restrict(w, y);
    }
    /// `Σ a_i b_i` over the active functions.
    fn dot(&self, a: &[T], b: &[T]) -> f64 {
        self.active
            .iter()
            .map(|&i| (a[i] * b[i]).to_f64())
            .sum::<f64>()
    }
}

/// Scratch of the conjugate-gradient solve.
#[derive(Default)]
struct Scratch<T> {
    x: Vec<T>,
    r: Vec<T>,
    z: Vec<T>,
    p: Vec<T>,
    q: Vec<T>,
    u: Vec<T>,
    w: Vec<T>,
}

impl<T: Scalar> Scratch<T> {
    fn new(n: usize) -> Self {
        let v = || vec![T::zero(); n];
        Scratch {
            x: v(),
            r: v(),
            z: v(),
            p: v(),
            q: v(),
            u: v(),
            w: v(),
        }
    }
}

/// Solves `Eᵀ M E x = b` (b zero off the free functions) by preconditioned
/// conjugate gradients from `x = D⁻¹ b`; the result is left in `s.x`.
fn conjugate_gradients<T: Scalar>(
    op: &Reduced<T>,
    precond: &[T],
    b: &[T],
    s: &mut Scratch<T>,
) -> Result<usize, MassError> {
    let b_norm = op.dot(b, b).sqrt();
    for &i in op.active {
        s.x[i] = if op.free(i) {
            b[i] / precond[i]
        } else {
            T::zero()
        };
    }
    if b_norm == 0.0 {
        return Ok(0);
    }
    op.apply(&s.x, &mut s.q, &mut s.u, &mut s.w);
    for &i in op.active {
        s.r[i] = b[i] - s.q[i];
        s.z[i] = if op.free(i) {
            s.r[i] / precond[i]
        } else {
            T::zero()
        };
        s.p[i] = s.z[i];
    }
    let mut rz = op.dot(&s.r, &s.z);
    let mut residual = op.dot(&s.r, &s.r).sqrt() / b_norm;
    for iteration in 0..CG_MAX_ITERATIONS {
        if residual <= CG_TOLERANCE {
            return Ok(iteration);
        }
        op.apply(&s.p, &mut s.q, &mut s.u, &mut s.w);
        let pq = op.dot(&s.p, &s.q);
        if pq.is_nan() || pq <= 0.0 {
            break;
        }
        let alpha = T::of(rz / pq);
        for &i in op.active {
            s.x[i] += alpha * s.p[i];
            s.r[i] -= alpha * s.q[i];
            s.z[i] = if op.free(i) {
                s.r[i] / precond[i]
            } else {
                T::zero()
            };
        }
        let rz_new = op.dot(&s.r, &s.z);
        let beta = T::of(rz_new / rz);
        rz = rz_new;
        for &i in op.active {
            s.p[i] = s.z[i] + beta * s.p[i];
        }
        residual = op.dot(&s.r, &s.r).sqrt() / b_norm;
    }
    if residual <= CG_TOLERANCE {
        return Ok(CG_MAX_ITERATIONS);
    }
    Err(MassError::NotConverged {
        iterations: CG_MAX_ITERATIONS,
        residual,
    })
}

/// Extension of the functions covered below `coverage`, solved matrix-free.
pub struct Extended<T: Scalar> {
    coverage: f64,
    support: SupportFacts,
    fixed: Vec<Vec<bool>>,
    solver_of: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<T>,
    role: Vec<Role>,
    active: Vec<usize>,
    extended: Vec<usize>,
    ext_ptr: Vec<usize>,
    ext_idx: Vec<usize>,
    ext_w: Vec<T>,
    /// Jacobi preconditioner per fixed set.
    precond: Vec<Vec<T>>,
    /// The consistent solve, for the steps in which nothing is extended.
    cholesky: MaskedCholesky<T>,
    /// This step is solved by `cholesky` (nothing extended, factor exists).
    direct: bool,
    scratch: Scratch<T>,
    /// Buffers of the condition estimate.
    estimate: [Vec<T>; 5],
    rhs: Vec<T>,
    // Neighbourhood search.
    mark: Vec<u32>,
    stamp: u32,
    queue: Vec<usize>,
    front: Vec<usize>,
    candidates: Vec<usize>,
    local: Vec<f64>,
    weights: Vec<f64>,
}

impl<T: Scalar> Extended<T> {
    /// Extension below `coverage` (a fraction in `(0, 1)`).
    pub fn new(coverage: f64) -> Self {
        Extended {
            coverage,
            support: SupportFacts::default(),
            fixed: Vec::new(),
            solver_of: Vec::new(),
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            values: Vec::new(),
            role: Vec::new(),
            active: Vec::new(),
            extended: Vec::new(),
            ext_ptr: Vec::new(),
            ext_idx: Vec::new(),
            ext_w: Vec::new(),
            precond: Vec::new(),
            cholesky: MaskedCholesky::default(),
            direct: false,
            scratch: Scratch::default(),
            estimate: Default::default(),
            rhs: Vec::new(),
            mark: Vec::new(),
            stamp: 0,
            queue: Vec::new(),
            front: Vec::new(),
            candidates: Vec::new(),
            local: Vec::new(),
            weights: Vec::new(),
        }
    }

    fn reduced(&self, s: usize) -> Reduced<'_, T> {
        Reduced {
            col_ptr: &self.col_ptr,
            row_idx: &self.row_idx,
            values: &self.values,
            role: &self.role,
            ext_ptr: &self.ext_ptr,
            ext_idx: &self.ext_idx,
            ext_w: &self.ext_w,
            fixed: &self.fixed[s],
            active: &self.active,
            extended: &self.extended,
        }
    }

    /// Collects the solved functions of the next ring around the current search
    /// front into `candidates`; returns `false` when the front is exhausted.
    fn next_ring(&mut self) -> bool {
        std::mem::swap(&mut self.front, &mut self.queue);
        self.queue.clear();
        for idx in 0..self.front.len() {
            let f = self.front[idx];
            for &g in self.support.neighbours_of(f) {
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
                    if s.is_nan() || s <= 1e-12 * max_diag {
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
        let largest = self.weights.iter().fold(0.0f64, |a, w| a.max(w.abs()));
        (largest <= MAX_EXTENSION_WEIGHT && largest.is_finite()).then_some(())
    }

    /// Builds the row of `E` for the under-supported function `j`; returns `false`
    /// when no well-covered function can carry it.
    fn extend(&mut self, j: usize) -> bool {
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
            // Lower precision with every candidate found: linear, then constant.
            let lower = [1 + self.support.dim, 1];
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

impl<T: Scalar> MassStrategy<T> for Extended<T> {
    fn spec(&self) -> String {
        if self.coverage == DEFAULT_COVERAGE {
            "extended".into()
        } else {
            format!("extended:{}", self.coverage)
        }
    }
    fn needs(&self) -> Needs {
        Needs {
            empty_elements: false,
            coverage: true,
            polynomials: true,
        }
    }
    fn prepare(&mut self, setup: &MassSetup) {
        let pattern = setup.pattern;
        let n = pattern.dim();
        let (distinct, solver_of) = distinct_fixed_sets(setup.fixed);
        self.precond = distinct.iter().map(|_| vec![T::zero(); n]).collect();
        self.cholesky.prepare(setup);
        self.fixed = distinct;
        self.solver_of = solver_of;
        self.support = setup
            .support
            .cloned()
            .expect("the extended strategy is prepared with the basis facts");
        self.col_ptr = pattern.col_ptr().to_vec();
        self.row_idx = pattern.row_idx().to_vec();
        self.values = vec![T::zero(); pattern.nnz()];
        self.role = vec![Role::Inactive; n];
        self.active = Vec::with_capacity(n);
        self.extended = Vec::with_capacity(n);
        self.ext_ptr = vec![0; n + 1];
        // Room for every function extended through 16 neighbours: steps then
        // allocate only in the rare case of wider extensions.
        self.ext_idx = Vec::with_capacity(16 * n);
        self.ext_w = Vec::with_capacity(16 * n);
        self.scratch = Scratch::new(n);
        self.estimate = std::array::from_fn(|_| vec![T::zero(); n]);
        self.rhs = vec![T::zero(); n];
        self.mark = vec![0; n];
        self.queue = Vec::with_capacity(n);
        self.front = Vec::with_capacity(n);
        self.candidates = Vec::with_capacity(MAX_EXTENSION_TERMS);
        self.local = Vec::with_capacity(6 * MAX_EXTENSION_TERMS);
        self.weights = Vec::with_capacity(MAX_EXTENSION_TERMS);
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError> {
        let n = pattern.dim();
        self.values.copy_from_slice(values);
        let mut report = MassReport::default();
        for i in 0..n {
            let d = values[pattern.diagonal_position(i)];
            if d <= T::zero() {
                self.role[i] = Role::Inactive;
                continue;
            }
            report.active += 1;
            let coverage =
                SupportFacts::coverage_of(context.particle_volume[i], self.support.volume[i]);
            if report.worst_coverage.is_none_or(|(_, w)| coverage < w) {
                report.worst_coverage = Some((i, coverage));
            }
            self.role[i] = if coverage < self.coverage && !self.support.coefficients.is_empty() {
                Role::Extended
            } else {
                Role::Solved
            };
        }
        self.ext_idx.clear();
        self.ext_w.clear();
        for j in 0..n {
            self.ext_ptr[j] = self.ext_idx.len();
            if self.role[j] == Role::Extended {
                if self.extend(j) {
                    report.extended += 1;
                } else {
                    // Nothing to carry it: keep it as an unknown.
                    self.role[j] = Role::Solved;
                }
            }
        }
        self.ext_ptr[n] = self.ext_idx.len();
        self.active.clear();
        self.extended.clear();
        for i in 0..n {
            match self.role[i] {
                Role::Inactive => {}
                Role::Solved => self.active.push(i),
                Role::Extended => {
                    self.active.push(i);
                    self.extended.push(i);
                }
            }
        }
        // The solves touch only the active entries; the others stay zero.
        let s = &mut self.scratch;
        for v in [
            &mut s.x,
            &mut s.r,
            &mut s.z,
            &mut s.p,
            &mut s.q,
            &mut s.u,
            &mut s.w,
            &mut self.rhs,
        ] {
            v.iter_mut().for_each(|a| *a = T::zero());
        }
        // Jacobi preconditioner: M_ii + Σ_j e_ji² M_jj.
        for s in 0..self.fixed.len() {
            let mut precond = std::mem::take(&mut self.precond[s]);
            {
                let op = self.reduced(s);
                for i in 0..n {
                    precond[i] = if op.free(i) {
                        values[pattern.diagonal_position(i)]
                    } else {
                        T::one()
                    };
                }
                for j in 0..n {
                    if self.role[j] == Role::Extended && !op.fixed[j] {
                        let mjj = values[pattern.diagonal_position(j)];
                        for t in self.ext_ptr[j]..self.ext_ptr[j + 1] {
                            let i = self.ext_idx[t];
                            if op.free(i) {
                                precond[i] += self.ext_w[t] * self.ext_w[t] * mjj;
                            }
                        }
                    }
                }
            }
            self.precond[s] = precond;
        }
        // Nothing extended: `E = I`, the consistent system, solved as the
        // consistent strategy solves it (bit for bit).
        self.direct = false;
        if self.extended.is_empty() {
            for i in 0..n {
                self.cholesky.inactive[i] = self.role[i] == Role::Inactive;
                self.cholesky.lumped[i] = false;
            }
            self.direct = self.cholesky.factorize(pattern, values).is_ok();
        }
        Ok(report)
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        if self.direct {
            return self.cholesky.solve(k, rhs);
        }
        let s = self.solver_of[k];
        let mut b = std::mem::take(&mut self.rhs);
        let mut scratch = std::mem::take(&mut self.scratch);
        let result = {
            let op = self.reduced(s);
            op.restrict(rhs, &mut b);
            let result = conjugate_gradients(&op, &self.precond[s], &b, &mut scratch);
            if std::env::var("PSMPM_DEBUG_CG").is_ok() {
                eprintln!("cg {:?} extended {}", result, self.ext_ptr[self.role.len()]);
            }
            op.expand_all(&scratch.x, rhs);
            result
        };
        self.rhs = b;
        self.scratch = scratch;
        result.map(|_| ())
    }
    /// `κ(Eᵀ M E)` on the solved functions, from Lanczos steps (no solves).
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        if self.direct {
            return self.cholesky.condition_estimate(pattern);
        }
        let mut worst = 0.0f64;
        let [mut u, mut w, mut x, mut q, mut y] = std::mem::take(&mut self.estimate);
        for v in [&mut u, &mut w, &mut q, &mut y] {
            v.iter_mut().for_each(|a| *a = T::zero());
        }
        for s in 0..self.fixed.len() {
            let op = self.reduced(s);
            for i in 0..x.len() {
                x[i] = if op.free(i) {
                    T::of(1.0 + (i % 7) as f64 * 0.1)
                } else {
                    T::zero()
                };
            }
            let mut apply = |v: &[T], out: &mut [T]| op.apply(v, out, &mut u, &mut w);
            worst = worst.max(lanczos_estimate(&mut apply, &mut x, &mut q, &mut y));
        }
        self.estimate = [u, w, x, q, y];
        worst
    }
}
