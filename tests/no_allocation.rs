//! The time step allocates nothing: a counting global allocator watches
//! `Driver::step` after set-up, for every mass strategy (PS and PL), with the
//! condition estimate on, and with slip walls, damping and body forces.
//!
//! The steps run inside a rayon pool (`ThreadPool::install`) of 1 and of 2
//! threads, and allocations are counted on every thread while they run (the
//! pool's workers included). Inside `install` the parallel phases push their
//! tasks onto the workers' own deques, which keep their capacity once grown (the
//! warm-up step grows them). Stepping from a thread outside any pool would
//! instead hand every parallel phase to rayon's global pool through its shared
//! injector queue, which allocates a block of slots now and then (every few
//! dozen tasks): not the step's allocation, but counted here if it were on; a
//! loop of steps belongs inside `install` anyway (see `psmpm::threads`).

use nalgebra::Vector2;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::Basis;
use psmpm::driver::{Driver, Fix, WATCH_EVERY};
use psmpm::effect::{BodyForce, Effect, Gravity, LocalDamping};
use psmpm::mass::MassKind;
use psmpm::material::{Elastic, LinearElastic};
use psmpm::particles::Particles;
use psmpm::studies::exact::AxisAligned;
use psmpm::threads::ThreadPool;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::OnceLock;

struct Counting;
/// Counting is on, on every thread, while the steps run (this file holds one
/// test: no other test allocates meanwhile).
static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A column of 6 × `rows` particles in the 2 × 25 mesh (40 rows fill it); with
/// `rows` above 40, a lattice of 24 × `rows` filling it.
fn column_particles(rows: usize) -> Particles<f64, 2> {
    let (across, dy) = if rows > 40 {
        (24, 25.0 / rows as f64)
    } else {
        (6, 1.0 / 1.6)
    };
    let mut x = Vec::new();
    for j in 0..rows {
        for i in 0..across {
            x.push(Vector2::new(
                (i as f64 + 0.5) * 2.0 / across as f64,
                (j as f64 + 0.5) * dy,
            ));
        }
    }
    let n = x.len();
    let volume = if rows > 40 {
        50.0 / n as f64
    } else {
        2.0 * 25.0 / 240.0
    };
    Particles::new(x, vec![volume; n], 1.0)
}

/// Allocations during 20 steps after a warm-up step, on pools of 1 and 2
/// threads (the larger count); `rows` particle rows, and with `extra` a slip
/// wall on the right, local damping and a body force.
fn steps_allocate<B: Basis<f64, 2> + Clone + Send>(
    basis: B,
    kind: MassKind,
    rows: usize,
    extra: bool,
) -> usize {
    [1, 2]
        .into_iter()
        .map(|threads| {
            let basis = basis.clone();
            pool(threads).install(|| steps_allocate_here(basis, kind, rows, extra))
        })
        .max()
        .unwrap_or(0)
}

/// The pool of 1 or 2 threads, built once and started before any count: threads
/// that start or end allocate.
fn pool(threads: usize) -> &'static ThreadPool {
    static POOLS: OnceLock<[ThreadPool; 2]> = OnceLock::new();
    let pools = POOLS.get_or_init(|| {
        let pools = [1, 2].map(|n| psmpm::threads::pool(Some(n)).unwrap());
        // Every worker started (starting threads allocate) before any count.
        for pool in &pools {
            pool.broadcast(|_| ());
        }
        pools
    });
    &pools[threads - 1]
}

/// [`steps_allocate`] on the current pool.
fn steps_allocate_here<B: Basis<f64, 2>>(
    basis: B,
    kind: MassKind,
    rows: usize,
    extra: bool,
) -> usize {
    let material = LinearElastic::new(Elastic::new(5e4, 0.0, 1.0).unwrap(), 2);
    let mut fixes = vec![
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
    ];
    if !extra {
        fixes.push(Fix {
            tag: "right".into(),
            component: 0,
        });
    }
    let mut effects: Vec<Box<dyn Effect<f64, 2>>> = vec![Box::new(Gravity {
        g: Vector2::new(0.0, -9.81),
    })];
    if extra {
        effects.push(Box::new(BodyForce::Uniform(Vector2::new(0.1, 0.0))));
        // The manufactured field is evaluated per particle, at its reference position.
        effects.push(Box::new(BodyForce::Manufactured(AxisAligned {
            u0: 1e-4,
            ..AxisAligned::PAPER
        })));
        effects.push(Box::new(LocalDamping { alpha: 0.05 }));
    }
    let mut driver = Driver::new(
        basis,
        column_particles(rows),
        material,
        kind.build(),
        &fixes,
        effects,
        1e-4,
    )
    .unwrap();
    if extra {
        driver
            .add_slip_wall("right", &Vector2::new(1.0, 0.0))
            .unwrap();
    }
    driver.estimate_condition = true;
    // The watch over the critical step, set to split every step in two or more, so that
    // every counted step checks the critical step and takes sub-steps.
    let critical = driver.critical_time_step().unwrap();
    driver.watch_critical_step(0.5 * driver.dt() / critical, 0.0);
    // Warm-up outside the count, through the watch's first check.
    for _ in 0..WATCH_EVERY + 1 {
        driver.step().unwrap();
    }
    ALLOCATIONS.store(0, Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    for _ in 0..20 {
        assert!(driver.step().unwrap().substeps >= 2);
    }
    COUNTING.store(false, Ordering::SeqCst);
    ALLOCATIONS.load(Ordering::SeqCst)
}

#[test]
fn a_step_allocates_nothing() {
    let mesh = || block_grid(0.0, 2.0, 0.0, 25.0, 1, 8).unwrap();
    let ps = || PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
    for (kind, rows) in [
        ("consistent", 40),
        ("partial", 40),
        ("partial-coverage:0.3", 24),
        ("deactivate", 24),
        ("extended", 24),
        ("fmpm:3", 24),
        ("lumped", 40),
    ] {
        let mass = MassKind::parse(kind).unwrap();
        assert_eq!(steps_allocate(ps(), mass, rows, false), 0, "PS {kind}");
    }
    let pl = Linear::<f64>::new(mesh());
    assert_eq!(
        steps_allocate(pl, MassKind::Lumped, 40, false),
        0,
        "PL lumped"
    );
    let pl = Linear::<f64>::new(mesh());
    assert_eq!(
        steps_allocate(pl, MassKind::default(), 24, false),
        0,
        "PL extended"
    );
    // Several particle chunks and element tasks: 24 × 200 particles on 2 × 16 blocks.
    let mesh = || block_grid(0.0, 2.0, 0.0, 25.0, 2, 16).unwrap();
    let ps = PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
    assert_eq!(
        steps_allocate(ps, MassKind::default(), 200, false),
        0,
        "PS default, 4800 particles"
    );
    // A body over a small part of the mesh (two rows of particles under 8 × 64
    // blocks): the gathers, element loops and lumped solves through the lists.
    let mesh = || block_grid(0.0, 2.0, 0.0, 25.0, 8, 64).unwrap();
    for kind in ["lumped", "extended-hybrid"] {
        let ps = PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
        let mass = MassKind::parse(kind).unwrap();
        let counted = pool(1).install(|| {
            let material = LinearElastic::new(Elastic::new(5e4, 0.0, 1.0).unwrap(), 2);
            let effects: Vec<Box<dyn Effect<f64, 2>>> = vec![Box::new(Gravity {
                g: Vector2::new(0.0, -9.81),
            })];
            let mut driver = Driver::new(
                ps,
                column_particles(2),
                material,
                mass.build(),
                &[],
                effects,
                1e-4,
            )
            .unwrap();
            for _ in 0..3 {
                driver.step().unwrap();
            }
            ALLOCATIONS.store(0, Ordering::SeqCst);
            COUNTING.store(true, Ordering::SeqCst);
            for _ in 0..20 {
                driver.step().unwrap();
            }
            COUNTING.store(false, Ordering::SeqCst);
            ALLOCATIONS.load(Ordering::SeqCst)
        });
        assert_eq!(counted, 0, "PS {kind}, a small body");
    }
    let mesh = || block_grid(0.0, 2.0, 0.0, 25.0, 1, 8).unwrap();
    let ps = || PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
    // Slip wall (general constraints), damping and a body force (work booked).
    for kind in ["extended", "consistent", "lumped"] {
        let mass = MassKind::parse(kind).unwrap();
        let rows = if kind == "consistent" { 40 } else { 24 };
        assert_eq!(
            steps_allocate(ps(), mass, rows, true),
            0,
            "PS {kind} with effects"
        );
    }
}
