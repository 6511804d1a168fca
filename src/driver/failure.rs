//! What a failing step can see, and the fix that fits its cause: a function with
//! almost no particle support that the strategy solves for, a time step above the
//! critical one, an inversion below it.

use super::{phases, to_f64_point, Driver, UNDER_SUPPORTED_COVERAGE};

/// A strategy's critical step this many times below the lumped mass's means its
/// mass matrix is nearly singular (an invertible particle mass matrix stays within
/// a factor of about 2–4 of its row sums' step).
pub const NEARLY_SINGULAR: f64 = 10.0;

/// A polynomial piece whose longest edge is this many times its height on it is a
/// sliver, named as the cause of an inversion in it (the six PS pieces of a
/// well-shaped triangle stay below about 4).
pub const SLIVER_ASPECT: f64 = 20.0;
use crate::mass::{MassError, MassStrategy, SupportFacts};
use crate::materials::ParticleMaterials;
use crate::sparse::Scalar;
use nalgebra::SVector;
use psmpm_basis::Basis;
use psmpm_basis::BasisError;

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// The coverage of every function (the fraction of its support's integral that
    /// particle volume covers; `None` without particles in its support), as the
    /// strategy measured it or measured here if it did not need it. For messages
    /// only: it allocates.
    fn coverage(&self) -> Vec<Option<f64>> {
        let computed;
        let (support, particle_volume) = match &self.inputs.support {
            Some(s) if self.inputs.needs.coverage => (&**s, &self.inputs.particle_volume),
            _ => {
                let mut volume = vec![0.0; self.basis.num_functions()];
                phases::particle_volume(&self.evals, &self.particles.volume, &mut volume);
                computed = (SupportFacts::new(&self.basis, &self.pattern, false), volume);
                (&computed.0, &computed.1)
            }
        };
        (0..particle_volume.len())
            .map(|i| {
                (particle_volume[i] > 0.0)
                    .then(|| SupportFacts::coverage_of(particle_volume[i], support.volume[i]))
            })
            .collect()
    }

    /// The worst-covered function with particles in its support, when it is covered
    /// below [`UNDER_SUPPORTED_COVERAGE`] and the mass strategy treated no function at
    /// the last assembly: `(function, coverage, a message naming both and the fix)`.
    /// Measured here if the strategy does not measure coverage itself (call after an
    /// assembly, e.g. after [`Driver::critical_time_step`]).
    pub fn untreated_under_supported(&self) -> Option<(usize, f64, String)> {
        if self.last_report.treated() > 0 {
            return None;
        }
        let coverage = self.coverage();
        let (i, c) = coverage
            .iter()
            .enumerate()
            .filter_map(|(i, c)| c.map(|c| (i, c)))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        (c < UNDER_SUPPORTED_COVERAGE).then(|| {
            (
                i,
                c,
                format!(
                    "function {i} at {} is covered to only {c:.1e} of its support by particles and the mass strategy `{}` solves for it, which makes the mass matrix nearly singular",
                    point(&to_f64_point(&self.basis.function_point(i))),
                    self.mass.spec()
                ),
            )
        })
    }

    /// Why the mass matrix of the last assembly is (nearly) singular, when the driver
    /// can see it: fewer particles than the functions solved for consistently (a
    /// matrix summed from `n` particle outer products has rank at most `n`), or a
    /// function with almost no particle support that the strategy solves for.
    pub fn singular_mass_cause(&self) -> Option<String> {
        self.singular_mass_cause_with(None)
    }

    /// [`Driver::singular_mass_cause`], and, when `critical` (the strategy's
    /// critical step) is [`NEARLY_SINGULAR`] times or more below `lumped_critical`
    /// (the lumped mass's), that ratio as the cause when no other is seen.
    pub fn singular_mass_cause_with(&self, critical: Option<(f64, f64)>) -> Option<String> {
        if let Some(cause) = self.singular_mass_cause_seen() {
            return Some(cause);
        }
        let (critical, lumped) = critical?;
        let ratio = lumped / critical;
        (ratio >= NEARLY_SINGULAR).then(|| {
            let spec = self.mass.spec();
            // The default extends the nearly empty functions: what is left to it is
            // the sampling. The strategies that solve for them (consistent, partial,
            // deactivate, FMPM, ...) fail on a body's edge however many particles each
            // element holds (a user's thrown block with `partial` stopped at the same
            // time with 3.8 and 13.8 per element).
            let per_element = self.particles_per_occupied_element();
            let fix = if spec.starts_with("extended-hybrid") {
                few_particles(per_element)
            } else if per_element < FEW_PER_ELEMENT {
                few_particles_or_the_default(per_element)
            } else {
                format!(
                    "the mass strategy `{spec}` solves for the nearly empty functions at the bodies' edges, which more particles per element do not fill ({per_element:.1} per occupied element here); take the default mass strategy (`mass = \"default\"`), which extends them, or `lumped`"
                )
            };
            format!(
                "its critical step is {ratio:.1e} times below the lumped mass's ({lumped:.3e}; an invertible mass stays within a few times of it): {fix}"
            )
        })
    }

    /// The particles' changes of element since the driver placed them: one per
    /// particle and location (each step and sub-step) that found it in another
    /// element than the last.
    pub fn element_changes(&self) -> u64 {
        self.element_changes
    }

    /// The width (smallest altitude; length in 1D) of the widest element that
    /// holds a particle, at the last location.
    pub fn widest_occupied_element(&self) -> f64 {
        self.particles
            .element
            .iter()
            .map(|&e| self.element_width[e])
            .fold(0.0, f64::max)
    }

    /// Per body (`body_sizes` as [`Driver::sampling_by_body`]): its extents, the
    /// smallest and the largest over the axes of its particles' spread plus their
    /// mean spacing (`(V⁰_p)^(1/D)`, so that a lattice filling a box of side 1
    /// measures 1), and the width of the widest element holding one of its
    /// particles.
    pub fn body_extents(&self, body_sizes: &[usize]) -> Vec<(f64, f64, f64)> {
        let sizes = bodies_or_one(body_sizes, self.particles.len());
        let mut first = 0;
        sizes
            .iter()
            .map(|&size| {
                let range = first..first + size;
                first += size;
                let (mut low, mut high) = ([f64::INFINITY; D], [f64::NEG_INFINITY; D]);
                let (mut spacing, mut widest) = (0.0, 0.0f64);
                for p in range {
                    for k in 0..D {
                        let x = self.particles.x[p][k].to_f64();
                        low[k] = low[k].min(x);
                        high[k] = high[k].max(x);
                    }
                    spacing += self.particles.volume0[p].to_f64().powf(1.0 / D as f64);
                    widest = widest.max(self.element_width[self.particles.element[p]]);
                }
                let spacing = spacing / size.max(1) as f64;
                let spread = |k: usize| high[k] - low[k] + spacing;
                let smallest = (0..D).map(spread).fold(f64::INFINITY, f64::min);
                let largest = (0..D).map(spread).fold(0.0, f64::max);
                (smallest, largest, widest)
            })
            .collect()
    }

    /// Particles per element that holds at least one, at the last location.
    pub fn particles_per_occupied_element(&self) -> f64 {
        let occupied = (0..self.basis.num_elements())
            .filter(|&e| self.bins.occupied(e))
            .count()
            .max(1);
        self.particles.len() as f64 / occupied as f64
    }

    /// How each body is sampled at the last location (`body_sizes`: the numbers of
    /// particles of the bodies, whose particles follow each other in that order;
    /// empty or not adding up: one body). `outside(b, x)`: the point `x` lies
    /// outside the region body `b` was placed in (`false` where that is not
    /// known), so that an empty element there is no hole in its sampling.
    pub fn sampling_by_body(
        &self,
        body_sizes: &[usize],
        outside: &dyn Fn(usize, &[f64]) -> bool,
    ) -> Vec<BodySampling> {
        let sizes = bodies_or_one(body_sizes, self.particles.len());
        let ne = self.basis.num_elements();
        // Per element, the body's particles in it (`own`), and in its closure
        // (`touching`: a particle on an edge or a vertex counts in every element
        // around it, the same on both sides for a C¹ basis, where which one point
        // location picks is a tie).
        let (mut own, mut touching) = (vec![0usize; ne], vec![0usize; ne]);
        let (mut elements, mut touched) = (Vec::new(), Vec::new());
        let mut pieces = Vec::new();
        // The empty elements around a body's (`seen_empty`: listed in `around`),
        // and which of them are holes in its particles (`hole_here`).
        let (mut seen_empty, mut hole_here) = (vec![false; ne], vec![false; ne]);
        let mut around = Vec::new();
        let mut first = 0;
        sizes
            .iter()
            .enumerate()
            .map(|(body, &size)| {
                let (mut size_of_elements, mut volume) = (0.0, 0.0);
                for p in first..first + size {
                    volume += self.particles.volume0[p].to_f64();
                    let e = self.particles.element[p];
                    if own[e] == 0 {
                        elements.push(e);
                    }
                    own[e] += 1;
                    let mut add = |o: usize| {
                        if touching[o] == 0 {
                            touched.push(o);
                        }
                        touching[o] += 1;
                    };
                    add(e);
                    self.basis
                        .other_elements_at(e, &self.particles.x[p], &mut add);
                }
                first += size;
                for &e in &elements {
                    pieces.clear();
                    self.basis.polynomial_pieces(e, &mut pieces);
                    size_of_elements += pieces.chunks(D + 1).map(simplex_measure).sum::<f64>();
                }
                let (mut filled, mut thin, mut empty) = (0usize, 0usize, 0usize);
                // The empty elements around the body's: holes where each of
                // their corners touches an element of the body.
                around.clear();
                for &e in &touched {
                    pieces.clear();
                    self.basis.polynomial_pieces(e, &mut pieces);
                    for corner in &pieces {
                        let x = SVector::<T, D>::from_fn(|k, _| T::of(corner[k]));
                        self.basis.other_elements_at(e, &x, &mut |o| {
                            if touching[o] == 0 && !seen_empty[o] {
                                seen_empty[o] = true;
                                around.push(o);
                            }
                        });
                    }
                }
                for &e in &around {
                    pieces.clear();
                    self.basis.polynomial_pieces(e, &mut pieces);
                    let mut hole = true;
                    // Every vertex (a point shared with two or more other
                    // elements) touches the body's elements, and two of its edges
                    // (a point shared with one: the PS pieces' points on the
                    // edges; a point inside has none) border them. With the
                    // vertices alone, an element beside a beam one element thick,
                    // outside it, counted.
                    let mut edges = 0;
                    for corner in &pieces {
                        let x = SVector::<T, D>::from_fn(|k, _| T::of(corner[k]));
                        let (mut others, mut held) = (0usize, false);
                        self.basis.other_elements_at(e, &x, &mut |o| {
                            others += 1;
                            held |= touching[o] > 0;
                        });
                        hole &= others < 2 || held;
                        edges += usize::from(others == 1 && held);
                    }
                    hole &= edges >= 2;
                    // Not where the body is not: the empty triangles at a
                    // re-entrant corner of its outline also border its elements
                    // on two edges (a user's L-shaped plate was told of 4 empty
                    // triangles inside it, which it has none of).
                    if hole {
                        let mut centre = [0.0; D];
                        for corner in &pieces {
                            for k in 0..D {
                                centre[k] += corner[k] / pieces.len() as f64;
                            }
                        }
                        hole = !outside(body, &centre);
                    }
                    hole_here[e] = hole;
                    if hole {
                        filled += 1;
                        thin += 1;
                        empty += 1;
                    }
                }
                for &e in &touched {
                    // Inside the body: every element touching this one (at its
                    // vertices and edges) holds some of the body's particles, or is
                    // a hole in them.
                    pieces.clear();
                    self.basis.polynomial_pieces(e, &mut pieces);
                    let mut inside = true;
                    for corner in &pieces {
                        let x = SVector::<T, D>::from_fn(|k, _| T::of(corner[k]));
                        self.basis.other_elements_at(e, &x, &mut |o| {
                            inside &= touching[o] > 0 || hole_here[o]
                        });
                    }
                    if inside {
                        filled += 1;
                        if (touching[e] as f64) < THIN_ELEMENT {
                            thin += 1;
                        }
                    }
                }
                let occupied = elements.len();
                // A body whose particles' volume is that of the elements holding
                // them fills those elements whole (its edges on element edges):
                // every one of them is inside it.
                let whole =
                    ((volume - size_of_elements).abs() <= 1e-9 * size_of_elements).then(|| {
                        let thin = elements
                            .iter()
                            .filter(|&&e| (touching[e] as f64) < THIN_ELEMENT)
                            .count();
                        (occupied, thin)
                    });
                for &e in &elements {
                    own[e] = 0;
                }
                for &e in &touched {
                    touching[e] = 0;
                }
                for &e in &around {
                    seen_empty[e] = false;
                    hole_here[e] = false;
                }
                elements.clear();
                touched.clear();
                BodySampling {
                    per_occupied: size as f64 / occupied.max(1) as f64,
                    volume_over_elements: if size_of_elements > 0.0 {
                        volume / size_of_elements
                    } else {
                        1.0
                    },
                    filled,
                    thin,
                    empty,
                    whole,
                }
            })
            .collect()
    }

    /// Per body, its particles on the closure of another element than their own
    /// (on an edge or a vertex of the mesh) and its particles, at the last location
    /// (`body_sizes` as [`Driver::sampling_by_body`]).
    pub fn particles_on_element_edges(&self, body_sizes: &[usize]) -> Vec<(usize, usize)> {
        let sizes = bodies_or_one(body_sizes, self.particles.len());
        let mut first = 0;
        sizes
            .iter()
            .map(|&size| {
                let on = (first..first + size)
                    .filter(|&p| {
                        let mut other = false;
                        self.basis.other_elements_at(
                            self.particles.element[p],
                            &self.particles.x[p],
                            &mut |_| other = true,
                        );
                        other
                    })
                    .count();
                first += size;
                (on, size)
            })
            .collect()
    }

    /// The basis's largest number of functions on one element.
    pub fn functions_per_element(&self) -> usize {
        self.basis.max_functions_per_element()
    }

    fn singular_mass_cause_seen(&self) -> Option<String> {
        let report = &self.last_report;
        let consistent = report.active.saturating_sub(report.treated());
        let particles = self.particles.len();
        if particles < consistent {
            return Some(format!(
                "{} for {consistent} functions solved with the `{}` mass: a mass matrix summed from fewer particles than functions is singular; use more particles per element (`per_block` or `count`; `--particles`)",
                crate::scene::limits::plural(particles, "particle", "particles"),
                self.mass.spec()
            ));
        }
        if self.mass.spec().starts_with("extended") {
            // Already the strategy that treats such functions.
            return None;
        }
        self.untreated_under_supported().map(|(_, _, why)| {
            format!("{why}; use the default mass strategy (`extended-hybrid`: remove `mass`, or `--mass default`), which expresses such functions through their neighbours")
        })
    }

    /// The critical step the step was taken against, and when it was estimated:
    /// the watch's latest estimate ([`Driver::watch_critical_step`]) or the
    /// start's.
    fn critical_now(&self) -> Option<(f64, String)> {
        match self
            .watch
            .as_ref()
            .and_then(|w| w.latest.map(|c| (c, w.latest_step)))
        {
            Some((c, step)) if step > 0 => Some((c, format!("estimated at step {step}"))),
            _ => self
                .dt_critical
                .map(|c| (c, "estimated at the start".to_string())),
        }
    }

    /// What the driver can see around a failing particle, and the fix that fits.
    pub(super) fn diagnose_particle(&self, particle: usize) -> String {
        if let Some((critical, when)) = self.critical_now() {
            let dt = self.dt.to_f64();
            if dt > critical {
                let speed = self.particles.v[particle].norm().to_f64();
                return format!(
                    "the element around it inverted (speed {speed:.3e}): Δt = {dt:.3e} is above the critical step {critical:.3e} of this basis, mass strategy and material ({when}): lower `time.dt` below it (or `time.courant` below 1)"
                );
            }
        }
        // Thrown faster than its material's P-wave speed: the strains of an impact
        // are of the order of `v / c`, beyond any elastic law, whatever the step
        // or the particles (a user's soft block thrown at 5 times its wave speed
        // at a wall was told to add particles, and inverted again with 4 times
        // more). The scene's own speeds at the start, not a blow-up's.
        let (lambda, mu) = self.material.elastic(particle).lame(D);
        let density = (self.particles.mass[particle] / self.particles.volume0[particle]).to_f64();
        let wave = ((lambda + 2.0 * mu) / density).sqrt();
        if wave > 0.0 && self.initial_speed > wave {
            let speed = self.particles.v[particle].norm().to_f64();
            return format!(
                "the element around it inverted (speed {speed:.3e}): the bodies started at up to {:.3e}, {:.1} times this material's P-wave speed √((λ + 2μ)/ρ) = {wave:.3e}, so an impact strains it by the order of that ratio, beyond what an elastic body survives whatever the step or the particles: if that is not the physics meant, check the speeds and the units of `young` and `density`",
                self.initial_speed,
                self.initial_speed / wave
            );
        }
        // A spinning or turning body of the paper's non-objective law: that law
        // first, then what else the driver sees.
        let rotated = self.non_objective_rotation(particle);
        if let Some(cause) = crate::material::non_objective_cause(rotated) {
            let speed = self.particles.v[particle].norm().to_f64();
            let lead = format!("the element around it inverted (speed {speed:.3e})");
            let also = match self.sampling_cause(particle) {
                Some(other) => format!(
                    "; if it still fails with an objective law: {}",
                    other.strip_prefix(&format!("{lead}; ")).unwrap_or(&other)
                ),
                None => String::new(),
            };
            return format!("{lead}; {cause}{also}");
        }
        if let Some(cause) = self.sampling_cause(particle) {
            return cause;
        }
        let speed = self.particles.v[particle].norm().to_f64();
        if let Some((critical, when)) = self.critical_now() {
            let dt = self.dt.to_f64();
            // In 1D nothing rotates: objectivity is not a cause there.
            let ratio = dt / critical;
            let cause = if !(self.material.is_objective(particle) || D == 1) {
                "its law, `linear-elastic`, is not objective and builds spurious stress where the body rotates: use `neo-hookean` or `corotational`, or a smaller `time.dt`".to_string()
            } else if ratio > 0.5 && self.watch.is_some() {
                // The watch estimates again every 4 to 32 steps; between two
                // estimates a body moving into new functions can lower it.
                format!(
                    "Δt is {ratio:.2} of that step, which can fall between two of its estimates (every {} to {} steps) as a body moves into functions its particles barely cover: take `time.courant` 0.5 or less, and less again where the body is compressed or struck",
                    super::critical::WATCH_EVERY,
                    super::critical::WATCH_EVERY_MOST
                )
            } else if ratio > 0.5 {
                // The estimate is of the start's particles; as the bodies move over
                // the mesh the functions they cover, and the rows the mass strategy
                // lumps or extends, change (a user's block falling freely, PS, 6 × 6
                // per block, inverted at courant 0.7 and held at 0.6 without the
                // watch; with it, at 0.95).
                format!(
                    "Δt is {ratio:.2} of that step, which changes as the bodies move over the mesh (the basis functions their particles cover change; a block falling freely inverted at 0.7): remove `watch = false` from `[time]` (or `--no-watch`), so that the run estimates it again and splits the steps that need it, or take `time.courant` 0.5 or less"
                )
            } else {
                "the deformation there is large, with a stiffer response than at the start (compression, an impact): lower `time.courant` or `time.dt`".to_string()
            };
            return format!(
                "the element around it inverted (speed {speed:.3e}) although Δt = {dt:.3e} is below the critical step {critical:.3e} {when}: {cause}"
            );
        }
        let rotation = if D == 1 {
            ""
        } else {
            "; if the body rotates, a law that is not objective (`linear-elastic`) also builds spurious stress"
        };
        format!(
            "the element around it inverted (speed {speed:.3e}, Δt = {:.3e}): the time step is likely above the critical one for this material and mesh, lower `time.dt` or `time.courant`{rotation}",
            self.dt.to_f64()
        )
    }

    /// The median rotation angle of the particles of a non-objective law other than
    /// `particle` whose `det F` is still positive (an inverted `F` has no rotation
    /// to speak of); 0 when there are none, and in 1D. The median, not the largest:
    /// a body that spins turns as a whole, while the few particles around a failing
    /// one turn by any angle as it fails.
    pub(super) fn non_objective_rotation(&self, particle: usize) -> f64 {
        let mut angles: Vec<f64> = self
            .particles
            .f
            .iter()
            .enumerate()
            .filter(|&(q, f)| {
                q != particle
                    && !self.material.is_objective(q)
                    && crate::material::det(f).to_f64() > 0.0
            })
            .map(|(_, f)| crate::material::rotation_angle(f))
            .filter(|a| a.is_finite())
            .collect();
        if angles.is_empty() {
            return 0.0;
        }
        let middle = angles.len() / 2;
        *angles.select_nth_unstable_by(middle, f64::total_cmp).1
    }

    /// Why the critical step fell, when the particles reached elements at least
    /// `1 / WATCH_NARROWER` times narrower than the narrowest they were in when
    /// the watch started: the element, how narrow, and the fix
    /// ([`Driver::narrow_elements_fix`]; a block dropped on a floor of triangles
    /// 43 times longer than high: the critical step fell 100 times as it landed).
    pub(super) fn narrower_elements_cause(&self) -> Option<String> {
        let watch = self.watch.as_ref()?;
        let (start, (element, width)) = (watch.narrowest_start?, watch.narrowest?);
        if width >= super::critical::WATCH_NARROWER * start.1 {
            return None;
        }
        let mut corners = Vec::new();
        self.basis.polynomial_pieces(element, &mut corners);
        let mut centre = [0.0; D];
        for c in &corners {
            for (k, x) in centre.iter_mut().enumerate() {
                *x += c[k] / corners.len() as f64;
            }
        }
        let sliver = self
            .sliver_aspect(element)
            .map_or_else(String::new, |aspect| {
                format!(", a sliver: its pieces' longest edge is {aspect:.0} times their height")
            });
        Some(format!(
            "the particles reached elements {:.0} times narrower than those they started in (element {element} near {}: width {width:.2e}{sliver}), and the critical step falls with the width of the elements the particles are in; {}",
            start.1 / width,
            point(&centre),
            self.narrow_elements_fix()
        ))
    }

    /// The fix for a run failing in elements much narrower than the rest: a
    /// quarter of the step (a block dropped on a floor of triangles 43 times
    /// longer than high failed at `courant` 0.1 and held at 0.05; in the watch's
    /// sub-steps at `courant` times the critical step, a smaller `courant` keeps
    /// them further below a critical step that falls within a step), or a mesh
    /// without them.
    fn narrow_elements_fix(&self) -> String {
        let dt = self.dt_outer;
        let lower = match self.dt_critical {
            Some(critical) if critical.is_finite() && critical > 0.0 => format!(
                "lower `time.courant` from {} to {} (or `time.dt` to {:.2e})",
                crate::scene::limits::echo_significant(dt / critical, 2),
                crate::scene::limits::echo_significant(0.25 * dt / critical, 2),
                0.25 * dt
            ),
            _ => format!("lower `time.dt` to {:.2e}", 0.25 * dt),
        };
        format!(
            "{lower}, or mesh without such elements (Gmsh: `Mesh.Optimize = 1`, `Mesh.OptimizeNetgen = 1`, a larger smallest edge, no graded layer where the bodies go)"
        )
    }

    /// Why the element around a failing particle inverted, when the driver sees it
    /// in the sampling or the mesh: a function with almost no particle support that
    /// the strategy solves for, a sliver, fewer particles than functions.
    fn sampling_cause(&self, particle: usize) -> Option<String> {
        // The worst-covered function among those the particle sees (the coverage
        // is measured here if the strategy did not need it).
        let coverage = self.coverage();
        let worst = self
            .evals
            .functions(particle)
            .iter()
            .map(|&i| i as usize)
            .map(|i| (i, coverage[i].unwrap_or(0.0)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        // The default strategy is the fix only where it is not already in use.
        let extends = self.mass.spec().starts_with("extended");
        if let Some((i, c)) = worst.filter(|&(_, c)| {
            c < UNDER_SUPPORTED_COVERAGE && self.last_report.extended == 0 && !extends
        }) {
            return Some(format!(
                "the particle sits in the support of function {i} at {}, which particles cover to only {:.1e} of its support, and the mass strategy `{}` solves for it: use the default mass strategy (`extended-hybrid`), which expresses such functions through their neighbours",
                point(&to_f64_point(&self.basis.function_point(i))),
                c,
                self.mass.spec()
            ));
        }
        if let Some((i, c)) = self.last_report.worst_coverage {
            if c < UNDER_SUPPORTED_COVERAGE && self.last_report.treated() == 0 && !extends {
                return Some(format!(
                    "function {i} at {} is covered to only {c:.1e} and the mass strategy `{}` treats nothing: use the default mass strategy (`extended-hybrid`)",
                    point(&to_f64_point(&self.basis.function_point(i))),
                    self.mass.spec()
                ));
            }
        }
        if let Some(cause) = self.dropped_function_cause(particle) {
            return Some(cause);
        }
        let speed = self.particles.v[particle].norm().to_f64();
        let element = self.particles.element[particle];
        let (inside, functions) = (
            self.bins.particles(element).len(),
            self.basis.element_functions(element).len(),
        );
        if let Some(aspect) = self.sliver_aspect(element) {
            let watched = if self.watch.is_some() {
                "which stiffens the system as particles enter it, faster than the watch over the critical step follows: "
            } else {
                "whose stiffness the critical step estimated at the start did not see if the body was not in it yet, and nothing estimated it again: turn the watch on (`time.watch = true`, the default; `allow_above_critical` turns it off too), which splits steps as the critical step falls, or "
            };
            return Some(format!(
                "the element around it inverted (speed {speed:.3e}); it is a sliver (its pieces' longest edge is {aspect:.0} times their height), {watched}{}",
                self.narrow_elements_fix()
            ));
        }
        if inside < functions {
            let held = if inside == 1 {
                "1 particle".to_string()
            } else {
                format!("{inside} particles")
            };
            // At an impact with a long step, more particles alone does not help
            // (a user's block at `courant = 0.5` failed sooner with more).
            let step = match self.critical_now().map(|(c, _)| c) {
                Some(c) if c > 0.0 && self.dt.to_f64() > 0.3 * c => format!(
                    "; if it inverted at an impact, lower `time.courant` too (the step is {:.2} of the critical one; impacts want 0.25 or less)",
                    self.dt.to_f64() / c
                ),
                _ => String::new(),
            };
            // Lumping keeps a smooth basis's rows from coupling through the empty
            // parts of the support; a linear element's few functions are not helped
            // by it (a user's PL block at one particle per element blew apart with
            // `lumped`), nor is a mass that is lumped already.
            let lumped = if functions > D + 1 && self.mass.spec() != "lumped" {
                ", or `lumped`"
            } else {
                ""
            };
            return Some(format!(
                "the element around it inverted (speed {speed:.3e}); it holds {held} for the {functions} functions of the element, too few to sample them: use more particles per element (`per_block` or `count`; `--particles`){lumped}{step}"
            ));
        }
        None
    }

    /// With `deactivate`, a function the particle sees that the strategy dropped
    /// (`0 < M_ii` below its threshold): its coefficient is held at zero, which
    /// holds back a moving body's edge as it crosses elements, and the elements
    /// there invert whatever the sampling (a user's disk thrown in free flight
    /// inverted at 7 particles per triangle and again at 28; the advice to add
    /// particles did not help).
    fn dropped_function_cause(&self, particle: usize) -> Option<String> {
        let threshold = self.mass.deactivation_threshold()?;
        let spec = self.mass.spec();
        let dropped = self
            .evals
            .functions(particle)
            .iter()
            .map(|&i| i as usize)
            .map(|i| (i, self.values[self.pattern.diagonal_position(i)].to_f64()))
            .filter(|&(_, m)| m > 0.0 && m < threshold)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let fix = "use the default mass strategy (`extended-hybrid`: remove `mass`, or `--mass default`), which expresses such functions through their neighbours instead of dropping them";
        match dropped {
            Some((i, m)) => Some(format!(
                "the particle sits in the support of function {i} at {}, whose mass {m:.2e} is below the threshold of `{spec}`, which dropped it: a dropped function's coefficient is held at zero, which holds back a moving body's edge as it crosses elements, and the elements there invert whatever the number of particles; {fix}",
                point(&to_f64_point(&self.basis.function_point(i)))
            )),
            None if self.last_report.deactivated > 0 => Some(format!(
                "`{spec}` dropped {} in this step (their mass below its threshold), each held at zero, which holds back a moving body's edge as it crosses elements; {fix}",
                crate::scene::limits::plural(self.last_report.deactivated, "function", "functions")
            )),
            None => None,
        }
    }

    /// In 2D, the largest aspect ratio (longest edge over the height on it) of the
    /// polynomial pieces of `element` when it is at least [`SLIVER_ASPECT`].
    fn sliver_aspect(&self, element: usize) -> Option<f64> {
        if D != 2 {
            return None;
        }
        let mut corners = Vec::new();
        self.basis.polynomial_pieces(element, &mut corners);
        let aspect = corners
            .chunks(3)
            .filter(|t| t.len() == 3)
            .map(|t| triangle_aspect([t[0][0], t[0][1]], [t[1][0], t[1][1]], [t[2][0], t[2][1]]))
            .fold(0.0, f64::max);
        (aspect >= SLIVER_ASPECT).then_some(aspect)
    }

    /// The error of a failed mass solve, with what the strategy reported.
    pub(super) fn mass_failure(&self, source: MassError) -> StepError {
        let treated = self.last_report.treated();
        let hint = if let MassError::NothingActive { largest, .. } = source {
            format!(
                "the threshold is absolute, in the scene's units of mass: give one below {} (`deactivate:THRESHOLD`; the thesis' 1e-2 is for its columns), or use the default mass strategy, which needs none",
                crate::scene::limits::echo_number(largest)
            )
        } else if let Some(cause) = self.singular_mass_cause() {
            cause
        } else if treated > 0 {
            // The strategy already treats functions (extension, lumped rows or
            // deactivation): suggesting it again would not help.
            let worst = match self.last_report.worst_coverage {
                Some((i, c)) => format!(
                    "; the worst-covered function it solves for is {i} at {}, covered to {c:.1e} of its support",
                    point(&to_f64_point(&self.basis.function_point(i)))
                ),
                None => String::new(),
            };
            let spec = self.mass.spec();
            let alternative = if spec.starts_with("extended-hybrid") {
                "`lumped`, which gives up the accuracy of the consistent rows"
            } else {
                "`extended-hybrid` (the default), which also lumps the rows of functions covered below 0.75"
            };
            format!(
                "`{spec}` treated {} and the rest is still singular{worst}: use more particles per element (`per_block` or `count`; `--particles`), or {alternative}",
                crate::scene::limits::plural(treated, "function", "functions")
            )
        } else {
            match self.last_report.worst_coverage {
                Some((i, c)) => format!(
                    "the worst-covered function {i} at {} is covered to {c:.1e} of its support: use the default mass strategy (`extended-hybrid`), which expresses such functions through their neighbours",
                    point(&to_f64_point(&self.basis.function_point(i)))
                ),
                None if self.particles_per_occupied_element() < FEW_PER_ELEMENT => {
                    // A matrix of so few particles per element is singular whether
                    // or not the bodies' edges leave functions nearly empty (the
                    // seeds' column at 3 per triangle for the 9 PS functions).
                    few_particles_or_the_default(self.particles_per_occupied_element())
                }
                None => {
                    let spec = self.mass.spec();
                    let others = if spec.starts_with("partial") {
                        "`lumped`"
                    } else {
                        "`partial` or `lumped`"
                    };
                    format!(
                        "functions with almost no particle in their support make `{spec}` singular: use the default mass strategy (`extended-hybrid`), or {others}"
                    )
                }
            }
        };
        StepError::MassNotPositiveDefinite {
            step: self.step + 1,
            source,
            hint,
        }
    }
}

/// `per_element` particles per occupied element, too few for the functions each
/// element holds, and the fix.
fn few_particles(per_element: f64) -> String {
    format!(
        "{per_element:.1} particles per occupied element are too few for the functions each element holds; use more particles per element (`per_block` or `count`; `--particles`), or `lumped`"
    )
}

/// [`few_particles`], and the default mass strategy for functions a body's edge
/// leaves nearly empty, which more particles do not fill.
fn few_particles_or_the_default(per_element: f64) -> String {
    format!(
        "{}; where a body's edge leaves functions nearly empty more particles do not fill them, and the default mass strategy (`mass = \"default\"`) extends them",
        few_particles(per_element)
    )
}

/// A triangle's longest edge over its height on that edge (`L² / 2A`; infinite
/// for a degenerate one): 1.15 equilateral, 2 for a right isosceles triangle.
pub(crate) fn triangle_aspect(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
    let area2 = (u[0] * v[1] - u[1] * v[0]).abs();
    let length = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    let longest = length(a, b).max(length(b, c)).max(length(c, a));
    if area2 > 0.0 {
        longest * longest / area2
    } else {
        f64::INFINITY
    }
}

/// The message of [`StepError::CriticalStepFell`].
fn critical_fell_message(
    time: f64,
    critical: f64,
    start: Option<f64>,
    dt: f64,
    limit: usize,
    cause: Option<&str>,
) -> String {
    let from = start.map_or(String::new(), |s| {
        format!(" from {s:.3e} at the start ({:.1e} of it)", critical / s)
    });
    let cause = cause.map_or_else(
        || "the mass system the strategy solves became nearly singular as the bodies moved (a function the particles barely sample), or a body is collapsing: look at the particles (`--out`) near the worst-covered function (`worst_coverage` in diagnostics.csv); use more particles per element (`per_block`, `per_triangle`, `count` or `spacing`; `--particles`), or `--mass lumped`".to_string(),
        str::to_string,
    );
    format!(
        "at t = {time:.4e} the critical step fell to {critical:.3e}{from}: Δt = {dt:.3e} would take more than {limit} sub-steps; {cause}"
    )
}

/// Why a step failed. Each names the step, the cause the driver can see, and a
/// fix that fits that cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    #[error(
        "step {step}: particle {particle} at {} left the mesh; {hint}",
        point(position)
    )]
    ParticleLeftMesh {
        step: usize,
        particle: usize,
        position: Vec<f64>,
        /// What to change.
        hint: String,
    },
    #[error("step {step}: the mass system could not be solved ({source}); {hint}")]
    MassNotPositiveDefinite {
        step: usize,
        source: MassError,
        /// What the driver sees (the worst-covered function) and what to change.
        hint: String,
    },
    #[error(
        "step {step}: {quantity} of particle {particle} at {} is not valid; {hint}",
        point(position)
    )]
    NotFinite {
        step: usize,
        quantity: &'static str,
        particle: usize,
        position: Vec<f64>,
        /// What the driver sees near the particle and what to change.
        hint: String,
    },
    /// The critical step, estimated again as the bodies moved
    /// ([`super::Driver::watch_critical_step`]), fell so far that the step would
    /// take more than [`super::critical::MAX_SUBSTEPS`] sub-steps.
    #[error("step {step}: {}", critical_fell_message(*time, *critical, *start, *dt, *limit, cause.as_deref()))]
    CriticalStepFell {
        step: usize,
        /// The time at the start of the step.
        time: f64,
        /// The critical step estimated at the start of the step.
        critical: f64,
        /// The critical step estimated at the start of the run.
        start: Option<f64>,
        /// The time step.
        dt: f64,
        /// The most sub-steps the step could take
        /// (`Driver::critical_substep_limit`).
        limit: usize,
        /// What makes the mass system nearly singular, with its fix, when the driver
        /// sees it.
        cause: Option<String>,
    },
    /// A particle so fast that keeping its move within its element would take
    /// more than [`super::critical::MAX_SUBSTEPS`] sub-steps
    /// ([`super::Driver::watch_critical_step`], the advection limit).
    #[error("step {step}: {reason}")]
    TooFast {
        step: usize,
        /// The particle, its speed and what to change.
        reason: String,
    },
    /// A body compressed to a few percent of its volume: judged by the caller, who
    /// knows the material (see `crate::material::COLLAPSED_JACOBIAN`).
    #[error("step {step}: {reason}")]
    Collapsed {
        step: usize,
        /// Where, and what to change.
        reason: String,
    },
}

/// Errors setting up a driver.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetupError {
    #[error(transparent)]
    Basis(#[from] BasisError),
    #[error("boundary condition on `{tag}`: {message}")]
    Boundary { tag: String, message: String },
    #[error("particle {particle} at {} lies outside the mesh", point(position))]
    ParticleOutside { particle: usize, position: Vec<f64> },
    #[error("the basis has {functions} functions on {elements} elements; the driver stores function indices and matrix positions in 32 bits (below 2^31 functions and 2^31 element-local entries)")]
    TooManyFunctions { functions: usize, elements: usize },
    #[error(
        "{particles} particles: the driver stores particle slots in 32 bits (below 2^32 particles)"
    )]
    TooManyParticles { particles: usize },
}

/// A position for a message: `[0.00312378, 0.947718]`, six significant digits per
/// coordinate (enough to find the place, without the noise of the last bits).
pub(crate) fn point(x: &[f64]) -> String {
    let coordinates: Vec<String> = x
        .iter()
        .map(|&c| {
            if c == 0.0 || !c.is_finite() {
                return format!("{c}");
            }
            crate::scene::limits::echo_significant(c, 6)
        })
        .collect();
    format!("[{}]", coordinates.join(", "))
}

/// How one body is sampled ([`Driver::sampling_by_body`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySampling {
    /// Its particles per element holding at least one of them.
    pub per_occupied: f64,
    /// Its particles' volume over the size (area, length) of the elements holding
    /// them: about 1 for a body whose particles fill their elements, below where
    /// the body's edges cut elements, above where elements between its particles
    /// hold none (a lattice coarser than the mesh: 4 for one particle per block of
    /// four triangles).
    pub volume_over_elements: f64,
    /// Its elements inside it (every element touching one holds some of its
    /// particles), and of those the ones holding fewer than 3 (`THIN_ELEMENT`)
    /// particles (a particle on an edge or a vertex counting in every element
    /// around it): a lattice whose average per element is enough may still leave
    /// some elements thin (`per_block = [3, 4]` on blocks of four triangles puts 2
    /// in the left and right triangles, 4 in the others).
    pub filled: usize,
    pub thin: usize,
    /// Of the thin ones, those holding none: an element every corner of which
    /// touches an element holding some of the body's particles (a hole in the
    /// sampling: `per_block = [1, 16]` on blocks of four triangles leaves the left
    /// and right triangles of every block empty).
    pub empty: usize,
    /// `(elements, thin)` where the body fills the elements holding its particles
    /// whole (their size is its particles' volume, its edges on element edges):
    /// all of them, and those holding fewer than 3 (`THIN_ELEMENT`); `None` where
    /// its edges cut elements.
    pub whole: Option<(usize, usize)>,
}

/// Particles per occupied element below which a critical step far below the
/// lumped mass's is put first on the sampling, for the strategies that solve for
/// nearly empty functions: the seeds' columns on coarse lattices (2.25 and 3 per
/// triangle for the 9 PS functions of each) fail for that; a user's block thrown
/// through a mostly empty mesh with `partial` failed at the same time with 3.8 and
/// 13.8 per element, for the functions at its edge.
pub const FEW_PER_ELEMENT: f64 = 4.0;

/// Particles per element below which a PS element inside a body is thin
/// ([`BodySampling::thin`]): its nine functions are quadratic on six
/// sub-triangles, and fewer sums over particles integrate them poorly.
pub const THIN_ELEMENT: f64 = 3.0;

/// A body's particles whose volume exceeds the size of the elements holding them
/// by more than this factor leave elements between them empty (jittered lattices
/// and round-off stay near 1).
pub const EMPTY_BETWEEN: f64 = 1.25;

impl BodySampling {
    /// Whether elements between its particles hold none: their volume exceeds
    /// the size of the elements that hold them by more than `EMPTY_BETWEEN`.
    pub fn fills_in_part(&self) -> bool {
        self.volume_over_elements > EMPTY_BETWEEN
    }

    /// Its particles per element of the mesh under it: per occupied element,
    /// divided by [`volume_over_elements`](Self::volume_over_elements) where
    /// elements between its particles hold none.
    pub fn per_element(&self) -> f64 {
        if self.fills_in_part() {
            self.per_occupied / self.volume_over_elements
        } else {
            self.per_occupied
        }
    }
}

/// The measure of a simplex of `D + 1` points (a length, an area).
fn simplex_measure<const D: usize>(s: &[SVector<f64, D>]) -> f64 {
    match D {
        1 => (s[1] - s[0]).norm(),
        _ => {
            let (u, w) = (s[1] - s[0], s[2] - s[0]);
            0.5 * (u[0] * w[1] - u[1] * w[0]).abs()
        }
    }
}

/// The numbers of particles of the bodies, `body_sizes`, where they add up to all
/// `n` particles; else one body of all of them.
fn bodies_or_one(body_sizes: &[usize], n: usize) -> Vec<usize> {
    if body_sizes.iter().sum::<usize>() == n && !body_sizes.is_empty() {
        body_sizes.to_vec()
    } else {
        vec![n]
    }
}
