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
//!   spacings, `½ (V_p⁰)^(1/D)`) among the particles on the function. The normal
//!   comes from the bodies' mass gradients `g = Σ_p m_p grad phi_i(x_p)`, which
//!   point out of a body (`g = −∫ phi_i ∇ρ`), summed over the functions of the
//!   vertex of `i` (those with its support: the three PS functions of a vertex,
//!   whose own gradients lean towards their control-triangle corners by up to 15°
//!   on a flat surface; PL and B-spline functions are alone). The two bodies'
//!   unit outward normals are weighted by a high power of their lengths,
//!   `n ∝ |G_a|^k Ĝ_a − |G_b|^k Ĝ_b` (`k = 64`, `n` from `a` to `b`): the longer
//!   dominates, so a face against a corner gives the face's normal, not the
//!   corner's, and two of equal length (a mirror-symmetric pair, whose normals are
//!   mirror images) give their mean, not one chosen by round-off. Where that
//!   is more than 60° from the direction between the two bodies' mass centres on
//!   the vertex (a body that nearly fills the support has a gradient of noise), the
//!   centres' direction is taken instead. With the trial
//!   velocities `ṽ_a = v̂_a + Δt F_a / m_a` (and `ṽ_b`), the bodies approach where
//!   `(ṽ_a − ṽ_b) · n > 0`, and there the pair of forces
//!
//!   `f_a = −μ ((ṽ_a − ṽ_b) · n) n / Δt = −f_b`, `μ = m_a m_b / (m_a + m_b)`,
//!
//!   removes the approach speed along `n` (with lumped rows exactly), keeps the total
//!   momentum and leaves the tangential velocities alone (no friction). Bodies that
//!   move apart are left free: nothing holds them together.
//!
//! Measured (`docs/scenes.md`, the `body-contact` effect): normals from the mass
//! centres alone tilt at a sliding block's ends into friction. Until 2026-12-04
//! the gradients were taken with the wrong sign (as pointing into the body), so
//! every normal failed the 60° test and came from the centres: a block sliding at
//! 1 m/s on a block under gravity stopped within 0.8 s. With the sign right it keeps
//! 0.55 of its speed at 1 s, with the vertex sums and the longer normal 0.73, with
//! the weighted normals 0.72 (0.85 at 0.5 s, against 0.84): two equal blocks meeting
//! head-on now stay mirror images (to 3e-14, against 7.8e-4 of their positions with
//! the longer normal alone), and part with `e` 0.68 instead of 0.61.
//!
//! Open: stacked bodies sink into each other slowly, since overlapping positions
//! are never pushed back. A correction of the overlap was tried (2026-12-04, not
//! kept; `docs/scenes.md`, the `body-contact` effect): the overlap `δ` along the
//! normal of the touching pairs on each function, and a separating speed `β δ / Δt`
//! in place of zero approach, either in the contact forces or on the projected
//! velocity the particles move with. In 1D the forces' form holds two stacked bars
//! (overlap 3.0 % of a spacing at t = 4 → 0.03 % with `β = 0.01`, the contact's
//! work +2.4e-4 of 19.6), but in 2D every `β` from 1e-4 to 0.1 made a stiff block
//! on a soft one worse (it sinks faster at 1e-4, bounces and gains energy above).

use crate::effect::{Effect, StepState};
use crate::particles::Particles;
use crate::sparse::Scalar;
use psmpm_basis::basis::{Basis, BasisError, BasisEval, Constraint, Point};
use psmpm_basis::Real;
use std::sync::Mutex;

/// The most bodies a scene with contact between bodies may have: each copies the
/// basis.
pub const MAX_CONTACT_BODIES: usize = 8;

/// The power `k` of the lengths that weights the two bodies' unit outward normals,
/// `n ∝ |G_a|^k Ĝ_a − |G_b|^k Ĝ_b`: the longer dominates (a face against a
/// corner gets the face's normal), and equal lengths give the mean.
const NORMAL_WEIGHT_POWER: i32 = 64;

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
    fn element_cache_len(&self) -> usize {
        self.base.element_cache_len()
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
    fn dual_value(&self, function: usize, p: &psmpm_basis::Quadratic<D>) -> Option<f64> {
        self.base.dual_value(function % self.functions, p)
    }
}

/// Frictionless contact between the bodies of a [`PerBody`] basis (module doc).
#[derive(Debug)]
pub struct BodyContact {
    bodies: usize,
    /// The vertex of each function of every copy: functions with the same
    /// support share one ([`vertices`]).
    vertex: Vec<u32>,
    /// How many vertices `vertex` numbers.
    vertices: usize,
    /// What `add_forces` gathers for `adjust_forces`.
    sums: Mutex<Sums>,
}

/// Per function of every copy, from the particles of the step.
#[derive(Debug, Default)]
struct Sums {
    /// The lumped mass `m_i = Σ_p phi_i(x_p) m_p`.
    mass: Vec<f64>,
    /// The mass gradient `Σ_p m_p grad phi_i(x_p)`: it points out of the body.
    gradient: Vec<[f64; 3]>,
    /// The first moment `Σ_p phi_i(x_p) m_p x_p`.
    moment: Vec<[f64; 3]>,
    /// The mass, mass gradient and first moment summed over each vertex's functions.
    vertex_mass: Vec<f64>,
    vertex_gradient: Vec<[f64; 3]>,
    vertex_moment: Vec<[f64; 3]>,
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

/// The vertex of each function of `basis`, numbered from 0 in the order of the
/// functions: functions with the same support share a vertex (the three PS
/// functions of a mesh vertex; a PL or B-spline function is alone).
pub fn vertices<T: Real, const D: usize>(basis: &dyn Basis<T, D>) -> Vec<u32> {
    let mut numbers: std::collections::HashMap<Vec<usize>, u32> = Default::default();
    (0..basis.num_functions())
        .map(|i| {
            let mut support = basis.function_support(i).to_vec();
            support.sort_unstable();
            let next = numbers.len() as u32;
            *numbers.entry(support).or_insert(next)
        })
        .collect()
}

impl BodyContact {
    /// Contact between the bodies of `basis`, a [`PerBody`] basis of `bodies`
    /// copies.
    pub fn new<T: Real, const D: usize>(bodies: usize, basis: &dyn Basis<T, D>) -> Self {
        let vertex = vertices(basis);
        BodyContact {
            bodies,
            vertices: vertex.iter().map(|&v| v as usize + 1).max().unwrap_or(0),
            vertex,
            sums: Mutex::new(Sums::default()),
        }
    }

    /// The momentum changes `Δp` (`add(k, i, Δp_k)`) that remove the approach
    /// speed of each pair of bodies in `sums.touching` on their shared function,
    /// from the trial velocity coefficients `trial(k, i) = v̂ⁿ + Δt F / m` and the
    /// step's lumped masses and the vertices' mass gradients and mass centres
    /// (module doc): the normal from body `a` to body `b` is the weighted mean of
    /// the outward normals `G_a` and `−G_b`, or the direction between the mass centres
    /// where the two differ by more than 60°.
    fn changes(
        &self,
        sums: &Sums,
        dim: usize,
        trial: impl Fn(usize, usize) -> f64,
        mut add: impl FnMut(usize, usize, f64),
    ) {
        let Sums {
            mass,
            vertex_mass,
            vertex_gradient,
            vertex_moment,
            touching,
            ..
        } = sums;
        let n = mass.len() / self.bodies.max(1);
        let unit = |v: [f64; 3]| {
            let length = v.iter().map(|c| c * c).sum::<f64>().sqrt();
            (length > 0.0).then(|| v.map(|c| c / length))
        };
        let length_squared = |v: &[f64; 3]| v.iter().map(|c| c * c).sum::<f64>();
        for &(j, a, b) in touching {
            let (ia, ib) = (j + a * n, j + b * n);
            let (ma, mb) = (mass[ia], mass[ib]);
            if ma <= 0.0 || mb <= 0.0 {
                continue;
            }
            // The two bodies' outward normals at their vertices; the mass centres
            // give the side (a gradient of a vertex the body nearly fills is noise):
            // where the two disagree by more than 60°, the centres' direction.
            let (va, vb) = (self.vertex[ia] as usize, self.vertex[ib] as usize);
            let (ga, gb) = (&vertex_gradient[va], &vertex_gradient[vb]);
            let mut by_gradient = [0.0; 3];
            let mut by_centre = [0.0; 3];
            // The unit normals weighted by a power of their lengths: the longer
            // dominates, and two of equal length (a mirror-symmetric pair) give
            // their mean, not one chosen by round-off.
            let (la, lb) = (length_squared(ga), length_squared(gb));
            let power = |l: f64| l.powi(NORMAL_WEIGHT_POWER / 2);
            let (wa, wb) = if la > 0.0 && lb > 0.0 {
                let scale = la.max(lb);
                (power(la / scale) / la.sqrt(), power(lb / scale) / lb.sqrt())
            } else {
                (f64::from(la > 0.0), f64::from(lb > 0.0))
            };
            for k in 0..dim {
                by_gradient[k] = wa * ga[k] - wb * gb[k];
                by_centre[k] =
                    vertex_moment[vb][k] / vertex_mass[vb] - vertex_moment[va][k] / vertex_mass[va];
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
            vertex_mass,
            vertex_gradient,
            vertex_moment,
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
        // The vertices' sums, read only where bodies share functions.
        let vertices = self.vertices;
        vertex_mass.clear();
        vertex_mass.resize(vertices, 0.0);
        vertex_gradient.clear();
        vertex_gradient.resize(vertices, [0.0; 3]);
        vertex_moment.clear();
        vertex_moment.resize(vertices, [0.0; 3]);
        for (i, &v) in self.vertex.iter().enumerate().take(n) {
            let v = v as usize;
            vertex_mass[v] += mass[i];
            for k in 0..dim {
                vertex_gradient[v][k] += gradient[i][k];
                vertex_moment[v][k] += moment[i][k];
            }
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
    /// Frictionless contact only takes energy out: work it adds over the run is
    /// energy the discretisation gained (PL's default mass spreads the forces
    /// sized on lumped rows through nearly consistent ones).
    fn dissipative(&self) -> bool {
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
    fn a_mass_gradient_points_out_of_the_body() {
        // Particles left of a function's point: the gradient points right, away
        // from them (the sign the contact normal relies on).
        let basis = square();
        let centre = (0..basis.num_functions())
            .find(|&i| basis.function_point(i) == Point::<f64, 2>::new(0.5, 0.5))
            .unwrap();
        let mut eval = BasisEval::for_basis(&basis);
        let mut gradient = [0.0f64; 2];
        for x in [0.3, 0.4, 0.45] {
            for y in [0.4, 0.5, 0.6] {
                let x = Point::<f64, 2>::new(x, y);
                basis.eval(basis.locate(&x, None).unwrap(), &x, &mut eval);
                for k in 0..eval.len() {
                    if eval.index[k] == centre {
                        gradient[0] += eval.grad_phi[k][0];
                        gradient[1] += eval.grad_phi[k][1];
                    }
                }
            }
        }
        assert!(gradient[0] > 2.0 * gradient[1].abs(), "{gradient:?}");
    }

    #[test]
    fn the_three_ps_functions_of_a_vertex_share_it() {
        use psmpm_basis::basis::powell_sabin::PowellSabin;
        let ps = PowellSabin::new(
            block_grid(0.0, 1.0, 0.0, 1.0, 2, 2).unwrap(),
            psmpm_basis::refinement::SplitPoint::Incentre,
        )
        .unwrap();
        let vertex = vertices::<f64, 2>(&ps);
        assert_eq!(vertex.len(), ps.num_functions());
        assert_eq!(
            vertex.iter().max().map(|&v| 3 * (v as usize + 1)),
            Some(ps.num_functions())
        );
        for i in 0..ps.num_functions() {
            let same = (0..ps.num_functions())
                .filter(|&j| vertex[j] == vertex[i])
                .count();
            assert_eq!(same, 3);
        }
        let linear = square();
        let alone = (0..linear.num_functions() as u32).collect::<Vec<u32>>();
        assert_eq!(vertices::<f64, 2>(&linear), alone);
    }

    #[test]
    fn approaching_bodies_lose_their_normal_approach_and_keep_their_momentum() {
        let contact = BodyContact::new::<f64, 2>(2, &PerBody::new::<f64, 2>(square(), 2));
        // One function in the base, at the vertex shared by the two copies: body 0
        // on the left moving right (its outward gradient points right), body 1
        // on the right moving left and sliding up, with the gradient nearly four
        // times as long, along x (the normal is then body 1's to round-off); their
        // surfaces touch.
        let n = contact.vertex.len();
        let mut mass = vec![0.0; n];
        let mut gradient = vec![[0.0; 3]; n];
        let mut moment = vec![[0.0; 3]; n];
        let (i0, i1) = (0, n / 2);
        mass[i0] = 2.0;
        mass[i1] = 1.0;
        gradient[i0] = [0.25, 0.15, 0.0];
        gradient[i1] = [-1.0, 0.0, 0.0];
        moment[i1] = [1.0, 0.5, 0.0];
        let touching = [(0, 0, 1)];
        let mut velocity = [vec![0.0; n], vec![0.0; n]];
        velocity[0][i0] = 1.0;
        velocity[0][i1] = -2.0;
        velocity[1][i1] = 3.0;
        let run_with = |gradient: &[[f64; 3]],
                        velocity: &[Vec<f64>; 2],
                        touching: &[(usize, usize, usize)]| {
            let mut sums = Sums {
                mass: mass.clone(),
                gradient: gradient.to_vec(),
                moment: moment.clone(),
                touching: touching.to_vec(),
                ..Sums::default()
            };
            let vertices = n;
            sums.vertex_mass = mass.clone();
            sums.vertex_gradient = gradient.to_vec();
            sums.vertex_moment = moment.clone();
            assert_eq!(contact.vertex, (0..vertices as u32).collect::<Vec<_>>());
            let mut change = [vec![0.0; n], vec![0.0; n]];
            contact.changes(&sums, 2, |k, i| velocity[k][i], |k, i, p| change[k][i] += p);
            change
        };
        let run = |velocity: &[Vec<f64>; 2], touching: &[(usize, usize, usize)]| {
            run_with(&gradient, velocity, touching)
        };
        let change = run(&velocity, &touching);
        let after = |k: usize, i: usize| velocity[k][i] + change[k][i] / mass[i];
        assert!(
            (after(0, i0) - after(0, i1)).abs() < 1e-14,
            "normal speeds equal"
        );
        assert!(
            (change[0][i0] + change[0][i1]).abs() < 1e-14,
            "momentum kept"
        );
        assert!(
            change[1][i0].abs() < 1e-14 && change[1][i1].abs() < 1e-14,
            "no friction: the longer normal, along x"
        );
        // Outward normals of equal length, mirror images about x (a symmetric
        // pair): their mean, along x, not one of them tilted by round-off.
        let mut mirrored = gradient.clone();
        mirrored[i0] = [0.6, 0.8, 0.0];
        mirrored[i1] = [-0.6, 0.8, 0.0];
        let change = run_with(&mirrored, &velocity, &touching);
        assert_eq!(
            [change[1][i0], change[1][i1]],
            [0.0, 0.0],
            "the mean normal"
        );
        assert!(change[0][i0] < 0.0 && (change[0][i0] + change[0][i1]).abs() < 1e-14);
        // Bodies that part, or whose surfaces do not touch, are left alone.
        let mut parting = velocity.clone();
        parting[0][i0] = -1.0;
        parting[0][i1] = 2.0;
        assert!(run(&parting, &touching).iter().flatten().all(|&c| c == 0.0));
        assert!(run(&velocity, &[]).iter().flatten().all(|&c| c == 0.0));
    }
}
