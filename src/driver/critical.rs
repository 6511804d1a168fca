//! The critical time step of the explicit update for the basis and mass strategy in
//! use: `Δt_crit = 2 / ω_max` with `ω_max² = λ_max(M⁻¹ K)`, `M` the system the mass
//! strategy solves (its own inverse, walls included) and `K` the small-strain
//! stiffness `K v = Σ_p V_p σ(∇v_p) ∇phi_i` with each particle's Lamé constants at
//! the current particle positions. `λ_max` by power iteration: a lower bound, so the
//! estimate is an upper bound on `Δt_crit` that tightens with the iterations.
//! Local damping makes the update up to `1 + α` times stiffer: the step is divided
//! by `√(1 + α)` ([`crate::effect::Effect::force_amplification`]).

use super::{phases, solve_with_walls, Driver, StepError};
use crate::mass::{tridiagonal_extremes, MassStrategy};
use crate::materials::ParticleMaterials;
use crate::sparse::Scalar;
use nalgebra::SMatrix;
use psmpm_basis::Basis;
use rayon::iter::{IntoParallelIterator, IntoParallelRefIterator, ParallelIterator};

/// Power iterations of the critical-step estimate.
pub const CRITICAL_ITERATIONS: usize = 40;

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// The critical time step at the current state (see the module doc). Uses the
    /// step's own buffers; call before a step (e.g. at the start of a run).
    pub fn critical_time_step(&mut self) -> Result<f64, StepError> {
        self.locate_and_evaluate()?;
        self.assemble_mass();
        self.factorize()?;
        let critical = self.power_iteration(None)?;
        self.dt_critical = Some(critical);
        Ok(critical)
    }

    /// The product of the effects' [`Effect::force_amplification`](crate::effect::Effect::force_amplification)
    /// (local damping: `1 + α`): it scales `ω_max²`.
    fn effects_amplification(&self) -> f64 {
        self.effects
            .iter()
            .map(|e| e.force_amplification())
            .product()
    }

    /// The critical time step with the row-sum lumped mass `m_i = Σ_p m_p phi_i(x_p)`
    /// in place of the strategy's system, at the state of the last
    /// [`Driver::critical_time_step`] (whose evaluations it reuses). A strategy's
    /// step far below this one (the consistent mass's is typically within a factor
    /// of 2–4) means its mass matrix is nearly singular: too few particles for the
    /// functions it solves for, or functions with almost no support.
    pub fn lumped_critical_time_step(&mut self) -> Result<f64, StepError> {
        let n = self.basis.num_functions();
        let mut lumped = vec![0.0; n];
        for p in 0..self.particles.len() {
            let m = self.particles.mass[p].to_f64();
            for (s, i) in self.evals.entries(p) {
                lumped[i] += m * self.evals.phi[s].to_f64();
            }
        }
        self.power_iteration(Some(&lumped))
    }

    /// `f = K v`, the small-strain stiffness of the particles' own materials
    /// ([`stiffness_product`]).
    fn apply_stiffness(&mut self, v: &[Vec<T>], f: &mut [Vec<T>]) {
        let material = &self.material;
        stiffness_product(
            &self.evals,
            &self.bins,
            &self.gather,
            &mut self.local,
            &self.particles.volume,
            |p| material.elastic(p).lame(D),
            v,
            f,
        );
    }

    /// `2 / √(a λ_max(M⁻¹K))` by power iteration from [`seed`], `M` the strategy's
    /// system (`None`) or the diagonal `lumped` (its zero entries, functions without
    /// particles, left out), `a` the effects' amplification of the forces. With the
    /// strategy's system, keeps the iteration's last vector (`critical_vector`) for
    /// [`Driver::watch_critical_step`] to start from.
    fn power_iteration(&mut self, lumped: Option<&[f64]>) -> Result<f64, StepError> {
        let n = self.basis.num_functions();
        let (mut v, mut f) = (seed_field::<T>(D, n), vec![vec![T::zero(); n]; D]);
        let mut estimate = 0.0;
        for _ in 0..CRITICAL_ITERATIONS {
            let nv = norm(&v);
            if nv == 0.0 {
                break;
            }
            v.iter_mut()
                .flat_map(|c| c.iter_mut())
                .for_each(|a| *a /= T::of(nv));
            self.apply_stiffness(&v, &mut f);
            match lumped {
                None => solve_with_walls(&mut self.mass, &mut self.constraints, &mut f)
                    .map_err(|source| self.mass_failure(source))?,
                Some(m) => {
                    for fk in f.iter_mut() {
                        for (fi, &mi) in fk.iter_mut().zip(m) {
                            *fi = if mi > 0.0 { *fi / T::of(mi) } else { T::zero() };
                        }
                    }
                    self.constraints.project(&mut f);
                }
            }
            estimate = norm(&f);
            std::mem::swap(&mut v, &mut f);
        }
        if lumped.is_none() {
            self.critical_vector = v;
        }
        Ok(if estimate > 0.0 {
            2.0 / (estimate * self.effects_amplification()).sqrt()
        } else {
            f64::INFINITY
        })
    }

    /// The critical step `2 / √(a λ_max(A))` of the update as it is taken, by
    /// `iterations` Lanczos steps from `buffers.start`, with `A = M⁻¹ M_c M⁻¹ K`:
    /// `M⁻¹` the strategy's solve with the walls, `M_c` the particles' consistent
    /// mass. The grid velocities of a step are projected from the particles'
    /// (`M v̂ = Φᵀ m v_p`, eq. (20)) after the particles took the grid's
    /// acceleration, so a grid field `v̂` becomes `M⁻¹ M_c v̂` plus the step's
    /// change: where `M = M_c` (the consistent mass) `A = M⁻¹K`, and where rows are
    /// lumped (`M ⪰ M_c`) the projection damps what a lumped row's small mass would
    /// make stiff (a function that a particle near the edge of its support sees
    /// with `phi ≈ ε` has a lumped mass `∝ ε` and a consistent one `∝ ε²`).
    /// Measured: PL's default on a block falling onto a no-slip floor ran stable
    /// with every step whole at 3.5 times the critical step of `M⁻¹K`.
    ///
    /// `A` is self-adjoint in the stiffness's inner product `⟨x, y⟩_K = xᵀKy`
    /// (`KA = K M⁻¹ M_c M⁻¹ K`), so the Lanczos recurrence in that product gives a
    /// tridiagonal `T` whose largest eigenvalue approaches `λ_max(A)` from below,
    /// much faster than a power iteration where the top of the spectrum is crowded
    /// (a body half over new functions). Per step: a stiffness product, a
    /// consistent-mass product and two solves; no allocation. The rigid modes
    /// (`Kx = 0`) drop out of the product, which is what the largest eigenvalue
    /// needs.
    pub(super) fn lanczos_critical(
        &mut self,
        buffers: &mut Lanczos<T>,
        iterations: usize,
    ) -> Result<f64, StepError> {
        let iterations = iterations.min(MAX_LANCZOS);
        let Lanczos {
            start,
            kept,
            previous,
            current,
            k_current,
            next,
            scratch,
        } = buffers;
        // r = start, u = K r, β₀ = √(rᵀ u).
        for (n, s) in next.iter_mut().zip(start.iter()) {
            n.copy_from_slice(s);
        }
        self.apply_stiffness(next, k_current);
        let mut beta = dot(next, k_current).max(0.0).sqrt();
        let (mut alpha, mut betas) = ([0.0; MAX_LANCZOS], [0.0; MAX_LANCZOS]);
        phases::zero(previous);
        let mut m = 0;
        while m < iterations && beta > 0.0 {
            // q_j = r / β, K q_j = u / β; q_{j−1} in `previous`.
            let scale = T::of(1.0 / beta);
            for (q, r) in current.iter_mut().zip(next.iter()) {
                for (a, b) in q.iter_mut().zip(r) {
                    *a = *b * scale;
                }
            }
            k_current
                .iter_mut()
                .flat_map(|c| c.iter_mut())
                .for_each(|a| *a *= scale);
            if let Some(q) = kept.get_mut(m) {
                for (a, b) in q.iter_mut().zip(current.iter()) {
                    a.copy_from_slice(b);
                }
            }
            // w = M⁻¹ K q_j, with the walls.
            for (w, kq) in next.iter_mut().zip(k_current.iter()) {
                w.copy_from_slice(kq);
            }
            solve_with_walls(&mut self.mass, &mut self.constraints, next)
                .map_err(|source| self.mass_failure(source))?;
            // The velocity projection's filter: w ← M⁻¹ M_c w.
            consistent_mass_product(
                &self.evals,
                &self.bins,
                &self.gather,
                &mut self.local,
                &self.particles.mass,
                next,
                scratch,
            );
            for (w, m) in next.iter_mut().zip(scratch.iter()) {
                w.copy_from_slice(m);
            }
            solve_with_walls(&mut self.mass, &mut self.constraints, next)
                .map_err(|source| self.mass_failure(source))?;
            let a = dot(next, k_current);
            alpha[m] = a;
            betas[m] = beta;
            // r = w − α q_j − β q_{j−1}.
            let (ta, tb) = (T::of(a), T::of(if m == 0 { 0.0 } else { beta }));
            for ((r, q), p) in next.iter_mut().zip(current.iter()).zip(previous.iter()) {
                for ((ri, qi), pi) in r.iter_mut().zip(q).zip(p) {
                    *ri = *ri - ta * *qi - tb * *pi;
                }
            }
            std::mem::swap(previous, current);
            m += 1;
            self.apply_stiffness(next, k_current);
            beta = dot(next, k_current).max(0.0).sqrt();
            // A Krylov space exhausted to round-off: T holds the whole spectrum.
            if beta.is_nan() || beta <= 1e-12 * a.abs() {
                break;
            }
        }
        // β_j for j ≥ 1 couples rows j − 1 and j of T.
        let lambda = tridiagonal_extremes(&alpha[..m], &betas[1..m.max(1)]).1;
        // The Ritz vector `Σ s_j q_j` of λ into `start`, for the next call to start
        // from, when every q_j was kept: `s` by the recurrence of `(T − λ) s = 0`.
        if m > 0 && m <= kept.len() {
            let mut s = [0.0; MAX_LANCZOS];
            s[0] = 1.0;
            for j in 0..m - 1 {
                let back = if j == 0 { 0.0 } else { betas[j] * s[j - 1] };
                s[j + 1] = ((lambda - alpha[j]) * s[j] - back) / betas[j + 1];
            }
            let norm_s = s[..m].iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm_s.is_finite() && norm_s > 0.0 {
                phases::zero(start);
                for (j, q) in kept.iter().enumerate().take(m) {
                    let w = T::of(s[j] / norm_s);
                    for (a, b) in start.iter_mut().zip(q) {
                        for (ai, bi) in a.iter_mut().zip(b) {
                            *ai += w * *bi;
                        }
                    }
                }
            }
        }
        Ok(if lambda > 0.0 {
            2.0 / (lambda * self.effects_amplification()).sqrt()
        } else {
            f64::INFINITY
        })
    }

    /// Enables the watch over the critical step while the bodies move: every
    /// [`WATCH_EVERY`] steps (every step while steps are split) the step estimates
    /// the critical step again at its own mass system, with [`WATCH_ITERATIONS`]
    /// Lanczos steps from the last estimate's Ritz vector (plus a share of the fixed start field,
    /// for a new stiff mode elsewhere), and when `Δt` is above `trigger` times that
    /// estimate it is taken in `k = ⌈Δt / (courant Δt_crit)⌉` equal sub-steps;
    /// once split, it goes back to fewer only where those would be below the
    /// middle of `courant` and `trigger` (a hysteresis: each change of the step's
    /// length near the critical step moves energy into the fastest modes). The
    /// step's end time and everything reported per step stay those of `Δt`.
    /// Every step the watch also limits each particle's move per sub-step to
    /// [`ADVECTION_SHARE`] of its element's width, and to [`CONTACT_SHARE`] of its
    /// contact distance near a contact wall (the critical step knows
    /// the stiffness, not the speed): the step takes the larger of the two counts
    /// of sub-steps.
    /// Allocates the watch's buffers; call once, before the steps (after
    /// [`Driver::critical_time_step`], whose vector it starts from).
    pub fn watch_critical_step(&mut self, courant: f64, trigger: f64) {
        let n = self.basis.num_functions();
        let narrowest = self.narrowest_occupied_element();
        let mut watch = Watch {
            courant,
            trigger,
            lanczos: Lanczos::new(D, n, WATCH_ITERATIONS),
            seed_norm: (0..D)
                .flat_map(|k| (0..n).map(move |i| seed(i, k).powi(2)))
                .sum::<f64>()
                .sqrt(),
            latest: self.dt_critical,
            latest_step: 0,
            lowest: None,
            substeps: 1,
            split_steps: 0,
            most_substeps: 1,
            advection_substeps: 1,
            advected_steps: 0,
            speed: 0.0,
            fastest: None,
            pending: (1, 1),
            near_contact: self.near_contact_walls(),
            since_check: 0,
            interval: WATCH_EVERY,
            counts: (self.last_report.active, self.last_report.treated()),
            narrowest,
            narrowest_start: narrowest,
            probed: vec![false; n],
            #[cfg(test)]
            audit: Vec::new(),
        };
        if self.critical_vector.len() == D {
            watch.lanczos.start = std::mem::take(&mut self.critical_vector);
        }
        self.watch = Some(watch);
    }

    /// The number of sub-steps of this step (1 without the watch): the larger of
    /// what the critical step needs ([`Driver::critical_substeps`]) and what the
    /// particles' speeds need ([`Driver::advection_substeps`]).
    pub(super) fn substeps(&mut self) -> Result<usize, StepError> {
        let critical = self.critical_substeps()?;
        if self.watch.is_none() {
            return Ok(critical);
        }
        let advection = self.advection_substeps()?;
        let w = self.watch.as_mut().expect("the watch is on");
        w.pending = (critical, advection);
        Ok(critical.max(advection))
    }

    /// Books the sub-steps of a step taken whole ([`Driver::substeps`]), `taken` of
    /// them in all: in the watch's counts only once the step completed.
    pub(super) fn book_substeps(&mut self, taken: usize) {
        let step = self.step;
        let Some(w) = self.watch.as_mut() else {
            return;
        };
        // More taken than planned: the step was split again for the critical step
        // ([`Driver::resplit_substeps`]).
        let (mut critical, advection) = w.pending;
        if taken > critical.max(advection) {
            critical = taken;
        }
        if advection > critical {
            w.advected_steps += 1;
            if w.fastest.is_none_or(|(speed, _)| w.speed > speed) {
                w.fastest = Some((w.speed, step));
            }
        } else if critical > 1 {
            w.split_steps += 1;
        }
        w.most_substeps = w.most_substeps.max(critical.max(advection));
    }

    /// The sub-steps that keep every particle's move in a (sub-)step within
    /// [`ADVECTION_SHARE`] of its element's width (the smallest altitude), and,
    /// near a contact wall ([`Driver::near_contact_walls`]), within
    /// [`CONTACT_SHARE`] of its contact distance: the critical step knows the stiffness, not the speed, and
    /// a fast body crosses elements, or a contact wall's reach, in one step (a
    /// soft block at 60 m/s moved 3.3 elements per step at `courant` 0.4 and
    /// passed through a slip wall; a contact wall's springs stop a body arriving
    /// at `v` within about `v Δt / κ`, `κ = 1/2`). The particle speed `|v_p|`
    /// bounds the speed that moves it, with what the loads' acceleration adds
    /// over the step ([`Effect::acceleration_bound`](crate::effect::Effect::acceleration_bound)):
    /// a body at rest under gravity falls `|g| Δt²` in a step, which the speed at
    /// the start does not see (a soft block with the critical step of seconds
    /// fell 40 elements, out of the mesh, in its first step). Fewer sub-steps than
    /// now only where they stay below [`ADVECTION_RELEASE`] of the limit (a
    /// hysteresis).
    fn advection_substeps(&mut self) -> Result<usize, StepError> {
        let dt = self.dt_outer;
        let gained: f64 = dt
            * self
                .effects
                .iter()
                .map(|e| e.acceleration_bound())
                .sum::<f64>();
        let (x, v, element, volume0) = (
            &self.particles.x,
            &self.particles.v,
            &self.particles.element,
            &self.particles.volume0,
        );
        let width = &self.element_width;
        let near = self.watch.as_ref().map_or(&[][..], |w| &w.near_contact[..]);
        let contact = !near.is_empty();
        // The largest share of its allowed move a particle makes in `dt`, and its
        // speed (the larger share wins; ties to the lower particle: the same for
        // any thread count).
        let worst = (0..x.len())
            .into_par_iter()
            .map(|p| {
                let speed = v[p].norm().to_f64() + gained;
                let e = element[p];
                let mut allowed = ADVECTION_SHARE * width[e];
                // Not only the particles already within a wall's reach: one on
                // the next ring crosses the reach in a step of half its element.
                if contact && near[e] {
                    let d = crate::contact::contact_distance::<D>(volume0[p].to_f64());
                    allowed = allowed.min(CONTACT_SHARE * d);
                }
                // A speed that is not a number is the step's own failure to report
                // (`StepError::NotFinite`), and an element without width has none to
                // cross.
                if speed.is_nan() || allowed <= 0.0 {
                    return (0.0, speed, p);
                }
                (speed * dt / allowed, speed, p)
            })
            .reduce(
                || (0.0, 0.0, usize::MAX),
                |a, b| {
                    if b.0 > a.0 || (b.0 == a.0 && b.2 < a.2) {
                        b
                    } else {
                        a
                    }
                },
            );
        let (share, speed, particle) = worst;
        let w = self.watch.as_mut().expect("the watch is on");
        w.speed = speed;
        let needed = share.ceil().max(1.0);
        let mut k = needed.max(w.advection_substeps as f64);
        while k > needed && share / (k - 1.0) <= ADVECTION_RELEASE {
            k -= 1.0;
        }
        if !share.is_finite() || k > MAX_SUBSTEPS as f64 {
            let at = crate::driver::failure::point(
                &x[particle].iter().map(|c| c.to_f64()).collect::<Vec<_>>(),
            );
            // A step that the largest split would carry with a margin.
            let shorter = 0.75 * MAX_SUBSTEPS as f64 / share;
            let lower = match self.dt_critical {
                Some(c) if c.is_finite() && c > 0.0 => format!(
                    "`time.courant` to {} (or `dt` to {:.2e})",
                    crate::scene::limits::echo_significant(shorter * dt / c, 2),
                    shorter * dt
                ),
                _ => format!("`dt` to {:.2e}", shorter * dt),
            };
            // The loads' share of the speed, where it is most of it.
            let moves = if gained > 0.5 * speed {
                "reaches"
            } else {
                "moves at"
            };
            let loads = if gained > 0.5 * speed {
                format!(
                    " within the step ({:.3e} of it from the loads' acceleration, {:.3e}, over the step)",
                    gained,
                    gained / dt
                )
            } else {
                String::new()
            };
            // A step far longer than a motion under the loads allows: the critical
            // step is long, which a soft or light material makes.
            let soft = if gained > 0.5 * speed {
                match self.dt_critical {
                    Some(c) if c.is_finite() && c >= dt => format!(
                        "; the critical step, {c:.3e}, is long for the motion: the material is very soft for its density (check the units of `young`, Pa, and `density`, kg/m³)"
                    ),
                    _ => String::new(),
                }
            } else {
                "; if that speed is not one the scene gives (its initial velocities and what its loads add), the run became unstable earlier (see the energy column)".to_string()
            };
            let how_far = if contact {
                "half its element's width, or a quarter of its contact distance near a contact wall"
            } else {
                "half its element's width"
            };
            return Err(StepError::TooFast {
                step: self.step + 1,
                reason: format!(
                    "particle {particle} at {at} {moves} {speed:.3e}{loads}: a step of {dt:.3e} carries it {share:.0} times as far as it may go in one sub-step ({how_far}), more than the {MAX_SUBSTEPS} sub-steps a step may be split into; lower {lower}{soft}"
                ),
            });
        }
        w.advection_substeps = k as usize;
        Ok(k as usize)
    }

    /// The error of a critical step that fell to `estimate`, below what `limit`
    /// sub-steps of the step carry, with the cause the driver sees: elements
    /// narrower than at the start, or a nearly singular mass system.
    fn critical_step_fell(&mut self, estimate: f64, limit: f64) -> StepError {
        let cause = match self.narrower_elements_cause() {
            Some(cause) => Some(cause),
            None => {
                let lumped = self.lumped_critical_time_step().ok();
                self.singular_mass_cause_with(lumped.map(|l| (estimate, l)))
            }
        };
        StepError::CriticalStepFell {
            step: self.step + 1,
            time: self.time,
            critical: estimate,
            start: self.dt_critical,
            dt: self.dt_outer,
            limit: limit as usize,
            cause,
        }
    }

    /// The most sub-steps a step may take for the critical step:
    /// [`MAX_SUBSTEPS`], times the factor by which the narrowest element the
    /// particles are in is narrower than when the watch started (at most
    /// [`NARROWER_SUBSTEPS`]): a fall of the critical step the elements explain
    /// is not a nearly singular system (a block dropped on a floor of triangles
    /// 43 times longer than high: its critical step fell 65 to 100 times as it
    /// landed, at any `courant`, since the sub-steps are at `courant` times it).
    fn critical_substep_limit(&self, watch: &Watch<T>) -> f64 {
        let narrower = match (watch.narrowest_start, watch.narrowest) {
            (Some((_, start)), Some((_, now))) if now > 0.0 => (start / now).max(1.0),
            _ => 1.0,
        };
        MAX_SUBSTEPS as f64 * narrower.min(NARROWER_SUBSTEPS)
    }

    /// The narrowest element (smallest [`element_widths`]) holding a particle, and
    /// its width (ties to the lower element: the same for any thread count).
    fn narrowest_occupied_element(&self) -> Option<(usize, f64)> {
        let width = &self.element_width;
        self.particles
            .element
            .par_iter()
            .map(|&e| (e, width[e]))
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
    }

    /// `near[e]`: element `e` lies within a contact wall's reach
    /// ([`crate::effect::Effect::walls_element`]) or shares a function with one
    /// that does (a particle there reaches the wall's reach within a sub-step of
    /// half its element's width); empty without contact walls.
    fn near_contact_walls(&self) -> Vec<bool> {
        let n = self.basis.num_elements();
        let walled: Vec<usize> = (0..n)
            .filter(|&e| self.effects.iter().any(|f| f.walls_element(e)))
            .collect();
        if walled.is_empty() {
            return Vec::new();
        }
        let mut near = vec![false; n];
        for e in walled {
            near[e] = true;
            for &i in self.basis.element_functions(e) {
                for &f in self.basis.function_support(i) {
                    near[f] = true;
                }
            }
        }
        near
    }

    /// A check of the watch ([`Driver::watch_critical_step`]) at the state just
    /// factorised, `counts` the functions active and treated in it: the estimate
    /// of the critical step, booked in `watch` (the interval to the next check,
    /// the latest and the lowest estimate, the narrowest occupied element
    /// `narrowest`, [`Driver::narrowest_occupied_element`]).
    fn watch_estimate(
        &mut self,
        watch: &mut Watch<T>,
        counts: (usize, usize),
        narrowest: Option<(usize, f64)>,
    ) -> Result<f64, StepError> {
        watch.since_check = 0;
        // Warm start: the last Ritz vector, with a share of the fixed non-smooth
        // field (for a new stiff mode elsewhere).
        let (nv, ns) = (norm(&watch.lanczos.start), watch.seed_norm);
        for (k, c) in watch.lanczos.start.iter_mut().enumerate() {
            for (i, a) in c.iter_mut().enumerate() {
                let warm = if nv > 0.0 { a.to_f64() / nv } else { 0.0 };
                *a = T::of(warm + WATCH_SEED_SHARE * seed(i, k) / ns);
            }
        }
        // A probe on the narrowest occupied element's functions: the stiffest
        // mode lives where the elements are narrowest, and a few Lanczos steps
        // find it only from a start that reaches it.
        watch.narrowest = narrowest;
        if let Some((_, narrowest)) = watch.narrowest {
            let probed = &mut watch.probed;
            probed.iter_mut().for_each(|p| *p = false);
            for &e in &self.particles.element {
                if self.element_width[e] <= WATCH_PROBE_WIDTH * narrowest {
                    for &i in self.basis.element_functions(e) {
                        probed[i] = true;
                    }
                }
            }
            let count = probed.iter().filter(|&&p| p).count();
            let share = WATCH_PROBE_SHARE / ((D * count.max(1)) as f64).sqrt();
            for (k, c) in watch.lanczos.start.iter_mut().enumerate() {
                for (i, a) in c.iter_mut().enumerate() {
                    if probed[i] {
                        *a += T::of(share * seed(i, k).signum());
                    }
                }
            }
        }
        // The watch is out of `self` while it runs, so its buffers lend directly.
        let estimate = self.lanczos_critical(&mut watch.lanczos, WATCH_ITERATIONS)?;
        // A steady estimate of an unchanged system: the interval doubles, up to
        // `WATCH_EVERY_MOST`; else it is back to `WATCH_EVERY`.
        let steady = counts == watch.counts
            && watch
                .latest
                .is_some_and(|last| (estimate / last - 1.0).abs() < WATCH_STEADY);
        watch.interval = if steady {
            (2 * watch.interval).min(WATCH_EVERY_MOST)
        } else {
            WATCH_EVERY
        };
        watch.counts = counts;
        #[cfg(test)]
        {
            let mut cold = Lanczos::new(D, self.basis.num_functions(), 0);
            let reference = self.lanczos_critical(&mut cold, 40)?;
            watch.audit.push((estimate, reference));
        }
        watch.latest = Some(estimate);
        watch.latest_step = self.step + 1;
        if watch.lowest.is_none_or(|(low, _, _)| estimate < low) {
            watch.lowest = Some((estimate, self.step + 1, self.time));
        }
        Ok(estimate)
    }

    /// Within a split step, after sub-step `taken` of `planned` ([`Driver::step`]):
    /// where the functions the strategy's system holds or treats changed since the
    /// last check, the watch checks again, and where the sub-steps left are above
    /// `trigger` times the new estimate, the rest of the step (`remaining` of
    /// time) is split again at `courant`: the new count of its sub-steps. A body
    /// entering elements much narrower than its own meets their stiffness within
    /// the step (a block sliding into triangles 100 times longer than high: the
    /// critical step fell from 1.3e-3 to 6.4e-5 between two sub-steps of 1.4e-4,
    /// and the next inverted an element).
    pub(super) fn resplit_substeps(
        &mut self,
        remaining: f64,
        left: usize,
        crossed: bool,
    ) -> Result<Option<usize>, StepError> {
        let Some(mut watch) = self.watch.take() else {
            return Ok(None);
        };
        let counts = (self.last_report.active, self.last_report.treated());
        let narrowest = self.narrowest_occupied_element();
        let due = counts != watch.counts
            || narrower(narrowest, watch.narrowest)
            || (crossed && watch.pending.0 > 1);
        if !due {
            self.watch = Some(watch);
            return Ok(None);
        }
        let estimate = match self.watch_estimate(&mut watch, counts, narrowest) {
            Ok(e) => e,
            Err(e) => {
                self.watch = Some(watch);
                return Err(e);
            }
        };
        if remaining / left as f64 <= watch.trigger * estimate {
            self.watch = Some(watch);
            return Ok(None);
        }
        // The whole step at this estimate: the next steps start split as far,
        // and past `MAX_SUBSTEPS` the run stops as at a check between steps.
        let dt = self.dt_outer;
        let whole = (dt / (watch.courant * estimate)).ceil();
        let limit = self.critical_substep_limit(&watch);
        if whole > limit {
            self.watch = Some(watch);
            return Err(self.critical_step_fell(estimate, limit));
        }
        watch.substeps = watch.substeps.max(whole as usize);
        let courant = watch.courant;
        self.watch = Some(watch);
        Ok(Some(
            ((remaining / (courant * estimate)).ceil() as usize).max(left + 1),
        ))
    }

    /// The sub-steps the critical step needs (1 when the watch is not due): at the
    /// state the step has just factorised (see [`Driver::watch_critical_step`]).
    fn critical_substeps(&mut self) -> Result<usize, StepError> {
        let Some(mut watch) = self.watch.take() else {
            return Ok(1);
        };
        // Due: every step while steps are split; at the interval; and once
        // `WATCH_EVERY` steps have passed when the strategy's system changed (the
        // functions in it, or those it treats).
        let counts = (self.last_report.active, self.last_report.treated());
        let narrowest = self.narrowest_occupied_element();
        watch.since_check += 1;
        let due = watch.substeps > 1
            || watch.since_check >= watch.interval
            || (counts != watch.counts && watch.since_check >= WATCH_CHANGED)
            || narrower(narrowest, watch.narrowest);
        if !due {
            let k = watch.substeps;
            self.watch = Some(watch);
            return Ok(k);
        }
        let estimate = match self.watch_estimate(&mut watch, counts, narrowest) {
            Ok(e) => e,
            Err(e) => {
                self.watch = Some(watch);
                return Err(e);
            }
        };
        let dt = self.dt_outer;
        let k = substep_count(dt, estimate, watch.courant, watch.trigger, watch.substeps);
        let limit = self.critical_substep_limit(&watch);
        if k > limit {
            self.watch = Some(watch);
            return Err(self.critical_step_fell(estimate, limit));
        }
        let k = k as usize;
        watch.substeps = k;
        self.watch = Some(watch);
        Ok(k)
    }
}

/// The share of its element's width (smallest altitude) a particle may cross in
/// one (sub-)step ([`Driver::watch_critical_step`], the limit on the speeds).
pub const ADVECTION_SHARE: f64 = 0.5;
/// The share of its contact distance a particle near a contact wall may cross in
/// one (sub-)step ([`Driver::watch_critical_step`]).
pub const CONTACT_SHARE: f64 = 0.25;
/// Split steps return to fewer sub-steps for the speeds only where the particles'
/// moves stay below this share of what they may cross.
pub const ADVECTION_RELEASE: f64 = 0.8;

/// The width of each element: its smallest altitude `2 A / L` (`A` its area, `L`
/// its longest edge; in 1D its length), from its polynomial pieces.
pub(super) fn element_widths<T: Scalar, const D: usize, B: Basis<T, D>>(basis: &B) -> Vec<f64> {
    let mut pieces = Vec::new();
    (0..basis.num_elements())
        .map(|e| {
            pieces.clear();
            basis.polynomial_pieces(e, &mut pieces);
            let mut diameter = 0.0f64;
            for a in &pieces {
                for b in &pieces {
                    diameter = diameter.max((a - b).norm());
                }
            }
            if D == 1 {
                return diameter;
            }
            let area: f64 = pieces
                .chunks(D + 1)
                .map(|s| {
                    let (u, w) = (s[1] - s[0], s[2] - s[0]);
                    0.5 * (u[0] * w[1] - u[1] * w[0]).abs()
                })
                .sum();
            if diameter > 0.0 {
                2.0 * area / diameter
            } else {
                0.0
            }
        })
        .collect()
}

/// The sub-steps of a step `Δt = dt` at the critical step `estimate`, with
/// `current` sub-steps now ([`Driver::watch_critical_step`]): `⌈Δt / (courant
/// Δt_crit)⌉` when `Δt` is above `trigger` times the estimate, else 1; fewer
/// than `current` only where they stand clear of the trigger, below the middle of
/// `courant` and `trigger` (a hysteresis). A change of the step's length near the
/// critical step changes the energy of the fastest modes (their displacement, at
/// a step near the limit, is large against their velocity), and an estimate
/// hovering at the trigger would switch at every check: a column at a fixed `dt`
/// of 0.93 of its critical step switched 35 times and gained 26 % of its energy,
/// against 6 % taken whole (`docs/stability.md`).
fn substep_count(dt: f64, estimate: f64, courant: f64, trigger: f64, current: usize) -> f64 {
    if !estimate.is_finite() {
        return 1.0;
    }
    let needed = if dt > trigger * estimate {
        (dt / (courant * estimate)).ceil()
    } else {
        1.0
    };
    let release = 0.5 * (courant + trigger);
    let mut k = needed.max(current as f64);
    while k > needed && dt / (k - 1.0) <= release * estimate {
        k -= 1.0;
    }
    k
}

/// The watch over the critical step while the bodies move
/// ([`Driver::watch_critical_step`]).
#[derive(Debug, Clone)]
pub(super) struct Watch<T> {
    /// The Courant number of the sub-steps.
    pub courant: f64,
    /// Steps are split when `Δt` is above this multiple of the estimate.
    pub trigger: f64,
    /// The Lanczos buffers; the start vector is the last check's Ritz vector.
    pub lanczos: Lanczos<T>,
    /// `‖seed‖` over the basis's functions and the components.
    pub seed_norm: f64,
    /// The latest estimate of the critical step.
    pub latest: Option<f64>,
    /// The step (1-based) of the latest estimate; 0 for the start's.
    pub latest_step: usize,
    /// The lowest estimate, with the step (1-based) and the time at which it was made.
    pub lowest: Option<(f64, usize, f64)>,
    /// The sub-steps the critical step needs now ([`Driver::critical_substeps`]; the
    /// step takes the larger of this and [`Watch::advection_substeps`]).
    pub substeps: usize,
    /// Steps taken in more than one sub-step for the critical step.
    pub split_steps: usize,
    /// The most sub-steps of one step.
    pub most_substeps: usize,
    /// The sub-steps the particles' speeds need now
    /// ([`Driver::advection_substeps`]).
    pub advection_substeps: usize,
    /// Steps split further for the particles' speeds than the critical step needs.
    pub advected_steps: usize,
    /// The largest particle speed at this step's check of the speeds.
    pub speed: f64,
    /// The largest speed that split a step for the speeds, and the step (1-based).
    pub fastest: Option<(f64, usize)>,
    /// The sub-steps of the step under way for the critical step and for the
    /// speeds, booked once it completes ([`Driver::book_substeps`]).
    pub pending: (usize, usize),
    /// The elements within a contact wall's reach and those sharing a function
    /// with one ([`Driver::near_contact_walls`]); empty without contact walls.
    pub near_contact: Vec<bool>,
    /// Steps since the last check.
    pub since_check: usize,
    /// Steps between checks, from [`WATCH_EVERY`] to [`WATCH_EVERY_MOST`].
    pub interval: usize,
    /// The functions active and treated in the system at the last check.
    pub counts: (usize, usize),
    /// The narrowest element a particle was in at the last check, and its width.
    pub narrowest: Option<(usize, f64)>,
    /// The same when the watch started.
    pub narrowest_start: Option<(usize, f64)>,
    /// The functions of the probe ([`WATCH_PROBE_SHARE`]) at the last check.
    pub probed: Vec<bool>,
    /// Each check's estimate beside a cold 40-step Lanczos estimate at the same
    /// state (tests only).
    #[cfg(test)]
    pub audit: Vec<(f64, f64)>,
}

/// What the watch over the critical step saw over the run
/// ([`Driver::watch_critical_step`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WatchReport {
    /// The latest estimate of the critical step.
    pub latest: Option<f64>,
    /// The lowest estimate, the step (1-based) and the time at the start of it.
    pub lowest: Option<(f64, usize, f64)>,
    /// Steps taken in more than one sub-step for the critical step.
    pub split_steps: usize,
    /// The most sub-steps of one step.
    pub most_substeps: usize,
    /// Steps split further for the particles' speeds than the critical step
    /// needs, and the largest speed that split one (with its step, 1-based).
    pub advected_steps: usize,
    pub fastest: Option<(f64, usize)>,
}

/// Steps between two checks of the critical step while the bodies move, after a
/// change (of the estimate by `WATCH_STEADY` or more, or of the functions the
/// strategy's system holds or treats).
pub const WATCH_EVERY: usize = 4;
/// Steps from the last check after which a change of the functions the
/// strategy's system holds or treats makes a check due.
pub const WATCH_CHANGED: usize = 8;
/// Most steps between two checks, reached by doubling while the estimate is steady.
pub const WATCH_EVERY_MOST: usize = 32;
/// The relative change of the estimate under which it counts as steady.
pub const WATCH_STEADY: f64 = 0.02;
/// Lanczos steps of a check, from the last check's Ritz vector.
pub const WATCH_ITERATIONS: usize = 4;
/// The share (in norm) of the fixed start field added to the last Ritz vector at each check.
pub const WATCH_SEED_SHARE: f64 = 0.3;
/// The share (in norm) of the probe on the narrowest occupied element's
/// functions added to the start of each check ([`Driver::watch_estimate`]).
pub const WATCH_PROBE_SHARE: f64 = 0.3;
/// The probe covers the functions of every occupied element at most this many
/// times as wide as the narrowest occupied one.
pub const WATCH_PROBE_WIDTH: f64 = 2.0;
/// A check is due at once, between steps or within a split one, when a particle
/// is in an element narrower than this share of the narrowest at the last check.
pub const WATCH_NARROWER: f64 = 0.5;

/// A particle is in an element narrower than [`WATCH_NARROWER`] times the
/// narrowest at the last check (`last`).
fn narrower(now: Option<(usize, f64)>, last: Option<(usize, f64)>) -> bool {
    match (now, last) {
        (Some((_, width)), Some((_, last))) => width < WATCH_NARROWER * last,
        (Some(_), None) => true,
        _ => false,
    }
}

/// Most sub-steps one step may be split into before the run stops: a critical
/// step that fell that far means a nearly singular mass system or a collapse.
pub const MAX_SUBSTEPS: usize = 64;
/// The largest factor [`MAX_SUBSTEPS`] grows by for the critical step where the
/// particles are in elements narrower than at the start
/// ([`Driver::critical_substep_limit`]).
pub const NARROWER_SUBSTEPS: f64 = 16.0;

/// The fixed non-smooth field the power iterations start from (it excites the
/// highest modes): entry `i` of component `k`.
fn seed(i: usize, k: usize) -> f64 {
    1.0 + ((i * 7 + k * 3) % 11) as f64 * 0.1 * if i % 2 == 0 { 1.0 } else { -1.0 }
}

/// [`seed`] as a field of `d` components of `n` entries.
fn seed_field<T: Scalar>(d: usize, n: usize) -> Vec<Vec<T>> {
    (0..d)
        .map(|k| (0..n).map(|i| T::of(seed(i, k))).collect())
        .collect()
}

/// The Euclidean norm of a field of `D` components.
fn norm<T: Scalar>(v: &[Vec<T>]) -> f64 {
    v.iter()
        .flat_map(|c| c.iter())
        .map(|a| (*a * *a).to_f64())
        .sum::<f64>()
        .sqrt()
}

/// `f_i = Σ_p V_p σ(∇v_p) ∇phi_i(x_p)` with the small-strain law
/// `σ = λ_p tr(ε) I + 2 μ_p ε`, `ε = sym ∇v`, and the Lamé constants `lame(p)` of
/// each particle's material (the stiffness applied to `v`; with bodies of several
/// materials, each particle's own, so the estimate is that of the stiffest mode of
/// the whole system). Summed element by element on the pool and gathered in
/// element order, as the step's forces are: the same bits for any thread count.
#[allow(clippy::too_many_arguments)]
fn stiffness_product<T: Scalar, const D: usize>(
    evals: &phases::Evaluations<T, D>,
    bins: &phases::Bins,
    gather: &phases::Gather,
    local: &mut phases::Local<T, D>,
    volume: &[T],
    lame: impl Fn(usize) -> (f64, f64) + Sync,
    v: &[Vec<T>],
    f: &mut [Vec<T>],
) {
    phases::zero(f);
    local.for_each_vector(bins, |e, lv| {
        let functions = evals.element_functions(e);
        for &p in bins.particles(e) {
            let p = p as usize;
            let (lambda, mu) = lame(p);
            let range = evals.range(p);
            let mut grad = SMatrix::<T, D, D>::zeros();
            for (s, &i) in range.clone().zip(functions) {
                for k in 0..D {
                    for l in 0..D {
                        grad[(k, l)] += v[k][i as usize] * evals.grad_phi[s][l];
                    }
                }
            }
            let eps = (grad + grad.transpose()) * T::of(0.5);
            let sigma = SMatrix::<T, D, D>::identity() * (T::of(lambda) * eps.trace())
                + eps * T::of(2.0 * mu);
            for (a, s) in range.enumerate() {
                let g = sigma * evals.grad_phi[s] * volume[p];
                for k in 0..D {
                    lv[a * D + k] += g[k];
                }
            }
        }
    });
    gather.functions(local, false, f);
}

/// Lanczos steps at most ([`Driver::lanczos_critical`]).
pub const MAX_LANCZOS: usize = 64;

/// The buffers of [`Driver::lanczos_critical`]: the start vector, the Lanczos
/// vectors kept for the Ritz vector, and four work fields, `D` components of one
/// entry per function each.
#[derive(Debug, Clone)]
pub(super) struct Lanczos<T> {
    /// The start vector; after a run, the Ritz vector of the largest eigenvalue
    /// when every Lanczos vector was kept.
    pub start: Vec<Vec<T>>,
    /// The Lanczos vectors `q_j`, kept for the Ritz vector (as many as fit).
    kept: Vec<Vec<Vec<T>>>,
    previous: Vec<Vec<T>>,
    current: Vec<Vec<T>>,
    k_current: Vec<Vec<T>>,
    next: Vec<Vec<T>>,
    scratch: Vec<Vec<T>>,
}

impl<T: Scalar> Lanczos<T> {
    /// Buffers for `n` functions in `d` components, the start [`seed`], keeping
    /// `keep` Lanczos vectors for the Ritz vector.
    pub fn new(d: usize, n: usize, keep: usize) -> Self {
        let field = || vec![vec![T::zero(); n]; d];
        Self {
            start: seed_field(d, n),
            kept: (0..keep).map(|_| field()).collect(),
            previous: field(),
            current: field(),
            k_current: field(),
            next: field(),
            scratch: field(),
        }
    }
}

/// `out = M_c v`, `M_c = Σ_p m_p phi(x_p) phi(x_p)ᵀ` the consistent mass of the
/// particles (paper eq. (13)), per component, without the matrix; element by
/// element like [`stiffness_product`].
fn consistent_mass_product<T: Scalar, const D: usize>(
    evals: &phases::Evaluations<T, D>,
    bins: &phases::Bins,
    gather: &phases::Gather,
    local: &mut phases::Local<T, D>,
    mass: &[T],
    v: &[Vec<T>],
    out: &mut [Vec<T>],
) {
    phases::zero(out);
    local.for_each_vector(bins, |e, lv| {
        let functions = evals.element_functions(e);
        for &p in bins.particles(e) {
            let p = p as usize;
            let range = evals.range(p);
            for k in 0..D {
                let mut at = T::zero();
                for (s, &i) in range.clone().zip(functions) {
                    at += evals.phi[s] * v[k][i as usize];
                }
                let at = at * mass[p];
                for (a, s) in range.clone().enumerate() {
                    lv[a * D + k] += evals.phi[s] * at;
                }
            }
        }
    });
    gather.functions(local, false, out);
}

/// `Σ_k x_k · y_k` in `f64`.
fn dot<T: Scalar>(x: &[Vec<T>], y: &[Vec<T>]) -> f64 {
    x.iter()
        .zip(y)
        .flat_map(|(a, b)| a.iter().zip(b))
        .map(|(a, b)| (*a * *b).to_f64())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::{stiffness_product, Lanczos};
    use crate::driver::Driver;
    use crate::mass::tridiagonal_extremes;
    use crate::mass::{MassKind, MassStrategy};
    use crate::material::{Elastic, LinearElastic};
    use crate::particles::Particles;
    use nalgebra::{DMatrix, SVector};
    use psmpm_basis::basis::linear::Linear;
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    use psmpm_basis::mesh::generators::block_grid;
    use psmpm_basis::Basis;

    /// `λ_max(M⁻¹K)` computed densely: `M` and `K` assembled column by column from
    /// the driver's own evaluations, then the symmetric eigenvalues of `L⁻¹ K L⁻ᵀ`.
    fn dense_critical<B: Basis<f64, 2>>(basis: B) -> (f64, f64, f64) {
        let (nx, ny) = (12, 12);
        let mut positions = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                positions.push(SVector::<f64, 2>::new(
                    (i as f64 + 0.5) / nx as f64 * 2.0,
                    (j as f64 + 0.5) / ny as f64,
                ));
            }
        }
        let n_p = positions.len();
        let volume = 2.0 / n_p as f64;
        let particles = Particles::new(positions, vec![volume; n_p], 3.0);
        let material = LinearElastic::new(Elastic::new(100.0, 0.3, 3.0).unwrap(), 2);
        let mut driver: Driver<f64, 2, B, Box<dyn MassStrategy<f64>>, _> = Driver::new(
            basis,
            particles,
            material,
            MassKind::Consistent.build(),
            &[],
            Vec::new(),
            1e-3,
        )
        .unwrap();
        let estimate = driver.critical_time_step().unwrap();
        let n = driver.basis.num_functions();
        let lanczos = driver
            .lanczos_critical(&mut Lanczos::new(2, n, 0), 30)
            .unwrap();
        let e = &driver.evals;
        let mut m = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for p in 0..n_p {
            let mass = driver.particles.mass[p];
            for (s, i) in e.entries(p) {
                for (r, j) in e.entries(p) {
                    let v = mass * e.phi[s] * e.phi[r];
                    for k in 0..2 {
                        m[(k * n + i, k * n + j)] += v;
                    }
                }
            }
        }
        let (lambda, mu) = Elastic::new(100.0, 0.3, 3.0).unwrap().lame(2);
        let mut k = DMatrix::<f64>::zeros(2 * n, 2 * n);
        let mut f = vec![vec![0.0; n]; 2];
        for col in 0..2 * n {
            let mut v = vec![vec![0.0; n]; 2];
            v[col / n][col % n] = 1.0;
            stiffness_product(
                &driver.evals,
                &driver.bins,
                &driver.gather,
                &mut driver.local,
                &driver.particles.volume,
                |_| (lambda, mu),
                &v,
                &mut f,
            );
            for row in 0..2 * n {
                k[(row, col)] = f[row / n][row % n];
            }
        }
        let l = m
            .cholesky()
            .expect("the consistent mass of a filled mesh")
            .l();
        let l_inv = l.clone().try_inverse().unwrap();
        let a = &l_inv * &k * l_inv.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let lambda_max = a.symmetric_eigenvalues().max();
        (estimate, lanczos, 2.0 / lambda_max.sqrt())
    }

    #[test]
    fn the_critical_step_matches_a_dense_eigenvalue_computation() {
        let mesh = || block_grid(0.0, 2.0, 0.0, 1.0, 4, 2).unwrap();
        for (name, (estimate, lanczos, exact)) in [
            (
                "PS",
                dense_critical(PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap()),
            ),
            ("PL", dense_critical(Linear::<f64>::new(mesh()))),
        ] {
            println!("{name}: power iteration {estimate:.6e}, dense {exact:.6e}");
            // The estimate is never below the true critical step by more than the
            // iteration's round-off, and within 5 % of it after 40 iterations.
            assert!(
                estimate >= exact * (1.0 - 1e-9),
                "{name}: {estimate} < {exact}"
            );
            assert!(estimate <= exact * 1.05, "{name}: {estimate} vs {exact}");
            // Lanczos in the stiffness's inner product: 30 steps give it to round-off.
            println!("{name}: Lanczos {lanczos:.9e}, dense {exact:.9e}");
            assert!(
                (lanczos / exact - 1.0).abs() < 1e-8,
                "{name}: {lanczos} vs {exact}"
            );
        }
    }

    /// Sub-steps at `courant = 0.5` (trigger 0.625): a step is split when it
    /// passes the trigger, and goes back to fewer sub-steps only below 0.5625 of
    /// the estimate, not as soon as it is under the trigger again.
    #[test]
    fn split_steps_return_to_fewer_sub_steps_only_clear_of_the_trigger() {
        let (c, trigger) = (0.5, 0.625);
        let count = |ratio: f64, current| super::substep_count(ratio, 1.0, c, trigger, current);
        assert_eq!(count(0.6, 1), 1.0);
        assert_eq!(count(0.7, 1), 2.0);
        // Back under the trigger, but above the middle: still split.
        assert_eq!(count(0.6, 2), 2.0);
        assert_eq!(count(0.57, 2), 2.0);
        assert_eq!(count(0.56, 2), 1.0);
        // From three sub-steps: to two where two are needed and clear (1.0 / 2 ≤
        // 0.5625).
        assert_eq!(count(1.0, 3), 2.0);
        assert_eq!(count(1.2, 3), 3.0);
        // More are needed: taken at once.
        assert_eq!(count(1.6, 2), 4.0);
        assert_eq!(super::substep_count(1.0, f64::INFINITY, c, trigger, 3), 1.0);
    }

    #[test]
    fn the_largest_eigenvalue_of_a_tridiagonal_matrix() {
        // diag 2, off-diagonal −1: eigenvalues 2 − 2 cos(k π / (m + 1)).
        for m in [1usize, 2, 5, 20] {
            let alpha = vec![2.0; m];
            let beta = vec![-1.0; m];
            let exact = 2.0 + 2.0 * (std::f64::consts::PI / (m + 1) as f64).cos();
            let got = tridiagonal_extremes(&alpha, &beta[1..]).1;
            assert!(
                (got - exact).abs() < 1e-12 * exact,
                "m = {m}: {got} vs {exact}"
            );
        }
        // Uncoupled rows: the largest diagonal entry.
        let got = tridiagonal_extremes(&[1.0, 5.0, 3.0], &[0.0, 0.0]).1;
        assert!((got - 5.0).abs() < 1e-12, "{got}");
    }

    /// A PS block thrown across a mostly empty mesh with the default mass: the
    /// functions its particles cover change, and with them the critical step. At
    /// every check the watch's estimate (4 Lanczos steps from the last Ritz vector)
    /// is compared with a cold 40-step estimate at the same state.
    #[test]
    fn the_watch_follows_the_critical_step_of_a_moving_body() {
        let mesh = block_grid(0.0, 2.0, 0.0, 2.0, 8, 8).unwrap();
        let basis = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
        let (nx, ny) = (12, 6);
        let mut positions = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                positions.push(SVector::<f64, 2>::new(
                    0.2 + (i as f64 + 0.5) / nx as f64,
                    1.2 + 0.5 * (j as f64 + 0.5) / ny as f64,
                ));
            }
        }
        let n_p = positions.len();
        let mut particles = Particles::new(positions, vec![0.5 / n_p as f64; n_p], 100.0);
        for v in &mut particles.v {
            *v = SVector::<f64, 2>::new(1.5, -2.0);
        }
        let elastic = Elastic::new(1e5, 0.3, 100.0).unwrap();
        let material = LinearElastic::new(elastic, 2);
        let mut driver: Driver<f64, 2, _, Box<dyn MassStrategy<f64>>, _> = Driver::new(
            basis,
            particles,
            material,
            MassKind::default().build(),
            &[],
            Vec::new(),
            1e-3,
        )
        .unwrap();
        let start = driver.critical_time_step().unwrap();
        driver.set_dt(0.7 * start);
        driver.watch_critical_step(0.7, 0.85);
        let steps = (0.45 / driver.dt()) as usize;
        for _ in 0..steps {
            driver.step().unwrap();
        }
        let watch = driver.watch.as_ref().unwrap();
        let mut ratios: Vec<f64> = watch.audit.iter().map(|(e, r)| e / r).collect();
        ratios.sort_by(f64::total_cmp);
        let quantile = |q: f64| ratios[((ratios.len() - 1) as f64 * q) as usize];
        let lowest = watch.lowest.unwrap().0;
        println!(
            "{} checks in {steps} steps; estimate ÷ cold estimate: median {:.4}, 90 % {:.4}, largest {:.4}; lowest critical step {:.3e} ({:.2} of the start's), {} steps split",
            ratios.len(),
            quantile(0.5),
            quantile(0.9),
            ratios[ratios.len() - 1],
            lowest,
            lowest / start,
            watch.split_steps
        );
        assert!(ratios.len() >= steps / 32, "{} checks", ratios.len());
        // Never far below the cold estimate (both are upper bounds of the true
        // critical step; the cold one is the tighter).
        assert!(ratios[0] > 0.99, "{ratios:?}");
        assert!(quantile(0.9) < 1.05, "{ratios:?}");
        assert!(ratios[ratios.len() - 1] < 1.25, "{ratios:?}");
        // The body crossed into new functions and the step followed.
        assert!(lowest < 0.9 * start, "{lowest} vs {start}");
    }
}
