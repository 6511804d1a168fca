//! Error against a finer run, for refinement studies of scenes without an exact
//! solution ("self-convergence").
//!
//! The finest run of a study stands in for the exact solution. Its particles carry
//! the displacement `u(X)` at the end time as a function of the reference position
//! `X = x⁰`; [`FinestField::displacement`] evaluates it at any reference position by
//! a local quadratic least-squares fit to the nearest particles of that run (a
//! quadratic is reproduced exactly, so the fit adds an error of third order in the
//! fine particle spacing, far below the error of the coarser levels it measures).
//! [`error_against`] then forms the same measure as thesis eq. (4.4),
//! `E_u = sqrt(Σ_p V_p |u_p − u_finest(x_p⁰)|²)`, over the particles of a coarser
//! run. The orders it shows are those of `|u_l − u_L|`, which follow the true
//! orders while the finest level's own error is small against level `l`'s.

use crate::particles::Particles;
use nalgebra::{DMatrix, DVector, SVector};

/// Nearest particles used in a fit: twice the unknowns of a quadratic in 2D (6),
/// so that a fit near the body's edge, from one side, stays well posed.
const FIT_NEIGHBOURS_2D: usize = 12;
/// Nearest particles used in a fit in 1D (3 unknowns).
const FIT_NEIGHBOURS_1D: usize = 6;

/// The displacement field of the finest run of a study, as a function of the
/// reference position.
pub struct FinestField<const D: usize> {
    x0: Vec<SVector<f64, D>>,
    u: Vec<SVector<f64, D>>,
    /// Bucket grid over the reference positions: cell size and lower corner.
    cell: f64,
    origin: SVector<f64, D>,
    dims: [usize; 2],
    /// Particles of each bucket (`start[b]..start[b + 1]` in `order`).
    start: Vec<usize>,
    order: Vec<usize>,
}

/// Why a field cannot be built or evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// Too few particles for a quadratic fit.
    #[error("the finest run has {0} particles, too few for a quadratic fit")]
    TooFewParticles(usize),
    /// A position or displacement is not finite.
    #[error("the finest run has a non-finite position or displacement")]
    NotFinite,
}

impl<const D: usize> FinestField<D> {
    /// The field of `particles` (the finest run, at its end time).
    pub fn new(particles: &Particles<f64, D>) -> Result<Self, FieldError> {
        let n = particles.len();
        if n < Self::neighbours() {
            return Err(FieldError::TooFewParticles(n));
        }
        let finite = |v: &SVector<f64, D>| v.iter().all(|c| c.is_finite());
        if !particles.x0.iter().all(finite) || !particles.u.iter().all(finite) {
            return Err(FieldError::NotFinite);
        }
        let mut lo = particles.x0[0];
        let mut hi = particles.x0[0];
        for x in &particles.x0 {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        // About two particles per bucket.
        let extent = hi - lo;
        let measure: f64 = extent.iter().map(|e| e.max(f64::MIN_POSITIVE)).product();
        let mut cell = (2.0 * measure / n as f64)
            .powf(1.0 / D as f64)
            .max(f64::MIN_POSITIVE);
        let mut dims = [1usize; 2];
        loop {
            for k in 0..D {
                dims[k] = ((extent[k] / cell).floor().min(n as f64) as usize) + 1;
            }
            // At most 4 buckets per particle, whatever the particles' layout (all on
            // a line, say): memory bounded by the particles that exist.
            if dims[0] * dims[1] <= 4 * n {
                break;
            }
            cell *= 2.0;
        }
        let buckets = dims[0] * dims[1];
        let mut field = FinestField {
            x0: particles.x0.clone(),
            u: particles.u.clone(),
            cell,
            origin: lo,
            dims,
            start: vec![0; buckets + 1],
            order: vec![0; n],
        };
        for x in &field.x0 {
            let b = field.bucket_of(x);
            field.start[b + 1] += 1;
        }
        for b in 0..buckets {
            field.start[b + 1] += field.start[b];
        }
        let mut next = field.start.clone();
        for p in 0..n {
            let b = field.bucket_of(&field.x0[p]);
            field.order[next[b]] = p;
            next[b] += 1;
        }
        Ok(field)
    }

    fn neighbours() -> usize {
        if D == 1 {
            FIT_NEIGHBOURS_1D
        } else {
            FIT_NEIGHBOURS_2D
        }
    }

    fn cell_index(&self, x: &SVector<f64, D>) -> [usize; 2] {
        let mut c = [0usize; 2];
        for k in 0..D {
            let i = ((x[k] - self.origin[k]) / self.cell).floor();
            c[k] = if i <= 0.0 {
                0
            } else {
                (i as usize).min(self.dims[k] - 1)
            };
        }
        c
    }

    fn bucket_of(&self, x: &SVector<f64, D>) -> usize {
        let c = self.cell_index(x);
        c[0] + self.dims[0] * c[1]
    }

    /// The `k` particles nearest to `x` (reference positions), nearest first;
    /// ties broken by particle index so that the result is deterministic.
    fn nearest(&self, x: &SVector<f64, D>, k: usize) -> Vec<usize> {
        let centre = self.cell_index(x);
        let mut found: Vec<(f64, usize)> = Vec::new();
        let max_ring = self.dims[0].max(self.dims[1]);
        for ring in 0..=max_ring {
            let lo = |axis: usize| centre[axis].saturating_sub(ring);
            let hi = |axis: usize| (centre[axis] + ring).min(self.dims[axis] - 1);
            for j in lo(1)..=hi(1) {
                for i in lo(0)..=hi(0) {
                    let on_ring = i.abs_diff(centre[0]) == ring || j.abs_diff(centre[1]) == ring;
                    if !on_ring {
                        continue;
                    }
                    let b = i + self.dims[0] * j;
                    for &p in &self.order[self.start[b]..self.start[b + 1]] {
                        found.push(((self.x0[p] - x).norm_squared(), p));
                    }
                }
            }
            // Every particle outside the rings searched is at least `ring` cells away.
            if found.len() >= k {
                found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                let reach = ring as f64 * self.cell;
                if found[k - 1].0.sqrt() <= reach || ring == max_ring {
                    found.truncate(k);
                    return found.into_iter().map(|(_, p)| p).collect();
                }
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found.truncate(k);
        found.into_iter().map(|(_, p)| p).collect()
    }

    /// The finest run's displacement at the reference position `x`: a quadratic
    /// least-squares fit to its nearest particles, in coordinates centred at `x` and
    /// scaled by their spread (so that the fit is well conditioned at any scale).
    pub fn displacement(&self, x: &SVector<f64, D>) -> SVector<f64, D> {
        let near = self.nearest(x, Self::neighbours());
        let scale = near
            .iter()
            .map(|&p| (self.x0[p] - x).norm())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let terms = if D == 1 { 3 } else { 6 };
        let mut a = DMatrix::zeros(near.len(), terms);
        for (row, &p) in near.iter().enumerate() {
            let d = (self.x0[p] - x) / scale;
            let monomials: [f64; 6] = if D == 1 {
                [1.0, d[0], d[0] * d[0], 0.0, 0.0, 0.0]
            } else {
                [1.0, d[0], d[1], d[0] * d[0], d[0] * d[1], d[1] * d[1]]
            };
            for c in 0..terms {
                a[(row, c)] = monomials[c];
            }
        }
        let svd = a.svd(true, true);
        let mut out = SVector::<f64, D>::zeros();
        for k in 0..D {
            let b = DVector::from_iterator(near.len(), near.iter().map(|&p| self.u[p][k]));
            // The constant term is the value at `x`.
            out[k] = svd
                .solve(&b, 1e-12)
                .map(|c| c[0])
                .unwrap_or_else(|_| self.u[near[0]][k]);
        }
        out
    }
}

/// `E_u` of `particles` (a coarser run at the same end time) against `finest`:
/// `sqrt(Σ_p V_p |u_p − u_finest(x_p⁰)|²)`, the measure of thesis eq. (4.4) with the
/// finest run in place of the exact solution.
pub fn error_against<const D: usize>(
    finest: &FinestField<D>,
    particles: &Particles<f64, D>,
) -> f64 {
    let mut err2 = 0.0;
    for p in 0..particles.len() {
        let reference = finest.displacement(&particles.x0[p]);
        err2 += particles.volume[p] * (particles.u[p] - reference).norm_squared();
    }
    err2.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// A lattice of `n × n` particles on the unit square, displaced by `u(x)`.
    fn lattice(n: usize, u: impl Fn(Vector2<f64>) -> Vector2<f64>) -> Particles<f64, 2> {
        let h = 1.0 / n as f64;
        let mut x = Vec::new();
        for j in 0..n {
            for i in 0..n {
                x.push(Vector2::new((i as f64 + 0.5) * h, (j as f64 + 0.5) * h));
            }
        }
        let mut p = Particles::new(x, vec![h * h; n * n], 1.0);
        for q in 0..p.len() {
            p.u[q] = u(p.x0[q]);
        }
        p
    }

    #[test]
    fn a_quadratic_field_is_reproduced_everywhere_including_the_edges() {
        let u = |x: Vector2<f64>| {
            Vector2::new(
                0.1 + 0.2 * x[0] - 0.3 * x[1] * x[1] + 0.05 * x[0] * x[1],
                -0.4 * x[0] * x[0] + x[1],
            )
        };
        let field = FinestField::new(&lattice(16, u)).unwrap();
        for &(a, b) in &[
            (0.5, 0.5),
            (0.0, 0.0),
            (1.0, 0.3),
            (0.013, 0.99),
            (0.77, 0.21),
        ] {
            let x = Vector2::new(a, b);
            let got = field.displacement(&x);
            assert!(
                (got - u(x)).norm() < 1e-12,
                "at {x:?}: {got:?} against {:?}",
                u(x)
            );
        }
        // A coarser lattice of the same field has no error against it.
        assert!(error_against(&field, &lattice(4, u)) < 1e-12);
    }

    #[test]
    fn the_error_of_a_smooth_field_falls_with_the_fit_spacing_at_third_order() {
        let u = |x: Vector2<f64>| Vector2::new((3.0 * x[0]).sin() * x[1].cos(), 0.0);
        let coarse = lattice(4, u);
        // The same coarse particles, measured against finer and finer fields of
        // exactly the same function: what remains is the fit's own error.
        let e: Vec<f64> = [16, 32, 64]
            .iter()
            .map(|&n| error_against(&FinestField::new(&lattice(n, u)).unwrap(), &coarse))
            .collect();
        let order = |a: f64, b: f64| (a / b).log2();
        assert!(e[0] < 1e-4, "{e:?}");
        assert!(order(e[0], e[1]) > 2.5 && order(e[1], e[2]) > 2.5, "{e:?}");
    }

    #[test]
    fn a_one_dimensional_field_and_a_wrong_field_are_measured() {
        let x: Vec<_> = (0..20)
            .map(|i| SVector::<f64, 1>::new(i as f64 * 0.05))
            .collect();
        let mut fine = Particles::new(x.clone(), vec![0.05; 20], 1.0);
        for q in 0..20 {
            fine.u[q][0] = 2.0 * x[q][0] * x[q][0] - 1.0;
        }
        let field = FinestField::new(&fine).unwrap();
        let mut coarse = fine.clone();
        assert!(error_against(&field, &coarse) < 1e-12);
        // An offset of 0.1 everywhere on a bar of volume 1: E_u = 0.1.
        coarse.u.iter_mut().for_each(|u| u[0] += 0.1);
        assert!((error_against(&field, &coarse) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn too_few_or_non_finite_particles_are_errors() {
        let few = Particles::new(vec![Vector2::new(0.0, 0.0); 3], vec![1.0; 3], 1.0);
        assert_eq!(
            FinestField::new(&few).err(),
            Some(FieldError::TooFewParticles(3))
        );
        let mut bad = lattice(4, |_| Vector2::zeros());
        bad.u[3][1] = f64::NAN;
        assert_eq!(FinestField::new(&bad).err(), Some(FieldError::NotFinite));
    }
}
