//! Frictionless contact walls that act on the particles (a penalty), for the
//! boundaries a body slides, rolls or bounces along.
//!
//! A slip wall (`fix = ["normal"]`) holds the normal velocity of the basis
//! functions on the wall, and their supports reach an element into the body: a
//! body that spins or rolls against it is braked (`docs/stability.md`, "A slip wall
//! brakes a body that spins"). A contact wall leaves the functions free and pushes
//! each particle that comes within its contact distance `d_p` of the wall back,
//! along the wall's normal, with a linear spring:
//!
//! `f_p = k_p g_p n`, `g_p = d_p − dist(x_p, wall)` when positive, potential energy
//! `Σ_p ½ k_p g_p²` (in the total energy, so the balance still closes),
//!
//! with `d_p = ½ √V_p⁰` (half the particle spacing: the body's surface, not its
//! outermost particles, touches the wall; a particle placed closer keeps its
//! starting distance, so a body starts at rest where it is placed) and
//! `k_p = m_p (κ / Δt)² / c_p`, `c_p` the largest share of a function's lumped mass
//! carried by particles in contact, over the functions around `p`. A particle's
//! force accelerates the functions around it, not the particle alone, and every
//! particle in contact pushes the same functions: this choice bounds the rows of the
//! contact stiffness by `(κ / Δt)²` times the functions' masses, so the grid's
//! contact modes stay at or below the frequency `κ / Δt` at any particle count
//! (Gershgorin), and reach it when a layer of particles touches. It does not set the
//! time step (the default `κ = 1/2`; with 1 the slope runs grew unstable), and a
//! body arriving at speed `v` sinks about `v Δt / κ`. A spring sized on `m_p`
//! alone is too soft (a disk of 1 792 particles sank through a slope), one sized on
//! the grid mass around each particle too stiff once several particles share a
//! function (a block striking a wall gained 16 % energy at 9 particles per triangle,
//! 1.9 % with this one, 1.8 % once springs only soften in contact, below;
//! `docs/stability.md`, "Contact walls").
//!
//! While a particle stays in contact its spring only softens,
//! `k_p ← min(k_p, m_p (κ / Δt)² / c_p)`: the share `c_p` falls as particles leave
//! the contact, and a spring that stiffened while compressed by `g_p` would add the
//! energy `½ Δk_p g_p²`. So the springs' changes can only take energy out: a soft
//! disk bouncing on a contact floor gained 11.5 % of its energy (a real gain, the
//! time-centred total's 10.6 %) and now gains none (1.1 % swing, centred 3e-16);
//! the price is a small loss where the share grows during contact (a disk rolling
//! down a contact slope loses 1.2 % in 0.4 s).
//!
//! The particles are points: a body sampled on a lattice that is not aligned with
//! the wall touches it with a staircase of particles whose springs' resultant
//! passes up to half a spacing beside the centre of mass, a torque of about
//! `W s / 2` for a weight `W`; a disk on a 30° slope turns by 0.21 rad in 0.4 s
//! (0.08 with half the spacing), where a slip wall turns it by 1.4e-2: for a body
//! that slides along a slanted wall without turning, a slip wall is the better
//! model; for one that rolls or spins, this. The wall is the tagged boundary's
//! edges, and the boundary's reflex corners (a domain angle above π, the corners
//! of an obstacle) push radially, so a body can wrap around them. The contact
//! walls of all tags are one geometry and one effect, so that walls of different
//! tags that meet act as one wall ([`WallGeometry::new`]); each wall's `κ` scales
//! its part of a particle's spring.

use crate::effect::Effect;
use crate::particles::Particles;
use crate::sparse::Scalar;
use nalgebra::SVector;
use psmpm_basis::{TriMesh, Vec2};
use std::collections::{HashMap, VecDeque};
use std::sync::Mutex;

/// The default `κ`: the grid's contact modes have frequency at most `κ / Δt`. With
/// `κ = 1` a block striking a wall at 9 particles per triangle gained 11 % of its
/// energy (UNSTABLE; springs that followed the contact share both ways); with
/// `κ = 1/2` 1.9 % (1.8 % with springs that only soften in contact, time-centred
/// 3e-4), and a rubber disk on a slope (`docs/examples/disk-slope.toml` with a
/// contact wall) loses 7.9e-3 and 1.2e-2 at two particle spacings, gaining nothing
/// (`docs/stability.md`, "Contact walls").
pub const DEFAULT_STIFFNESS: f64 = 0.5;

/// The wall geometry of one boundary tag, and the wall items near each element.
#[derive(Debug, Clone)]
pub struct WallGeometry {
    /// Edges `(a, b, n)`, `n` the unit normal into the mesh.
    segments: Vec<(Vec2, Vec2, Vec2)>,
    /// Per edge, whether its end `a` and its end `b` are free ends of the wall (no
    /// wall edge beyond them): there the wall is bevelled ([`Self::contacts`]).
    free: Vec<[bool; 2]>,
    /// Reflex corners: the vertex and its two wall edges.
    corners: Vec<(Vec2, [usize; 2])>,
    /// Per item (the segments, then the corners), `κ²` of its wall (of the
    /// stiffer of a corner's two).
    stiffness: Vec<f64>,
    /// Per element, the segments (`i`) and corners (`segments.len() + j`) within
    /// `reach` of it (CSR).
    element_start: Vec<usize>,
    element_items: Vec<u32>,
    /// Items within this distance of an element are listed for it.
    reach: f64,
}

impl WallGeometry {
    /// The boundary edges of `mesh` tagged with the tags of `walls` (tag id and
    /// `κ`), with the items within `reach` of each element. `None` when no edge has
    /// any of the tags.
    ///
    /// The walls of all tags are one geometry: where two meet, neither end is free
    /// and their corner pushes radially, as within one tag, and a particle touching
    /// both has one spring ([`ContactWall`]). As two geometries, each bevelled at
    /// the common vertex, they left a gap there, and a particle touching both
    /// pressed on two springs, each sized as if the other were not there.
    pub fn new(mesh: &TriMesh, walls: &[(usize, f64)], reach: f64) -> Option<Self> {
        let v = mesh.vertices();
        let mut segments = Vec::new();
        let mut edge_of_segment = Vec::new();
        let mut stiffness = Vec::new();
        for (k, e) in mesh.edges().iter().enumerate() {
            let Some(&(_, kappa)) = walls.iter().find(|(tag, _)| e.tag == Some(*tag)) else {
                continue;
            };
            if e.is_boundary() {
                let (a, b) = (v[e.vertices[0]], v[e.vertices[1]]);
                // Counter-clockwise in its triangle: the mesh lies to the left.
                let d = (b - a).normalize();
                segments.push((a, b, Vec2::new(-d.y, d.x)));
                edge_of_segment.push(k);
                stiffness.push(kappa * kappa);
            }
        }
        if segments.is_empty() {
            return None;
        }
        // The wall edge that starts and the one that ends at each vertex (the first,
        // in edge order), for the free ends and the corners.
        let (mut starting, mut ending) = (HashMap::new(), HashMap::new());
        for (s, &k) in edge_of_segment.iter().enumerate() {
            let [a, b] = mesh.edges()[k].vertices;
            starting.entry(a).or_insert(s);
            ending.entry(b).or_insert(s);
        }
        let free = edge_of_segment
            .iter()
            .map(|&k| {
                let [a, b] = mesh.edges()[k].vertices;
                [!ending.contains_key(&a), !starting.contains_key(&b)]
            })
            .collect();
        // Reflex corners: vertices shared by two wall edges where the mesh's angle
        // exceeds π.
        let mut corners = Vec::new();
        for (s, &k) in edge_of_segment.iter().enumerate() {
            let end = mesh.edges()[k].vertices[1];
            let Some(&next) = starting.get(&end) else {
                continue;
            };
            let angle: f64 = mesh
                .vertex_triangles(end)
                .iter()
                .map(|&t| corner_angle(mesh, t, end))
                .sum();
            if angle > std::f64::consts::PI + 1e-9 {
                corners.push((v[end], [s, next]));
            }
        }
        let corner_stiffness: Vec<f64> = corners
            .iter()
            .map(|(_, [s0, s1])| stiffness[*s0].max(stiffness[*s1]))
            .collect();
        stiffness.extend(corner_stiffness);
        // Items near each element: a walk outwards from the triangles on each item
        // while their bounding boxes stay within `reach`.
        let ne = mesh.num_triangles();
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); ne];
        let mut seen = vec![usize::MAX; ne];
        let mut queue = VecDeque::new();
        let items = segments.len() + corners.len();
        for item in 0..items {
            let (lo, hi, start) = if item < segments.len() {
                let (a, b, _) = segments[item];
                let edge = &mesh.edges()[edge_of_segment[item]];
                (a.inf(&b), a.sup(&b), edge.triangles.0)
            } else {
                let (c, [s, _]) = corners[item - segments.len()];
                (c, c, mesh.edges()[edge_of_segment[s]].triangles.0)
            };
            queue.clear();
            queue.push_back(start);
            seen[start] = item;
            while let Some(t) = queue.pop_front() {
                lists[t].push(item as u32);
                for n in mesh.neighbours()[t].iter().flatten() {
                    if seen[*n] != item && box_distance(mesh, *n, lo, hi) <= reach {
                        seen[*n] = item;
                        queue.push_back(*n);
                    }
                }
            }
        }
        let mut element_start = vec![0];
        let mut element_items = Vec::new();
        for list in lists {
            element_items.extend(list);
            element_start.push(element_items.len());
        }
        Some(WallGeometry {
            segments,
            free,
            corners,
            stiffness,
            element_start,
            element_items,
            reach,
        })
    }

    /// Items are listed for the elements within this distance.
    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// The wall items listed for `element` (those within [`Self::reach`]). An
    /// element of a body's copy of the basis (`body_contact::PerBody`) is that
    /// element of the mesh.
    fn items(&self, element: usize) -> &[u32] {
        let element = element % (self.element_start.len() - 1).max(1);
        match (
            self.element_start.get(element),
            self.element_start.get(element + 1),
        ) {
            (Some(&a), Some(&b)) => &self.element_items[a..b],
            _ => &[],
        }
    }

    /// `true` if a wall item is listed for `element` (within [`Self::reach`]).
    pub fn near(&self, element: usize) -> bool {
        !self.items(element).is_empty()
    }

    /// How far inside the contact distance `d` of the walls `x` (in `element`)
    /// lies, at the deepest of them (0 outside it).
    fn depth(&self, element: usize, x: Vec2, d: f64) -> f64 {
        let mut deepest = 0.0f64;
        self.contacts(element, x, d, |g, _, _| deepest = deepest.max(g));
        deepest
    }

    /// `true` if `x` (a point outside the mesh that left it from `element`) lies
    /// behind one of the wall's edges listed for `element` (between the edge's
    /// ends, on the far side of its line), or within [`Self::reach`] of one of its
    /// reflex corners: it went out through the wall. A particle that left through
    /// an open side beside a wall is neither.
    pub fn behind(&self, element: usize, x: Vec2) -> bool {
        self.items(element).iter().any(|&item| {
            let item = item as usize;
            if let Some(&(a, b, n)) = self.segments.get(item) {
                let ab = b - a;
                let t = (x - a).dot(&ab) / ab.norm_squared();
                (0.0..=1.0).contains(&t) && (x - a).dot(&n) <= 0.0
            } else {
                let (c, _) = self.corners[item - self.segments.len()];
                (x - c).norm() <= self.reach
            }
        })
    }

    /// Calls `contact(g, n, κ²)` for each wall item within `d` of `x` (in
    /// `element`): `g` how far inside the distance, `n = −∇g` the direction from
    /// the wall to `x` (a unit vector, but for the bevels), `κ` the item's wall's.
    ///
    /// A free end of the walls (where the tagged boundary goes on untagged, or with a
    /// tag that is no contact wall) is bevelled over the contact distance: within `d` of the
    /// end `c` along the edge, `g = d − (x − c)·n − (d − σ)`, `σ = (x − c)·u` the
    /// distance from the end along the edge (`u` pointing into it), so that `g`
    /// is `−(x − c)·n ≤ 0` at the end itself and the potential `½ k g²` is
    /// continuous there. Without the bevel a particle that comes round the end
    /// (off a slanted slip wall over a contact cliff) entered the edge's strip from
    /// the side already `g ≈ d` deep, with the energy `½ k g²` its spring then
    /// released: a block sliding off a 30° ramp past a contact cliff gained 21 % of
    /// its energy at `courant = 0.25` and 57 % at 0.12 (the springs stiffen as
    /// `1 / Δt²`). A capsule end (radial push from `c`) keeps `g` continuous too,
    /// but stopped the block on the ramp: its particles sit slightly closer than
    /// `d` to the ramp, and the end pushed them back.
    #[inline]
    fn contacts(&self, element: usize, x: Vec2, d: f64, mut contact: impl FnMut(f64, Vec2, f64)) {
        let along = |s: usize| {
            let (a, b, _) = self.segments[s];
            let ab = b - a;
            (x - a).dot(&ab) / ab.norm_squared()
        };
        for &item in self.items(element) {
            let item = item as usize;
            if item < self.segments.len() {
                let (a, b, n) = self.segments[item];
                let t = along(item);
                let height = (x - a).dot(&n);
                // Behind the edge by more than the contact distance: the far side
                // of an obstacle, listed because the element is within `reach` of
                // it (an obstacle thinner than the mesh's longest edge), and out of
                // reach through the mesh. Counted, it pushed a particle beside the
                // near side towards the obstacle with `k_p (d + w)`, `w` its width,
                // or, at the start, took its contact distance below zero.
                if (0.0..=1.0).contains(&t) && height >= -d.max(0.0) {
                    let mut g = d - height;
                    let mut direction = n;
                    let [free_a, free_b] = self.free[item];
                    if free_a || free_b {
                        let length = (b - a).norm();
                        let u = (b - a) / length;
                        if free_a && t * length < d {
                            g -= d - t * length;
                            direction -= u;
                        }
                        if free_b && (1.0 - t) * length < d {
                            g -= d - (1.0 - t) * length;
                            direction += u;
                        }
                    }
                    if g > 0.0 {
                        contact(g, direction, self.stiffness[item]);
                    }
                }
            } else {
                let (c, [s0, s1]) = self.corners[item - self.segments.len()];
                let outside = |t: f64| !(0.0..=1.0).contains(&t);
                if outside(along(s0)) && outside(along(s1)) {
                    let r = x - c;
                    let dist = r.norm();
                    if dist < d && dist > 0.0 {
                        contact(d - dist, r / dist, self.stiffness[item]);
                    }
                }
            }
        }
    }
}

/// The particles (index and distance) that start closer to the walls than
/// [`crate::driver::STARTED_CLOSE`] of their contact distance (`distance`,
/// [`contact_distances`]): placed in the walls' contact layer, their springs have
/// that little room. The particles are located (`element`).
pub fn started_close<T: Scalar, const D: usize>(
    geometry: &WallGeometry,
    particles: &Particles<T, D>,
    distance: &[f64],
) -> Vec<(usize, f64)> {
    let mut close = Vec::new();
    for (p, &d) in distance.iter().enumerate().take(particles.len()) {
        let room = d - geometry.depth(
            particles.element[p],
            ContactWall::position(&particles.x[p]),
            d,
        );
        if room < crate::driver::STARTED_CLOSE * d {
            close.push((p, room));
        }
    }
    close
}

/// The angle of triangle `t` at vertex `v`.
fn corner_angle(mesh: &TriMesh, t: usize, v: usize) -> f64 {
    let tri = mesh.triangles()[t];
    let k = tri.iter().position(|&w| w == v).unwrap_or(0);
    let p = mesh.vertices();
    let (a, b, c) = (p[tri[k]], p[tri[(k + 1) % 3]], p[tri[(k + 2) % 3]]);
    let (u, w) = (b - a, c - a);
    (u.x * w.y - u.y * w.x).atan2(u.dot(&w)).abs()
}

/// Distance between the bounding box of triangle `t` and the box `[lo, hi]`.
fn box_distance(mesh: &TriMesh, t: usize, lo: Vec2, hi: Vec2) -> f64 {
    let p = mesh.triangle_points(t);
    let (tlo, thi) = (p[0].inf(&p[1]).inf(&p[2]), p[0].sup(&p[1]).sup(&p[2]));
    let gap = |a0: f64, a1: f64, b0: f64, b1: f64| (b0 - a1).max(a0 - b1).max(0.0);
    Vec2::new(gap(tlo.x, thi.x, lo.x, hi.x), gap(tlo.y, thi.y, lo.y, hi.y)).norm()
}

/// The frictionless contact walls of a run (see the module doc), all tags in one
/// geometry: per particle, the contact distance `d_p`, and the spring `k_p` of the
/// last step (for the potential energy); each wall's `κ` and the run's `Δt` give
/// the stiffness.
#[derive(Debug)]
pub struct ContactWall {
    /// The wall.
    pub geometry: WallGeometry,
    /// `d_p = ½ √V_p⁰`, or the particle's distance at the start if it was closer
    /// (the body starts at rest where it was placed, without a spring already
    /// compressed).
    distance: Mutex<Vec<f64>>,
    /// `1 / Δt²`, set by [`Effect::set_time_step`] (`ω_c² = κ² / Δt²` per wall).
    rate: f64,
    /// Scratch and state of [`Effect::add_forces`].
    state: Mutex<State>,
}

/// What [`ContactWall`] keeps from step to step.
#[derive(Debug)]
struct State {
    /// The lumped mass `m_i` of each function (scratch).
    grid_mass: Vec<f64>,
    /// The part of `m_i` carried by particles in contact (scratch).
    contact_mass: Vec<f64>,
    /// The particles in contact and their summed `κ² g n` (scratch).
    touching: Vec<(usize, Vec2)>,
    /// `k_p / κ²` of each particle (`m_p / Δt²` until the first step).
    springs: Vec<f64>,
    /// The particle was in contact at the last step (its spring may then only
    /// soften: see [`ContactWall`]'s `add_forces`).
    was_touching: Vec<bool>,
    /// The contact distances were checked against the particles' first positions.
    started: bool,
}

/// The contact distance of a particle of initial volume `volume0` in `D`
/// dimensions: half its spacing, `½ (V_p⁰)^(1/D)`, so that the body's surface, not
/// its outermost particles, touches a contact wall.
pub fn contact_distance<const D: usize>(volume0: f64) -> f64 {
    0.5 * volume0.powf(1.0 / D as f64)
}

/// Each particle's contact distance on a lattice stretched by `stretch` (each
/// body's largest lattice spacing over its mean, [`crate::arrangement::body_stretch`];
/// `body_sizes` the numbers of particles of the bodies in order; empty or sizes
/// that do not add up: 1): half its body's largest spacing,
/// [`contact_distance`] times the stretch, so that a body whose rows lie half a
/// row spacing from a wall starts touching it along either axis. With `½ √V⁰`
/// a block on `per_block = [5, 4]` (spacings 0.05 and 0.0625) placed on a
/// contact floor had its bottom row 0.03125 above it against a contact distance
/// of 0.028: it fell 3.3 mm, landed, and rang at 270 times its static strain
/// energy (a user's finding). Along the finer axis a particle then starts inside
/// the distance, which takes its start distance instead ([`ContactWall`]).
pub fn contact_distances<T: Scalar, const D: usize>(
    particles: &Particles<T, D>,
    body_sizes: &[usize],
    stretch: &[f64],
) -> Vec<f64> {
    let n = particles.len();
    let mut factor = vec![1.0; n];
    if body_sizes.len() == stretch.len() && body_sizes.iter().sum::<usize>() == n {
        let mut first = 0;
        for (&size, &s) in body_sizes.iter().zip(stretch) {
            factor[first..first + size].fill(s.max(1.0));
            first += size;
        }
    }
    particles
        .volume0
        .iter()
        .zip(factor)
        .map(|(v, f)| contact_distance::<D>(v.to_f64()) * f)
        .collect()
}

impl ContactWall {
    /// The walls' `geometry` for `particles` (a wall's spring frequency `κ / Δt`,
    /// its `κ` in the geometry), whose contact distances are `distance`
    /// ([`contact_distances`]). `Err` with the largest contact distance when it
    /// exceeds the geometry's reach (particles much coarser than the elements).
    pub fn new<T: Scalar, const D: usize>(
        geometry: WallGeometry,
        particles: &Particles<T, D>,
        distance: Vec<f64>,
    ) -> Result<Self, f64> {
        let largest = distance.iter().copied().fold(0.0, f64::max);
        if largest > geometry.reach {
            return Err(largest);
        }
        let mass: Vec<f64> = particles.mass.iter().map(|m| m.to_f64()).collect();
        let was_touching = vec![false; mass.len()];
        Ok(ContactWall {
            geometry,
            rate: 0.0,
            distance: Mutex::new(distance),
            state: Mutex::new(State {
                grid_mass: Vec::new(),
                contact_mass: Vec::new(),
                touching: Vec::new(),
                springs: mass,
                was_touching,
                started: false,
            }),
        })
    }

    /// At the first call (the particles located): a particle closer to the wall
    /// than its `d_p` takes its distance as its contact distance.
    fn start<T: Scalar, const D: usize>(&self, state: &mut State, particles: &Particles<T, D>) {
        if state.started {
            return;
        }
        state.started = true;
        let mut distance = self.distance.lock().unwrap_or_else(|e| e.into_inner());
        for (p, d) in distance.iter_mut().enumerate() {
            *d -= self
                .geometry
                .depth(particles.element[p], Self::position(&particles.x[p]), *d);
        }
    }

    fn position<T: Scalar, const D: usize>(x: &SVector<T, D>) -> Vec2 {
        Vec2::new(x[0].to_f64(), if D > 1 { x[1].to_f64() } else { 0.0 })
    }
}

impl<T: Scalar, const D: usize> Effect<T, D> for ContactWall {
    fn name(&self) -> &'static str {
        "contact-wall"
    }
    fn set_time_step(&mut self, dt: f64) {
        let rate = (1.0 / dt).powi(2);
        // Before the first step the springs are `m_p (κ / Δt)²`; after, those of
        // the last step follow the new rate.
        let scale = if self.rate > 0.0 {
            rate / self.rate
        } else {
            rate
        };
        let springs = &mut self
            .state
            .get_mut()
            .unwrap_or_else(|e| e.into_inner())
            .springs;
        springs.iter_mut().for_each(|k| *k *= scale);
        self.rate = rate;
    }
    /// `f_p = k_p g_p n` with `k_p = m_p (κ / Δt)² / c_p` (or the particle's spring
    /// of the last step if it was in contact then and is softer), `c_p = max_i c_i` over
    /// the functions around the particle, `c_i = Σ_{q in contact} φ_i(x_q) m_q / m_i`
    /// the share of function `i`'s lumped mass `m_i` that is in contact. Row `i` of
    /// the contact stiffness `K_c = Σ_p k_p (φ(x_p) n)(φ(x_p) n)ᵀ` then sums to at
    /// most `(κ / Δt)² m_i` (the functions are a non-negative partition of unity),
    /// so by Gershgorin the contact modes' frequency is at most `κ / Δt` whatever the
    /// particle count, and at about that bound when a layer of particles touches.
    /// Serial, in particle order.
    fn add_forces(
        &self,
        particles: &Particles<T, D>,
        state: &crate::effect::StepState<T, D>,
        forces: &mut [Vec<T>],
    ) {
        let mut guard = self.state.lock().unwrap_or_else(|e| e.into_inner());
        self.start(&mut guard, particles);
        let State {
            grid_mass,
            contact_mass,
            touching,
            springs,
            was_touching,
            ..
        } = &mut *guard;
        let distance = self.distance.lock().unwrap_or_else(|e| e.into_inner());
        let basis = &state.basis;
        touching.clear();
        for p in 0..particles.len() {
            let mut f = Vec2::zeros();
            let mut touches = false;
            let x = Self::position(&particles.x[p]);
            self.geometry
                .contacts(particles.element[p], x, distance[p], |g, n, kappa2| {
                    touches = true;
                    f += n * (kappa2 * g);
                });
            if touches {
                touching.push((p, f));
            }
        }
        if touching.is_empty() {
            was_touching.iter_mut().for_each(|t| *t = false);
            return;
        }
        grid_mass.clear();
        grid_mass.resize(forces[0].len(), 0.0);
        contact_mass.clear();
        contact_mass.resize(forces[0].len(), 0.0);
        for p in 0..particles.len() {
            let m = particles.mass[p].to_f64();
            for (i, phi) in basis.functions(p) {
                grid_mass[i] += phi.to_f64() * m;
            }
        }
        for &(p, _) in touching.iter() {
            let m = particles.mass[p].to_f64();
            for (i, phi) in basis.functions(p) {
                contact_mass[i] += phi.to_f64() * m;
            }
        }
        for &(p, f) in touching.iter() {
            let share = basis
                .functions(p)
                .filter(|&(i, phi)| grid_mass[i] > 0.0 && phi.to_f64() > 0.0)
                .map(|(i, _)| contact_mass[i] / grid_mass[i])
                .fold(0.0, f64::max);
            let bound = self.rate * particles.mass[p].to_f64() / share;
            // While a particle stays in contact its spring only softens: a spring
            // stiffened while compressed would gain the energy `½ Δk g²`.
            let k = if was_touching[p] {
                springs[p].min(bound)
            } else {
                bound
            };
            springs[p] = k;
            let f = SVector::<T, D>::from_fn(|c, _| T::of(if c < 2 { f[c] * k } else { 0.0 }));
            basis.scatter(p, &f, forces);
        }
        was_touching.iter_mut().for_each(|t| *t = false);
        for &(p, _) in touching.iter() {
            was_touching[p] = true;
        }
    }
    fn walls_element(&self, element: usize) -> bool {
        self.geometry.near(element)
    }
    fn went_through(&self, element: usize, x: [f64; 2]) -> bool {
        self.geometry.behind(element, Vec2::new(x[0], x[1]))
    }
    fn contact_distance(&self, particle: usize) -> Option<f64> {
        let distance = self.distance.lock().unwrap_or_else(|e| e.into_inner());
        distance.get(particle).copied()
    }
    fn potential_energy(&self, particles: &Particles<T, D>) -> f64 {
        let mut guard = self.state.lock().unwrap_or_else(|e| e.into_inner());
        self.start(&mut guard, particles);
        let springs = &guard.springs;
        let distance = self.distance.lock().unwrap_or_else(|e| e.into_inner());
        (0..particles.len())
            .map(|p| {
                let mut energy = 0.0;
                let k = springs[p];
                self.geometry.contacts(
                    particles.element[p],
                    Self::position(&particles.x[p]),
                    distance[p],
                    |g, _, kappa2| energy += 0.5 * k * kappa2 * g * g,
                );
                energy
            })
            .sum()
    }
}
