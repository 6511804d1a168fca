//! Mass strategies: how the system `M a = F` (paper eq. (17)) and the velocity
//! projection `M v̂ = P` (eq. (20)) are solved, with
//! `M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)` (eq. (13)).
//!
//! Each strategy is its own type, configured by value and chosen once at set-up
//! ([`MassKind::build`]); the driver asks it ([`MassStrategy::needs`]) which
//! per-step facts it uses and computes only those.
//!
//! | [`MassKind`] | type | what is solved |
//! |---|---|---|
//! | `consistent` | [`Consistent`] | `M` itself, sparse Cholesky |
//! | `lumped` | [`Lumped`] | row sums `M_ii^L = Σ_j M_ij` |
//! | `partial`, `partial:TAU`, `partial-coverage:C` | [`Partial`] | `M` with some rows lumped (thesis §5.3; by `M_ii`; by particle coverage) |
//! | `deactivate[:THRESHOLD]` | [`Deactivate`] | `M` without the functions with `M_ii < threshold` (thesis §5.2) |
//! | `extended[:C]` | [`Extended`] | `Eᵀ M E`: functions covered below `C` expressed through well-covered neighbours |
//! | `extended-hybrid[:C1:C2]` (the default, `0.02:0.75`) | [`Extended`] | `Eᵀ M_A E`: functions covered below `C1` extended, the rows of those covered in `[C1, C2)` or sampled by less than one particle lumped in `M_A` except for the part an affine field sees ([`Correction::InMass`]) |
//! | `extended-hybrid-apic`, `extended-hybrid-rpic`, `extended-hybrid-plain` | [`Extended`] | `Eᵀ M' E` with the rows plainly lumped and the momentum corrected for affine fields ([`Correction::Affine`]), rigid ones, or not at all |
//! | `fmpm:K` | [`Fmpm`] | no solve: the series `Σ_{j≤K} (I − M_L⁻¹ M)^j M_L⁻¹` |
//!
//! Homogeneous Dirichlet conditions come as a set of fixed coefficients per
//! component; functions with no particle in their support are inactive. Both are
//! held at zero. General (multi-term) constraints are imposed on top of any
//! strategy by [`Constraints`], so that "solve" always means solve and project.
//! What a strategy did is returned as a [`MassReport`], never printed.

mod condition;
pub(crate) use condition::tridiagonal_extremes;
mod consistent;
mod constraints;
mod deactivate;
mod extended;
mod fmpm;
mod lumped;
mod masked;
mod partial;
pub mod support;

pub use condition::CONDITION_ITERATIONS;
pub use consistent::Consistent;
pub use constraints::Constraints;
pub use deactivate::Deactivate;
pub use extended::{Extended, DEFAULT_COVERAGE};
pub use fmpm::Fmpm;
pub use lumped::Lumped;
pub use partial::{LumpRule, Partial};
pub use support::SupportFacts;

use crate::scene::limits::echo_number;
use crate::sparse::{NotPositiveDefinite, Scalar, SymmetricPattern};
use std::sync::Arc;

/// The thesis' threshold on `M_ii` below which `deactivate` removes a function.
pub const DEFAULT_DEACTIVATION_THRESHOLD: f64 = 1e-2;

/// Why a strategy could not solve the step's system.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MassError {
    /// The factorisation met a non-positive pivot.
    #[error("non-positive pivot at row {} of the reordered matrix", .0.row)]
    NotPositiveDefinite(#[from] NotPositiveDefinite),
    /// Every function with mass lies below the deactivation threshold: the system
    /// has no unknown left and nothing would move.
    #[error("every function with mass is below the deactivation threshold {} (the largest M_ii is {}), so nothing would move", echo_number(*.threshold), echo_number(*.largest))]
    NothingActive {
        /// The threshold on `M_ii`.
        threshold: f64,
        /// The largest diagonal entry of `M`.
        largest: f64,
    },
    /// An iterative solve did not reach its tolerance.
    #[error("the iterative solve stalled at relative residual {residual:.1e} after {iterations} iterations")]
    NotConverged {
        /// Iterations taken.
        iterations: usize,
        /// Relative residual reached.
        residual: f64,
    },
}

/// The mass strategy a scene or the command line asks for: the typed choice made
/// at the edge, turned into a strategy once by [`MassKind::build`].
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
    /// Extension: functions whose support is covered by particles below
    /// `coverage` are expressed through well-covered neighbours.
    Extended {
        /// Coverage threshold (fraction of the support's integral).
        coverage: f64,
    },
    /// Extension of the functions covered below `extend`, and the rows of the
    /// functions covered in `[extend, lump)` lumped.
    ExtendedHybrid {
        /// Coverage below which a function is extended.
        extend: f64,
        /// Coverage below which (and at or above `extend`) a row is lumped.
        lump: f64,
        /// How the momentum of the lumped rows is corrected.
        correction: Correction,
        /// Coverage below which a function a wall constrains is extended instead
        /// of lumped (`0`: none; the third number of `extended-hybrid:C1:C2:W`).
        walls: f64,
    },
    /// Truncated series for `M⁻¹` preconditioned by the lumped mass.
    Fmpm {
        /// Number of correction terms `K` (`0` is the lumped mass).
        order: usize,
    },
}

/// Coverage below which `extended-hybrid` (without numbers) extends a function
/// (its `C1`): only functions with almost no particles leave the solve.
pub const DEFAULT_HYBRID_EXTEND: f64 = 0.02;
/// Coverage below which `extended-hybrid` (without numbers) lumps a function's row
/// (its `C2`).
pub const DEFAULT_HYBRID_LUMP: f64 = 0.75;

impl Default for MassKind {
    /// The default strategy of every basis: the hybrid extension (functions covered
    /// below 0.02 extended, rows covered below 0.75 lumped in the affine-preserving
    /// way, [`Correction::InMass`]; on a basis of degree 1, PL, that way keeps
    /// only a share 0.1 of plain lumping, `driver::phases::add_affine_lumping`;
    /// `docs/stability.md`).
    fn default() -> Self {
        MassKind::ExtendedHybrid {
            extend: DEFAULT_HYBRID_EXTEND,
            lump: DEFAULT_HYBRID_LUMP,
            correction: Correction::InMass,
            walls: 0.0,
        }
    }
}

/// Names [`MassKind::parse`] knows, for messages.
pub const MASS_NAMES: &str = "default, consistent, lumped, partial, partial:TAU, partial-coverage:C, deactivate, deactivate:THRESHOLD, extended, extended:C, extended-hybrid, extended-hybrid:C1:C2[:W], extended-hybrid-apic[:C1:C2], extended-hybrid-rpic[:C1:C2], extended-hybrid-plain[:C1:C2], fmpm:K";

impl MassKind {
    /// Parses `default`, `consistent`, `lumped`, `partial` (seed rule), `partial:TAU`
    /// (threshold rule), `partial-coverage:C`, `deactivate` (threshold 1e-2),
    /// `deactivate:THRESHOLD`, `extended` (default coverage), `extended:C`,
    /// `extended-hybrid:C1:C2` (`C1 ≤ C2`), `extended-hybrid:C1:C2:W` (wall
    /// functions covered below `W` extended), `fmpm:K`.
    pub fn parse(name: &str) -> Result<Self, String> {
        let (head, arg) = match name.split_once(':') {
            Some((h, a)) => (h, Some(a)),
            None => (name, None),
        };
        let shown = crate::scene::limits::echo(name);
        // A number that parses but is not finite (`1e400` overflows to infinity,
        // `nan`) is named as such, with the range wanted: "must be positive" would
        // hide why `1e400` fails.
        let not_finite = |a: &str, v: f64, what: &str, range: &str| {
            let why = if v.is_nan() {
                "is not a number".to_string()
            } else {
                format!(
                    "is not finite (it reads as {}infinity: beyond ±1.8e308)",
                    if v < 0.0 { "minus " } else { "" }
                )
            };
            format!(
                "`{shown}`: the {what} `{}` {why}; give {range}",
                crate::scene::limits::echo(a)
            )
        };
        let number = |a: &str| -> Result<f64, String> {
            match a.parse::<f64>() {
                Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
                Ok(v) if !v.is_finite() => {
                    Err(not_finite(a, v, "threshold", "a positive finite number"))
                }
                _ => Err(format!(
                    "`{shown}`: the threshold must be a positive number, got `{}`",
                    crate::scene::limits::echo(a)
                )),
            }
        };
        let fraction = |a: &str| -> Result<f64, String> {
            match a.parse::<f64>() {
                Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
                Ok(v) if !v.is_finite() => Err(not_finite(a, v, "coverage", "a number in (0, 1)")),
                _ => Err(format!(
                    "`{shown}`: the coverage must be a number in (0, 1), got `{}`",
                    crate::scene::limits::echo(a)
                )),
            }
        };
        match (head, arg) {
            ("default", None) => Ok(MassKind::default()),
            ("consistent", None) => Ok(MassKind::Consistent),
            ("lumped", None) => Ok(MassKind::Lumped),
            ("partial", None) => Ok(MassKind::Partial(LumpRule::EmptyElement)),
            ("partial", Some(a)) => {
                let tau = number(a)?;
                // `M_ii < TAU max M_jj` with `TAU ≥ 1` lumps every row but the
                // largest: `lumped` under another name.
                if tau >= 1.0 {
                    return Err(format!(
                        "`{shown}`: the threshold is a fraction of the largest diagonal entry, so at 1 or more it lumps every row but the largest, which is `lumped`: give a number below 1 (e.g. `partial:0.1`), or `lumped`"
                    ));
                }
                Ok(MassKind::Partial(LumpRule::Threshold(tau)))
            }
            ("partial-coverage", Some(a)) => {
                Ok(MassKind::Partial(LumpRule::Coverage(fraction(a)?)))
            }
            ("deactivate", None) => Ok(MassKind::Deactivate {
                threshold: DEFAULT_DEACTIVATION_THRESHOLD,
            }),
            ("deactivate", Some(a)) => Ok(MassKind::Deactivate {
                threshold: number(a)?,
            }),
            ("extended", None) => Ok(MassKind::Extended {
                coverage: DEFAULT_COVERAGE,
            }),
            (hybrid, None) if Correction::of_name(hybrid).is_some() => {
                Ok(MassKind::ExtendedHybrid {
                    extend: DEFAULT_HYBRID_EXTEND,
                    lump: DEFAULT_HYBRID_LUMP,
                    correction: Correction::of_name(hybrid).unwrap_or_default(),
                    walls: 0.0,
                })
            }
            ("extended", Some(a)) => Ok(MassKind::Extended {
                coverage: fraction(a)?,
            }),
            (hybrid, Some(a)) if Correction::of_name(hybrid).is_some() => {
                // `:` between the two (lists of strategies are comma-separated);
                // `,` is read too.
                let numbers: Vec<&str> = a.split([':', ',']).collect();
                let [c1, c2, rest @ ..] = &numbers[..] else {
                    return Err(format!(
                        "`{shown}`: expected two coverages `C1:C2` (or three, `C1:C2:W`), got `{}`",
                        crate::scene::limits::echo(a)
                    ));
                };
                let (extend, lump) = (fraction(c1)?, fraction(c2)?);
                if extend > lump {
                    return Err(format!(
                        "`{shown}`: the extension coverage {extend} is above the lumping coverage {lump}"
                    ));
                }
                let walls = match rest {
                    [] => 0.0,
                    [w] => fraction(w)?,
                    _ => {
                        return Err(format!(
                            "`{shown}`: expected at most three coverages `C1:C2:W`"
                        ))
                    }
                };
                Ok(MassKind::ExtendedHybrid {
                    extend,
                    lump,
                    correction: Correction::of_name(hybrid).unwrap_or_default(),
                    walls,
                })
            }
            ("fmpm", Some(a)) => a
                .parse::<usize>()
                .ok()
                .filter(|k| *k <= 64)
                .map(|order| MassKind::Fmpm { order })
                .ok_or_else(|| {
                    format!(
                        "`{shown}`: the order must be an integer in 0..=64, got `{}`",
                        crate::scene::limits::echo(a)
                    )
                }),
            _ => Err(crate::scene::names::did_you_mean(format!(
                "unknown mass strategy `{shown}` (known: {MASS_NAMES})"
            ))),
        }
    }

    /// The form [`MassKind::parse`] reads back (`partial:0.1`, `extended:0.3`).
    pub fn spec(self) -> String {
        match self {
            MassKind::Partial(LumpRule::Threshold(tau)) => format!("partial:{}", echo_number(tau)),
            MassKind::Partial(LumpRule::Coverage(c)) => {
                format!("partial-coverage:{}", echo_number(c))
            }
            MassKind::Deactivate { threshold } => format!("deactivate:{}", echo_number(threshold)),
            MassKind::Extended { coverage } if coverage != DEFAULT_COVERAGE => {
                format!("extended:{}", echo_number(coverage))
            }
            MassKind::ExtendedHybrid {
                extend,
                lump,
                correction,
                walls,
            } if walls > 0.0 => format!(
                "{}:{}:{}:{}",
                correction.hybrid_name(),
                echo_number(extend),
                echo_number(lump),
                echo_number(walls)
            ),
            MassKind::ExtendedHybrid {
                extend,
                lump,
                correction,
                ..
            } if (extend, lump) != (DEFAULT_HYBRID_EXTEND, DEFAULT_HYBRID_LUMP) => {
                format!(
                    "{}:{}:{}",
                    correction.hybrid_name(),
                    echo_number(extend),
                    echo_number(lump)
                )
            }
            MassKind::Fmpm { order } => format!("fmpm:{order}"),
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
            MassKind::Extended { .. } => "extended",
            MassKind::ExtendedHybrid { correction, .. } => correction.hybrid_name(),
            MassKind::Fmpm { .. } => "fmpm",
        }
    }

    /// The strategy this choice names, ready for [`MassStrategy::prepare`].
    pub fn build<T: Scalar>(self) -> Box<dyn MassStrategy<T>> {
        match self {
            MassKind::Consistent => Box::new(Consistent::default()),
            MassKind::Lumped => Box::new(Lumped::default()),
            MassKind::Partial(rule) => Box::new(Partial::new(rule)),
            MassKind::Deactivate { threshold } => Box::new(Deactivate::new(threshold)),
            MassKind::Extended { coverage } => Box::new(Extended::new(coverage)),
            MassKind::ExtendedHybrid {
                extend,
                lump,
                correction,
                walls,
            } => Box::new(Extended::hybrid(extend, lump, correction).with_walls(walls)),
            MassKind::Fmpm { order } => Box::new(Fmpm::new(order)),
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
    /// Functions expressed through their neighbours (extension).
    pub extended: usize,
    /// The worst-covered function the strategy solves for and its coverage
    /// (fraction of its support's integral covered by particle volume), when the
    /// strategy measures it; the functions an extension expresses through their
    /// neighbours are not solved for and are left out.
    pub worst_coverage: Option<(usize, f64)>,
    /// The largest diagonal mass `M_ii`, where the strategy compares masses
    /// with a threshold of its own (deactivation); `0` otherwise.
    pub largest_mass: f64,
    /// The share of the step's force `Σ_i |F_i|` on the rows deactivation held
    /// at zero (set after the step's solve; `0` without deactivation): their
    /// zero velocity holds the particles on them as a wall would, and this is the
    /// share of the load that wall takes.
    pub held_force_share: f64,
}

impl MassReport {
    /// Functions the strategy treated (lumped, deactivated or extended).
    pub fn treated(&self) -> usize {
        self.lumped_rows + self.deactivated + self.extended
    }
}

/// Which per-step facts a strategy uses; the driver computes only these.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Needs {
    /// `touches_empty[i]`: the support of `i` has an element without particles.
    pub empty_elements: bool,
    /// `particle_volume[i] = Σ_p V_p phi_i(x_p)`, and the [`SupportFacts`] of the basis.
    pub coverage: bool,
    /// The polynomial coefficients of the basis in [`SupportFacts`].
    pub polynomials: bool,
    /// The correction of the momentum for the rows [`MassStrategy::lumped_rows`]
    /// returns (the driver then keeps a velocity gradient per particle and the
    /// basis's points of linear precision).
    pub correction: Correction,
    /// The strategy reads only the row sums `Σ_j M_ij` of `M` (the lumped mass):
    /// the driver then assembles them on the diagonal and nothing else
    /// (`driver::phases::MassMatrix::RowSums`).
    pub row_sums_only: bool,
}

/// How the driver corrects the momentum `P` of the rows a strategy lumped, so that
/// some velocity fields still project exactly through them
/// (`driver::phases::Affine`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Correction {
    /// No correction: a lumped row smooths every field but a constant.
    #[default]
    None,
    /// Rigid-body motions (translation and rotation) project exactly: the particle
    /// velocity gradient's skew part (RPIC, Jiang et al. 2015). Lumping still
    /// smooths the straining modes; measured unstable on a jittered column and a
    /// dropped block (`docs/stability.md`), kept for the comparison.
    Rigid,
    /// Every affine field projects exactly: the whole velocity gradient (APIC,
    /// Jiang et al. 2015), added to the momentum only. Measured to dissipate the
    /// straining modes of a body after an impact (`docs/stability.md`).
    Affine,
    /// Every affine field projects exactly, through the mass matrix itself: the
    /// lumped pairs move onto the diagonal only the part of `M_ij` that an affine
    /// field does not see (`driver::phases::add_affine_lumping`). The matrix
    /// stays symmetric positive definite and serves both solves of the step, so
    /// the step's energy balance holds as with the consistent mass. No momentum
    /// correction.
    InMass,
}

impl Correction {
    /// The name of the hybrid extension with this correction.
    pub fn hybrid_name(self) -> &'static str {
        match self {
            Correction::InMass => "extended-hybrid",
            Correction::Affine => "extended-hybrid-apic",
            Correction::Rigid => "extended-hybrid-rpic",
            Correction::None => "extended-hybrid-plain",
        }
    }
    fn of_name(name: &str) -> Option<Self> {
        [
            Correction::InMass,
            Correction::Affine,
            Correction::Rigid,
            Correction::None,
        ]
        .into_iter()
        .find(|c| c.hybrid_name() == name)
    }
}

/// Per-step facts a strategy may use (empty slices for facts it did not ask for).
#[derive(Debug, Clone, Copy)]
pub struct StepContext<'a> {
    /// `touches_empty[i]`: the support of function `i` contains an element without particles.
    pub touches_empty: &'a [bool],
    /// `Σ_p V_p phi_i(x_p)`: the particle volume seen by function `i`.
    pub particle_volume: &'a [f64],
    /// `Σ_p phi_i(x_p)`: how many particles sample function `i` (each weighted by
    /// its value there); measured with the coverage.
    pub particle_count: &'a [f64],
    /// `on_wall[i]`: a wall constrains function `i` (a fixed component, or a
    /// slip wall's constraint has a term on it); empty when not measured.
    pub on_wall: &'a [bool],
    /// `live[i]`: an element holding a particle has function `i` (empty when not
    /// measured).
    pub live: &'a [bool],
    /// The true entries of `live`, ascending, when the step's gathers ran through
    /// the live functions (a body over a small part of the mesh): every function
    /// outside the list has only zero entries in the values. `None`: any function
    /// may have mass.
    pub live_list: Option<&'a [u32]>,
    /// The values hold the row sums on the diagonal and zero elsewhere (the
    /// driver assembled only those, as [`Needs::row_sums_only`] asked).
    pub diagonal_only: bool,
    /// `flat[i]`: no element of function `i`'s support that holds particles has
    /// particles that determine an affine field (fewer than `D + 1`, or nearly
    /// on a line: `driver::phases::mark_flat_functions`), so that its consistent
    /// row can be singular however many particles sample it; empty when not
    /// measured (the default strategy with a basis of degree 2 measures it).
    pub flat: &'a [bool],
}

/// What a strategy is prepared with once per mesh.
pub struct MassSetup<'a> {
    /// The sparsity pattern of `M`.
    pub pattern: &'a SymmetricPattern,
    /// `fixed[k][i]`: component `k` of coefficient `i` is held at zero (Dirichlet).
    pub fixed: &'a [Vec<bool>],
    /// Facts of the basis, when the strategy asked for them.
    pub support: Option<&'a Arc<SupportFacts>>,
}

/// How to solve the mass systems of a step.
pub trait MassStrategy<T: Scalar>: Send {
    /// The form [`MassKind::parse`] reads back.
    fn spec(&self) -> String;
    /// The per-step facts this strategy uses.
    fn needs(&self) -> Needs {
        Needs::default()
    }
    /// Set-up once per mesh (symbolic work, buffers).
    fn prepare(&mut self, setup: &MassSetup);
    /// Numeric work for the matrix whose upper triangle has `values`
    /// (`M_ij = Σ_p m_p phi_i(x_p) phi_j(x_p)`, eq. (13)), reused by every solve of the step.
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError>;
    /// Solves component `k` in place: `rhs` becomes the coefficients, zero at fixed
    /// and inactive functions.
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError>;
    /// Solves every component, `rhs[k]` with [`solve`](Self::solve)`(k, ·)`;
    /// strategies with a factorisation per fixed set solve them side by side on
    /// the pool (the same result for any thread count).
    fn solve_all(&mut self, rhs: &mut [Vec<T>]) -> Result<(), MassError> {
        solve_each(self, rhs)
    }
    /// [`solve_all`](Self::solve_all) of two sets of right-hand sides with the
    /// same systems; a strategy with a factorisation solves each component's
    /// pair in one pass over its factor.
    fn solve_all_two(
        &mut self,
        first: &mut [Vec<T>],
        second: &mut [Vec<T>],
    ) -> Result<(), MassError> {
        self.solve_all(first)?;
        self.solve_all(second)
    }
    /// For a strategy that drops the functions whose `M_ii` is below an absolute
    /// threshold (`deactivate`): that threshold, for the driver's failure messages.
    fn deactivation_threshold(&self) -> Option<f64> {
        None
    }
    /// For a strategy that holds rows with particles at zero (`deactivate`): the
    /// share of `Σ_i |F_i|` on those rows in the last
    /// [`solve_all_two`](Self::solve_all_two) (the step's solve of the forces and
    /// momenta), [`MassReport::held_force_share`].
    fn held_force_share(&self) -> f64 {
        0.0
    }
    /// `true` when the system last factorised is `M` itself on the rows it
    /// solves, every other row held at zero (no row lumped, no function
    /// extended): then `M'⁻¹ M x = x` for every `x` that vanishes off those rows.
    fn solves_mass_itself(&self) -> bool {
        false
    }
    /// An estimate of the spectral condition number of the systems last factorised
    /// (the largest over components). Costs about `2 ×` [`CONDITION_ITERATIONS`]
    /// solves; call on request.
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64;
    /// The functions whose rows were lumped in the system last factorised
    /// (`M' = M + Σ M_ij (e_i − e_j)(e_i − e_j)ᵀ` over the pairs with a lumped
    /// row), when the strategy asked ([`Needs::correction`]) for the momentum to be
    /// corrected so that rigid or affine velocity fields project exactly
    /// (`phases::update_velocities_and_momentum`). `None`: no row lumped this step,
    /// or no correction wanted.
    fn lumped_rows(&self) -> Option<&[bool]> {
        None
    }
    /// For a strategy whose [`Needs::correction`] is [`Correction::InMass`]: the
    /// functions of the step classified from `context` and the assembled `values`
    /// of `M`, before [`factorize`](Self::factorize); returns the functions whose
    /// rows are lumped, for the driver to add the affine-preserving lumping term
    /// to `values` (`driver::phases::add_affine_lumping`). `factorize` is then
    /// called with the modified values and keeps this classification. `None`: no
    /// row lumped this step.
    fn classify(
        &mut self,
        _pattern: &SymmetricPattern,
        _values: &[T],
        _context: StepContext,
    ) -> Option<&[bool]> {
        None
    }
}

impl<T: Scalar> MassStrategy<T> for Box<dyn MassStrategy<T>> {
    fn spec(&self) -> String {
        (**self).spec()
    }
    fn needs(&self) -> Needs {
        (**self).needs()
    }
    fn prepare(&mut self, setup: &MassSetup) {
        (**self).prepare(setup)
    }
    fn factorize(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Result<MassReport, MassError> {
        (**self).factorize(pattern, values, context)
    }
    fn solve(&mut self, k: usize, rhs: &mut [T]) -> Result<(), MassError> {
        (**self).solve(k, rhs)
    }
    fn solve_all(&mut self, rhs: &mut [Vec<T>]) -> Result<(), MassError> {
        (**self).solve_all(rhs)
    }
    fn solve_all_two(
        &mut self,
        first: &mut [Vec<T>],
        second: &mut [Vec<T>],
    ) -> Result<(), MassError> {
        (**self).solve_all_two(first, second)
    }
    fn solves_mass_itself(&self) -> bool {
        (**self).solves_mass_itself()
    }
    fn deactivation_threshold(&self) -> Option<f64> {
        (**self).deactivation_threshold()
    }
    fn held_force_share(&self) -> f64 {
        (**self).held_force_share()
    }
    fn condition_estimate(&mut self, pattern: &SymmetricPattern) -> f64 {
        (**self).condition_estimate(pattern)
    }
    fn lumped_rows(&self) -> Option<&[bool]> {
        (**self).lumped_rows()
    }
    fn classify(
        &mut self,
        pattern: &SymmetricPattern,
        values: &[T],
        context: StepContext,
    ) -> Option<&[bool]> {
        (**self).classify(pattern, values, context)
    }
}

/// [`MassStrategy::solve`] of every component in turn (the default of
/// [`MassStrategy::solve_all`]).
pub(crate) fn solve_each<T: Scalar, S: MassStrategy<T> + ?Sized>(
    strategy: &mut S,
    rhs: &mut [Vec<T>],
) -> Result<(), MassError> {
    for (k, r) in rhs.iter_mut().enumerate() {
        strategy.solve(k, r)?;
    }
    Ok(())
}

/// Groups the components by their set of fixed coefficients: returns the
/// distinct sets and, per component, the index of its set (one factorisation per set).
fn distinct_fixed_sets(fixed: &[Vec<bool>]) -> (Vec<Vec<bool>>, Vec<usize>) {
    let mut distinct: Vec<Vec<bool>> = Vec::new();
    let of = fixed
        .iter()
        .map(|f| match distinct.iter().position(|d| d == f) {
            Some(i) => i,
            None => {
                distinct.push(f.clone());
                distinct.len() - 1
            }
        })
        .collect();
    (distinct, of)
}

#[cfg(test)]
mod tests;
