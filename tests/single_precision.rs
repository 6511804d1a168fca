//! The driver in single precision. The driver, the bases, the mass strategies and
//! the materials are generic over the scalar (`f32` or `f64`, [`psmpm::basis::Real`]);
//! these tests are what keeps that genericity honest: an `f32` run of the same
//! problem follows the `f64` run to within `f32` round-off, for PL and PS and for
//! the consistent, lumped and default (extended) mass.
//!
//! The problem: an elastic block that fills the lower half of a 2 × 2 mesh and falls
//! freely while it vibrates (an initial stretching velocity), so that the upper
//! elements are empty and the extended mass has work to do.

use nalgebra::SVector;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::Basis;
use psmpm::driver::Driver;
use psmpm::effect::{Effect, Gravity};
use psmpm::mass::{MassKind, MassStrategy};
use psmpm::material::{Elastic, NeoHookean};
use psmpm::particles::Particles;
use psmpm::sparse::Scalar;

const STEPS: usize = 200;
const DT: f64 = 2e-4;

/// Positions and velocities of every particle after [`STEPS`] steps, widened to f64.
fn fall<T: Scalar, B: Basis<T, 2>>(basis: B, mass: MassKind) -> Vec<[f64; 4]> {
    let (nx, ny) = (16, 8);
    let (hx, hy) = (2.0 / nx as f64, 1.0 / ny as f64);
    let mut positions = Vec::new();
    let mut velocities = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = ((i as f64 + 0.5) * hx, 0.5 + (j as f64 + 0.5) * hy);
            positions.push(SVector::<T, 2>::new(T::of(x), T::of(y)));
            velocities.push(SVector::<T, 2>::new(T::of(0.05 * (x - 1.0)), T::of(0.0)));
        }
    }
    let n = positions.len();
    let mut particles = Particles::new(positions, vec![T::of(hx * hy); n], T::of(1.0));
    particles.v = velocities;
    let material = NeoHookean::new(Elastic::new(1e3, 0.3, 1.0).unwrap(), 2);
    let gravity: Vec<Box<dyn Effect<T, 2>>> = vec![Box::new(Gravity {
        g: SVector::<T, 2>::new(T::of(0.0), T::of(-9.81)),
    })];
    let mut driver: Driver<T, 2, B, Box<dyn MassStrategy<T>>, _> =
        Driver::new(basis, particles, material, mass.build(), &[], gravity, DT).unwrap();
    for _ in 0..STEPS {
        driver.step().unwrap();
    }
    let p = &driver.particles;
    (0..p.len())
        .map(|i| {
            [
                p.x[i][0].to_f64(),
                p.x[i][1].to_f64(),
                p.v[i][0].to_f64(),
                p.v[i][1].to_f64(),
            ]
        })
        .collect()
}

/// Largest difference in position and in velocity between two runs.
fn difference(a: &[[f64; 4]], b: &[[f64; 4]]) -> (f64, f64) {
    a.iter().zip(b).fold((0.0f64, 0.0f64), |(dx, dv), (p, q)| {
        (
            dx.max((p[0] - q[0]).abs()).max((p[1] - q[1]).abs()),
            dv.max((p[2] - q[2]).abs()).max((p[3] - q[3]).abs()),
        )
    })
}

fn mesh() -> psmpm::basis::TriMesh {
    block_grid(0.0, 2.0, 0.0, 2.0, 4, 4).unwrap()
}

#[test]
fn an_f32_run_follows_the_f64_run_for_ps_and_pl_and_every_common_mass() {
    let masses = [
        MassKind::Consistent,
        MassKind::Lumped,
        MassKind::Extended { coverage: 0.5 },
    ];
    for mass in masses {
        let ps64 = fall::<f64, _>(
            PowellSabin::<f64>::new(mesh(), SplitPoint::Centroid).unwrap(),
            mass,
        );
        let ps32 = fall::<f32, _>(
            PowellSabin::<f32>::new(mesh(), SplitPoint::Centroid).unwrap(),
            mass,
        );
        let pl64 = fall::<f64, _>(Linear::<f64>::new(mesh()), mass);
        let pl32 = fall::<f32, _>(Linear::<f32>::new(mesh()), mass);
        for (name, single, double) in [("PS", &ps32, &ps64), ("PL", &pl32, &pl64)] {
            let (dx, dv) = difference(single, double);
            // Free fall over 0.04 s moves the body by about 8e-3 and gives it a
            // velocity of 0.39: f32 keeps about 1e-6 of both, and the solve of an
            // ill-conditioned mass system loses a little more.
            println!("{name} {mass:?}: position {dx:.2e}, velocity {dv:.2e}");
            assert!(dx < 1e-5, "{name} {mass:?}: positions differ by {dx:e}");
            assert!(dv < 5e-4, "{name} {mass:?}: velocities differ by {dv:e}");
            // and the runs are not trivially equal: the body fell.
            let fell = double.iter().map(|p| p[3]).sum::<f64>() / double.len() as f64;
            assert!((fell + 9.81 * DT * STEPS as f64).abs() < 1e-2, "{fell}");
        }
    }
}
