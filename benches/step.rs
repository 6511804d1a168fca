//! One MPM step at about 1e4 particles: PL with the lumped mass and PS with the
//! consistent mass, on the same block grid and particles (B5a's column refined to
//! 4 × 32 blocks, 8 × 10 particles per block: 10 240 particles).
//!
//! Run: `cargo bench --bench step`. The per-phase split comes from the driver's
//! phase timers: `cargo run --release -p mpm-cli -- run column-small --blocks 4x32
//! --particles 8x10 --t-end 0.01 --basis ps --diag-every 0` prints it.
//!
//! Materials: the `materials` group steps the same particles with one law, a
//! one-law table and a two-law table (`cargo bench --bench step -- materials`).
//!
//! Threads: the `threads` group steps about 1e5 particles (8 × 64 blocks, 8 × 24
//! particles per block: 98 304) with PL lumped, PS lumped, PS consistent and PS
//! with the default mass, on a pool of one thread and on one of all cores
//! (`cargo bench --bench step -- threads`). The results are the same, bit for
//! bit; only the time differs.

use nalgebra::Vector2;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::{Basis, TriMesh};
use psmpm::driver::{Driver, Fix};
use psmpm::effect::{Effect, Gravity};
use psmpm::mass::{Consistent, Lumped, MassKind, MassStrategy};
use psmpm::material::{AnyMaterial, Corotational, Elastic, LinearElastic};
use psmpm::materials::{MaterialTable, ParticleMaterials};
use psmpm::particles::Particles;

const BLOCKS: (usize, usize) = (4, 32);
const PER_BLOCK: (usize, usize) = (8, 10);

/// Blocks and particles per block of the thread benchmarks (98 304 particles).
const LARGE: ((usize, usize), (usize, usize)) = ((8, 64), (8, 24));

fn mesh() -> TriMesh {
    mesh_of(BLOCKS)
}

fn mesh_of(blocks: (usize, usize)) -> TriMesh {
    block_grid(0.0, 2.0, 0.0, 25.0, blocks.0, blocks.1).unwrap()
}

fn particles() -> Particles<f64, 2> {
    particles_of(BLOCKS, PER_BLOCK)
}

fn particles_of(blocks: (usize, usize), per_block: (usize, usize)) -> Particles<f64, 2> {
    let (bx, by) = (2.0 / blocks.0 as f64, 25.0 / blocks.1 as f64);
    let mut x = Vec::new();
    for j in 0..blocks.1 * per_block.1 {
        for i in 0..blocks.0 * per_block.0 {
            x.push(Vector2::new(
                (i as f64 + 0.5) * bx / per_block.0 as f64,
                (j as f64 + 0.5) * by / per_block.1 as f64,
            ));
        }
    }
    let n = x.len();
    Particles::new(x, vec![50.0 / n as f64; n], 1.0)
}

fn driver<B: Basis<f64, 2>, M: MassStrategy<f64>>(
    basis: B,
    mass: M,
) -> Driver<f64, 2, B, M, LinearElastic> {
    driver_with(basis, mass, particles())
}

fn driver_with<B: Basis<f64, 2>, M: MassStrategy<f64>>(
    basis: B,
    mass: M,
    particles: Particles<f64, 2>,
) -> Driver<f64, 2, B, M, LinearElastic> {
    let material = LinearElastic::new(Elastic::new(5e4, 0.0, 1.0).unwrap(), 2);
    driver_of(basis, mass, particles, material)
}

fn driver_of<B: Basis<f64, 2>, M: MassStrategy<f64>, Mat: ParticleMaterials<f64, 2>>(
    basis: B,
    mass: M,
    particles: Particles<f64, 2>,
    material: Mat,
) -> Driver<f64, 2, B, M, Mat> {
    let fixes = [
        Fix {
            tag: "bottom".into(),
            component: 0,
        },
        Fix {
            tag: "bottom".into(),
            component: 1,
        },
        Fix {
            tag: "left".into(),
            component: 0,
        },
        Fix {
            tag: "right".into(),
            component: 0,
        },
    ];
    let effects: Vec<Box<dyn Effect<f64, 2>>> = vec![Box::new(Gravity {
        g: Vector2::new(0.0, -9.81),
    })];
    Driver::new(basis, particles, material, mass, &fixes, effects, 1e-5).unwrap()
}

#[divan::bench(sample_count = 20)]
fn pl_lumped_step(bencher: divan::Bencher) {
    let mut d = driver(Linear::<f64>::new(mesh()), Lumped::default());
    bencher.bench_local(|| d.step().unwrap());
}

#[divan::bench(sample_count = 20)]
fn ps_consistent_step(bencher: divan::Bencher) {
    let ps = PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
    let mut d = driver(ps, Consistent::default());
    bencher.bench_local(|| d.step().unwrap());
}

/// One thread, then one per core.
fn thread_counts() -> Vec<usize> {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    if all > 1 {
        vec![1, all]
    } else {
        vec![1]
    }
}

/// Steps of about 1e5 particles on a pool of `threads` threads; the variants
/// are named `BASIS_MASS`.
mod threads {
    use super::*;

    fn bench_on<B: Basis<f64, 2> + Send>(
        bencher: divan::Bencher,
        threads: usize,
        basis: B,
        mass: &str,
    ) {
        let pool = psmpm::threads::pool(Some(threads)).unwrap();
        let mass = MassKind::parse(mass).unwrap().build::<f64>();
        let (blocks, per_block) = LARGE;
        let mut d = driver_with(basis, mass, particles_of(blocks, per_block));
        pool.install(|| d.step().unwrap());
        bencher
            .counter(divan::counter::ItemsCount::new(d.particles.len()))
            .bench_local(|| pool.install(|| d.step().unwrap()));
    }

    fn ps() -> PowellSabin<f64> {
        PowellSabin::<f64>::new(mesh_of(LARGE.0), SplitPoint::Incentre).unwrap()
    }

    #[divan::bench(args = thread_counts(), sample_count = 10, sample_size = 1)]
    fn pl_lumped(bencher: divan::Bencher, threads: usize) {
        bench_on(
            bencher,
            threads,
            Linear::<f64>::new(mesh_of(LARGE.0)),
            "lumped",
        );
    }

    #[divan::bench(args = thread_counts(), sample_count = 10, sample_size = 1)]
    fn ps_lumped(bencher: divan::Bencher, threads: usize) {
        bench_on(bencher, threads, ps(), "lumped");
    }

    #[divan::bench(args = thread_counts(), sample_count = 10, sample_size = 1)]
    fn ps_consistent(bencher: divan::Bencher, threads: usize) {
        bench_on(bencher, threads, ps(), "consistent");
    }

    #[divan::bench(args = thread_counts(), sample_count = 10, sample_size = 1)]
    fn ps_default(bencher: divan::Bencher, threads: usize) {
        bench_on(bencher, threads, ps(), "default");
    }
}

/// The cost of the law of each particle: a PS lumped step of the 10 240 particles
/// with the scene's law as one `AnyMaterial` (before bodies had their own
/// materials), as a one-law `MaterialTable` (what a single-material scene runs
/// now), and as a two-law table (the upper half of the column ten times stiffer).
mod materials {
    use super::*;

    fn law(young: f64) -> AnyMaterial {
        AnyMaterial::Corotational(Corotational::new(Elastic::new(young, 0.0, 1.0).unwrap(), 2))
    }

    fn bench_with<Mat: ParticleMaterials<f64, 2>>(bencher: divan::Bencher, material: Mat) {
        let ps = PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
        let mut d = driver_of(ps, Lumped::default(), particles(), material);
        bencher.bench_local(|| d.step().unwrap());
    }

    #[divan::bench(sample_count = 20)]
    fn one_law(bencher: divan::Bencher) {
        bench_with(bencher, law(5e4));
    }

    #[divan::bench(sample_count = 20)]
    fn uniform_table(bencher: divan::Bencher) {
        bench_with(bencher, MaterialTable::uniform(law(5e4)));
    }

    #[divan::bench(sample_count = 20)]
    fn two_law_table(bencher: divan::Bencher) {
        let p = particles();
        let law_of: Vec<usize> = (0..p.len())
            .map(|i| usize::from(p.x[i][1] > 12.5))
            .collect();
        bench_with(
            bencher,
            MaterialTable::new(&[law(5e4), law(5e5)], &law_of).unwrap(),
        );
    }
}

fn main() {
    divan::main();
}
