//! The 1D updated-Lagrangian FEM reference solver (`psmpm::studies::ulfem`):
//! convergence to the exact solutions of B2, B3 (large amplitude, still exact in 1D)
//! and B5a/B5b under grid refinement, the time error, the disk cache, and
//! allocation-free steps.
//!
//! `cargo test --release -p psmpm --test ulfem -- --nocapture` prints the tables.

use psmpm::studies::ulfem::{
    cache_file_name, cached_reference_history, history_key, reference_history, End,
    InitialVelocity, UlFem, UlFemConfig, UlMass,
};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::f64::consts::PI;

// ---------------------------------------------------------------------------
// A global allocator counting the allocations of the current thread only (tests run
// in parallel).

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn note_allocation() {
    if COUNTING.try_with(Cell::get).unwrap_or(false) {
        let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note_allocation();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

// ---------------------------------------------------------------------------
// Helpers.

/// `(∫_0^L (u_h − u)² dX)^½` by 5-point Gauss per element.
fn l2_error(fem: &UlFem, exact: impl Fn(f64) -> f64) -> f64 {
    const XI: [f64; 5] = [
        0.046_910_077_030_668,
        0.230_765_344_947_158,
        0.5,
        0.769_234_655_052_842,
        0.953_089_922_969_332,
    ];
    const W: [f64; 5] = [
        0.118_463_442_528_095,
        0.239_314_335_249_683,
        0.284_444_444_444_444,
        0.239_314_335_249_683,
        0.118_463_442_528_095,
    ];
    let c = fem.config();
    let h = c.element_length();
    let mut sum = 0.0;
    for e in 0..c.elements {
        for (xi, w) in XI.iter().zip(W) {
            let x = (e as f64 + xi) * h;
            let d = fem.displacement_at(x) - exact(x);
            sum += w * h * d * d;
        }
    }
    sum.sqrt()
}

fn run(config: UlFemConfig, initial: InitialVelocity, t_end: f64) -> UlFem {
    let mut fem = UlFem::with_initial_velocity(config, initial).unwrap();
    let steps = (t_end / config.dt).round() as u64;
    for _ in 0..steps {
        fem.step().unwrap();
    }
    fem
}

fn orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

fn print_table(title: &str, elements: &[usize], errors: &[f64]) {
    println!("{title}");
    println!("  elements     error  order");
    for (i, (n, e)) in elements.iter().zip(errors).enumerate() {
        let order = if i == 0 {
            "     -".to_string()
        } else {
            format!("{:6.3}", (errors[i - 1] / e).log2())
        };
        println!("  {n:8}  {e:.3e} {order}");
    }
}

const GRIDS: [usize; 4] = [8, 16, 32, 64];

/// Exact standing wave of B2/B3, `u = (v0/ω) sin(ωt) sin(πX/L)`, `ω = π c / L`.
fn sine_mode(config: &UlFemConfig, v0: f64, t: f64) -> impl Fn(f64) -> f64 {
    let l = config.length;
    let omega = PI * config.wave_speed() / l;
    move |x| v0 / omega * (omega * t).sin() * (PI * x / l).sin()
}

/// Exact column of B5a (benchmarks.md, sign-corrected thesis (4.6)), series to
/// `terms` modes:
/// `u = (ρg/E)(H y − y²/2) − Σ_n u_n cos(c k_n t) sin(k_n y)`, `k_n = (2n−1)π/(2H)`,
/// `u_n = 16ρgH²/((2n−1)³π³E)`.
fn column_exact(config: &UlFemConfig, t: f64, terms: usize) -> impl Fn(f64) -> f64 {
    let (h, rho, g, e) = (config.length, config.density, config.gravity, config.young);
    let c = config.wave_speed();
    let modes: Vec<(f64, f64)> = (1..=terms)
        .map(|n| {
            let m = (2 * n - 1) as f64;
            let k = m * PI / (2.0 * h);
            let un = 16.0 * rho * g * h * h / (m * m * m * PI.powi(3) * e);
            (k, un * (c * k * t).cos())
        })
        .collect();
    move |y| {
        rho * g / e * (h * y - 0.5 * y * y)
            - modes.iter().map(|(k, a)| a * (k * y).sin()).sum::<f64>()
    }
}

// ---------------------------------------------------------------------------
// Convergence.

/// B2 in 1D: both masses converge with order 2 to the exact standing wave.
#[test]
fn b2_converges_with_order_two() {
    let (v0, t_end, dt) = (0.1, 1.0, 1e-4);
    for mass in [UlMass::Lumped, UlMass::Consistent] {
        let mut errors = Vec::new();
        for n in GRIDS {
            let config = UlFemConfig {
                mass,
                ..UlFemConfig::vibrating_bar(n, dt)
            };
            assert!(config.dt <= 0.5 * config.critical_dt());
            let fem = run(config, InitialVelocity::SineMode { v0 }, t_end);
            errors.push(l2_error(&fem, sine_mode(&config, v0, fem.time())));
        }
        print_table(
            &format!("B2, {mass:?}, t = {t_end}, dt = {dt}"),
            &GRIDS,
            &errors,
        );
        for order in orders(&errors) {
            assert!(order >= 1.8, "{mass:?}: {errors:?}");
        }
        // Time error: halving dt on the finest grid changes the error by < 1 %.
        let config = UlFemConfig {
            mass,
            ..UlFemConfig::vibrating_bar(64, dt / 2.0)
        };
        let fem = run(config, InitialVelocity::SineMode { v0 }, t_end);
        let half = l2_error(&fem, sine_mode(&config, v0, t_end));
        println!("  64 with dt/2: {half:.3e}");
        assert!(
            (half - errors[3]).abs() < 0.01 * errors[3],
            "{half} vs {errors:?}"
        );
    }
}

/// B3 (thesis constants, max strain 7 %): in 1D with σ = E (F − 1) the problem is
/// linear, so the large-amplitude run converges with order 2 to the same formula.
#[test]
fn b3_large_amplitude_is_still_the_exact_standing_wave() {
    let (v0, t_end, dt) = (0.1, 10.0, 1e-3);
    let mut errors = Vec::new();
    let mut max_strain: f64 = 0.0;
    for n in GRIDS {
        let config = UlFemConfig::vibrating_bar_large(n, dt);
        assert!(config.dt <= 0.5 * config.critical_dt());
        let mut fem =
            UlFem::with_initial_velocity(config, InitialVelocity::SineMode { v0 }).unwrap();
        let steps = (t_end / dt).round() as u64;
        for _ in 0..steps {
            fem.step().unwrap();
            if n == 64 {
                for e in 0..n {
                    max_strain = max_strain.max((fem.stretch(e) - 1.0).abs());
                }
            }
        }
        errors.push(l2_error(&fem, sine_mode(&config, v0, fem.time())));
    }
    print_table(
        &format!("B3 (max strain {max_strain:.4}), lumped, t = {t_end}, dt = {dt}"),
        &GRIDS,
        &errors,
    );
    // A quarter period is 8.8 s, so t = 10 passes the largest strain.
    assert!(max_strain > 0.065, "{max_strain}");
    for order in orders(&errors) {
        assert!(order >= 1.8, "{errors:?}");
    }
    let fem = run(
        UlFemConfig::vibrating_bar_large(64, dt / 2.0),
        InitialVelocity::SineMode { v0 },
        t_end,
    );
    let half = l2_error(&fem, sine_mode(fem.config(), v0, t_end));
    println!("  64 with dt/2: {half:.3e}");
    assert!((half - errors[3]).abs() < 0.01 * errors[3]);
}

/// B5a in 1D: the column suddenly loaded by its weight converges to the series.
#[test]
fn b5a_converges() {
    // Δt small: the suddenly applied load makes the time error first order (the
    // symplectic Euler velocity starts half a step off); with Δt = 1e-5 it would be
    // ~ 3 % of the 64-element error.
    let (t_end, dt, terms) = (0.5, 2.5e-6, 4000);
    // The series at t = 0 vanishes (the column starts undeformed).
    let config = UlFemConfig::column_small(8, dt);
    let at_rest = column_exact(&config, 0.0, terms);
    for y in [0.0, 5.0, 12.5, 25.0] {
        assert!(at_rest(y).abs() < 1e-8, "{}", at_rest(y));
    }
    let mut errors = Vec::new();
    let mut exact_norm = 0.0;
    for n in GRIDS {
        let config = UlFemConfig::column_small(n, dt);
        assert!(config.dt <= 0.5 * config.critical_dt());
        let fem = run(config, InitialVelocity::Rest, t_end);
        let exact = column_exact(&config, fem.time(), terms);
        errors.push(l2_error(&fem, &exact));
        exact_norm = l2_error(&UlFem::new(config, |_| 0.0).unwrap(), &exact);
    }
    print_table(
        &format!("B5a, lumped, t = {t_end}, dt = {dt} (‖u‖ = {exact_norm:.3e})"),
        &GRIDS,
        &errors,
    );
    // Measured 1.67, 1.67, 1.68 (and 1.69, 1.68 on to 256 elements).
    for order in orders(&errors) {
        assert!(order > 1.5, "{errors:?}");
    }
    let config = UlFemConfig::column_small(64, dt / 2.0);
    let fem = run(config, InitialVelocity::Rest, t_end);
    let half = l2_error(&fem, column_exact(&config, t_end, terms));
    println!("  64 with dt/2: {half:.3e}");
    assert!((half - errors[3]).abs() < 0.01 * errors[3]);
}

/// B5b (max strain ≈ 18 %): also linear in 1D, so it converges to the B5a series with
/// B5b's constants; the run stays free of inversion to t = 2.5.
#[test]
fn b5b_large_deformation_converges_to_the_series() {
    let (t_end, dt, terms) = (2.5, 1e-5, 4000);
    let mut errors = Vec::new();
    let mut min_stretch: f64 = 1.0;
    for n in GRIDS {
        let config = UlFemConfig::column_large(n, dt);
        assert!(config.dt <= 0.5 * config.critical_dt());
        let mut fem = UlFem::with_initial_velocity(config, InitialVelocity::Rest).unwrap();
        let e0 = fem.energies().total();
        let scale = config.density * config.length * 9.81 * 0.1;
        let steps = (t_end / dt).round() as u64;
        for s in 0..steps {
            fem.step().unwrap();
            if n == 64 && s % 100 == 0 {
                min_stretch = min_stretch.min(fem.stretch(0));
                assert!((fem.energies().total() - e0).abs() < 1e-3 * scale);
            }
        }
        errors.push(l2_error(&fem, column_exact(&config, fem.time(), terms)));
    }
    print_table(
        &format!("B5b (min stretch {min_stretch:.4}), lumped, t = {t_end}, dt = {dt}"),
        &GRIDS,
        &errors,
    );
    assert!(min_stretch < 0.83, "{min_stretch}");
    for order in orders(&errors) {
        assert!(order > 1.5, "{errors:?}");
    }
    let config = UlFemConfig::column_large(64, dt / 2.0);
    let fem = run(config, InitialVelocity::Rest, t_end);
    let half = l2_error(&fem, column_exact(&config, t_end, terms));
    println!("  64 with dt/2: {half:.3e}");
    assert!((half - errors[3]).abs() < 0.01 * errors[3]);
}

// ---------------------------------------------------------------------------
// Histories and the cache.

fn scratch_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("psmpm-ulfem-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn history_records_and_cache_round_trip() {
    let config = UlFemConfig::column_large(16, 1e-4);
    let samples = [0.0, 0.5, 1.0];
    let history = reference_history(&config, InitialVelocity::Rest, &samples, 100, 0.25).unwrap();
    assert_eq!(history.steps, 2500);
    assert_eq!(history.records.len(), 26);
    let last = history.records.last().unwrap();
    assert!((last.time - 0.25).abs() < 1e-12);
    // The bottom is fixed; the top has fallen.
    assert_eq!(last.displacement[0], 0.0);
    assert!(last.displacement[2] < 0.0);
    assert_eq!(
        history.records[0].energies.total(),
        history.records[0].energies.potential
    );

    let dir = scratch_dir("cache");
    let key = history_key(&config, InitialVelocity::Rest, &samples, 100, 0.25);
    let file = dir.join(cache_file_name(&key));
    let first = cached_reference_history(
        Some(&dir),
        &config,
        InitialVelocity::Rest,
        &samples,
        100,
        0.25,
    )
    .unwrap();
    assert_eq!(first, history);
    assert!(file.exists(), "{file:?}");
    // Read back bit for bit (serde_json with float_roundtrip).
    let second = cached_reference_history(
        Some(&dir),
        &config,
        InitialVelocity::Rest,
        &samples,
        100,
        0.25,
    )
    .unwrap();
    assert_eq!(second, history);
    // A cached file is really used: a doctored (but well-formed) file is returned...
    let mut doctored = history.clone();
    doctored.records[0].time = 123.0;
    std::fs::write(&file, serde_json::to_vec(&doctored).unwrap()).unwrap();
    let read = cached_reference_history(
        Some(&dir),
        &config,
        InitialVelocity::Rest,
        &samples,
        100,
        0.25,
    )
    .unwrap();
    assert_eq!(read.records[0].time, 123.0);
    // ...one whose key differs (hash collision, old version) is not, nor a corrupt one;
    // both are recomputed and overwritten.
    doctored.key.push('x');
    std::fs::write(&file, serde_json::to_vec(&doctored).unwrap()).unwrap();
    let read = cached_reference_history(
        Some(&dir),
        &config,
        InitialVelocity::Rest,
        &samples,
        100,
        0.25,
    )
    .unwrap();
    assert_eq!(read, history);
    std::fs::write(&file, b"{ not json").unwrap();
    let read = cached_reference_history(
        Some(&dir),
        &config,
        InitialVelocity::Rest,
        &samples,
        100,
        0.25,
    )
    .unwrap();
    assert_eq!(read, history);
    let stored: psmpm::studies::ulfem::History =
        serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    assert_eq!(stored, history);
    // No temporary files left behind.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();

    // An unusable cache directory (a regular file) just computes.
    let blocker = scratch_dir("blocker");
    std::fs::write(&blocker, b"file").unwrap();
    let computed = cached_reference_history(
        Some(&blocker),
        &config,
        InitialVelocity::Rest,
        &samples,
        100,
        0.25,
    )
    .unwrap();
    assert_eq!(computed, history);
    std::fs::remove_file(&blocker).unwrap();
    // Bad input is still an error, cache or not.
    let bad = UlFemConfig { dt: -1.0, ..config };
    assert!(cached_reference_history(None, &bad, InitialVelocity::Rest, &samples, 1, 1.0).is_err());
}

#[test]
fn a_failed_run_is_an_error_not_a_panic() {
    // Far beyond the stability limit: the history reports the failing step.
    let config = UlFemConfig::column_small(16, 0.1);
    let error = reference_history(&config, InitialVelocity::Rest, &[25.0], 1, 10.0).unwrap_err();
    assert!(error.to_string().starts_with("step "), "{error}");
}

// ---------------------------------------------------------------------------
// Allocation-free steps.

#[test]
fn steps_allocate_nothing() {
    for mass in [UlMass::Lumped, UlMass::Consistent] {
        for (left, right) in [
            (End::Fixed, End::Free),
            (End::Free, End::Free),
            (End::Fixed, End::Fixed),
        ] {
            let config = UlFemConfig {
                left,
                right,
                mass,
                ..UlFemConfig::column_small(32, 1e-4)
            };
            let mut fem =
                UlFem::with_initial_velocity(config, InitialVelocity::SineMode { v0: 0.1 })
                    .unwrap();
            fem.step().unwrap();
            COUNTING.with(|c| c.set(true));
            for _ in 0..100 {
                fem.step().unwrap();
            }
            let _ = fem.energies();
            let _ = fem.displacement_at(3.0) + fem.velocity_at(3.0) + fem.stress_at(3.0);
            COUNTING.with(|c| c.set(false));
            let allocations = ALLOCATIONS.with(Cell::get);
            assert_eq!(allocations, 0, "{mass:?} {left:?} {right:?}");
        }
    }
}
