//! Benchmark B1: L² projection of sin(πx) sin(πy) on the unit square
//! (thesis Tables 3.1–3.2, paper Fig. 8).

use psmpm::bases::BasisKind;
use psmpm::studies::projection::{default_levels, unit_square_study, MassOption, StudyRow};

fn study(kind: BasisKind, mass: MassOption) -> Vec<StudyRow> {
    let levels = default_levels(kind, 4).unwrap();
    unit_square_study::<f64>(kind, mass, &levels).unwrap()
}

/// Rounds to `digits` significant digits for snapshots that are stable across machines.
fn sig(x: f64, digits: usize) -> String {
    format!("{:.*e}", digits - 1, x)
}

fn render(rows: &[StudyRow]) -> String {
    let mut out = String::new();
    for r in rows {
        out.push_str(&format!(
            "{:>2} {:<10} n={:>3} functions={:>4} error={} order={} error_dx={} order_dx={}\n",
            r.basis,
            r.mass,
            r.n.unwrap(),
            r.functions,
            sig(r.error, 3),
            r.order.map_or("-".into(), |o| format!("{o:.2}")),
            sig(r.error_dx, 3),
            r.order_dx.map_or("-".into(), |o| format!("{o:.2}")),
        ));
    }
    out
}

#[test]
fn consistent_ps_is_third_order_and_pl_second_order() {
    let ps = study(BasisKind::Ps, MassOption::Consistent);
    let pl = study(BasisKind::Pl, MassOption::Consistent);
    let ps_order = ps.last().unwrap().order.unwrap();
    let pl_order = pl.last().unwrap().order.unwrap();
    assert!(ps_order >= 2.9, "PS consistent order {ps_order}");
    assert!(pl_order >= 1.9, "PL consistent order {pl_order}");
    // Gradients: one order less.
    assert!(ps.last().unwrap().order_dx.unwrap() >= 1.9);
    assert!(pl.last().unwrap().order_dx.unwrap() >= 0.9);
    // Every level improves.
    for rows in [&ps, &pl] {
        for w in rows.windows(2) {
            assert!(w[1].error < w[0].error);
        }
    }
}

#[test]
fn lumped_projection_is_first_order_and_ps_gradient_does_not_converge() {
    let ps = study(BasisKind::Ps, MassOption::Lumped);
    let pl = study(BasisKind::Pl, MassOption::Lumped);
    for rows in [&ps, &pl] {
        let order = rows.last().unwrap().order.unwrap();
        assert!(
            (0.8..1.5).contains(&order),
            "{} lumped order {order}",
            rows[0].basis
        );
    }
    // Paper Fig. 8: the lumped PS derivative error stalls.
    let dx_order = ps.last().unwrap().order_dx.unwrap();
    assert!(dx_order.abs() < 0.3, "lumped PS ∂f/∂x order {dx_order}");
}

#[test]
fn projection_table_snapshot() {
    let mut table = String::new();
    for kind in [BasisKind::Ps, BasisKind::Pl] {
        for mass in [MassOption::Consistent, MassOption::Lumped] {
            table.push_str(&render(&study(kind, mass)));
        }
    }
    insta::assert_snapshot!(table);
}

#[test]
fn f32_projection_follows_f64_down_to_its_precision_floor() {
    let levels = default_levels(BasisKind::Ps, 4).unwrap();
    let single = unit_square_study::<f32>(BasisKind::Ps, MassOption::Consistent, &levels).unwrap();
    let double = unit_square_study::<f64>(BasisKind::Ps, MassOption::Consistent, &levels).unwrap();
    // f32 round-off in the solve is about 1e-6 relative to |f| ~ 1: above that floor
    // the errors agree, and the f32 error never drops far below it.
    for (s, d) in single.iter().zip(&double) {
        let floor = 1e-5;
        assert!(
            (s.error - d.error).abs() <= 1e-2 * d.error + floor,
            "n = {:?}: f32 {} vs f64 {}",
            s.n,
            s.error,
            d.error
        );
    }
}
