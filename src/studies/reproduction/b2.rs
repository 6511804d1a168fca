//! B2 (thesis §4.1): the vibrating bar, small deformation.

use super::{builtin, log_log, opt, order, row, sci, setup, Effort, Figure, Report, Table, Tally};
use crate::bases::BasisKind;
use crate::output::chart::Series;
use crate::simulation::RunError;
use crate::studies::published::THESIS_TABLES_4_2_AND_4_3;

/// B2 (thesis §4.1): E_u of the thesis variant against Tables 4.2–4.3, and orders of
/// the default variant.
pub(super) fn b2(effort: Effort) -> Result<Report, RunError> {
    let mut tally = Tally::default();
    let printed = &THESIS_TABLES_4_2_AND_4_3;
    let limit = if effort == Effort::Quick { 5 } else { 33 };
    let mut table = Table {
        title: "B2: E_u at t_end, thesis variant (centroids, Delaunay blocks, 1999 steps) and default variant (incentres, 4-triangle blocks, 2000 steps)".into(),
        columns: vec!["basis", "n_x", "functions", "thesis", "thesis variant", "default variant", "default order"],
        rows: Vec::new(),
    };
    let mut series: Vec<Series> = Vec::new();
    for basis in [BasisKind::Ps, BasisKind::Pl] {
        let (mut ours, mut theirs) = (Vec::new(), Vec::new());
        let mut previous: Option<(f64, f64)> = None;
        for &(_, n_x, thesis) in printed.iter().filter(|p| p.0 == basis && p.1 <= limit) {
            let h = 25.0 / (n_x - 1) as f64;
            let mut variant = builtin("vibrating-bar-thesis")?;
            variant.basis = basis;
            setup(variant.set_blocks(n_x - 1, 1))?;
            let thesis_run = tally.run(&variant, &mut |_| {})?;
            let mut default = builtin("vibrating-bar")?;
            default.basis = basis;
            setup(default.set_blocks(n_x - 1, 1))?;
            default.set_particles_per_block([16, 14]);
            default.set_dt(1e-5);
            default.time.t_end = 0.02;
            let default_run = tally.run(&default, &mut |_| {})?;
            let e = default_run.error.unwrap_or(f64::NAN);
            table.rows.push(row![
                basis.name(),
                n_x.to_string(),
                thesis_run.functions.to_string(),
                sci(thesis),
                opt(thesis_run.error),
                sci(e),
                previous.map_or("-".into(), |(h0, e0)| order(e0, e, h0, h)),
            ]);
            previous = Some((h, e));
            ours.push((h, thesis_run.error.unwrap_or(f64::NAN)));
            theirs.push((h, thesis));
        }
        series.push(Series::line_and_markers(
            format!("{} (ours)", basis.name().to_uppercase()),
            ours,
        ));
        series.push(Series::markers(
            format!("{} (thesis)", basis.name().to_uppercase()),
            theirs,
        ));
    }
    let mut plot = log_log(
        "B2: vibrating bar, E_u at t = 0.02 against block width",
        "block width h (m)",
        "E_u (m²)",
    );
    for s in series {
        plot = plot.with_series(s);
    }
    Ok(Report {
        benchmark: "b2",
        runs: tally,
        tables: vec![table],
        figures: vec![Figure {
            file: "b2-convergence.svg".into(),
            plot,
        }],
        findings: Vec::new(),
    })
}
