//! One MPM step at about 1e4 particles: PL with the lumped mass and PS with the
//! consistent mass, on the same block grid and particles (B5a's column refined to
//! 4 × 32 blocks, 8 × 10 particles per block: 10 240 particles).
//!
//! Run: `cargo bench --bench step`. The per-phase split comes from the driver's
//! phase timers: `cargo run --release -p mpm-cli -- run column-small --blocks 4x32
//! --particles 8x10 --t-end 0.01 --basis ps --diag-every 0` prints it.

use nalgebra::Vector2;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::{Basis, TriMesh};
use psmpm::driver::{Driver, Fix};
use psmpm::effect::{Effect, Gravity};
use psmpm::mass::{Consistent, Lumped, MassStrategy};
use psmpm::material::{Elastic, LinearElastic};
use psmpm::particles::Particles;

const BLOCKS: (usize, usize) = (4, 32);
const PER_BLOCK: (usize, usize) = (8, 10);

fn mesh() -> TriMesh {
    block_grid(0.0, 2.0, 0.0, 25.0, BLOCKS.0, BLOCKS.1).unwrap()
}

fn particles() -> Particles<f64, 2> {
    let (bx, by) = (2.0 / BLOCKS.0 as f64, 25.0 / BLOCKS.1 as f64);
    let mut x = Vec::new();
    for j in 0..BLOCKS.1 * PER_BLOCK.1 {
        for i in 0..BLOCKS.0 * PER_BLOCK.0 {
            x.push(Vector2::new(
                (i as f64 + 0.5) * bx / PER_BLOCK.0 as f64,
                (j as f64 + 0.5) * by / PER_BLOCK.1 as f64,
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
    let material = LinearElastic::new(Elastic::new(5e4, 0.0, 1.0).unwrap(), 2);
    Driver::new(basis, particles(), material, mass, &fixes, effects, 1e-5).unwrap()
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

fn main() {
    divan::main();
}
