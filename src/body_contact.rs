//! Contact between bodies: a velocity field per body (multi-field MPM) and a
//! frictionless contact condition on the functions two bodies share (Bardenhagen,
//! Brackbill and Sulsky 2000).
//!
//! Without it, bodies meet through the one velocity field of the mesh: once
//! functions couple them they move together, and the field between them holds them
//! together as well as it pushes them apart, so a collision is mostly sticky
//! (`docs/scenes.md`, "Overlaps and contact"). With it:
//! - the basis is copied once per body ([`PerBody`]): the particles of body `b` live
//!   in elements `e + b n_e` and see the functions `i + b n` of their own copy, so
//!   each body has its own mass system and solve, and for the default mass its own
//!   coverage and extension (a function over the gap between two bodies is no
//!   longer filled from both sides);
//! - the copies meet only in [`BodyContact`], an effect on the assembled forces. On
//!   a function `i` that carries the lumped masses `m_a = Σ_{p ∈ a} phi_i(x_p) m_p`
//!   of body `a` and `m_b` of body `b`, the bodies are in contact when their
//!   surfaces touch: a particle of each within the sum of their radii (half their
//!   spacings, `½ (V_p⁰)^(1/D)`) among the particles on the function. The normal `n`
//!   from `a` to `b` is that of the mass gradients `g = Σ_p m_p grad phi_i(x_p)`,
//!   `(g_b − g_a) / |g_b − g_a|`, unless it is more than 60° from the direction
//!   between the two bodies' mass centres on the function (a body that nearly fills
//!   the support has a gradient of noise), which is then taken. With the trial
//!   velocities `ṽ_a = v̂_a + Δt F_a / m_a` (and `ṽ_b`), the bodies approach where
//!   `(ṽ_a − ṽ_b) · n > 0`, and there the pair of forces
//!
//!   `f_a = −μ ((ṽ_a − ṽ_b) · n) n / Δt = −f_b`, `μ = m_a m_b / (m_a + m_b)`,
//!
//!   removes the approach speed along `n` (with lumped rows exactly), keeps the total
//!   momentum and leaves the tangential velocities alone (no friction). Bodies that
//!   move apart are left free: nothing holds them together.
//!
//! Measured (`docs/scenes.md`, the `body-contact` effect): the mass centres alone as
//! the normal, with a test of the surfaces along it, tilted the normal at a sliding
//! block's ends into friction (a block sliding at 1 m/s over another slowed to
//! 0.83 in 0.18 s and flew off it) and let bodies come to rest a quarter of an
//! element apart; the mass gradients alone let a block dropped onto another pass
//! through it (noisy normals on functions the lower block fills).

use crate::effect::{Effect, StepState};
use crate::particles::Particles;
use crate::sparse::Scalar;
use psmpm_basis::basis::{Basis, BasisError, BasisEval, Constraint, Point};
use psmpm_basis::Real;
use std::sync::Mutex;

/// The most bodies a scene with contact between bodies may have: each copies the
/// basis.
pub const MAX_CONTACT_BODIES: usize = 8;

/// A basis copied once per body: element `e + b n_e` is element `e` of the mesh in
/// the copy of body `b`, whose functions are `i + b n` (`n_e` elements and `n`
/// functions in the base). A point is located in the copy of its hint's body (the
/// copy of body 0 without a hint): a particle stays in its body's copy as it moves.
#[derive(Debug, Clone)]
pub struct PerBody<B> {
    base: B,
    bodies: usize,
    elements: usize,
    functions: usize,
    /// The functions of each element of every copy (CSR).
    element_start: Vec<usize>,
    element_functions: Vec<usize>,
    /// The elements of each function's support in every copy (CSR).
    support_start: Vec<usize>,
    support: Vec<usize>,
}

impl<B> PerBody<B> {
    /// `base` copied for `bodies` bodies.
    pub fn new<T: Real, const D: usize>(base: B, bodies: usize) -> Self
    where
        B: Basis<T, D>,
    {
        let (elements, functions) = (base.num_elements(), base.num_functions());
        let (mut element_start, mut element_functions) = (vec![0], Vec::new());
        let (mut support_start, mut support) = (vec![0], Vec::new());
        for b in 0..bodies {
            for e in 0..elements {
                element_functions
                    .extend(base.element_functions(e).iter().map(|i| i + b * functions));
                element_start.push(element_functions.len());
            }
            for i in 0..functions {
                support.extend(base.function_support(i).iter().map(|e| e + b * elements));
                support_start.push(support.len());
            }
        }
        PerBody {
            base,
            bodies,
            elements,
            functions,
            element_start,
            element_functions,
            support_start,
            support,
        }
    }

    /// The basis of one body.
    pub fn base(&self) -> &B {
        &self.base
    }

    /// Number of bodies (copies).
    pub fn bodies(&self) -> usize {
        self.bodies
    }

    /// The first element of body `body`'s copy.
    pub fn first_element(&self, body: usize) -> usize {
        body * self.elements
    }
}

impl<T: Real, const D: usize, B: Basis<T, D>> Basis<T, D> for PerBody<B> {
    fn name(&self) -> &'static str {
        self.base.name()
    }
    fn num_functions(&self) -> usize {
        self.functions * self.bodies
    }
    fn num_elements(&self) -> usize {
        self.elements * self.bodies
    }
    fn max_functions_per_element(&self) -> usize {
        self.base.max_functions_per_element()
    }
    fn locate(&self, x: &Point<T, D>, hint: Option<usize>) -> Option<usize> {
        let offset = hint.map_or(0, |h| h / self.elements * self.elements);
        self.base
            .locate(x, hint.map(|h| h % self.elements))
            .map(|e| e + offset)
    }
    fn other_elements_at(&self, element: usize, x: &Point<T, D>, visit: &mut dyn FnMut(usize)) {
        let offset = element / self.elements * self.elements;
        self.base
            .other_elements_at(element % self.elements, x, &mut |e| visit(e + offset));
    }
    fn eval(&self, element: usize, x: &Point<T, D>, out: &mut BasisEval<T, D>) {
        self.base.eval(element % self.elements, x, out);
        let shift = element / self.elements * self.functions;
        if shift > 0 {
            let len = out.len();
            out.index[..len].iter_mut().for_each(|i| *i += shift);
        }
    }
    fn element_functions(&self, element: usize) -> &[usize] {
        &self.element_functions[self.element_start[element]..self.element_start[element + 1]]
    }
    fn function_support(&self, function: usize) -> &[usize] {
        &self.support[self.support_start[function]..self.support_start[function + 1]]
    }
    fn function_point(&self, function: usize) -> Point<f64, D> {
        self.base.function_point(function % self.functions)
    }
    fn boundary_tags(&self) -> Vec<String> {
        self.base.boundary_tags()
    }
    fn dirichlet(
        &self,
        tag: &str,
        direction: &Point<T, D>,
    ) -> Result<Vec<Constraint<T, D>>, BasisError> {
        let base = self.base.dirichlet(tag, direction)?;
        Ok((0..self.bodies)
            .flat_map(|b| {
                base.iter().map(move |c| Constraint {
                    direction: c.direction,
                    terms: c
                        .terms
                        .iter()
                        .map(|&(i, w)| (i + b * self.functions, w))
                        .collect(),
                })
            })
            .collect())
    }
    fn polynomial_pieces(&self, element: usize, out: &mut Vec<Point<f64, D>>) {
        self.base.polynomial_pieces(element % self.elements, out)
    }
    fn degree(&self) -> usize {
        self.base.degree()
    }
}

/// Frictionless contact between the bodies of a [`PerBody`] basis (module doc).
#[derive(Debug)]
pub struct BodyContact {
    bodies: usize,
    /// What `add_forces` gathers for `adjust_forces`.
    sums: Mutex<Sums>,
}

/// Per function of every copy, from the particles of the step.
#[derive(Debug, Default)]
struct Sums {
    /// The lumped mass `m_i = Σ_p phi_i(x_p) m_p`.
    mass: Vec<f64>,
    /// The mass gradient `Σ_p m_p grad phi_i(x_p)`: it points into the body.
    gradient: Vec<[f64; 3]>,
    /// The first moment `Σ_p phi_i(x_p) m_p x_p`.
    moment: Vec<[f64; 3]>,
    /// Other bodies hold mass on the function too.
    shared: Vec<bool>,
    /// The particles of the body on each shared function (scratch).
    members: Vec<Vec<u32>>,
    /// The pairs of bodies `(j, a, b)`, `a < b`, whose surfaces touch on function
    /// `j` of the base: a particle of each within the sum of their radii.
    touching: Vec<(usize, usize, usize)>,
    /// The step's `Δt`.
    dt: f64,
}

impl BodyContact {
    /// Contact between the `bodies` bodies of a [`PerBody`] basis.
    pub fn new(bodies: usize) -> Self {
        BodyContact {
            bodies,
            sums: Mutex::new(Sums::default()),
        }
    }

    /// The momentum changes `Δp` (`add(k, i, Δp_k)`) that remove the approach
    /// speed of each pair of bodies in `sums.touching` on their shared function,
    /// from the trial velocity coefficients `trial(k, i) = v̂ⁿ + Δt F / m` and the
    /// step's lumped masses, mass gradients and first moments (module doc): the normal from body `a` to body `b` is `(g_b − g_a) / |g_b −
    /// g_a|`, or the direction between their mass centres where the two differ by
    /// more than 60°.
    fn changes(
        &self,
        sums: &Sums,
        dim: usize,
        trial: impl Fn(usize, usize) -> f64,
        mut add: impl FnMut(usize, usize, f64),
    ) {
        let Sums {
            mass,
            gradient,
            moment,
            touching,
            ..
        } = sums;
        let n = mass.len() / self.bodies.max(1);
        for &(j, a, b) in touching {
            let (ia, ib) = (j + a * n, j + b * n);
            let (ma, mb) = (mass[ia], mass[ib]);
            if ma <= 0.0 || mb <= 0.0 {
                continue;
            }
            // The mass gradients give the normal; the mass centres on the function
            // its side (a gradient of a function the body nearly fills is noise):
            // where the two disagree by more than 60°, the centres' direction.
            let unit = |v: [f64; 3]| {
                let length = v.iter().map(|c| c * c).sum::<f64>().sqrt();
                (length > 0.0).then(|| v.map(|c| c / length))
            };
            let mut by_gradient = [0.0; 3];
            let mut by_centre = [0.0; 3];
            for k in 0..dim {
                by_gradient[k] = gradient[ib][k] - gradient[ia][k];
                by_centre[k] = moment[ib][k] / mb - moment[ia][k] / ma;
            }
            let Some(centre) = unit(by_centre) else {
                continue;
            };
            let normal = match unit(by_gradient) {
                Some(g) if (0..dim).map(|k| g[k] * centre[k]).sum::<f64>() > 0.5 => g,
                _ => centre,
            };
            let approach: f64 = (0..dim)
                .map(|k| (trial(k, ia) - trial(k, ib)) * normal[k])
                .sum();
            if approach > 0.0 {
                let impulse = ma * mb / (ma + mb) * approach;
                for (k, c) in normal.iter().enumerate().take(dim) {
                    add(k, ia, -impulse * c);
                    add(k, ib, impulse * c);
                }
            }
        }
    }
}

impl<T: Scalar, const D: usize> Effect<T, D> for BodyContact {
    fn name(&self) -> &'static str {
        "body-contact"
    }
    /// No force here: the functions' lumped masses and mass gradients of the step,
    /// and the pairs of bodies whose surfaces touch on a function they share.
    fn add_forces(
        &self,
        particles: &Particles<T, D>,
        state: &StepState<T, D>,
        forces: &mut [Vec<T>],
    ) {
        let mut guard = self.sums.lock().unwrap_or_else(|e| e.into_inner());
        let Sums {
            mass,
            gradient,
            moment,
            shared,
            members,
            touching,
            dt,
        } = &mut *guard;
        *dt = state.dt;
        touching.clear();
        let n = forces[0].len();
        let per_body = n / self.bodies.max(1);
        let dim = D.min(3);
        mass.clear();
        mass.resize(n, 0.0);
        gradient.clear();
        gradient.resize(n, [0.0; 3]);
        moment.clear();
        moment.resize(n, [0.0; 3]);
        for p in 0..particles.len() {
            let m = particles.mass[p].to_f64();
            for (i, phi, grad) in state.basis.functions_with_gradients(p) {
                let w = phi.to_f64() * m;
                mass[i] += w;
                for k in 0..dim {
                    gradient[i][k] += m * grad[k].to_f64();
                    moment[i][k] += w * particles.x[p][k].to_f64();
                }
            }
        }
        shared.clear();
        shared.resize(n, false);
        let mut any = false;
        for j in 0..per_body {
            let holding = (0..self.bodies)
                .filter(|b| mass[j + b * per_body] > 0.0)
                .count();
            if holding >= 2 {
                any = true;
                for b in 0..self.bodies {
                    shared[j + b * per_body] = mass[j + b * per_body] > 0.0;
                }
            }
        }
        if !any {
            return;
        }
        members.resize_with(n, Vec::new);
        members.iter_mut().for_each(Vec::clear);
        for p in 0..particles.len() {
            for (i, _) in state.basis.functions(p) {
                if shared[i] {
                    members[i].push(p as u32);
                }
            }
        }
        let radius = |p: usize| 0.5 * particles.volume0[p].to_f64().powf(1.0 / D as f64);
        let distance_squared = |p: usize, q: usize| {
            (0..D)
                .map(|k| (particles.x[p][k] - particles.x[q][k]).to_f64().powi(2))
                .sum::<f64>()
        };
        for j in 0..per_body {
            if !shared[j..].iter().step_by(per_body).any(|&s| s) {
                continue;
            }
            for a in 0..self.bodies {
                for b in a + 1..self.bodies {
                    let (ia, ib) = (j + a * per_body, j + b * per_body);
                    if !(shared[ia] && shared[ib]) {
                        continue;
                    }
                    // Surfaces touch: two particles within the sum of their radii
                    // (half their spacings), with room for round-off.
                    let touches = members[ia].iter().any(|&p| {
                        members[ib].iter().any(|&q| {
                            let (p, q) = (p as usize, q as usize);
                            let reach = (radius(p) + radius(q)) * (1.0 + 1e-9);
                            distance_squared(p, q) <= reach * reach
                        })
                    });
                    if touches {
                        touching.push((j, a, b));
                    }
                }
            }
        }
    }
    /// The contact forces `Δp / Δt` from the trial velocities
    /// `ṽ = v̂ⁿ + Δt F / m` of the assembled total force `F`.
    fn adjust_forces(&self, total: &[Vec<T>], velocity: &[Vec<T>], forces: &mut [Vec<T>]) {
        let guard = self.sums.lock().unwrap_or_else(|e| e.into_inner());
        let sums = &*guard;
        let (mass, dt) = (&sums.mass, sums.dt);
        if sums.touching.is_empty() || mass.len() != total[0].len() || dt.is_nan() || dt <= 0.0 {
            return;
        }
        self.changes(
            sums,
            D.min(3),
            |k, i| velocity[k][i].to_f64() + dt * total[k][i].to_f64() / mass[i],
            |k, i, impulse| forces[k][i] += T::of(impulse / dt),
        );
    }
    /// The contact forces take energy out (a perfectly inelastic impact along the
    /// normal, on the lumped rows): their work is booked.
    fn does_work(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use psmpm_basis::basis::linear::Linear;
    use psmpm_basis::mesh::generators::block_grid;

    fn square() -> Linear<f64> {
        Linear::new(block_grid(0.0, 1.0, 0.0, 1.0, 2, 2).unwrap())
    }

    #[test]
    fn each_copy_is_the_base_on_its_own_functions() {
        let base = square();
        let per = PerBody::new(square(), 3);
        let (ne, nf) = (base.num_elements(), base.num_functions());
        assert_eq!(per.num_elements(), 3 * ne);
        assert_eq!(per.num_functions(), 3 * nf);
        let x = Point::<f64, 2>::new(0.3, 0.7);
        let e = base.locate(&x, None).unwrap();
        let (mut a, mut b) = (BasisEval::for_basis(&base), BasisEval::for_basis(&per));
        base.eval(e, &x, &mut a);
        for body in 0..3 {
            let hint = per.first_element(body);
            let found = per.locate(&x, Some(hint)).unwrap();
            assert_eq!(found, e + body * ne);
            per.eval(found, &x, &mut b);
            assert_eq!(b.len(), a.len());
            for k in 0..a.len() {
                assert_eq!(b.index[k], a.index[k] + body * nf);
                assert_eq!(b.phi[k], a.phi[k]);
            }
            assert_eq!(per.element_functions(found), &b.index[..b.len()]);
            for &i in per.element_functions(found) {
                assert!(per.function_support(i).contains(&found));
                assert_eq!(per.function_point(i), base.function_point(i - body * nf));
            }
        }
        let tags = Basis::<f64, 2>::boundary_tags(&base);
        assert!(!tags.is_empty());
        let x_axis = Point::<f64, 2>::new(1.0, 0.0);
        let wall = Basis::<f64, 2>::dirichlet(&base, &tags[0], &x_axis).unwrap();
        let walls = Basis::<f64, 2>::dirichlet(&per, &tags[0], &x_axis).unwrap();
        assert_eq!(walls.len(), 3 * wall.len());
        assert_eq!(walls[wall.len()].terms[0].0, wall[0].terms[0].0 + nf);
    }

    #[test]
    fn approaching_bodies_lose_their_normal_approach_and_keep_their_momentum() {
        let contact = BodyContact::new(2);
        // One function: body 0 on the left (its mass grows to the left) moving
        // right, body 1 on the right moving left and sliding up; their surfaces
        // touch.
        let mass = [2.0, 1.0];
        let gradient = [[-1.0, 0.1, 0.0], [1.0, 0.1, 0.0]];
        let moment = [[0.0; 3], [1.0, 0.0, 0.0]];
        let touching = [(0, 0, 1)];
        let velocity = [[1.0, -2.0], [0.0, 3.0]];
        let run = |velocity: [[f64; 2]; 2], touching: &[(usize, usize, usize)]| {
            let sums = Sums {
                mass: mass.to_vec(),
                gradient: gradient.to_vec(),
                moment: moment.to_vec(),
                touching: touching.to_vec(),
                ..Sums::default()
            };
            let mut change = [[0.0; 2]; 2];
            contact.changes(&sums, 2, |k, i| velocity[k][i], |k, i, p| change[k][i] += p);
            change
        };
        let change = run(velocity, &touching);
        let after = |k: usize, i: usize| velocity[k][i] + change[k][i] / mass[i];
        assert!(
            (after(0, 0) - after(0, 1)).abs() < 1e-14,
            "normal speeds equal"
        );
        assert!((change[0][0] + change[0][1]).abs() < 1e-14, "momentum kept");
        assert_eq!(change[1], [0.0, 0.0], "no friction");
        // Bodies that part, or whose surfaces do not touch, are left alone.
        assert_eq!(run([[-1.0, 2.0], [0.0, 0.0]], &touching), [[0.0; 2]; 2]);
        assert_eq!(run(velocity, &[]), [[0.0; 2]; 2]);
    }
}
