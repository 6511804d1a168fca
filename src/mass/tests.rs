use super::*;
use nalgebra::Vector2;
use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm_basis::mesh::generators::block_grid;
use psmpm_basis::rng::SplitMix64;
use psmpm_basis::{Basis, BasisEval};

/// A PS mass matrix from random particles filling the lower 60 % of a 2 × 4 block
/// grid (the top elements are empty), the empty-element marks and the particle
/// volume each function sees.
struct Column {
    ps: PowellSabin<f64>,
    pattern: SymmetricPattern,
    values: Vec<f64>,
    touches_empty: Vec<bool>,
    particle_volume: Vec<f64>,
    particle_count: Vec<f64>,
}

fn column_mass() -> Column {
    filled_to(1.2)
}

/// Particles filling the grid up to `height` (of 2).
fn filled_to(height: f64) -> Column {
    let ps = PowellSabin::<f64>::new(
        block_grid(0.0, 1.0, 0.0, 2.0, 2, 4).unwrap(),
        SplitPoint::Incentre,
    )
    .unwrap();
    filled(ps, (1.0, height), (400.0 * height / 1.2) as usize)
}

/// `count` random particles in `[0, extent.0] × [0, extent.1]` on `ps`.
fn filled(ps: PowellSabin<f64>, extent: (f64, f64), count: usize) -> Column {
    filled_in(ps, (0.0, 0.0), extent, count)
}

/// `count` random particles in `[min.0, min.0 + extent.0] × [min.1, min.1 + extent.1]`.
fn filled_in(ps: PowellSabin<f64>, min: (f64, f64), extent: (f64, f64), count: usize) -> Column {
    let pattern = SymmetricPattern::new(&ps);
    let mut values = vec![0.0; pattern.nnz()];
    let mut particle_volume = vec![0.0; ps.num_functions()];
    let mut particle_count = vec![0.0; ps.num_functions()];
    let mut eval = BasisEval::for_basis(&ps);
    let mut rng = SplitMix64(3);
    let mut occupied = vec![false; ps.num_elements()];
    for _ in 0..count {
        let x = Vector2::new(
            min.0 + extent.0 * rng.next_f64(),
            min.1 + extent.1 * rng.next_f64(),
        );
        let e = ps.locate(&x, None).unwrap();
        occupied[e] = true;
        ps.eval(e, &x, &mut eval);
        let scatter = pattern.element_scatter(e);
        for a in 0..9 {
            particle_volume[eval.index[a]] += 0.003 * eval.phi[a];
            particle_count[eval.index[a]] += eval.phi[a];
            for b in a..9 {
                values[scatter[a * 9 + b] as usize] += 0.01 * eval.phi[a] * eval.phi[b];
            }
        }
    }
    let mut touches_empty = vec![false; ps.num_functions()];
    for e in (0..ps.num_elements()).filter(|&e| !occupied[e]) {
        for &i in ps.element_functions(e) {
            touches_empty[i] = true;
        }
    }
    Column {
        ps,
        pattern,
        values,
        touches_empty,
        particle_volume,
        particle_count,
    }
}

fn prepared(c: &Column, kind: MassKind) -> Box<dyn MassStrategy<f64>> {
    let n = c.ps.num_functions();
    prepared_with(c, kind, &[vec![false; n], vec![false; n]])
}

/// [`prepared`] with the `fixed` components.
fn prepared_with(c: &Column, kind: MassKind, fixed: &[Vec<bool>]) -> Box<dyn MassStrategy<f64>> {
    let mut m = kind.build::<f64>();
    let needs = m.needs();
    let support = (needs.coverage || needs.polynomials)
        .then(|| std::sync::Arc::new(SupportFacts::new(&c.ps, &c.pattern, needs.polynomials)));
    m.prepare(&MassSetup {
        pattern: &c.pattern,
        fixed,
        support: support.as_ref(),
    });
    m
}

fn context(c: &Column) -> StepContext<'_> {
    StepContext {
        touches_empty: &c.touches_empty,
        particle_volume: &c.particle_volume,
        particle_count: &c.particle_count,
        on_wall: &[],
        live: &[],
        live_list: None,
        diagonal_only: false,
        flat: &[],
    }
}

/// Solving `M' y = M 1` returns `y = 1` on the active functions: the strategy keeps
/// the row sums of `M` (mass and momentum are conserved).
fn assert_keeps_row_sums(c: &Column, m: &mut Box<dyn MassStrategy<f64>>, label: &str) {
    keeps_row_sums_to(c, m, label, 1e-9);
}

/// [`assert_keeps_row_sums`] to `tolerance`.
fn keeps_row_sums_to(c: &Column, m: &mut Box<dyn MassStrategy<f64>>, label: &str, tolerance: f64) {
    let n = c.ps.num_functions();
    let mut rhs = vec![0.0; n];
    c.pattern.row_sums(&c.values, &mut rhs);
    let active: Vec<bool> = rhs.iter().map(|&r| r > 0.0).collect();
    m.solve(0, &mut rhs).unwrap();
    for i in 0..n {
        let expected = if active[i] { 1.0 } else { 0.0 };
        assert!(
            (rhs[i] - expected).abs() < tolerance,
            "{label}: y[{i}] = {}",
            rhs[i]
        );
    }
}

/// The consistent matrix of this near-empty configuration is singular (three PS
/// functions of a top vertex see too few particles): reported, not a panic.
/// Partial lumping keeps every row sum and stays SPD.
#[test]
fn partial_lumping_keeps_row_sums_and_stays_spd() {
    let c = column_mass();
    let mut consistent = prepared(&c, MassKind::Consistent);
    assert!(consistent
        .factorize(&c.pattern, &c.values, context(&c))
        .is_err());
    for kind in [
        MassKind::Partial(LumpRule::EmptyElement),
        MassKind::Partial(LumpRule::Threshold(0.3)),
        MassKind::Partial(LumpRule::Coverage(0.5)),
    ] {
        let mut m = prepared(&c, kind);
        let report = m.factorize(&c.pattern, &c.values, context(&c)).unwrap();
        assert!(report.lumped_rows > 0, "{kind:?} lumped nothing");
        assert_keeps_row_sums(&c, &mut m, &kind.spec());
        assert!(m.condition_estimate(&c.pattern) >= 1.0);
    }
}

/// Extension solves where the consistent mass fails, keeps the row sums, and its
/// solved system is well conditioned.
#[test]
fn extension_keeps_row_sums_where_consistent_fails() {
    let c = column_mass();
    let mut m = prepared(
        &c,
        MassKind::Extended {
            coverage: DEFAULT_COVERAGE,
        },
    );
    let report = m.factorize(&c.pattern, &c.values, context(&c)).unwrap();
    assert!(report.extended > 0, "nothing extended: {report:?}");
    // The worst-covered function reported is the worst one solved for: every
    // function below the threshold is extended, out of the system.
    let (_, worst) = report.worst_coverage.unwrap();
    assert!(worst >= DEFAULT_COVERAGE, "worst solved coverage {worst}");
    assert_keeps_row_sums(&c, &mut m, "extended");
    let condition = m.condition_estimate(&c.pattern);
    assert!((1.0..1e4).contains(&condition), "condition {condition}");
}

/// The extension keeps the row sums on every fill of the column, at thresholds that
/// extend few functions and many: each row's weights reproduce the constants (a
/// ring that cannot reproduce the polynomials is refused by its residual, whatever
/// round-off leaves of its pivots).
#[test]
fn extension_keeps_row_sums_on_every_fill() {
    let domain = psmpm_basis::mesh::generators::PolygonDomain::rectangle(0.0, 4.0, 0.0, 3.0);
    let mesh = psmpm_basis::mesh::generators::polygon_mesh(&domain, 0.2).unwrap();
    for tenths in 2..20 {
        let blob = (0.2 * tenths as f64, 0.1 * tenths as f64);
        let ps = PowellSabin::<f64>::new(mesh.clone(), SplitPoint::Incentre).unwrap();
        let columns = [
            filled_to(0.1 * tenths as f64),
            filled(ps, blob, (blob.0 * blob.1 * 400.0) as usize),
        ];
        for (c, coverage) in columns
            .iter()
            .flat_map(|c| [0.25, 0.5, 0.9].map(|w| (c, w)))
        {
            let mut m = prepared(c, MassKind::Extended { coverage });
            if m.factorize(&c.pattern, &c.values, context(c)).is_ok() {
                // The solve's own round-off on the blob's larger systems reaches
                // 2e-9; a row missing the constants missed them by 0.1.
                let label = format!("fill {tenths}/10, {coverage}");
                keeps_row_sums_to(c, &mut m, &label, 1e-7);
            }
        }
    }
}

/// The extension strategies given the step's live list (a body over a small part
/// of the mesh, as the driver gives it) classify, factorise and solve exactly as
/// they do passing over every function, bit for bit, while the body moves, fills
/// the mesh and shrinks again (the roles, marks and rows of the last list reset).
#[test]
fn extension_through_the_live_list_equals_the_pass_over_every_function() {
    let mesh = block_grid(0.0, 4.0, 0.0, 3.0, 20, 15).unwrap();
    let ps = || PowellSabin::<f64>::new(mesh.clone(), SplitPoint::Incentre).unwrap();
    // (corner, extent, listed): the fills of successive steps; the second fills
    // whole blocks, so that a small threshold extends nothing there.
    let fills = [
        ((0.3, 0.3), (0.6, 0.6), true),
        ((0.6, 0.6), (0.8, 0.8), true),
        ((0.5, 0.4), (0.6, 0.5), true),
        ((0.0, 0.0), (4.0, 3.0), false),
        ((2.5, 1.5), (0.7, 0.7), true),
        ((2.6, 1.45), (0.7, 0.7), true),
        ((1.0, 2.2), (0.3, 0.6), true),
    ];
    let columns: Vec<Column> = fills
        .iter()
        .map(|&(min, extent, _)| {
            filled_in(ps(), min, extent, (extent.0 * extent.1 * 900.0) as usize)
        })
        .collect();
    for spec in [
        "default",
        "extended",
        "extended:0.9",
        "extended:0.0001",
        "extended-hybrid-plain",
    ] {
        let kind = MassKind::parse(spec).unwrap();
        // Component 0 of every seventh function held at zero: two fixed sets, and
        // extension rows through fixed functions.
        let n = columns[0].ps.num_functions();
        let fixed = [(0..n).map(|i| i % 7 == 3).collect(), vec![false; n]];
        let (mut full, mut listed) = (
            prepared_with(&columns[0], kind, &fixed),
            prepared_with(&columns[0], kind, &fixed),
        );
        for (step, (c, &(_, _, use_list))) in columns.iter().zip(&fills).enumerate() {
            let n = c.ps.num_functions();
            // The functions of the elements holding a particle (the gather's live ones).
            let mut live = vec![false; n];
            for e in 0..c.ps.num_elements() {
                let closure = c.ps.element_functions(e);
                let occupied = closure.iter().all(|&i| c.particle_volume[i] > 0.0);
                if occupied {
                    closure.iter().for_each(|&i| live[i] = true);
                }
            }
            let list: Vec<u32> = (0..n as u32).filter(|&i| live[i as usize]).collect();
            fn with<'a>(
                c: &'a Column,
                live: &'a [bool],
                list: Option<&'a [u32]>,
            ) -> StepContext<'a> {
                StepContext {
                    live,
                    live_list: list,
                    ..context(c)
                }
            }
            let none = with(c, &live, None);
            let some = with(c, &live, use_list.then_some(&list[..]));
            let label = format!("{spec}, step {step}");
            let rows = |lumped: Option<&[bool]>| {
                lumped.map(|l| (0..n).filter(|&i| l[i]).collect::<Vec<_>>())
            };
            let a = rows(full.classify(&c.pattern, &c.values, none));
            let b = rows(listed.classify(&c.pattern, &c.values, some));
            assert_eq!(a, b, "{label}: lumped rows");
            let a = full.factorize(&c.pattern, &c.values, none);
            let b = listed.factorize(&c.pattern, &c.values, some);
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "{label}: report");
            if a.is_err() {
                continue;
            }
            // A right-hand side nonzero on every function (the watch solves such).
            let rhs: Vec<f64> = (0..n).map(|i| 1.0 + (i % 13) as f64 * 0.1).collect();
            let (mut x, mut y) = (vec![rhs.clone(); 2], vec![rhs.clone(); 2]);
            let (a, b) = (full.solve_all(&mut x), listed.solve_all(&mut y));
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "{label}: solve");
            for k in 0..2 {
                for i in 0..n {
                    assert_eq!(x[k][i].to_bits(), y[k][i].to_bits(), "{label}: x[{k}][{i}]");
                }
            }
            let (ka, kb) = (
                full.condition_estimate(&c.pattern),
                listed.condition_estimate(&c.pattern),
            );
            assert_eq!(ka.to_bits(), kb.to_bits(), "{label}: condition");
            // Without the hybrid's hysteresis a step depends on nothing before it:
            // a strategy prepared for this step alone solves the same (its buffers
            // are left clean by the steps before).
            if spec.starts_with("extended:") || spec == "extended" {
                let mut fresh = prepared_with(c, kind, &fixed);
                fresh.factorize(&c.pattern, &c.values, some).unwrap();
                let mut z = vec![rhs.clone(); 2];
                if fresh.solve_all(&mut z).is_ok() {
                    for k in 0..2 {
                        for i in 0..n {
                            assert_eq!(x[k][i].to_bits(), z[k][i].to_bits(), "{label}: fresh");
                        }
                    }
                }
            }
        }
    }
}

/// The hybrid (extension below the first coverage, lumped rows below the second)
/// keeps the row sums where the consistent mass fails, and its system is well
/// conditioned.
#[test]
fn hybrid_extension_keeps_row_sums_where_consistent_fails() {
    let c = column_mass();
    for spec in ["extended-hybrid:0.02:0.75", "extended-hybrid:0.25:0.75"] {
        let kind = MassKind::parse(spec).unwrap();
        let mut m = prepared(&c, kind);
        let report = m.factorize(&c.pattern, &c.values, context(&c)).unwrap();
        assert!(report.lumped_rows > 0, "{spec}: nothing lumped: {report:?}");
        assert_keeps_row_sums(&c, &mut m, spec);
        let condition = m.condition_estimate(&c.pattern);
        assert!(
            (1.0..1e4).contains(&condition),
            "{spec}: condition {condition}"
        );
    }
}

/// With every function well covered the extension does nothing and solves the
/// consistent system.
#[test]
fn extension_is_the_consistent_mass_where_everything_is_covered() {
    let c = filled_to(2.0);
    let mut consistent = prepared(&c, MassKind::Consistent);
    let mut extended = prepared(
        &c,
        MassKind::Extended {
            coverage: DEFAULT_COVERAGE,
        },
    );
    consistent
        .factorize(&c.pattern, &c.values, context(&c))
        .unwrap();
    let report = extended
        .factorize(&c.pattern, &c.values, context(&c))
        .unwrap();
    assert_eq!(report.treated(), 0, "{report:?}");
    let n = c.ps.num_functions();
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 7) % 5) as f64 * 1e-3 - 1e-3).collect();
    let (mut a, mut b) = (rhs.clone(), rhs);
    consistent.solve(1, &mut a).unwrap();
    extended.solve(1, &mut b).unwrap();
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        assert!(
            (a[i] - b[i]).abs() < 1e-9 * scale,
            "{i}: {} against {}",
            a[i],
            b[i]
        );
    }
}

/// FMPM(K) keeps row sums for every K and approaches the consistent solve as K grows.
#[test]
fn fmpm_keeps_row_sums_and_converges_to_the_consistent_solve() {
    let c = column_mass();
    let n = c.ps.num_functions();
    let mut reference = prepared(&c, MassKind::Deactivate { threshold: 1e-4 });
    reference
        .factorize(&c.pattern, &c.values, context(&c))
        .unwrap();
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 7) % 5) as f64 * 1e-3).collect();
    let mut exact = rhs.clone();
    reference.solve(0, &mut exact).unwrap();
    let mut errors = Vec::new();
    for order in [0, 2, 8] {
        let mut m = prepared(&c, MassKind::Fmpm { order });
        m.factorize(&c.pattern, &c.values, context(&c)).unwrap();
        assert_keeps_row_sums(&c, &mut m, &format!("fmpm:{order}"));
        let mut a = rhs.clone();
        m.solve(0, &mut a).unwrap();
        // Compare on well-supported functions only (the series converges slowest
        // on nearly empty ones, where the reference deactivated a few).
        let err: f64 = (0..n)
            .filter(|&i| c.values[c.pattern.diagonal_position(i)] > 1e-3)
            .map(|i| (a[i] - exact[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        errors.push(err);
    }
    assert!(errors[1] < errors[0] && errors[2] < errors[1], "{errors:?}");
}

#[test]
fn deactivation_removes_small_rows_and_lumped_matches_row_sums() {
    let c = column_mass();
    let n = c.ps.num_functions();
    let active = (0..n)
        .filter(|&i| c.values[c.pattern.diagonal_position(i)] > 0.0)
        .count();
    // Particle masses 0.01: a threshold of 1e-4 on M_ii removes the nearly empty rows.
    let mut deact = prepared(&c, MassKind::Deactivate { threshold: 1e-4 });
    let r = deact.factorize(&c.pattern, &c.values, context(&c)).unwrap();
    assert!(r.deactivated > 0);
    assert_eq!(r.active + r.deactivated, active);
    let mut lumped = prepared(&c, MassKind::Lumped);
    lumped
        .factorize(&c.pattern, &c.values, context(&c))
        .unwrap();
    let mut rhs = vec![0.0; n];
    c.pattern.row_sums(&c.values, &mut rhs);
    lumped.solve(1, &mut rhs).unwrap();
    assert!(rhs.iter().all(|&y| y == 0.0 || (y - 1.0).abs() < 1e-14));
}

/// A threshold above every row's mass (`deactivate:1e300`) left no unknown: the
/// body hung still, judged stable. Now the factorisation refuses, naming the
/// largest `M_ii`; and the strategy's name shows the threshold in short form.
#[test]
fn a_threshold_that_deactivates_every_function_is_an_error() {
    let c = column_mass();
    let mut deact = prepared(&c, MassKind::Deactivate { threshold: 1e300 });
    match deact.factorize(&c.pattern, &c.values, context(&c)) {
        Err(MassError::NothingActive { threshold, largest }) => {
            assert_eq!(threshold, 1e300);
            assert!(largest > 0.0 && largest < 1.0, "{largest}");
        }
        other => panic!("expected NothingActive, got {:?}", other.err()),
    }
    assert_eq!(deact.spec(), "deactivate:1e300");
    assert_eq!(
        MassKind::Deactivate { threshold: 1e300 }.spec(),
        "deactivate:1e300"
    );
    assert_eq!(
        MassKind::Partial(LumpRule::Threshold(1e-300)).spec(),
        "partial:1e-300"
    );
}

/// `deactivate:1e400` parses to infinity: the message said the threshold must be
/// positive; every strategy parameter read as a number now says it is not finite
/// and gives the range.
#[test]
fn mass_parameters_that_are_not_finite_are_named_so() {
    let error = |spec: &str| MassKind::parse(spec).unwrap_err();
    assert_eq!(
        error("deactivate:1e400"),
        "`deactivate:1e400`: the threshold `1e400` is not finite (it reads as infinity: beyond ±1.8e308); give a positive finite number"
    );
    assert_eq!(
        error("partial:-1e400"),
        "`partial:-1e400`: the threshold `-1e400` is not finite (it reads as minus infinity: beyond ±1.8e308); give a positive finite number"
    );
    assert_eq!(
        error("deactivate:nan"),
        "`deactivate:nan`: the threshold `nan` is not a number; give a positive finite number"
    );
    for (spec, value) in [
        ("partial-coverage:1e400", "1e400"),
        ("extended:inf", "inf"),
        ("extended-hybrid:1e400:0.5", "1e400"),
        ("extended-hybrid:0.01:1e400", "1e400"),
        ("extended-hybrid-apic:0.01:0.5:1e999", "1e999"),
    ] {
        assert_eq!(
            error(spec),
            format!("`{spec}`: the coverage `{value}` is not finite (it reads as infinity: beyond ±1.8e308); give a number in (0, 1)")
        );
    }
    // A partial-lumping threshold of 1 or more lumps every row: `lumped` by
    // another name, refused (a user's `partial:2` ran as `lumped`).
    for spec in ["partial:1", "partial:2"] {
        assert!(
            error(spec).contains("at 1 or more it lumps every row but the largest, which is `lumped`: give a number below 1"),
            "{}",
            error(spec)
        );
    }
    assert!(MassKind::parse("partial:0.99").is_ok());
    // Finite values out of range keep their messages.
    assert_eq!(
        error("deactivate:-1"),
        "`deactivate:-1`: the threshold must be a positive number, got `-1`"
    );
    assert_eq!(
        error("extended:1.5"),
        "`extended:1.5`: the coverage must be a number in (0, 1), got `1.5`"
    );
}

#[test]
fn mass_kinds_parse() {
    assert_eq!(
        MassKind::parse("partial").unwrap(),
        MassKind::Partial(LumpRule::EmptyElement)
    );
    assert_eq!(
        MassKind::parse("partial:0.1").unwrap(),
        MassKind::Partial(LumpRule::Threshold(0.1))
    );
    assert_eq!(
        MassKind::parse("deactivate").unwrap(),
        MassKind::Deactivate { threshold: 1e-2 }
    );
    assert_eq!(MassKind::parse("default").unwrap(), MassKind::default());
    assert_eq!(
        MassKind::parse("extended:0.4").unwrap().spec(),
        "extended:0.4"
    );
    assert_eq!(
        MassKind::parse("fmpm:3").unwrap(),
        MassKind::Fmpm { order: 3 }
    );
    assert_eq!(
        MassKind::parse("extended-hybrid:0.02:0.75").unwrap(),
        MassKind::ExtendedHybrid {
            extend: 0.02,
            lump: 0.75,
            correction: super::Correction::InMass,
            walls: 0.0,
        }
    );
    assert_eq!(
        MassKind::parse("extended-hybrid-apic").unwrap(),
        MassKind::ExtendedHybrid {
            extend: 0.02,
            lump: 0.75,
            correction: super::Correction::Affine,
            walls: 0.0,
        }
    );
    assert_eq!(
        MassKind::parse("extended-hybrid-plain").unwrap(),
        MassKind::ExtendedHybrid {
            extend: 0.02,
            lump: 0.75,
            correction: super::Correction::None,
            walls: 0.0,
        }
    );
    let walls = MassKind::parse("extended-hybrid:0.02:0.75:0.5").unwrap();
    assert_eq!(
        walls,
        MassKind::ExtendedHybrid {
            extend: 0.02,
            lump: 0.75,
            correction: super::Correction::InMass,
            walls: 0.5,
        }
    );
    assert_eq!(walls.spec(), "extended-hybrid:0.02:0.75:0.5");
    assert_eq!(MassKind::parse(&walls.spec()).unwrap(), walls);
    assert!(MassKind::parse("extended-hybrid:0.02:0.75:1.5").is_err());
    assert!(MassKind::parse("extended-hybrid:0.02:0.75:0.5:0.5").is_err());
    assert_eq!(
        MassKind::parse("extended-hybrid:0.1,0.5").unwrap().spec(),
        "extended-hybrid:0.1:0.5"
    );
    assert!(MassKind::parse("extended-hybrid:0.5:0.1").is_err());
    assert!(MassKind::parse("extended-hybrid:0.5").is_err());
    for kind in [
        "partial-coverage:0.2",
        "fmpm:2",
        "extended",
        "extended-hybrid:0.25:0.5",
        "extended-hybrid-plain:0.25:0.5",
        "extended-hybrid-plain",
        "extended-hybrid-rpic:0.1:0.2",
        "lumped",
    ] {
        assert_eq!(MassKind::parse(kind).unwrap().spec(), kind);
        assert_eq!(MassKind::parse(kind).unwrap().build::<f64>().spec(), kind);
    }
    assert!(MassKind::parse("partial:-1").is_err());
    assert!(MassKind::parse("extended:1.5").is_err());
    assert!(MassKind::parse("fmpm").is_err());
    assert!(MassKind::parse("heavy").unwrap_err().contains("known:"));
}

/// A body in a small part of the mesh: the consistent and partially lumped
/// systems are factorised on their kept rows alone (`masked::Compact`), and solve
/// as the whole masked system does: against a dense solve of the masked system's
/// kept block (`modify_rows` over the whole pattern), to round-off.
#[test]
fn the_kept_rows_alone_solve_as_the_whole_masked_system() {
    let c = filled_to(0.5);
    let n = c.ps.num_functions();
    let mut rhs0 = vec![0.0; n];
    c.pattern.row_sums(&c.values, &mut rhs0);
    let kept: Vec<usize> = (0..n).filter(|&i| rhs0[i] > 0.0).collect();
    assert!(2 * kept.len() < n, "{} kept of {n}", kept.len());
    for kind in [
        MassKind::Partial(LumpRule::EmptyElement),
        MassKind::Consistent,
    ] {
        let mut m = prepared(&c, kind);
        m.classify(&c.pattern, &c.values, context(&c));
        if m.factorize(&c.pattern, &c.values, context(&c)).is_err() {
            // The consistent matrix of so few particles may be singular.
            assert_eq!(kind, MassKind::Consistent);
            continue;
        }
        // The whole masked system's kept block, dense.
        let lumped: Vec<bool> = if kind == MassKind::Consistent {
            vec![false; n]
        } else {
            c.touches_empty.clone()
        };
        let mut full = vec![0.0; c.pattern.nnz()];
        let mut add = vec![0.0; n];
        modify_rows_for_test(
            &c.pattern,
            &c.values,
            &lumped,
            |i| rhs0[i] <= 0.0,
            &mut add,
            &mut full,
        );
        let k = kept.len();
        let mut dense = nalgebra::DMatrix::<f64>::zeros(k, k);
        let (ptr, rows) = (c.pattern.col_ptr(), c.pattern.row_idx());
        let position = |i: usize| kept.binary_search(&i).ok();
        for col in 0..n {
            for e in ptr[col]..ptr[col + 1] {
                if let (Some(a), Some(b)) = (position(rows[e]), position(col)) {
                    dense[(a, b)] = full[e];
                    dense[(b, a)] = full[e];
                }
            }
        }
        let mut rhs = vec![0.0; n];
        for (i, r) in rhs.iter_mut().enumerate() {
            *r = (i as f64 * 0.37).sin();
        }
        let b = nalgebra::DVector::from_iterator(k, kept.iter().map(|&i| rhs[i]));
        let expected = dense.cholesky().unwrap().solve(&b);
        m.solve(0, &mut rhs).unwrap();
        for (q, &i) in kept.iter().enumerate() {
            assert!(
                (rhs[i] - expected[q]).abs() < 1e-9 * expected.amax(),
                "{kind:?}: y[{i}] = {} against {}",
                rhs[i],
                expected[q]
            );
        }
        for i in (0..n).filter(|i| kept.binary_search(i).is_err()) {
            assert_eq!(rhs[i], 0.0, "{kind:?}: a row without particles");
        }
    }
}

fn modify_rows_for_test(
    pattern: &SymmetricPattern,
    values: &[f64],
    lumped: &[bool],
    masked: impl Fn(usize) -> bool,
    diagonal_add: &mut [f64],
    out: &mut [f64],
) {
    super::masked::modify_rows(pattern, values, lumped, masked, 1.0, diagonal_add, out);
}

/// The default strategy lumps the row of a function sampled by less than one
/// particle, and keeps it lumped until the function is sampled by
/// `RESTORE_PARTICLE_COUNT` (hysteresis): a function at the edge of a vibrating body
/// whose count hovers about one would otherwise switch its row at every other step
/// (`extended::RESTORE_PARTICLE_COUNT`).
#[test]
fn a_row_lumped_for_too_few_particles_stays_lumped_until_well_sampled() {
    use super::extended::{MIN_PARTICLE_COUNT, RESTORE_PARTICLE_COUNT};
    let mut c = column_mass();
    let mut m = prepared(&c, MassKind::parse("default").unwrap());
    let lumped = |m: &mut Box<dyn MassStrategy<f64>>, c: &Column| {
        m.classify(&c.pattern, &c.values, context(c))
            .map(|l| l.to_vec())
            .unwrap_or_else(|| vec![false; c.ps.num_functions()])
    };
    // A well-covered, well-sampled function whose row is consistent.
    let start = lumped(&mut m, &c);
    let i = (0..c.ps.num_functions())
        .find(|&i| !start[i] && c.particle_count[i] > RESTORE_PARTICLE_COUNT + 1.0)
        .expect("an interior function");
    let well = c.particle_count[i];
    for (count, expected) in [
        (0.5 * MIN_PARTICLE_COUNT, true),
        (0.5 * (MIN_PARTICLE_COUNT + RESTORE_PARTICLE_COUNT), true),
        (0.99 * RESTORE_PARTICLE_COUNT, true),
        (well, false),
        (0.5 * (MIN_PARTICLE_COUNT + RESTORE_PARTICLE_COUNT), false),
        (0.5 * MIN_PARTICLE_COUNT, true),
    ] {
        c.particle_count[i] = count;
        assert_eq!(lumped(&mut m, &c)[i], expected, "sampled by {count}");
    }
}
