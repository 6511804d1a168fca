//! The kernels of a step, one by one, at about 1e5 particles (B5a's column refined
//! to 14 × 112 blocks, 8 × 8 particles per block: 100 352 particles, as
//! `mpm-cli throughput --sizes 1e5`), on a pool of one thread:
//!
//! - `locate`: point location of every particle, from the element it was in
//!   before the particles moved by a tenth of a particle spacing (the step's
//!   case), and with no hint (set-up);
//! - `eval`: basis values and gradients at every particle in lattice order (PL,
//!   PS; the 1D quadratic B-spline and PL on 1e5 points of a 3 263-element line),
//!   and phase 1 of the step for PS (locate, bin by element, evaluate in element
//!   order);
//! - `assemble`: the mass matrix (every entry, or the row sums the lumped mass
//!   reads) and the internal force, element by element as the driver does;
//! - `cholesky`: the numeric factorisation of the PS mass matrix (9 789
//!   functions) and one solve with two right-hand sides;
//! - `conjugate_gradients`: the alternative, a conjugate-gradient solve
//!   preconditioned by the lumped mass and warm-started from the previous step's
//!   solution, to the same accuracy.
//!
//! Run: `cargo bench --bench kernels`. The whole step of each variant is in
//! `benches/step.rs` and `mpm-cli throughput`; `docs/performance.md` has the
//! figures.

use nalgebra::{Matrix2, SVector, Vector1, Vector2};
use psmpm::basis::basis::bspline1d::QuadraticBSpline;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::linear1d::Linear1d;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::mesh::mesh1d::Mesh1d;
use psmpm::basis::{Basis, BasisEval, TriMesh};
use psmpm::driver::phases::{
    assemble_mass_and_internal_force, locate_and_evaluate, Bins, Evaluations, Gather, Local,
    MassMatrix,
};
use psmpm::particles::Particles;
use psmpm::sparse::{SparseCholesky, SymmetricPattern};

const BLOCKS: (usize, usize) = (14, 112);
const PER_BLOCK: usize = 8;
const WIDTH: f64 = 2.0;
const HEIGHT: f64 = 25.0;

fn mesh() -> TriMesh {
    block_grid(0.0, WIDTH, 0.0, HEIGHT, BLOCKS.0, BLOCKS.1).unwrap()
}

/// Particle positions on the lattice of `PER_BLOCK × PER_BLOCK` per block, shifted
/// by `shift` particle spacings along both axes.
fn positions(shift: f64) -> Vec<Vector2<f64>> {
    let (nx, ny) = (BLOCKS.0 * PER_BLOCK, BLOCKS.1 * PER_BLOCK);
    let (dx, dy) = (WIDTH / nx as f64, HEIGHT / ny as f64);
    let mut x = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            x.push(Vector2::new(
                (i as f64 + 0.5 + shift) * dx,
                (j as f64 + 0.5 + shift) * dy,
            ));
        }
    }
    x
}

fn particles() -> Particles<f64, 2> {
    let x = positions(0.0);
    let n = x.len();
    let mut p = Particles::new(x, vec![WIDTH * HEIGHT / n as f64; n], 1e3);
    p.sigma
        .iter_mut()
        .for_each(|s| *s = Matrix2::new(-1e3, 10.0, 10.0, -2e3));
    p
}

fn ps() -> PowellSabin<f64> {
    PowellSabin::new(mesh(), SplitPoint::Incentre).unwrap()
}

/// The elements of the particles at their lattice positions.
fn elements<B: Basis<f64, 2>>(basis: &B, x: &[Vector2<f64>]) -> Vec<usize> {
    x.iter().map(|x| basis.locate(x, None).unwrap()).collect()
}

mod locate {
    use super::*;

    #[divan::bench(sample_count = 20)]
    fn from_previous_element(bencher: divan::Bencher) {
        let basis = Linear::<f64>::new(mesh());
        let before = elements(&basis, &positions(0.0));
        let moved = positions(0.1);
        bencher.bench_local(|| {
            let mut found = 0;
            for (x, &e) in moved.iter().zip(&before) {
                found += basis.locate(x, Some(e)).unwrap();
            }
            found
        });
    }

    #[divan::bench(sample_count = 10)]
    fn without_hint(bencher: divan::Bencher) {
        let basis = Linear::<f64>::new(mesh());
        let moved = positions(0.1);
        bencher.bench_local(|| {
            let mut found = 0;
            for x in &moved {
                found += basis.locate(x, None).unwrap();
            }
            found
        });
    }
}

mod eval {
    use super::*;

    /// Evaluates `basis` at every point `x` in its element `e`.
    fn bench_points<const D: usize, B: Basis<f64, D>>(
        bencher: divan::Bencher,
        basis: B,
        x: Vec<SVector<f64, D>>,
    ) {
        let e: Vec<usize> = x.iter().map(|x| basis.locate(x, None).unwrap()).collect();
        let mut out = BasisEval::for_basis(&basis);
        bencher.bench_local(|| {
            let mut sum = 0.0;
            for (x, &e) in x.iter().zip(&e) {
                basis.eval(e, x, &mut out);
                sum += out.phi[0];
            }
            sum
        });
    }

    fn bench_2d<B: Basis<f64, 2>>(bencher: divan::Bencher, basis: B) {
        bench_points(bencher, basis, positions(0.1));
    }

    fn bench_1d<B: Basis<f64, 1>>(bencher: divan::Bencher, basis: B) {
        let n = BLOCKS.0 * BLOCKS.1 * PER_BLOCK * PER_BLOCK;
        let x = (0..n)
            .map(|p| Vector1::new((p as f64 + 0.5) / n as f64))
            .collect();
        bench_points(bencher, basis, x);
    }

    #[divan::bench(sample_count = 20)]
    fn pl(bencher: divan::Bencher) {
        bench_2d(bencher, Linear::<f64>::new(mesh()));
    }

    #[divan::bench(sample_count = 20)]
    fn ps(bencher: divan::Bencher) {
        bench_2d(bencher, super::ps());
    }

    /// Points of one line with as many elements as the 2D mesh has vertices.
    fn line() -> Mesh1d {
        Mesh1d::uniform(0.0, 1.0, 3263).unwrap()
    }

    #[divan::bench(sample_count = 20)]
    fn bspline_1d(bencher: divan::Bencher) {
        bench_1d(bencher, QuadraticBSpline::<f64>::new(line()));
    }

    #[divan::bench(sample_count = 20)]
    fn pl_1d(bencher: divan::Bencher) {
        bench_1d(bencher, Linear1d::<f64>::new(line()));
    }

    /// Locate and evaluate as the step's phase 1 does (stored per particle).
    #[divan::bench(sample_count = 20)]
    fn ps_phase(bencher: divan::Bencher) {
        let basis = super::ps();
        let x = positions(0.1);
        let mut element = elements(&basis, &positions(0.0));
        let mut evals = Evaluations::for_basis(&basis, x.len());
        let mut bins = Bins::new(basis.num_elements(), x.len());
        let mut scratch: Vec<BasisEval<f64, 2>> = (0..psmpm::driver::phases::chunks(x.len()))
            .map(|_| BasisEval::for_basis(&basis))
            .collect();
        bencher.bench_local(|| {
            locate_and_evaluate(
                &basis,
                &x,
                &mut element,
                &mut bins,
                &mut scratch,
                &mut evals,
            )
            .is_ok()
        });
    }
}

mod assemble {
    use super::*;

    /// What phase 2a needs, after phase 1 on `parts`: pattern, evaluations, bins,
    /// gather, local buffers, and the value and force buffers.
    pub(super) struct Assembly {
        pub pattern: SymmetricPattern,
        evals: Evaluations<f64, 2>,
        bins: Bins,
        gather: Gather,
        local: Local<f64, 2>,
        pub values: Vec<f64>,
        force: Vec<Vec<f64>>,
        /// The coverage sums (particle volume, particle count per function).
        coverage: [Vec<f64>; 2],
    }

    impl Assembly {
        pub fn new<B: Basis<f64, 2>>(basis: &B, parts: &Particles<f64, 2>) -> Self {
            let pattern = SymmetricPattern::new(basis);
            let stride = basis.max_functions_per_element();
            let mut element = elements(basis, &parts.x);
            let mut evals = Evaluations::for_basis(basis, parts.len());
            let mut scratch: Vec<BasisEval<f64, 2>> =
                (0..psmpm::driver::phases::chunks(parts.len()))
                    .map(|_| BasisEval::for_basis(basis))
                    .collect();
            let mut bins = Bins::new(basis.num_elements(), parts.len());
            locate_and_evaluate(
                basis,
                &parts.x,
                &mut element,
                &mut bins,
                &mut scratch,
                &mut evals,
            )
            .ok()
            .unwrap();
            Assembly {
                gather: Gather::new(basis, &pattern, stride),
                local: Local::new(basis.num_elements(), stride).with_coverage(),
                values: vec![0.0; pattern.nnz()],
                force: vec![vec![0.0; basis.num_functions()]; 2],
                coverage: [
                    vec![0.0; basis.num_functions()],
                    vec![0.0; basis.num_functions()],
                ],
                pattern,
                evals,
                bins,
            }
        }

        /// Phase 2a into `values` and the force.
        pub fn run(&mut self, parts: &Particles<f64, 2>, matrix: MassMatrix) {
            self.run_with(parts, matrix, false);
        }

        /// Phase 2a, and the coverage sums with `coverage` (what the default
        /// strategy asks for).
        pub fn run_with(&mut self, parts: &Particles<f64, 2>, matrix: MassMatrix, coverage: bool) {
            let [volume, count] = &mut self.coverage;
            assemble_mass_and_internal_force(
                parts,
                &self.evals,
                &self.bins,
                &mut self.gather,
                &mut self.local,
                matrix,
                &mut self.values,
                &mut self.force,
                coverage.then_some((&mut volume[..], &mut count[..])),
                None,
            );
        }
    }

    fn bench<B: Basis<f64, 2>>(bencher: divan::Bencher, basis: B, matrix: MassMatrix) {
        bench_with(bencher, basis, matrix, false);
    }

    fn bench_with<B: Basis<f64, 2>>(
        bencher: divan::Bencher,
        basis: B,
        matrix: MassMatrix,
        coverage: bool,
    ) {
        let parts = particles();
        let mut assembly = Assembly::new(&basis, &parts);
        bencher.bench_local(|| {
            assembly.run_with(&parts, matrix, coverage);
            assembly.values[0]
        });
    }

    #[divan::bench(sample_count = 20)]
    fn pl_row_sums(bencher: divan::Bencher) {
        bench(bencher, Linear::<f64>::new(mesh()), MassMatrix::RowSums);
    }

    #[divan::bench(sample_count = 20)]
    fn pl_full(bencher: divan::Bencher) {
        bench(bencher, Linear::<f64>::new(mesh()), MassMatrix::Full);
    }

    #[divan::bench(sample_count = 20)]
    fn ps_row_sums(bencher: divan::Bencher) {
        bench(bencher, super::ps(), MassMatrix::RowSums);
    }

    #[divan::bench(sample_count = 20)]
    fn ps_full(bencher: divan::Bencher) {
        bench(bencher, super::ps(), MassMatrix::Full);
    }

    /// With the coverage sums of the default strategy in the same pass.
    #[divan::bench(sample_count = 20)]
    fn ps_full_coverage(bencher: divan::Bencher) {
        bench_with(bencher, super::ps(), MassMatrix::Full, true);
    }
}

mod cholesky {
    use super::*;

    /// The PS mass matrix of the particles (upper triangle) and its pattern.
    fn mass_matrix() -> (SymmetricPattern, Vec<f64>) {
        mass_matrix_at(0.0)
    }

    /// The PS mass matrix with the particles shifted by `shift` particle spacings.
    pub(super) fn mass_matrix_at(shift: f64) -> (SymmetricPattern, Vec<f64>) {
        let basis = super::ps();
        let mut parts = particles();
        parts.x = positions(shift);
        let mut assembly = assemble::Assembly::new(&basis, &parts);
        assembly.run(&parts, MassMatrix::Full);
        (assembly.pattern, assembly.values)
    }

    #[divan::bench(sample_count = 20)]
    fn factorize(bencher: divan::Bencher) {
        let (pattern, values) = mass_matrix();
        let mut solver = SparseCholesky::new(&pattern, 2);
        bencher.bench_local(|| solver.factorize(&values).is_ok());
    }

    #[divan::bench(sample_count = 20)]
    fn solve_two_columns(bencher: divan::Bencher) {
        let (pattern, values) = mass_matrix();
        let mut solver = SparseCholesky::new(&pattern, 2);
        solver.factorize(&values).unwrap();
        let n = pattern.dim();
        let mut rhs = vec![1.0; 2 * n];
        bencher.bench_local(|| {
            solver.solve_in_place(&mut rhs, 2);
            rhs[0]
        });
    }
}

/// The alternative to the factorisation: conjugate gradients preconditioned by the
/// lumped mass (the row sums), warm-started from the previous step's solution, to
/// the relative residual 1e-12 that matches the direct solve's accuracy here. The
/// system is the mass matrix after the particles moved by a hundredth of their
/// spacing, the start the exact solution of the system before; one solve, one
/// right-hand side (a step needs four, two per component).
mod conjugate_gradients {
    use super::*;

    /// Preconditioned CG on `M x = b` from `x`; returns the iterations.
    fn pcg(
        pattern: &SymmetricPattern,
        values: &[f64],
        lumped: &[f64],
        b: &[f64],
        x: &mut [f64],
        work: &mut [Vec<f64>; 4],
    ) -> usize {
        let [r, z, q, p] = work;
        let n = b.len();
        pattern.mul_vec(values, x, q);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
        let b_norm = dot(b, b).sqrt();
        for i in 0..n {
            r[i] = b[i] - q[i];
            z[i] = r[i] / lumped[i];
        }
        p.copy_from_slice(z);
        let mut rz = dot(r, z);
        for iteration in 0..10_000 {
            if dot(r, r).sqrt() <= 1e-12 * b_norm {
                return iteration;
            }
            pattern.mul_vec(values, p, q);
            let alpha = rz / dot(p, q);
            for i in 0..n {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
                z[i] = r[i] / lumped[i];
            }
            let rz_new = dot(r, z);
            for i in 0..n {
                p[i] = z[i] + rz_new / rz * p[i];
            }
            rz = rz_new;
        }
        10_000
    }

    #[divan::bench(sample_count = 10)]
    fn warm_started_solve(bencher: divan::Bencher) {
        let (pattern, before) = cholesky::mass_matrix_at(0.0);
        let (_, after) = cholesky::mass_matrix_at(0.01);
        let n = pattern.dim();
        // A smooth right-hand side, and the solution of the system before.
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin()).collect();
        let mut solver = SparseCholesky::new(&pattern, 1);
        solver.factorize(&before).unwrap();
        let mut start = b.clone();
        solver.solve_in_place(&mut start, 1);
        let mut lumped = vec![0.0; n];
        pattern.row_sums(&after, &mut lumped);
        let mut work = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut x = start.clone();
        let iterations = pcg(&pattern, &after, &lumped, &b, &mut x, &mut work);
        eprintln!(
            "conjugate gradients: {iterations} iterations to 1e-12 from the previous solution"
        );
        bencher.bench_local(|| {
            x.copy_from_slice(&start);
            pcg(&pattern, &after, &lumped, &b, &mut x, &mut work)
        });
    }
}

fn main() {
    // One thread: the kernels' own cost (phase 1 and the assembly run on the pool).
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(divan::main);
}
