//! The time step allocates nothing: a counting global allocator watches
//! `Driver::step` after set-up, for PS with the consistent mass (sparse Cholesky)
//! and PL with the lumped mass.

use nalgebra::Vector2;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::Basis;
use psmpm::driver::{Driver, Fix};
use psmpm::effect::{Effect, Gravity};
use psmpm::mass::{Lumped, MassKind, MassStrategy, SparseMass};
use psmpm::material::{Elastic, LinearElastic};
use psmpm::particles::Particles;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

struct Counting;
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

fn column_particles() -> Particles<f64, 2> {
    let mut x = Vec::new();
    for j in 0..40 {
        for i in 0..6 {
            x.push(Vector2::new((i as f64 + 0.5) / 3.0, (j as f64 + 0.5) / 1.6));
        }
    }
    let n = x.len();
    Particles::new(x, vec![2.0 * 25.0 / n as f64; n], 1.0)
}

fn steps_allocate<B: Basis<f64, 2>, M: MassStrategy<f64>>(basis: B, kind: MassKind) -> usize {
    let material = LinearElastic::new(Elastic::new(5e4, 0.0, 1.0).unwrap(), 2);
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
    let mut driver: Driver<f64, 2, B, M, LinearElastic> = Driver::new(
        basis,
        column_particles(),
        material,
        kind,
        &fixes,
        effects,
        1e-4,
    )
    .unwrap();
    driver.estimate_condition = true;
    driver.step().unwrap(); // warm-up outside the count
    ALLOCATIONS.store(0, Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    for _ in 0..20 {
        driver.step().unwrap();
    }
    COUNTING.store(false, Ordering::SeqCst);
    ALLOCATIONS.load(Ordering::SeqCst)
}

#[test]
fn a_step_allocates_nothing() {
    let mesh = || block_grid(0.0, 2.0, 0.0, 25.0, 1, 8).unwrap();
    let ps = PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
    assert_eq!(
        steps_allocate::<_, SparseMass<f64>>(ps, MassKind::Consistent),
        0,
        "PS consistent"
    );
    let ps = PowellSabin::<f64>::new(mesh(), SplitPoint::Incentre).unwrap();
    let partial = MassKind::Partial(psmpm::mass::LumpRule::EmptyElement);
    assert_eq!(
        steps_allocate::<_, SparseMass<f64>>(ps, partial),
        0,
        "PS partially lumped"
    );
    let pl = Linear::<f64>::new(mesh());
    assert_eq!(
        steps_allocate::<_, Lumped<f64>>(pl, MassKind::Lumped),
        0,
        "PL lumped"
    );
}
