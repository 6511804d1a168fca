//! Every built-in scene runs (shortened) and its summary is pinned, one snapshot per
//! scene: error at the end, energies at a few times, and a tracked particle's
//! displacement and velocity. Values are pinned to four significant digits, and a
//! component below 1e-10 of its vector's size (round-off, such as the vertical
//! displacement of a bar that only stretches) is pinned as 0.

use psmpm::scene::{Scene, BUILTIN};
use psmpm::simulation::{build_effects, run_1d, run_2d};

fn sig(x: f64) -> String {
    format!("{x:.4e}")
}

/// The components of `v`, with round-off (below 1e-10 of the largest) shown as 0.
fn components(v: &[f64]) -> String {
    let size = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let shown: Vec<String> = v
        .iter()
        .map(|&x| {
            if x.abs() <= 1e-10 * size {
                "0".to_string()
            } else {
                sig(x)
            }
        })
        .collect();
    format!("({})", shown.join(", "))
}

#[test]
fn builtin_scene_summaries() {
    for (name, _, _) in BUILTIN {
        let mut s = Scene::builtin(name).unwrap();
        s.time.t_end = match name {
            "vibrating-bar-thesis" => 0.002,
            "axis-aligned" => 0.0045,
            n if n.starts_with("vibrating") || n.starts_with("bar") => 1.0,
            _ => 0.05,
        };
        s.output.tracked = vec![match name {
            _ if s.dim == 1 => vec![12.5],
            "axis-aligned" => vec![0.25, 0.47],
            "bar-large" => vec![0.5, 0.025],
            "column-large" | "column-damped" => vec![0.05, 0.5],
            n if n.starts_with("vibrating") || n.starts_with("bar") => vec![12.5, 1.0],
            _ => vec![1.0, 12.5],
        }];
        let mut energies = Vec::new();
        let steps = s.steps();
        let mut record = |r: &psmpm::driver::StepReport| {
            if r.step % (steps / 4) == 0 {
                energies.push(format!("t={:.3} E={}", r.time, sig(r.total_energy())));
            }
        };
        let (summary, tracked) = if s.dim == 2 {
            let o = run_2d(&s, &mut record).unwrap();
            (o.summary, o.tracked)
        } else {
            let o = run_1d(&s, &mut record).unwrap();
            (o.summary, o.tracked)
        };
        let t = &tracked[0];
        let (u, v) = (t.displacement.last().unwrap(), t.velocity.last().unwrap());
        let out = format!(
            "{name}: {} {} functions={} particles={} steps={} error={} stable={}\n  {}\n  tracked x0=({:.3}, {:.3}) u={} v={}\n",
            summary.basis,
            summary.mass,
            summary.functions,
            summary.particles,
            summary.steps,
            sig(summary.error.unwrap()),
            summary.stable,
            energies.join(" "),
            t.x0[0],
            t.x0[1],
            components(u),
            components(v),
        );
        insta::assert_snapshot!(format!("scene_{name}"), out);
    }
}

/// Only the effects a scene declares are assembled: the bar declares none, the column
/// gravity; an effect in the driver's list is called exactly once per step.
#[test]
fn only_declared_effects_are_evaluated() {
    use psmpm::effect::{Effect, StepState};
    use psmpm::particles::Particles;
    use std::sync::atomic::{AtomicUsize, Ordering};

    let none = Particles::<f64, 2>::new(Vec::new(), Vec::new(), 1.0);
    let mesh = psmpm_basis::mesh::generators::block_grid(0.0, 1.0, 0.0, 1.0, 1, 1).unwrap();
    let basis = psmpm_basis::basis::linear::Linear::<f64>::new(mesh);
    let bar = Scene::builtin("vibrating-bar").unwrap();
    assert!(build_effects(&bar, &none, &[], None, &basis)
        .unwrap()
        .is_empty());
    let column = Scene::builtin("column-small").unwrap();
    let effects = build_effects(&column, &none, &[], None, &basis).unwrap();
    let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
    assert_eq!(names, ["gravity"]);

    static CALLS: AtomicUsize = AtomicUsize::new(0);
    struct Counting;
    impl Effect<f64, 1> for Counting {
        fn name(&self) -> &'static str {
            "counting"
        }
        fn add_forces(&self, _: &Particles<f64, 1>, _: &StepState<f64, 1>, _: &mut [Vec<f64>]) {
            CALLS.fetch_add(1, Ordering::SeqCst);
        }
    }
    use nalgebra::Vector1;
    use psmpm::basis::basis::linear1d::Linear1d;
    use psmpm::basis::Mesh1d;
    use psmpm::driver::Driver;
    use psmpm::mass::Lumped;
    use psmpm::material::{Elastic, LinearElastic};
    let particles = Particles::new(
        (0..8)
            .map(|i| Vector1::new(0.0625 + 0.125 * i as f64))
            .collect(),
        vec![0.125; 8],
        1.0,
    );
    let material = LinearElastic::new(Elastic::new(1.0, 0.0, 1.0).unwrap(), 1);
    let basis = Linear1d::<f64>::new(Mesh1d::uniform(0.0, 1.0, 4).unwrap());
    let mut d: Driver<f64, 1, _, Lumped<f64>, _> = Driver::new(
        basis,
        particles,
        material,
        Lumped::default(),
        &[],
        vec![Box::new(Counting)],
        1e-3,
    )
    .unwrap();
    for _ in 0..5 {
        d.step().unwrap();
    }
    assert_eq!(CALLS.load(Ordering::SeqCst), 5);
}

/// Every scene file the docs give as an example (`docs/examples`) parses and
/// validates: a figure in the docs is only as good as the file behind its command.
#[test]
fn every_documented_example_parses() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/examples");
    let mut count = 0;
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    for path in paths {
        let text = std::fs::read_to_string(&path).unwrap();
        if let Err(e) = Scene::from_toml(&text, &path.display().to_string()) {
            panic!("{e}");
        }
        count += 1;
    }
    assert!(count >= 31, "{count} examples");
}
