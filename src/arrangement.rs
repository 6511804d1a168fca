//! How the particles lie, judged from their positions alone: particles flung off
//! alone (stray), bodies come apart in pieces, and arrangements gone irregular.
//! An energy verdict sees none of these (a body can tear, scatter or lose its
//! lattice with its energy bounded), so a run checks them at its end and warns.

use crate::particles::Particles;
use nalgebra::{SMatrix, SVector};

/// How far, in its own spacing `√V⁰_p` (`V⁰_p` in 1D; times its body's stretch,
/// [`body_stretch`]), a particle's nearest neighbour must be for it to count as
/// stray ([`stray_particles`]).
pub const STRAY_DISTANCE: f64 = 2.0;

/// The largest spacing of a lattice of spacings `h` (one per axis) over its mean
/// spacing `(Π h_k)^(1/D)`, the `√V⁰_p` the arrangement measures by: 1 for a
/// square lattice, 2 for `per_block = [2, 8]` on square blocks. A particle's
/// spacing is `√V⁰_p` times its body's stretch, so that the neighbours along the
/// coarse axis count: without it a block at `[2, 8]`, whose columns lie exactly
/// `2 √V⁰_p` apart, was reported in 8 pieces 0.002 s into a standing wave of
/// amplitude 1e-5.
pub fn body_stretch(h: &[f64]) -> f64 {
    let mean = h.iter().product::<f64>().powf(1.0 / h.len().max(1) as f64);
    let largest = h.iter().copied().fold(0.0, f64::max);
    if mean > 0.0 && largest.is_finite() {
        (largest / mean).max(1.0)
    } else {
        1.0
    }
}

/// The most a particle's spacing grows with its stretch in the neighbour relation
/// ([`principal_stretch`]): a particle stretched further (a lone particle's `F`
/// after a blow-up) counts as stretched this much, so that one such particle does
/// not make the search's cells hold every particle.
pub const MOST_STRETCH: f64 = 10.0;

/// The largest principal stretch of a deformation gradient `F` (its largest
/// singular value, `|F|` in 1D), at least 1 and at most [`MOST_STRETCH`]; 1 for an
/// `F` that is not finite. A body stretched to `λ` times its length has its
/// particles `λ` times their spacing apart along the stretch: a soft bar hanging
/// under its own weight (E = 10, ρ = 1, L = 1, g = 9.81, strain up to about 2)
/// was reported in 4 pieces with 121 of its 256 particles stray, though whole.
pub fn principal_stretch<const D: usize>(f: &SMatrix<f64, D, D>) -> f64 {
    let c = f.transpose() * f;
    let largest = match D {
        1 => c[(0, 0)],
        2 => {
            let (a, b, d) = (c[(0, 0)], c[(0, 1)], c[(1, 1)]);
            let half_trace = 0.5 * (a + d);
            half_trace + (0.25 * (a - d) * (a - d) + b * b).sqrt()
        }
        // Not used (1D and 2D only): the trace bounds the largest eigenvalue.
        _ => c.trace(),
    };
    let lambda = largest.sqrt();
    if lambda.is_finite() {
        lambda.clamp(1.0, MOST_STRETCH)
    } else {
        1.0
    }
}

/// The particles near each particle: a grid of cells of the largest reach
/// (`distance` times the largest particle's spacing `√V⁰_p`, `V⁰_p` in 1D) over
/// `positions`, and the 3^D cells around each particle. The particles are counted
/// by cell (4 bytes per particle, in index order within a cell) over the cells of
/// their bounding box, or, where that box holds more than [`DENSE_CELLS`] cells
/// per particle (particles flung far apart), over their occupied cells kept sorted;
/// a hash map of cells took about 40 bytes per particle at the end of a run, its
/// peak. Deterministic: the neighbours of a particle come in the order of the
/// cells and, within a cell, of the particles.
struct NeighbourGrid<'a, const D: usize> {
    positions: &'a [SVector<f64, D>],
    volume0: &'a [f64],
    /// The deformation gradients (each particle's spacing grows with its largest
    /// stretch, [`principal_stretch`]).
    f: &'a [SMatrix<f64, D, D>],
    /// The body of each particle (empty: one body) and each body's stretch
    /// ([`body_stretch`]; empty: 1).
    body: &'a [u32],
    stretch: &'a [f64],
    distance: f64,
    reach: f64,
    cells: Cells<D>,
    /// The particles of cell `c` (numbered by [`Cells`]) are
    /// `members[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    /// The particles, by cell and, within a cell, by index.
    members: Vec<u32>,
}

/// At most this many cells of the bounding box per particle for [`Cells::Box`].
const DENSE_CELLS: u64 = 2;

/// How [`NeighbourGrid`] numbers its cells.
enum Cells<const D: usize> {
    /// Every cell of the box from `low` with `size` cells per axis, the first
    /// axis fastest.
    Box { low: [i64; D], size: [u64; D] },
    /// The occupied cells, sorted.
    Sorted(Vec<[i64; D]>),
}

impl<'a, const D: usize> NeighbourGrid<'a, D> {
    /// The grid of `positions` (particles of reference volumes `volume0` and
    /// deformation gradients `f`) for the neighbours within `distance` of their
    /// spacing; `None` when the particles have no size to measure by. The caller
    /// bounds the particles below 2³² (the driver does).
    fn new(
        positions: &'a [SVector<f64, D>],
        volume0: &'a [f64],
        f: &'a [SMatrix<f64, D, D>],
        bodies: (&'a [u32], &'a [f64]),
        distance: f64,
    ) -> Option<Self> {
        Self::with_box_limit(positions, volume0, f, bodies, distance, DENSE_CELLS)
    }

    /// [`NeighbourGrid::new`] with at most `box_limit` cells of the bounding box
    /// per particle for [`Cells::Box`].
    fn with_box_limit(
        positions: &'a [SVector<f64, D>],
        volume0: &'a [f64],
        f: &'a [SMatrix<f64, D, D>],
        (body, stretch): (&'a [u32], &'a [f64]),
        distance: f64,
        box_limit: u64,
    ) -> Option<Self> {
        let reach = volume0
            .iter()
            .map(|v| v.powf(1.0 / D as f64))
            .fold(0.0, f64::max)
            * stretch.iter().copied().fold(1.0, f64::max)
            * f.iter().map(principal_stretch).fold(1.0, f64::max)
            * distance;
        if !(reach > 0.0 && reach.is_finite()) {
            return None;
        }
        let mut grid = Self {
            positions,
            volume0,
            f,
            body,
            stretch,
            distance,
            reach,
            cells: Cells::Sorted(Vec::new()),
            starts: Vec::new(),
            members: Vec::new(),
        };
        let n = positions.len();
        let (mut low, mut high) = ([i64::MAX; D], [i64::MIN; D]);
        for p in 0..n {
            let c = grid.cell(p);
            for k in 0..D {
                (low[k], high[k]) = (low[k].min(c[k]), high[k].max(c[k]));
            }
        }
        // Cells per axis (none for no particles, or a span past 2⁶⁴ where a
        // position is not finite).
        let span = |k: usize| u64::try_from(high[k] as i128 - low[k] as i128 + 1).ok();
        let size: [u64; D] = std::array::from_fn(|k| span(k).unwrap_or(0));
        let cells = (0..D).try_fold(1u64, |a, k| a.checked_mul(span(k)?));
        match cells {
            Some(cells) if n > 0 && cells <= box_limit.saturating_mul(n as u64) + 64 => {
                grid.cells = Cells::Box { low, size };
                // Counting sort: counts, their prefix sums, then the particles in
                // index order.
                let mut starts = vec![0u32; cells as usize + 1];
                for p in 0..n {
                    starts[grid.number(&grid.cell(p)).expect("in the box") + 1] += 1;
                }
                for c in 0..cells as usize {
                    starts[c + 1] += starts[c];
                }
                let mut members = vec![0u32; n];
                for p in 0..n {
                    let c = grid.number(&grid.cell(p)).expect("in the box");
                    members[starts[c] as usize] = p as u32;
                    starts[c] += 1;
                }
                // Each start has moved to the next cell's: shift back.
                starts.copy_within(0..cells as usize, 1);
                starts[0] = 0;
                (grid.starts, grid.members) = (starts, members);
            }
            _ => {
                let mut members: Vec<u32> = (0..n as u32).collect();
                members.sort_unstable_by_key(|&p| (grid.cell(p as usize), p));
                let (mut cells, mut starts) = (Vec::new(), Vec::new());
                for (k, &p) in members.iter().enumerate() {
                    let cell = grid.cell(p as usize);
                    if cells.last() != Some(&cell) {
                        cells.push(cell);
                        starts.push(k as u32);
                    }
                }
                starts.push(n as u32);
                (grid.cells, grid.starts, grid.members) = (Cells::Sorted(cells), starts, members);
            }
        }
        Some(grid)
    }

    /// The number of cell `key`, `None` for a cell that holds no particle for sure
    /// (outside the box, or not among the sorted cells).
    fn number(&self, key: &[i64; D]) -> Option<usize> {
        match &self.cells {
            Cells::Box { low, size } => {
                let mut number = 0u64;
                for k in (0..D).rev() {
                    let offset = key[k].checked_sub(low[k])?;
                    if offset < 0 || offset as u64 >= size[k] {
                        return None;
                    }
                    number = number * size[k] + offset as u64;
                }
                Some(number as usize)
            }
            Cells::Sorted(cells) => cells.binary_search(key).ok(),
        }
    }

    /// The particles of cell `key` (none when it is empty).
    fn members_of(&self, key: &[i64; D]) -> &[u32] {
        match self.number(key) {
            Some(c) => &self.members[self.starts[c] as usize..self.starts[c + 1] as usize],
            None => &[],
        }
    }

    fn cell(&self, p: usize) -> [i64; D] {
        std::array::from_fn(|k| (self.positions[p][k] / self.reach).floor() as i64)
    }

    /// Particle `p`'s spacing `√V⁰_p` (`V⁰_p` in 1D), times its body's stretch
    /// and its own largest stretch ([`principal_stretch`]).
    fn spacing(&self, p: usize) -> f64 {
        let stretch = match (self.stretch, self.body.get(p)) {
            ([], _) => 1.0,
            ([one], _) => *one,
            (all, Some(&b)) => all.get(b as usize).copied().unwrap_or(1.0),
            (all, None) => all.iter().copied().fold(1.0, f64::max),
        };
        let deformed = self.f.get(p).map_or(1.0, principal_stretch);
        self.volume0[p].powf(1.0 / D as f64) * stretch.max(1.0) * deformed
    }

    /// Calls `near(q)` for each particle `q ≠ p` within `distance` times the
    /// spacing of `p`.
    fn each(&self, p: usize, mut near: impl FnMut(usize)) {
        let (c, r) = (self.cell(p), self.distance * self.spacing(p));
        for n in 0..3usize.pow(D as u32) {
            let key: [i64; D] = std::array::from_fn(|k| {
                c[k].saturating_add(((n / 3usize.pow(k as u32)) % 3) as i64 - 1)
            });
            for &q in self.members_of(&key) {
                let q = q as usize;
                if q != p && (self.positions[q] - self.positions[p]).norm() <= r {
                    near(q);
                }
            }
        }
    }
}

/// Calls `pair(p, q)` for each particle `q` within [`STRAY_DISTANCE`] times the
/// spacing of particle `p`, now. `false` when the particles have no size to
/// measure by.
fn neighbours<const D: usize>(
    particles: &Particles<f64, D>,
    bodies: (&[u32], &[f64]),
    mut pair: impl FnMut(usize, usize),
) -> bool {
    let Some(grid) = NeighbourGrid::new(
        &particles.x,
        &particles.volume0,
        &particles.f,
        bodies,
        STRAY_DISTANCE,
    ) else {
        return false;
    };
    for p in 0..particles.len() {
        grid.each(p, |q| pair(p, q));
    }
    true
}

/// The body of each particle, where there are several (`body_sizes`: the numbers
/// of particles of the bodies, in order); empty for one body or sizes that do not
/// add up (no buffer for one: the run's peak memory per particle counts it).
fn bodies(body_sizes: &[usize], n: usize) -> Vec<u32> {
    let mut body = Vec::new();
    if body_sizes.len() > 1 && body_sizes.iter().sum::<usize>() == n {
        body = vec![0u32; n];
        let mut first = 0;
        for (b, &size) in body_sizes.iter().enumerate() {
            body[first..first + size].fill(b as u32);
            first += size;
        }
    }
    body
}

/// What the neighbour relation of the particles (a particle and those within
/// [`STRAY_DISTANCE`] times its spacing) says of them, from one pass over it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fragments {
    /// Particles with no other particle within [`STRAY_DISTANCE`] times their own
    /// spacing: none in a body sampled on a lattice or jittered in its cells; one
    /// for each particle a body that came apart flung off alone.
    pub stray: usize,
    /// The sizes of the pieces the particles form, largest first: the connected
    /// sets of the relation, counting those of at least 3 particles and
    /// [`STRAY_WARNING`] of all. One per body on a lattice, however it is
    /// stretched (a particle's spacing grows with its `F`, up to [`MOST_STRETCH`]),
    /// and moved apart by up to about twice its spacing besides; two for a body
    /// torn in two.
    pub pieces: Vec<usize>,
}

/// The [`Fragments`] of `particles`: the neighbour relation walked once, marking
/// the particles with a neighbour and joining the pieces (union–find). The pieces
/// are those of each body: `body_sizes` are the numbers of particles of the bodies,
/// whose particles follow each other in that order (empty: one body), and
/// neighbours of different bodies are not joined, so bodies that start in contact
/// and part stay one piece each, while a body torn in two is two. `stretch` is
/// each body's [`body_stretch`] (empty: 1).
pub fn fragments<const D: usize>(
    particles: &Particles<f64, D>,
    body_sizes: &[usize],
    stretch: &[f64],
) -> Fragments {
    // Union–find over particle indices in 32 bits (the driver bounds the
    // particles below 2³²).
    fn root(parent: &mut [u32], a: usize) -> usize {
        let mut a = a as u32;
        while parent[a as usize] != a {
            parent[a as usize] = parent[parent[a as usize] as usize];
            a = parent[a as usize];
        }
        a as usize
    }
    let n = particles.len();
    let body = bodies(body_sizes, n);
    let mut near = vec![false; n];
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let measured = neighbours(particles, (&body, stretch), |p, q| {
        near[p] = true;
        if !body.is_empty() && body[p] != body[q] {
            return;
        }
        let (a, b) = (root(&mut parent, p), root(&mut parent, q));
        if a != b {
            parent[a.max(b)] = a.min(b) as u32;
        }
    });
    if !measured {
        return Fragments {
            stray: 0,
            pieces: Vec::new(),
        };
    }
    let mut size = vec![0usize; n];
    for p in 0..n {
        size[root(&mut parent, p)] += 1;
    }
    let least = 3.max((STRAY_WARNING * n as f64).ceil() as usize);
    let mut pieces: Vec<usize> = size.into_iter().filter(|&s| s >= least).collect();
    pieces.sort_unstable_by(|a, b| b.cmp(a));
    Fragments {
        stray: near.iter().filter(|&&n| !n).count(),
        pieces,
    }
}

/// [`Fragments::stray`] of `particles`.
pub fn stray_particles<const D: usize>(particles: &Particles<f64, D>) -> usize {
    fragments(particles, &[], &[]).stray
}

/// [`Fragments::pieces`] of `particles`, taken as one body.
pub fn pieces<const D: usize>(particles: &Particles<f64, D>) -> Vec<usize> {
    fragments(particles, &[], &[]).pieces
}

/// The warning for a run whose particles form more [`pieces`] at the end (`end`,
/// their sizes) than at the start (`start`): a body came apart, torn where it was
/// stretched or broken at an impact, which an energy verdict of stable does not
/// show (a soft neo-Hookean block hanging from a no-slip ceiling at 4 × 4 particles
/// per block tore below its top rows and fell, its energy bounded).
pub fn pieces_warning(start: usize, end: &[usize], particles: usize) -> Option<String> {
    (end.len() > start).then(|| {
        let shares: Vec<String> = end
            .iter()
            .take(4)
            .map(|&s| format!("{:.0} %", 100.0 * s as f64 / particles as f64))
            .collect();
        let more = if end.len() > 4 { ", …" } else { "" };
        format!(
            "the particles form {} pieces at the end ({start} at the start), holding {}{more} of them: a body came apart (torn where it was stretched, or broken at an impact), which the energy verdict does not show: look at the particles (`--out`); a body torn where it stretches needs more particles per element there (`per_block`, `count` or `spacing`), one broken at an impact also a smaller `courant`",
            end.len(),
            shares.join(", ")
        )
    })
}

/// The warning for a run that ends with `end` stray particles
/// ([`stray_particles`]) of `particles`, `start` of them at
/// the start: when at least [`STRAY_WARNING`] of the particles (and 3) became stray,
/// the bodies came apart, which an energy verdict of stable does not show (a soft
/// neo-Hookean disk, E = 2e3, dropped onto a contact floor at 4 particles per
/// triangle, ended with its particles scattered).
pub fn stray_warning(start: usize, end: usize, particles: usize) -> Option<String> {
    strayed(start, end, particles).then(|| {
        format!(
            "{end} of the {particles} particles ended stray ({start} at the start): no other particle within {STRAY_DISTANCE} times their own spacing; the bodies came apart (fragments or single particles flung off), which the energy verdict does not show: look at the particles (`--out`), and for a soft body use more particles per element (`per_block`, `count` or `spacing`) and a smaller `courant`"
        )
    })
}

/// Whether `end` stray particles of `particles`, `start` of them at the start,
/// mean that the bodies came apart: at least [`STRAY_WARNING`] of the particles,
/// and 3, became stray ([`stray_warning`]).
pub fn strayed(start: usize, end: usize, particles: usize) -> bool {
    let new = end.saturating_sub(start);
    new >= 3 && new as f64 >= STRAY_WARNING * particles as f64
}

/// The share of the particles that must become stray for [`stray_warning`].
pub const STRAY_WARNING: f64 = 0.01;

/// A vector of the plane from one of dimension `D` (the second component zero in
/// 1D).
fn plane<const D: usize>(v: SVector<f64, D>) -> nalgebra::Vector2<f64> {
    nalgebra::Vector2::new(v[0], if D > 1 { v[D - 1] } else { 0.0 })
}

/// How far, in a particle's spacing, its neighbours for [`irregularity`] lie in the
/// reference configuration: the eight around a particle of a lattice (the
/// diagonal ones at `√2`), about as many in a jittered one.
pub const NEIGHBOURHOOD: f64 = 1.5;

/// The residual of the affine fit, in the particle's spacing, above which a
/// particle has left the arrangement of its neighbours ([`irregularity`]). Smooth
/// motions stay well below it: a soft block dropped onto a floor with 25 % strains
/// at 8 × 8 particles per block ends with a largest residual of 0.24 and a median of
/// 0.08; the same block with PS at 4 × 4 (4 per triangle), whose columns of
/// particles buckle into a zig-zag, has a tenth of its particles above 0.3.
pub const IRREGULAR_RESIDUAL: f64 = 0.3;

/// The share of the measured particles (and at least 3) above [`IRREGULAR_RESIDUAL`]
/// for [`irregularity_warning`].
pub const IRREGULAR_WARNING: f64 = 0.05;

/// How far the particles have left the arrangement they started in, beyond what a
/// smooth motion does to it ([`irregularity`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Irregularity {
    /// Particles whose neighbourhood could be fitted (neighbours of the same body
    /// spanning the plane).
    pub measured: usize,
    /// Of those, the particles whose residual is above [`IRREGULAR_RESIDUAL`].
    pub irregular: usize,
    /// The largest residual, in the particle's spacing.
    pub largest: f64,
}

/// The non-affine displacement of each particle's neighbourhood (Falk and Langer's
/// `D²_min`): the neighbours `q` of particle `p` within [`NEIGHBOURHOOD`] times its
/// spacing `h_p` at the start (reference positions `x0`, the same body), the affine
/// map `F` that best carries their offsets `ΔX_q = X_q − X_p` to their offsets now
/// `Δx_q = x_q − x_p` (least squares, `F = (Σ Δx ΔXᵀ)(Σ ΔX ΔXᵀ)⁻¹`), and the
/// residual `r_p = √(mean_q |Δx_q − F ΔX_q|²) / h_p`. Any smooth motion (a
/// translation, a rotation, a uniform or slowly varying strain) leaves `r_p` small,
/// of the order of the strain's variation over a spacing; particles that pair up,
/// open voids or cross their neighbours' rows raise it to a fair fraction of a
/// spacing. Counts, over the particles, those above [`IRREGULAR_RESIDUAL`]. In 1D
/// no neighbourhood spans the plane and nothing is measured. The neighbourhood
/// reaches along the coarse axis of a stretched lattice (`stretch`, each body's
/// [`body_stretch`]; empty: 1), and the residual is measured in `√V⁰_p`.
pub fn irregularity<const D: usize>(
    particles: &Particles<f64, D>,
    body_sizes: &[usize],
    stretch: &[f64],
) -> Irregularity {
    let mut out = Irregularity::default();
    let body = bodies(body_sizes, particles.len());
    let Some(grid) = NeighbourGrid::new(
        &particles.x0,
        &particles.volume0,
        // In the reference configuration: unstretched.
        &[],
        (&body, stretch),
        NEIGHBOURHOOD,
    ) else {
        return out;
    };
    for p in 0..particles.len() {
        // Σ ΔX ΔXᵀ, Σ Δx ΔXᵀ, Σ |Δx|² and the count.
        let (mut a, mut b) = (nalgebra::Matrix2::zeros(), nalgebra::Matrix2::zeros());
        let (mut c, mut count) = (0.0, 0usize);
        grid.each(p, |q| {
            if !body.is_empty() && body[p] != body[q] {
                return;
            }
            let dx0 = plane(particles.x0[q] - particles.x0[p]);
            let dx = plane(particles.x[q] - particles.x[p]);
            a += dx0 * dx0.transpose();
            b += dx * dx0.transpose();
            c += dx.norm_squared();
            count += 1;
        });
        let h = particles.volume0[p].powf(1.0 / D as f64);
        // A neighbourhood that spans the plane: det(Σ ΔX ΔXᵀ) well away from zero
        // on the scale of the spacing (a row of particles does not).
        if count < 2 || a.determinant().abs() <= 1e-6 * h.powi(4) {
            continue;
        }
        let Some(a_inv) = a.try_inverse() else {
            continue;
        };
        // Σ |Δx − F ΔX|² = Σ |Δx|² − tr(B A⁻¹ Bᵀ) at the least-squares F = B A⁻¹.
        let squared = (c - (b * a_inv * b.transpose()).trace()).max(0.0) / count as f64;
        let r = squared.sqrt() / h;
        if !r.is_finite() {
            continue;
        }
        out.measured += 1;
        out.largest = out.largest.max(r);
        if r > IRREGULAR_RESIDUAL {
            out.irregular += 1;
        }
    }
    out
}

/// Particles per occupied triangle from which a PS body kept its arrangement under
/// large strains in the measurements of [`irregularity_warning`].
pub const PS_REGULAR_SAMPLING: f64 = 9.0;

/// The warning for a run whose particles ended out of their neighbours'
/// arrangement ([`irregularity`]): at least [`IRREGULAR_WARNING`] of the measured
/// particles (and 3) above [`IRREGULAR_RESIDUAL`]. `ps` says whether the basis is
/// PS and `sampling` is the particles per occupied element at the start. Measured
/// on a soft neo-Hookean block (E = 3e3, ρ = 100, 1 × 0.75, ρ g H / E = 0.25)
/// dropped 0.125 onto a slip floor of 0.25 blocks of four triangles each, to t = 2:
/// PS with 3 × 3, 4 × 4, 5 × 5, 6 × 6 particles per block (2.25 to 9 per triangle)
/// ends with 48 %, 9.4 %, 1.3 %, 0 % of its particles irregular, PL with 2 × 2 and
/// 4 × 4 with 79 % and 0 %; none of the scenes of `docs/examples` reaches 4 % with
/// either basis.
///
/// With `contact_walls` (the scene has a contact wall) the fix adds that a finer
/// lattice wants a smaller `courant`: the wall's contact distance is half a
/// particle spacing, while the time step of a given `courant` grows with the
/// particles (better covered functions, fewer lumped rows), so a body sampled
/// finer at the same `courant` can pass through the wall (a user's soft disk did).
pub fn irregularity_warning(
    irregularity: &Irregularity,
    ps: bool,
    sampling: f64,
    contact_walls: bool,
) -> Option<String> {
    let Irregularity {
        measured,
        irregular,
        largest,
    } = *irregularity;
    (irregular >= 3 && irregular as f64 >= IRREGULAR_WARNING * measured as f64).then(|| {
        let fix = if ps && sampling < PS_REGULAR_SAMPLING {
            format!(
                "with PS, {sampling:.1} particles per occupied triangle under-sample its nine quadratic functions once the strains are large, and the body's rows buckle into modes the particles do not resist (a soft block dropped onto a floor: 9.4 % of its particles irregular at 4 per triangle, 1.3 % at 6.25, none at 9); give {PS_REGULAR_SAMPLING:.0} or more per triangle (`per_block` 6 × 6 on block meshes of four triangles, `per_triangle`, `count` or `spacing`; `--particles`); a hard impact can leave some at any sampling (a 1 × 1 block, E = 1e5, dropped 1 m onto a floor: 20 % at 4 per triangle, 8–12 % at 9 and 16, whatever the step): look at them to judge"
            )
        } else if ps {
            // A user's block crushed by its own weight (ρ g H / E = 2.5) at 9 per
            // triangle ended 81 % irregular: more particles was no fix.
            format!(
                "with PS at {sampling:.1} particles per occupied triangle, what a smooth motion at large strain needs, irregularity this large comes from strains the particles cannot follow: a body crushed by strains of order one (check `young` and the self-weight warning, if any: a block with ρ g H / E = 2.5 at 9 per triangle ended 81 % irregular) or struck hard (a smaller `courant`, and more particles, help there); look at them to judge"
            )
        } else {
            "give more particles per element (`per_block`, `per_triangle`, `count` or `spacing`; `--particles`), and if the body was struck hard a smaller `courant`".to_string()
        };
        let fix = if contact_walls {
            format!("{fix}; with a contact wall lower `courant` with the particle spacing as well (the contact distance is half a spacing, and the step of a given `courant` grows with the particles: from 4 to 9 per triangle, `courant` × 2/3), or the body can pass through the wall")
        } else {
            fix
        };
        format!(
            "{irregular} of the {measured} particles ({:.0} %) ended out of their neighbours' arrangement by more than {IRREGULAR_RESIDUAL} of their spacing (the largest {largest:.2}): beyond what a smooth motion does, the particles paired up, opened voids or crossed rows, which the energy verdict does not show: look at the particles (`--out`); {fix}",
            100.0 * irregular as f64 / measured as f64
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// The grid's neighbours are those within reach (against every pair), in the
    /// same order whether the cells are those of the bounding box or the sorted
    /// occupied ones, for a jittered lattice with and without particles flung far.
    #[test]
    fn the_neighbour_grid_finds_every_pair_within_reach_in_one_order() {
        let mut rng = psmpm_basis::rng::SplitMix64(3);
        for flung in [0usize, 5] {
            let x: Vec<Vector2<f64>> = (0..400)
                .map(|i| {
                    let (a, b) = ((i % 20) as f64, (i / 20) as f64);
                    let far = if i < flung {
                        10.0 * (i as f64 + 1.0)
                    } else {
                        0.0
                    };
                    Vector2::new(0.1 * a + 0.04 * rng.next_f64() + far, 0.1 * b - far)
                })
                .collect();
            let volume = vec![0.01; x.len()];
            let f = vec![SMatrix::<f64, 2, 2>::identity(); x.len()];
            let walk = |limit| {
                let grid = NeighbourGrid::with_box_limit(&x, &volume, &f, (&[], &[]), 2.0, limit)
                    .expect("a size to measure by");
                let boxed = matches!(grid.cells, Cells::Box { .. });
                let mut all = Vec::new();
                for p in 0..x.len() {
                    let mut near = Vec::new();
                    grid.each(p, |q| near.push(q));
                    all.push(near);
                }
                (boxed, all)
            };
            let (boxed, in_box) = walk(u64::MAX / 1024);
            let (sorted_is_box, in_sorted) = walk(0);
            assert!(boxed && !sorted_is_box);
            assert_eq!(in_box, in_sorted);
            assert_eq!(walk(DENSE_CELLS).0, flung == 0);
            for (p, near) in in_box.iter().enumerate() {
                let mut near = near.clone();
                near.sort_unstable();
                let every: Vec<usize> = (0..x.len())
                    .filter(|&q| q != p && (x[q] - x[p]).norm() <= 2.0 * 0.01f64.powf(0.5))
                    .collect();
                assert_eq!(near, every, "particle {p}");
            }
        }
    }

    /// A 10 × 10 lattice of spacing 0.1 has no stray particle, jittered by up to a
    /// third of its spacing neither; a particle flung 0.25 away from it is stray,
    /// and the warning asks for 1 % of the particles and 3.
    #[test]
    fn a_particle_flung_off_a_lattice_is_stray() {
        let lattice = |jitter: f64, flung: usize| {
            let x: Vec<Vector2<f64>> = (0..100)
                .map(|i| {
                    let (a, b) = ((i % 10) as f64, (i / 10) as f64);
                    let wobble = jitter * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
                    let mut x = Vector2::new(0.1 * a + wobble, 0.1 * b - wobble);
                    if i < flung {
                        x.y = -0.25 - 0.3 * i as f64;
                    }
                    x
                })
                .collect();
            Particles::<f64, 2>::new(x, vec![0.01; 100], 1.0)
        };
        assert_eq!(stray_particles(&lattice(0.0, 0)), 0);
        assert_eq!(stray_particles(&lattice(0.033, 0)), 0);
        assert_eq!(stray_particles(&lattice(0.0, 1)), 1);
        assert_eq!(stray_particles(&lattice(0.0, 3)), 3);
        assert!(stray_warning(0, 2, 100).is_none());
        assert!(stray_warning(0, 3, 1000).is_none());
        assert!(stray_warning(0, 3, 100)
            .unwrap()
            .contains("3 of the 100 particles"));
        assert!(stray_warning(3, 5, 100).is_none());
    }

    /// A lattice whose columns lie 4 times as far apart as its rows (`per_block =
    /// [2, 8]`: `√V⁰` is half the column spacing, so the columns are exactly at
    /// `STRAY_DISTANCE √V⁰`), its columns 1 % farther apart: one piece with the
    /// lattice's stretch, as many as columns without; torn in two, two with it.
    /// Its neighbourhoods span the plane for the irregularity with the stretch
    /// (without it a particle's neighbours within 1.5 `√V⁰` are its column's).
    #[test]
    fn a_stretched_lattice_is_one_piece() {
        let (dx, dy) = (0.4, 0.1);
        let lattice = |widen: f64, gap: f64| {
            let x: Vec<Vector2<f64>> = (0..100)
                .map(|i| {
                    let (a, b) = ((i % 5) as f64, (i / 5) as f64);
                    Vector2::new(dx * widen * a, dy * b + if b >= 10.0 { gap } else { 0.0 })
                })
                .collect();
            Particles::<f64, 2>::new(x, vec![dx * dy; 100], 1.0)
        };
        let stretch = [body_stretch(&[dx, dy])];
        assert!((stretch[0] - 2.0).abs() < 1e-12);
        let one = lattice(1.01, 0.0);
        assert_eq!(fragments(&one, &[], &stretch).pieces, vec![100]);
        assert_eq!(fragments(&one, &[], &[]).pieces, vec![20; 5]);
        assert_eq!(fragments(&one, &[], &stretch).stray, 0);
        let torn = lattice(1.0, 1.0);
        assert_eq!(fragments(&torn, &[], &stretch).pieces, vec![50, 50]);
        let mut moved = lattice(1.0, 0.0);
        moved.x.iter_mut().for_each(|x| x.x *= 1.01);
        assert_eq!(irregularity(&moved, &[], &stretch).measured, 100);
        assert_eq!(irregularity(&moved, &[], &stretch).irregular, 0);
        assert_eq!(irregularity(&moved, &[], &[]).measured, 0);
        assert_eq!(body_stretch(&[0.1, 0.1]), 1.0);
        assert_eq!(body_stretch(&[0.05, 0.0125]), 2.0);
    }

    /// A lattice is one piece, stretched by half its spacing too; torn in two it is
    /// two, and the warning gives their shares; a few particles flung off are not a
    /// piece (they are stray).
    #[test]
    fn a_lattice_torn_in_two_is_two_pieces() {
        let lattice = |stretch: f64, gap: f64, flung: usize| {
            let x: Vec<Vector2<f64>> = (0..100)
                .map(|i| {
                    let (a, b) = ((i % 10) as f64, (i / 10) as f64);
                    let mut x = Vector2::new(
                        0.1 * a,
                        0.1 * stretch * b + if b >= 7.0 { gap } else { 0.0 },
                    );
                    if i < flung {
                        x.x = -0.5 - 0.3 * i as f64;
                    }
                    x
                })
                .collect();
            Particles::<f64, 2>::new(x, vec![0.01; 100], 1.0)
        };
        assert_eq!(pieces(&lattice(1.0, 0.0, 0)), vec![100]);
        assert_eq!(pieces(&lattice(1.5, 0.0, 0)), vec![100]);
        assert_eq!(pieces(&lattice(1.0, 0.5, 0)), vec![70, 30]);
        assert_eq!(pieces(&lattice(1.0, 0.0, 2)), vec![98]);
        assert!(pieces_warning(1, &[100], 100).is_none());
        // The rows from 7 on as a body of their own (30 particles after the 70 of
        // the first): two pieces touching at the start, and still two once they
        // part, since pieces are counted per body; a body torn is one more.
        let two_bodies = |gap: f64| fragments(&lattice(1.0, gap, 0), &[70, 30], &[]).pieces;
        assert_eq!(two_bodies(0.0), vec![70, 30]);
        assert_eq!(two_bodies(0.5), vec![70, 30]);
        let mut torn = lattice(1.0, 0.0, 0);
        (0..20).for_each(|p| torn.x[p].y -= 0.5);
        assert_eq!(fragments(&torn, &[70, 30], &[]).pieces, vec![50, 30, 20]);
        assert_eq!(fragments(&torn, &[], &[]).pieces, vec![80, 20]);
        let warning = pieces_warning(1, &[70, 30], 100).unwrap();
        assert!(
            warning.contains("2 pieces at the end (1 at the start), holding 70 %, 30 %"),
            "{warning}"
        );
    }

    /// A body stretched to `λ` times its length (its particles' `F` say so) is one
    /// piece with no particle stray, up to [`MOST_STRETCH`]: a 1D bar of 40
    /// particles stretched 3 times, a 2D lattice 5 times along x; torn, it is two
    /// pieces all the same. Without the stretch both came apart (a user's soft bar
    /// hanging under its own weight: 4 pieces, 121 of 256 particles stray).
    #[test]
    fn a_body_stretched_by_its_deformation_is_one_piece() {
        let bar = |lambda: f64, gap: f64| {
            let x: Vec<SVector<f64, 1>> = (0..40)
                .map(|i| {
                    let tear = if i >= 25 { gap } else { 0.0 };
                    SVector::<f64, 1>::new(0.05 * lambda * (i as f64 + 0.5) + tear)
                })
                .collect();
            let mut p = Particles::<f64, 1>::new(x, vec![0.05; 40], 1.0);
            p.f.iter_mut().for_each(|f| f[(0, 0)] = lambda);
            p
        };
        assert_eq!(fragments(&bar(3.0, 0.0), &[], &[]).stray, 0);
        assert_eq!(pieces(&bar(3.0, 0.0)), vec![40]);
        assert_eq!(pieces(&bar(3.0, 1.0)), vec![25, 15]);
        let mut unstretched = bar(3.0, 0.0);
        unstretched.f.iter_mut().for_each(|f| f[(0, 0)] = 1.0);
        assert_eq!(fragments(&unstretched, &[], &[]).stray, 40);
        let block = |lambda: f64, gap: f64| {
            let x: Vec<Vector2<f64>> = (0..100)
                .map(|i| {
                    let (a, b) = ((i % 10) as f64, (i / 10) as f64);
                    let tear = if a >= 5.0 { gap } else { 0.0 };
                    Vector2::new(0.1 * lambda * a + tear, 0.1 * b)
                })
                .collect();
            let mut p = Particles::<f64, 2>::new(x, vec![0.01; 100], 1.0);
            p.f.iter_mut().for_each(|f| f[(0, 0)] = lambda);
            p
        };
        assert_eq!(pieces(&block(5.0, 0.0)), vec![100]);
        assert_eq!(pieces(&block(5.0, 2.0)), vec![50, 50]);
        // Rotated as it stretched: the largest singular value, not a component.
        let mut turned = block(5.0, 0.0);
        let r = nalgebra::Rotation2::new(0.7).into_inner();
        turned.x.iter_mut().for_each(|x| *x = r * *x);
        turned.f.iter_mut().for_each(|f| *f = r * *f);
        assert_eq!(pieces(&turned), vec![100]);
        assert!((principal_stretch(&turned.f[0]) - 5.0).abs() < 1e-12);
        // Bounded, and 1 for a compression or an `F` that is not a number.
        let huge = nalgebra::Matrix2::new(1e9, 0.0, 0.0, 1.0);
        assert_eq!(principal_stretch(&huge), MOST_STRETCH);
        assert_eq!(
            principal_stretch(&(nalgebra::Matrix2::identity() * 0.5)),
            1.0
        );
        assert_eq!(
            principal_stretch(&(nalgebra::Matrix2::identity() * f64::NAN)),
            1.0
        );
    }

    /// A 10 × 10 lattice (spacing 0.1) carried by any affine map has no particle out
    /// of place, nor one bent gently; one whose columns alternate up and down by
    /// 0.2 of a spacing (a zig-zag) has every inner particle out of place, and the
    /// warning needs 5 % and 3. Two bodies, one sliding along the other, are each
    /// in place; taken as one body, the particles along the slip are not.
    #[test]
    fn a_lattice_out_of_its_arrangement_is_irregular() {
        let moved = |map: &dyn Fn(Vector2<f64>) -> Vector2<f64>| {
            let x0: Vec<Vector2<f64>> = (0..100)
                .map(|i| Vector2::new(0.1 * (i % 10) as f64, 0.1 * (i / 10) as f64))
                .collect();
            let mut p = Particles::<f64, 2>::new(x0.clone(), vec![0.01; 100], 1.0);
            p.x = x0.into_iter().map(map).collect();
            p
        };
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let affine = |x: Vector2<f64>| {
            Vector2::new(
                1.3 * (c * x.x - s * x.y) + 0.4 * x.y + 2.0,
                s * x.x + c * x.y,
            )
        };
        let bent = |x: Vector2<f64>| Vector2::new(x.x, x.y + 0.3 * x.x * x.x);
        for (name, p) in [("affine", moved(&affine)), ("bent", moved(&bent))] {
            let r = irregularity(&p, &[], &[]);
            assert_eq!((r.measured, r.irregular), (100, 0), "{name}: {r:?}");
            assert!(r.largest < 0.05, "{name}: {r:?}");
        }
        let zigzag = moved(&|x: Vector2<f64>| {
            let column = (x.x / 0.1).round() as i64;
            x + Vector2::new(0.0, if column % 2 == 0 { 0.02 } else { -0.02 })
        });
        let r = irregularity(&zigzag, &[], &[]);
        assert!(r.irregular >= 64, "{r:?}");
        assert!(irregularity_warning(&r, true, 4.0, false)
            .unwrap()
            .contains("with PS, 4.0 particles per occupied triangle"));
        assert!(!irregularity_warning(&r, false, 4.0, false)
            .unwrap()
            .contains("with PS"));
        let few = |irregular| Irregularity {
            measured: 100,
            irregular,
            largest: 0.5,
        };
        assert!(irregularity_warning(&few(4), true, 4.0, false).is_none());
        assert!(irregularity_warning(&few(5), true, 4.0, false).is_some());
        assert!(!irregularity_warning(&few(5), true, 4.0, false)
            .unwrap()
            .contains("contact wall"));
        assert!(irregularity_warning(&few(5), true, 4.0, true)
            .unwrap()
            .contains("with a contact wall lower `courant`"));
        // PS already at 9 per triangle: more particles is not the fix it names.
        let sampled = irregularity_warning(&few(50), true, 9.0, false).unwrap();
        assert!(
            sampled.contains("strains the particles cannot follow")
                && !sampled.contains("give more particles per element"),
            "{sampled}"
        );
        // The top three rows (30 particles) slide by a spacing along the rest.
        let slid =
            moved(&|x: Vector2<f64>| x + Vector2::new(if x.y > 0.65 { 0.1 } else { 0.0 }, 0.0));
        assert_eq!(irregularity(&slid, &[70, 30], &[]).irregular, 0);
        assert!(irregularity(&slid, &[], &[]).irregular >= 20);
    }
}
