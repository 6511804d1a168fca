//! The seeds' benchmarks B2–B5 in their quick form (coarse grids, short runs): the
//! tables of `mpm-cli reproduce --quick` pinned, and the claims of
//! `docs/results.md` that hold at this size checked.

use psmpm::mass::MassKind;
use psmpm::scene::Scene;
use psmpm::simulation::run;
use psmpm::studies::reproduction::{reproduce, Effort, STUDIES};

#[test]
fn quick_reproductions_are_pinned() {
    for name in STUDIES {
        // No cache: the quick UL-FEM references take milliseconds to compute.
        let report = reproduce(name, Effort::Quick, None).unwrap();
        let text: String = report
            .tables
            .iter()
            .map(|t| t.markdown())
            .chain(report.findings.iter().map(|f| format!("- {f}\n")))
            .collect();
        insta::assert_snapshot!(format!("quick_{name}"), text);
        // What `reproduce --strict` judges: the runs made and those failed or
        // unstable (b4: the consistent mass on the finest mesh and three runs with
        // few particles per element, b5b: the consistent mass on 1 × 8; their
        // tables show `false` in `stable`).
        let (total, failed) = match name {
            "b2" => (8, 0),
            "b3" => (2, 0),
            "b4" => (16, 4),
            "b5b" => (8, 1),
            "b5c" => (2, 0),
            other => panic!("unknown study {other}"),
        };
        assert_eq!(
            (report.runs.total, report.runs.failed),
            (total, failed),
            "{name}"
        );
        let unstable_rows = report
            .tables
            .iter()
            .filter_map(|t| {
                t.columns
                    .iter()
                    .position(|c| *c == "stable")
                    .map(|i| (t, i))
            })
            .flat_map(|(t, i)| t.rows.iter().filter(move |r| r[i].text == "false"))
            .count();
        assert_eq!(unstable_rows, failed, "{name}: rows marked unstable");
        for figure in &report.figures {
            assert!(!figure.plot.series.is_empty(), "{name}: {}", figure.file);
        }
    }
}

/// Issue: "lumped and partially lumped PS on B5b 1 × 8 stay stable to t = 2.5", and
/// the consistent mass on that grid is reported as it is (here: unstable, with the
/// step and the reason), never a panic.
#[test]
fn column_large_on_1x8_lumped_and_partial_stay_stable_consistent_fails_cleanly() {
    let mut base = Scene::builtin("column-large").unwrap();
    base.set_blocks(1, 10).unwrap(); // 1 × 8 blocks on the column, two half rows above
    for mass in ["lumped", "partial"] {
        let mut s = base.clone();
        s.mass = MassKind::parse(mass).unwrap();
        let summary = run(&s, &mut |_| {}).unwrap();
        assert_eq!(summary.t_end, 2.5, "{mass}");
        assert!(summary.stable, "{mass}: {summary:?}");
    }
    let summary = run(&base, &mut |_| {}).unwrap();
    assert!(!summary.stable);
    let failure = summary.failure.unwrap();
    assert!(
        failure.starts_with("step ") && failure.contains("`extended-hybrid`"),
        "{failure}"
    );
    assert!(summary.t_end < 0.2, "fails early: {}", summary.t_end);
}
