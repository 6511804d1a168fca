//! The time step allocates nothing: a counting global allocator watches
//! `Driver::step` after set-up, for every mass strategy (PS and PL), with the
//! condition estimate on, and with slip walls, damping and body forces.

use nalgebra::Vector2;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::Basis;
use psmpm::driver::{Driver, Fix};
use psmpm::effect::{BodyForce, Effect, Gravity, LocalDamping};
use psmpm::mass::MassKind;
use psmpm::material::{Elastic, LinearElastic};
use psmpm::particles::Particles;
use psmpm::studies::exact::AxisAligned;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
thread_local! {
    /// Counting is on for the thread that steps (other threads of the test
    /// harness may allocate meanwhile; they are not the step).
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A column of 6 × `rows` particles in the 2 × 25 mesh (40 rows fill it).
fn column_particles(rows: usize) -> Particles<f64, 2> {
    let mut x = Vec::new();
    for j in 0..rows {
        for i in 0..6 {
            x.push(Vector2::new((i as f64 + 0.5) / 3.0, (j as f64 + 0.5) / 1.6));
        }
    }
    let n = x.len();
    Particles::new(x, vec![2.0 * 25.0 / 240.0; n], 1.0)
}

/// Allocations during 20 steps after a warm-up step; `rows` particle rows, and
/// with `extra` a slip wall on the right, local damping and a body force.
fn steps_allocate<B: Basis<f64, 2>>(basis: B, kind: MassKind, rows: usize, extra: bool) -> usize {
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
    driver.step().unwrap(); // warm-up outside the count
    ALLOCATIONS.store(0, Ordering::SeqCst);
    COUNTING.with(|c| c.set(true));
    for _ in 0..20 {
        driver.step().unwrap();
    }
    COUNTING.with(|c| c.set(false));
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
