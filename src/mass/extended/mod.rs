//! Extension (aggregation) of under-supported functions, alone (`extended`) or
//! with lumped rows (`extended-hybrid`, the default strategy).
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
//! The hybrid ([`Extended::hybrid`], `extended-hybrid:C1:C2`, the default strategy
//! at `0.02:0.75`) extends only the functions with almost no particles (below
//! `C1`) and lumps the rows of the solved functions covered in `[C1, C2)`:
//! lumping raises the critical step where extension of moderately covered
//! functions lowers it, and keeps their degrees of freedom. A plain lumped row,
//! `M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ`, damps the rotation of a free body;
//! the default lumps only the part of each pair that an affine field does not
//! see (`M_A`, [`Correction::InMass`], assembled by the driver in
//! `driver::phases::add_affine_lumping`), so affine fields project exactly and,
//! the matrix being one symmetric matrix for both solves, the step's energy
//! balance holds. The variants `-apic`, `-rpic` and `-plain` lump plainly and
//! correct the momentum instead ([`Correction::Affine`], [`Correction::Rigid`])
//! or not at all.
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
    distinct_fixed_sets, Correction, MassError, MassReport, MassSetup, MassStrategy, Needs,
    StepContext, SupportFacts,
};
use crate::last_written::LastWritten;
use crate::sparse::{Scalar, SymmetricPattern};
use direct::{Direct, FullPattern};
use solve::{conjugate_gradients, Reduced, Scratch};
use std::sync::Arc;

mod direct;
mod solve;
mod weights;

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
/// The hybrid also lumps the row of a function sampled by less than this,
/// `Σ_p phi_i(x_p) < N` (each particle weighted by the function's value there),
/// whatever its coverage: a function whose support lies in a few small elements
/// can be covered by the body yet seen by too few particles for its consistent
/// row (`docs/examples/slide-strike.toml` stops at t ≈ 0.32 with `N = 0.5` and
/// runs with `N = 1`; `N = 3` also lumps well-sampled boundary functions of B2
/// and B5a and costs accuracy there, `docs/stability.md`).
pub const MIN_PARTICLE_COUNT: f64 = 1.0;
/// A row lumped by the sampling rule ([`MIN_PARTICLE_COUNT`]) returns to its
/// consistent row only once its function is sampled by this many particles
/// (hysteresis). Without it, a function at the edge of a vibrating body whose
/// count hovers about one switches its row at every other step, and every switch
/// changes `M` at fixed momentum: the velocity the step's force works against jumps,
/// `Δt F · (M'⁻¹ − M⁻¹) P`, and over the compressions and releases of a vibration
/// these jumps gain energy. A block dropped on a contact floor gained 8.5 % of its
/// energy, all of it at such steps; with the hysteresis, nothing (`docs/stability.md`,
/// "Rows that switch at every other step").
pub const RESTORE_PARTICLE_COUNT: f64 = 6.0;
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
    /// No mass, but an element that holds a particle has it: the particles lie
    /// on the edge of its support, where it vanishes. Outside the system, and
    /// given its row of `E` after each solve: a C⁰ basis's gradient does not
    /// vanish there (PL on a particle lying on a triangle edge), and held at zero
    /// the function would put a kink into the velocity field at the particle,
    /// strain in a body that only translates. A C¹ basis vanishes there with its
    /// gradient, so nothing a particle sees changes.
    Ghost,
}

/// Extended functions the extension rows have room for before a step grows them.
const EXTENSION_ROOM: usize = 1024;

/// Extension of the functions covered below `coverage`, solved matrix-free.
pub struct Extended<T: Scalar> {
    coverage: f64,
    /// Rows of the solved functions covered below this are lumped (hybrid; equal
    /// to `coverage` when nothing is lumped).
    lump: f64,
    /// Hybrid: a function a wall constrains is extended below this coverage
    /// instead of lumped (`0`: no such rule; [`Extended::with_walls`]).
    walls: f64,
    lumped: Vec<bool>,
    /// Rows lumped by the sampling rule in the last step, which stay lumped until
    /// [`RESTORE_PARTICLE_COUNT`].
    sparse: Vec<bool>,
    /// How the driver corrects the momentum of the lumped rows.
    correction: Correction,
    /// Some row is lumped in this step.
    any_lumped: bool,
    /// The step's classification, made by [`MassStrategy::classify`] before the
    /// driver added the affine-preserving lumping term ([`Correction::InMass`]).
    classified: Option<MassReport>,
    /// Buffer of the row lumping.
    diagonal_add: Vec<T>,
    support: Arc<SupportFacts>,
    fixed: Vec<Vec<bool>>,
    solver_of: Vec<usize>,
    /// The pattern of `M`, shared with the driver's (not copied).
    col_ptr: Arc<[usize]>,
    row_idx: Arc<[usize]>,
    values: Vec<T>,
    role: Vec<Role>,
    /// The functions the last classification visited (its live list, ascending,
    /// when it had one): every function outside them is [`Role::Inactive`],
    /// without a lumped row or a sampling mark.
    visited: LastWritten,
    active: Vec<usize>,
    extended: Vec<usize>,
    /// The [`Role::Ghost`] functions, ascending.
    ghosts: Vec<usize>,
    ext_ptr: Vec<usize>,
    ext_idx: Vec<usize>,
    ext_w: Vec<T>,
    /// Jacobi preconditioner per fixed set (for the conjugate gradients, used
    /// where the direct factorisation of a step fails).
    precond: Vec<Vec<T>>,
    /// `Eᵀ M E` assembled and factorised, per fixed set.
    reduced_factor: Vec<Direct<T>>,
    /// Both triangles of the pattern of `M`.
    full_pattern: FullPattern,
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
        Self::hybrid(coverage, coverage, Correction::None)
    }

    /// In the hybrid, the functions a wall constrains (a fixed component, or a
    /// term of a slip wall's constraint) are extended below `walls` coverage, as
    /// in `extended`, instead of lumped (`extended-hybrid:C1:C2:W`). Solved for
    /// (lumped or not), a poorly covered wall function carries part of the wall's
    /// reaction at its point beyond the contact; on a frictionless wall the moment
    /// of those reactions turns a body that should slide without turning.
    /// Measured (`docs/stability.md`): a disk on a 30° slope turns by 7.4e-3 rad in
    /// 0.4 s with `W = 0.5`, 4.6e-2 without; the damped column B5c 1 × 4 loses
    /// accuracy (σ_yy error 2.04e-2 against 1.29e-2), so the default has no
    /// such rule.
    pub fn with_walls(mut self, walls: f64) -> Self {
        self.walls = walls;
        self
    }

    /// Extension below `extend`, and the rows of the functions covered in
    /// `[extend, lump)` lumped (`M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ` over their
    /// off-diagonal entries, as partial lumping does): mass and momentum are kept.
    /// The driver corrects the momentum of the lumped rows as `correction` says
    /// (with [`Correction::Affine`] a lumped row keeps rigid rotations, which it
    /// would otherwise damp).
    pub fn hybrid(extend: f64, lump: f64, correction: Correction) -> Self {
        Extended {
            coverage: extend,
            lump: lump.max(extend),
            walls: 0.0,
            lumped: Vec::new(),
            sparse: Vec::new(),
            correction,
            any_lumped: false,
            classified: None,
            diagonal_add: Vec::new(),
            support: Arc::default(),
            fixed: Vec::new(),
            solver_of: Vec::new(),
            col_ptr: Arc::from([]),
            row_idx: Arc::from([]),
            values: Vec::new(),
            role: Vec::new(),
            visited: LastWritten::default(),
            active: Vec::new(),
            extended: Vec::new(),
            ghosts: Vec::new(),
            ext_ptr: Vec::new(),
            ext_idx: Vec::new(),
            ext_w: Vec::new(),
            precond: Vec::new(),
            reduced_factor: Vec::new(),
            full_pattern: FullPattern::default(),
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

    /// The hybrid: rows of solved functions covered below `lump` are lumped
    /// (plain `extended` lumps none).
    fn lumps_rows(&self) -> bool {
        self.lump > self.coverage
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
}

impl<T: Scalar> Extended<T> {
    /// The roles of the step's functions from their coverage (inactive, solved,
    /// extended with their rows of `E`) and the lumped rows of the hybrid.
    ///
    /// With a live list (`StepContext::live_list`: a body over a small part of the
    /// mesh) only the listed functions are classified: every other one has no
    /// mass and is not live, so the pass over every function would make it
    /// [`Role::Inactive`] without a lumped or sampling mark, which is what it
    /// holds once the functions classified last step and no longer listed are
    /// reset. The same roles, rows of `E` and report either way.
    fn classify_functions(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> MassReport {
        let n = pattern.dim();
        let mut visited = std::mem::take(&mut self.visited);
        if let Some(list) = context.live_list {
            let live = |i: usize| context.live.get(i).copied().unwrap_or(false);
            for i in visited.each(n).filter(|&i| !live(i)) {
                self.reset(i);
            }
            visited.record(list);
        } else {
            visited.record_all();
        }
        let mut report = MassReport::default();
        for i in visited.each(n) {
            self.classify_one(
                i,
                values[pattern.diagonal_position(i)],
                context,
                &mut report,
            );
        }
        self.ext_idx.clear();
        self.ext_w.clear();
        // Row `j` of `E` is `ext_ptr[j]..ext_ptr[j + 1]`, read only for the
        // extended and ghost functions.
        for j in visited.each(n) {
            self.ext_ptr[j] = self.ext_idx.len();
            if self.role[j] == Role::Extended {
                if self.extend(j) {
                    report.extended += 1;
                } else {
                    // Nothing to carry it: keep it as an unknown, lumped in the hybrid.
                    self.role[j] = Role::Solved;
                    self.lumped[j] = self.lumps_rows();
                }
            } else if self.role[j] == Role::Ghost && !self.extend(j) {
                self.role[j] = Role::Inactive;
            }
            self.ext_ptr[j + 1] = self.ext_idx.len();
        }
        self.visited = visited;
        report
    }

    /// A function outside the step's live list: no role, no lumped row, no mark.
    fn reset(&mut self, i: usize) {
        self.role[i] = Role::Inactive;
        self.lumped[i] = false;
        self.sparse[i] = false;
    }

    /// The role of function `i` of diagonal mass `d`, and its lumped row.
    fn classify_one(&mut self, i: usize, d: T, context: StepContext, report: &mut MassReport) {
        if d <= T::zero() {
            let live = context.live.get(i).copied().unwrap_or(false);
            // A wall's function stays at zero: a value given to it would have
            // to satisfy the wall's constraints, which the projection imposes
            // on the functions with mass.
            let on_wall = context.on_wall.get(i).copied().unwrap_or(false);
            self.role[i] = if live && !on_wall && !self.support.coefficients.is_empty() {
                Role::Ghost
            } else {
                Role::Inactive
            };
            self.lumped[i] = false;
            self.sparse[i] = false;
            return;
        }
        report.active += 1;
        let coverage =
            SupportFacts::coverage_of(context.particle_volume[i], self.support.volume[i]);
        // A wall's function extended rather than lumped (`with_walls`).
        let on_wall = context.on_wall.get(i).copied().unwrap_or(false);
        let threshold = if on_wall && self.lumps_rows() {
            self.coverage.max(self.walls)
        } else {
            self.coverage
        };
        self.role[i] = if coverage < threshold && !self.support.coefficients.is_empty() {
            Role::Extended
        } else {
            Role::Solved
        };
        // The worst-covered function the system solves for (the extended ones
        // are out of it): what the system's conditioning depends on.
        if self.role[i] == Role::Solved && report.worst_coverage.is_none_or(|(_, w)| coverage < w) {
            report.worst_coverage = Some((i, coverage));
        }
        let sampled_by = if self.sparse[i] {
            RESTORE_PARTICLE_COUNT
        } else {
            MIN_PARTICLE_COUNT
        };
        // A function sampled only along a line (every element of its support
        // with particles failing the affine test) is lumped as one sampled by too
        // few: its consistent row is singular across the line (a user's blocks
        // on a mesh of 40:1 slivers, each particle row on a mesh line, stopped at
        // step 486: `docs/stability.md`, "Functions sampled along a line").
        let flat = context.flat.get(i).copied().unwrap_or(false);
        let sparse = context.particle_count[i] < sampled_by || flat;
        self.lumped[i] =
            self.role[i] == Role::Solved && self.lumps_rows() && (coverage < self.lump || sparse);
        self.sparse[i] = self.lumped[i] && sparse;
    }

    /// Whether some row is lumped (only classified functions can be).
    fn any_lumped_row(&self) -> bool {
        self.visited.each(self.lumped.len()).any(|i| self.lumped[i])
    }

    /// The reduced system `Eᵀ M E` of component `k`: its factorisation, else the
    /// conjugate gradients.
    fn solve_reduced(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        let s = self.solver_of[k];
        let mut b = std::mem::take(&mut self.rhs);
        let mut scratch = std::mem::take(&mut self.scratch);
        if self.reduced_factor[s].ready {
            let mut factor = std::mem::take(&mut self.reduced_factor[s]);
            factor.solve(&self.reduced(s), rhs, &mut b, &mut scratch.x);
            self.reduced_factor[s] = factor;
            self.rhs = b;
            self.scratch = scratch;
            return Ok(());
        }
        let result = {
            let op = self.reduced(s);
            op.restrict(rhs, &mut b);
            let result = conjugate_gradients(&op, &self.precond[s], &b, &mut scratch);
            rhs.iter_mut().for_each(|v| *v = T::zero());
            op.expand(&scratch.x, rhs);
            // `x` is zero between solves (`Direct::solve` relies on it).
            for &i in op.active {
                scratch.x[i] = T::zero();
            }
            result
        };
        self.rhs = b;
        self.scratch = scratch;
        result.map(|_| ())
    }

    /// The [`Role::Ghost`] functions of component `k` from their rows of `E`
    /// (their carriers are solved functions), except where a wall holds them.
    fn fill_ghosts(&self, k: usize, rhs: &mut [T]) {
        let fixed = &self.fixed[self.solver_of[k]];
        for &j in &self.ghosts {
            if fixed[j] {
                continue;
            }
            let mut value = T::zero();
            for t in self.ext_ptr[j]..self.ext_ptr[j + 1] {
                value += self.ext_w[t] * rhs[self.ext_idx[t]];
            }
            rhs[j] = value;
        }
    }
}

impl<T: Scalar> MassStrategy<T> for Extended<T> {
    fn spec(&self) -> String {
        let hybrid = self.correction.hybrid_name();
        if (self.coverage, self.lump) == (super::DEFAULT_HYBRID_EXTEND, super::DEFAULT_HYBRID_LUMP)
        {
            hybrid.into()
        } else if self.lumps_rows() {
            format!("{hybrid}:{}:{}", self.coverage, self.lump)
        } else if self.coverage == DEFAULT_COVERAGE {
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
            correction: if self.lumps_rows() {
                self.correction
            } else {
                Correction::None
            },
            row_sums_only: false,
        }
    }
    fn lumped_rows(&self) -> Option<&[bool]> {
        let corrects = matches!(self.correction, Correction::Rigid | Correction::Affine);
        (corrects && self.any_lumped).then_some(&self.lumped[..])
    }
    fn prepare(&mut self, setup: &MassSetup) {
        let pattern = setup.pattern;
        let n = pattern.dim();
        let (distinct, solver_of) = distinct_fixed_sets(setup.fixed);
        self.precond = distinct.iter().map(|_| vec![T::zero(); n]).collect();
        self.reduced_factor = distinct.iter().map(|_| Direct::new(n)).collect();
        self.full_pattern = FullPattern::new(pattern.col_ptr(), pattern.row_idx());
        self.cholesky.prepare(setup);
        self.fixed = distinct;
        self.solver_of = solver_of;
        self.support = setup
            .support
            .cloned()
            .expect("the extended strategy is prepared with the basis facts");
        (self.col_ptr, self.row_idx) = pattern.shared_structure();
        self.values = vec![T::zero(); pattern.nnz()];
        self.role = vec![Role::Inactive; n];
        self.visited = LastWritten::with_capacity(n);
        self.lumped = vec![false; n];
        self.sparse = vec![false; n];
        self.diagonal_add = vec![T::zero(); n];
        self.active = Vec::with_capacity(n);
        self.extended = Vec::with_capacity(n);
        self.ghosts = Vec::new();
        self.ext_ptr = vec![0; n + 1];
        // Room for `EXTENSION_ROOM` functions extended through 16 neighbours each
        // (under-supported functions lie along the body's edge, a small share of a
        // large mesh): a step that extends more grows the buffers, which keep their
        // capacity for the next steps.
        let room = 16 * n.min(EXTENSION_ROOM);
        self.ext_idx = Vec::with_capacity(room);
        self.ext_w = Vec::with_capacity(room);
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
    fn classify(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Option<&[bool]> {
        if self.correction != Correction::InMass {
            return None;
        }
        self.classified = Some(self.classify_functions(pattern, values, context));
        self.any_lumped_row().then_some(&self.lumped[..])
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError> {
        let n = pattern.dim();
        // `self.values` holds the solved matrix once `copied`: the lumped rows of
        // the hybrid written here, else a copy of `values` made only where the
        // reduced system needs it (nothing is copied in a step solved directly).
        let mut copied = false;
        let mut report = match self.classified.take() {
            // The driver added the affine-preserving lumping term to `values`.
            Some(report) => report,
            None => {
                let report = self.classify_functions(pattern, values, context);
                // Lumped rows: every off-diagonal entry of a lumped row moves onto
                // both diagonals (row sums kept, `M' ⪰ M`).
                if self.any_lumped_row() {
                    super::masked::modify_rows(
                        pattern,
                        values,
                        &self.lumped,
                        |_| false,
                        T::zero(),
                        &mut self.diagonal_add,
                        &mut self.values,
                    );
                    copied = true;
                }
                report
            }
        };
        let visited = std::mem::take(&mut self.visited);
        report.lumped_rows = visited.each(n).filter(|&i| self.lumped[i]).count();
        self.any_lumped = report.lumped_rows > 0;
        self.active.clear();
        self.extended.clear();
        self.ghosts.clear();
        for i in visited.each(n) {
            match self.role[i] {
                Role::Inactive => {}
                Role::Ghost => self.ghosts.push(i),
                Role::Solved => self.active.push(i),
                Role::Extended => {
                    self.active.push(i);
                    self.extended.push(i);
                }
            }
        }
        // Nothing extended: `E = I`, the consistent system, solved as the
        // consistent strategy solves it (bit for bit).
        self.direct = false;
        if self.extended.is_empty() {
            let solved = if copied { &self.values[..] } else { values };
            let factorised = match visited.listed() {
                Some(list) => {
                    let role = &self.role;
                    self.cholesky.factorize_listed(pattern, solved, list, |i| {
                        matches!(role[i], Role::Inactive | Role::Ghost)
                    })
                }
                None => {
                    for i in 0..n {
                        self.cholesky.inactive[i] =
                            matches!(self.role[i], Role::Inactive | Role::Ghost);
                        self.cholesky.lumped[i] = false;
                    }
                    self.cholesky.factorize(pattern, solved)
                }
            };
            self.direct = factorised.is_ok();
        }
        self.visited = visited;
        // `Eᵀ M E` factorised per fixed set; where that fails (a pivot lost to
        // rounding), the conjugate gradients with the Jacobi preconditioner
        // `M_ii + Σ_j e_ji² M_jj`.
        if !self.direct {
            if !copied {
                // The reduced system reads the entries between active functions
                // only, each in the column of the later one.
                for &c in &self.active {
                    let entries = self.col_ptr[c]..self.col_ptr[c + 1];
                    self.values[entries.clone()].copy_from_slice(&values[entries]);
                }
            }
            for s in 0..self.fixed.len() {
                let mut factor = std::mem::take(&mut self.reduced_factor[s]);
                let factorised = factor
                    .factorize(&self.reduced(s), &self.full_pattern)
                    .is_ok();
                self.reduced_factor[s] = factor;
                if factorised {
                    continue;
                }
                // The conjugate gradients touch only the active entries; the
                // others stay zero.
                let scratch = &mut self.scratch;
                for v in [
                    &mut scratch.x,
                    &mut scratch.r,
                    &mut scratch.z,
                    &mut scratch.p,
                    &mut scratch.q,
                    &mut scratch.u,
                    &mut scratch.w,
                ] {
                    v.iter_mut().for_each(|a| *a = T::zero());
                }
                let mut precond = std::mem::take(&mut self.precond[s]);
                {
                    let op = self.reduced(s);
                    for i in 0..n {
                        precond[i] = if op.free(i) {
                            self.values[pattern.diagonal_position(i)]
                        } else {
                            T::one()
                        };
                    }
                    for j in 0..n {
                        if self.role[j] == Role::Extended && !op.fixed[j] {
                            let mjj = self.values[pattern.diagonal_position(j)];
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
        }
        Ok(report)
    }
    fn solve_all(&mut self, rhs: &mut [Vec<T>]) -> Result<(), MassError> {
        if self.direct {
            self.cholesky.solve_all(rhs)?;
            for (k, r) in rhs.iter_mut().enumerate() {
                self.fill_ghosts(k, r);
            }
            return Ok(());
        }
        super::solve_each(self, rhs)
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        if self.direct {
            self.cholesky.solve(k, rhs)?;
            self.fill_ghosts(k, rhs);
            return Ok(());
        }
        let result = self.solve_reduced(k, rhs);
        self.fill_ghosts(k, rhs);
        result
    }
    fn solve_all_two(
        &mut self,
        first: &mut [Vec<T>],
        second: &mut [Vec<T>],
    ) -> Result<(), MassError> {
        if !self.direct {
            self.solve_all(first)?;
            return self.solve_all(second);
        }
        self.cholesky.solve_all_two(first, second)?;
        for rhs in [first, second] {
            for (k, r) in rhs.iter_mut().enumerate() {
                self.fill_ghosts(k, r);
            }
        }
        Ok(())
    }
    /// Nothing extended and no row lumped: `M` itself, solved by Cholesky; the
    /// ghosts (functions without mass) are filled from their neighbours, a
    /// linear map, after each solve.
    fn solves_mass_itself(&self) -> bool {
        self.direct && !self.any_lumped
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
