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
//!   of body `a` and `m_b` of body `b`, with the trial velocities
//!   `ṽ_a = v̂_a + Δt F_a / m_a` (and `ṽ_b`) and the unit normal `n` from body `a`'s
//!   mass centre on the function to body `b`'s, the bodies approach where
//!   `(ṽ_a − ṽ_b) · n > 0`, and there the pair of forces
//!
//!   `f_a = −μ ((ṽ_a − ṽ_b) · n) n / Δt = −f_b`, `μ = m_a m_b / (m_a + m_b)`,
//!
//!   removes the approach speed along `n` (with lumped rows exactly), keeps the total
//!   momentum and leaves the tangential velocities alone (no friction). Bodies that
//!   move apart are left free: nothing holds them together.
//!
//! Contact is detected on shared functions, so it starts when the bodies' supports
//! overlap, up to about one element (PL) or two (PS) before their surfaces touch:
//! bodies rebound with a gap of about an element between them.

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
    /// The first moment `Σ_p phi_i(x_p) m_p x_p`.
    moment: Vec<[f64; 3]>,
    /// On a function other bodies share: the unit normal from this body's mass
    /// centre on it to theirs, and how far the body's surface reaches along it,
    /// `max_p (x_p · n + r_p)` over its particles there (`r_p` half the particle's
    /// spacing); `−∞` elsewhere.
    outward: Vec<[f64; 3]>,
    reach: Vec<f64>,
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
    /// speed of each pair of bodies in contact on a function they share, from the
    /// trial velocity coefficients `trial(k, i) = v̂ⁿ + Δt a`, the lumped masses
    /// `mass`, first moments `moment` and surface reaches `reach` (module doc).
    fn changes(
        &self,
        mass: &[f64],
        moment: &[[f64; 3]],
        reach: &[f64],
        dim: usize,
        trial: impl Fn(usize, usize) -> f64,
        mut add: impl FnMut(usize, usize, f64),
    ) {
        let n = mass.len() / self.bodies;
        for j in 0..n {
            for a in 0..self.bodies {
                let ia = j + a * n;
                if mass[ia] <= 0.0 {
                    continue;
                }
                for b in a + 1..self.bodies {
                    let ib = j + b * n;
                    if mass[ib] <= 0.0 {
                        continue;
                    }
                    // The surfaces overlap along the normal (the particles'
                    // domains touch): `reach` of each along its own outward normal.
                    if reach[ia] + reach[ib] < 0.0 {
                        continue;
                    }
                    let (ma, mb) = (mass[ia], mass[ib]);
                    let mut normal = [0.0; 3];
                    for k in 0..dim {
                        normal[k] = moment[ib][k] / mb - moment[ia][k] / ma;
                    }
                    let length = normal.iter().map(|c| c * c).sum::<f64>().sqrt();
                    if length.is_nan() || length <= 0.0 {
                        continue;
                    }
                    let mut approach = 0.0;
                    for k in 0..dim {
                        normal[k] /= length;
                        approach += (trial(k, ia) - trial(k, ib)) * normal[k];
                    }
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
    }
}

impl<T: Scalar, const D: usize> Effect<T, D> for BodyContact {
    fn name(&self) -> &'static str {
        "body-contact"
    }
    /// No force here: the functions' lumped masses and first moments of the step,
    /// and on the functions two bodies share the reach of each body's surface.
    fn add_forces(
        &self,
        particles: &Particles<T, D>,
        state: &StepState<T, D>,
        forces: &mut [Vec<T>],
    ) {
        let mut guard = self.sums.lock().unwrap_or_else(|e| e.into_inner());
        let Sums {
            mass,
            moment,
            outward,
            reach,
            dt,
        } = &mut *guard;
        *dt = state.dt;
        let n = forces[0].len();
        let per_body = n / self.bodies.max(1);
        let dim = D.min(3);
        mass.clear();
        mass.resize(n, 0.0);
        moment.clear();
        moment.resize(n, [0.0; 3]);
        let position = |p: usize| -> [f64; 3] {
            let mut x = [0.0; 3];
            for (k, c) in x.iter_mut().enumerate().take(dim) {
                *c = particles.x[p][k].to_f64();
            }
            x
        };
        for p in 0..particles.len() {
            let (m, x) = (particles.mass[p].to_f64(), position(p));
            for (i, phi) in state.basis.functions(p) {
                let w = phi.to_f64() * m;
                mass[i] += w;
                for k in 0..dim {
                    moment[i][k] += w * x[k];
                }
            }
        }
        outward.clear();
        outward.resize(n, [0.0; 3]);
        reach.clear();
        reach.resize(n, f64::NEG_INFINITY);
        let mut shared = false;
        for j in 0..per_body {
            let (mut total, mut first) = (0.0, [0.0; 3]);
            let mut holding = 0;
            for b in 0..self.bodies {
                let i = j + b * per_body;
                if mass[i] > 0.0 {
                    holding += 1;
                    total += mass[i];
                    for k in 0..dim {
                        first[k] += moment[i][k];
                    }
                }
            }
            if holding < 2 {
                continue;
            }
            shared = true;
            for b in 0..self.bodies {
                let i = j + b * per_body;
                if mass[i] <= 0.0 {
                    continue;
                }
                let others = total - mass[i];
                let mut normal = [0.0; 3];
                for k in 0..dim {
                    normal[k] = (first[k] - moment[i][k]) / others - moment[i][k] / mass[i];
                }
                let length = normal.iter().map(|c| c * c).sum::<f64>().sqrt();
                if length > 0.0 {
                    normal.iter_mut().for_each(|c| *c /= length);
                    outward[i] = normal;
                }
            }
        }
        if !shared {
            return;
        }
        for p in 0..particles.len() {
            let x = position(p);
            let radius = 0.5 * particles.volume0[p].to_f64().powf(1.0 / D as f64);
            for (i, _) in state.basis.functions(p) {
                let normal = outward[i];
                if normal == [0.0; 3] {
                    continue;
                }
                let along: f64 = (0..dim).map(|k| x[k] * normal[k]).sum();
                reach[i] = reach[i].max(along + radius);
            }
        }
    }
    /// The contact forces `Δp / Δt` from the trial velocities
    /// `ṽ = v̂ⁿ + Δt F / m` of the assembled total force `F`.
    fn adjust_forces(&self, total: &[Vec<T>], velocity: &[Vec<T>], forces: &mut [Vec<T>]) {
        let guard = self.sums.lock().unwrap_or_else(|e| e.into_inner());
        let Sums {
            mass,
            moment,
            reach,
            dt,
            ..
        } = &*guard;
        let dt = *dt;
        if mass.len() != total[0].len() || reach.len() != mass.len() || dt.is_nan() || dt <= 0.0 {
            return;
        }
        self.changes(
            mass,
            moment,
            reach,
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
        // One function: body 0 on the left moving right, body 1 on the right moving
        // left and sliding up; their surfaces overlap (`reach` sums to 0).
        let mass = [2.0, 1.0];
        let moment = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let touching = [0.5, -0.5];
        let velocity = [[1.0, -2.0], [0.0, 3.0]];
        let run = |velocity: [[f64; 2]; 2], reach: &[f64]| {
            let mut change = [[0.0; 2]; 2];
            contact.changes(
                &mass,
                &moment,
                reach,
                2,
                |k, i| velocity[k][i],
                |k, i, p| change[k][i] += p,
            );
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
        // Bodies that part, or whose surfaces are apart, are left alone.
        assert_eq!(run([[-1.0, 2.0], [0.0, 0.0]], &touching), [[0.0; 2]; 2]);
        assert_eq!(run(velocity, &[0.5, -0.6]), [[0.0; 2]; 2]);
    }
}
