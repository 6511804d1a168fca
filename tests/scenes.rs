//! Every built-in scene runs (shortened) and its summary is pinned: error at the end,
//! energies at a few times, and a tracked particle's displacement and velocity.

use psmpm::scene::{run_1d, run_2d, Scene, BUILTIN};

fn sig(x: f64) -> String {
    format!("{x:.4e}")
}

#[test]
fn builtin_scene_summaries() {
    let mut out = String::new();
    for (name, _) in BUILTIN {
        let mut s = Scene::builtin(name).unwrap();
        s.t_end = if name.starts_with("vibrating") {
            1.0
        } else {
            0.05
        };
        s.tracked = vec![if s.dim == 1 {
            [12.5, 0.0]
        } else if name.starts_with("vibrating") {
            [12.5, 1.0]
        } else {
            [1.0, 12.5]
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
        out.push_str(&format!(
            "{name}: {} {} functions={} particles={} steps={} error={} stable={}\n  {}\n  tracked x0=({:.3}, {:.3}) u=({}, {}) v=({}, {})\n",
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
            sig(u[0]),
            sig(u[1]),
            sig(v[0]),
            sig(v[1]),
        ));
    }
    insta::assert_snapshot!(out);
}
