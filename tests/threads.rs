//! Bit-identical results for any number of threads: the full particle state and
//! every diagnostics row of 2D runs (PS with the consistent and the default mass,
//! PL lumped, and a damped PS column whose work is booked) with 1, 2 and 3
//! threads. The scenes hold several particle chunks (`phases::CHUNK`) and
//! several element tasks, so the work really is split.

use psmpm::bases::BasisKind;
use psmpm::driver::phases::CHUNK;
use psmpm::driver::StepReport;
use psmpm::mass::MassKind;
use psmpm::scene::Scene;
use psmpm::simulation::run_2d;

/// Every number of a diagnostics row but the timings, as bits.
fn row_bits(r: &StepReport) -> Vec<u64> {
    let m = r.mass_report;
    let mut row = vec![
        r.step as u64,
        r.time.to_bits(),
        r.kinetic.to_bits(),
        r.strain.to_bits(),
        r.potential.to_bits(),
        r.work.to_bits(),
        r.mass.to_bits(),
        r.momentum()[0].to_bits(),
        r.momentum()[1].to_bits(),
        r.max_speed.to_bits(),
        r.condition.map_or(0, f64::to_bits),
        r.substeps as u64,
        r.dt_critical.map_or(0, f64::to_bits),
        r.dt_critical_latest.map_or(0, f64::to_bits),
        m.active as u64,
        m.lumped_rows as u64,
        m.deactivated as u64,
        m.extended as u64,
    ];
    if let Some((i, c)) = m.worst_coverage {
        row.extend([i as u64, c.to_bits()]);
    }
    row
}

/// The particle state (x, u, v, F, σ, V, element) and the diagnostics rows with
/// `threads` threads, as bits.
fn run_bits(scene: &Scene, threads: usize) -> (Vec<u64>, Vec<Vec<u64>>) {
    let pool = psmpm::threads::pool(Some(threads)).unwrap();
    pool.install(|| {
        let mut rows = Vec::new();
        let out = run_2d(scene, &mut |r| rows.push(row_bits(r))).unwrap();
        assert!(out.failure.is_none(), "{:?}", out.failure);
        let p = &out.particles;
        assert!(p.len() > 2 * CHUNK, "{} particles: one chunk only", p.len());
        let mut state = Vec::new();
        for q in 0..p.len() {
            let vectors = [&p.x[q], &p.u[q], &p.v[q]];
            state.extend(vectors.iter().flat_map(|v| v.iter().map(|c| c.to_bits())));
            state.extend(p.f[q].iter().map(|c| c.to_bits()));
            state.extend(p.sigma[q].iter().map(|c| c.to_bits()));
            state.push(p.volume[q].to_bits());
            state.push(p.element[q] as u64);
        }
        (state, rows)
    })
}

fn same_for_any_threads(scene: &Scene, what: &str) {
    let (state, rows) = run_bits(scene, 1);
    assert!(rows.len() >= 10, "{what}: {} steps", rows.len());
    for threads in [2, 3] {
        let (s, r) = run_bits(scene, threads);
        assert!(
            r == rows,
            "{what}: diagnostics differ with {threads} threads"
        );
        assert!(
            s == state,
            "{what}: particle state differs with {threads} threads"
        );
    }
}

/// The B5a column on 2 × 16 blocks with 8 × 10 particles per block (2560
/// particles, 128 elements), 20 steps.
fn column(basis: BasisKind, mass: MassKind) -> Scene {
    let mut s = Scene::builtin("column-small").unwrap();
    s.basis = basis;
    s.mass = mass;
    s.set_blocks(2, 16).unwrap();
    s.set_particles_per_block([8, 10]);
    s.set_dt(1e-4);
    s.time.t_end = 2e-3;
    s
}

#[test]
fn ps_consistent_is_the_same_for_any_threads() {
    same_for_any_threads(
        &column(BasisKind::Ps, MassKind::Consistent),
        "PS consistent",
    );
}

#[test]
fn ps_default_is_the_same_for_any_threads() {
    same_for_any_threads(&column(BasisKind::Ps, MassKind::default()), "PS default");
}

#[test]
fn pl_lumped_is_the_same_for_any_threads() {
    same_for_any_threads(&column(BasisKind::Pl, MassKind::Lumped), "PL lumped");
}

#[test]
fn damped_column_is_the_same_for_any_threads() {
    let mut s = Scene::builtin("column-damped").unwrap();
    s.set_blocks(2, 20).unwrap();
    s.set_particles_per_block([8, 9]);
    s.set_dt(1e-5);
    s.time.t_end = 2e-4;
    same_for_any_threads(&s, "PS partial, damped");
}

/// A block falling across an empty mesh (`tests/data/falling-block.toml`, 24 × 24
/// particles per block, 4 608): the watch over the critical step estimates it
/// again as the block covers new functions (its stiffness and mass products on
/// the pool) and splits steps; the estimates, the splits and the state are the
/// same bits for any thread count.
#[test]
fn split_steps_of_a_falling_block_are_the_same_for_any_threads() {
    let text = std::fs::read_to_string("tests/data/falling-block.toml").unwrap();
    let mut s = Scene::from_toml(&text, "falling-block.toml").unwrap();
    s.set_particles_per_block([24, 24]);
    s.time.t_end = 0.16;
    let (_, rows) = run_bits(&s, 1);
    let split = rows.iter().filter(|r| r[11] > 1).count();
    assert!(
        split > 0,
        "no step was split: the watch's products are not exercised"
    );
    same_for_any_threads(&s, "PS default, falling block with split steps");
}

/// The step report's energies (per-particle terms in parallel, summed in particle
/// order) are those of `Driver::report` (all sequential), bit for bit.
#[test]
fn step_energies_are_the_sequential_sums() {
    use nalgebra::Vector2;
    use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    use psmpm::basis::mesh::generators::block_grid;
    use psmpm::driver::{Driver, Fix};
    use psmpm::effect::{Effect, Gravity};
    use psmpm::mass::Consistent;
    use psmpm::material::{Elastic, LinearElastic};
    use psmpm::particles::Particles;

    let mesh = block_grid(0.0, 2.0, 0.0, 25.0, 2, 16).unwrap();
    let ps = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
    let mut x = Vec::new();
    for j in 0..160 {
        for i in 0..16 {
            x.push(Vector2::new(
                (i as f64 + 0.5) / 8.0,
                (j as f64 + 0.5) * 25.0 / 160.0,
            ));
        }
    }
    let n = x.len();
    let particles = Particles::new(x, vec![50.0 / n as f64; n], 1.0);
    let fixes = [
        Fix {
            tag: "bottom".into(),
            component: 1,
        },
        Fix {
            tag: "left".into(),
            component: 0,
        },
    ];
    let effects: Vec<Box<dyn Effect<f64, 2>>> = vec![Box::new(Gravity {
        g: Vector2::new(0.0, -9.81),
    })];
    let material = LinearElastic::new(Elastic::new(5e4, 0.0, 1.0).unwrap(), 2);
    let mut d = Driver::new(
        ps,
        particles,
        material,
        Consistent::default(),
        &fixes,
        effects,
        1e-4,
    )
    .unwrap();
    let pool = psmpm::threads::pool(Some(2)).unwrap();
    for _ in 0..5 {
        let stepped = pool.install(|| d.step().unwrap());
        let sequential = d.report();
        let bits = |r: &StepReport| {
            [
                r.kinetic,
                r.strain,
                r.potential,
                r.mass,
                r.momentum()[0],
                r.momentum()[1],
                r.max_speed,
            ]
            .map(f64::to_bits)
        };
        assert_eq!(bits(&stepped), bits(&sequential));
    }
}
