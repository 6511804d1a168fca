//! B3 (paper §4.1): the vibrating bar, large deformation, against the UL-FEM
//! reference.

use super::{builtin, opt, row, run_2d, sci, setup, Effort, Figure, Report, Table, Tally};
use crate::bases::BasisKind;
use crate::output::chart::{LinePlot, Series};
use crate::scene::Reference;
use crate::simulation::RunError;
use crate::studies::ulfem::{self, End, InitialVelocity, UlFemConfig, UlMass};
use std::path::Path;

/// B3 (paper §4.1): energies of the large-deformation bar against the UL-FEM
/// reference.
pub(super) fn b3(effort: Effort, cache: Option<&Path>) -> Result<Report, RunError> {
    let mut tally = Tally::default();
    let t_end = if effort == Effort::Quick { 2.0 } else { 20.0 };
    let base = builtin("bar-large")?;
    let (length, width) = (1.0, 0.05);
    let reference_config = UlFemConfig {
        length,
        // The same integrator and time step as the MPM run, so that the comparison
        // isolates the spatial discretisation (symplectic Euler's measured energy
        // oscillates by about ω Δt / 2 ≈ 1 % here, in both); 100 elements keep its
        // Courant number at 0.71.
        elements: 100,
        young: base.material.young,
        density: base.material.density,
        gravity: 0.0,
        left: End::Fixed,
        right: End::Fixed,
        dt: 5e-3,
        mass: UlMass::Lumped,
    };
    let reference = ulfem::cached_reference_history(
        cache,
        &reference_config,
        InitialVelocity::SineMode { v0: 0.1 },
        &[0.5],
        20,
        t_end,
    )
    .map_err(|e| RunError::Reference(format!("UL-FEM reference: {e}")))?;
    // Per unit thickness: the 1D energies are per unit cross-section.
    let ref_energy: Vec<(f64, f64, f64)> = reference
        .records
        .iter()
        .map(|r| {
            (
                r.time,
                width * r.energies.kinetic,
                width * r.energies.total(),
            )
        })
        .collect();
    let ref_at = |t: f64| -> (f64, f64) {
        let k = ref_energy
            .iter()
            .position(|r| r.0 >= t - 1e-12)
            .unwrap_or(ref_energy.len() - 1);
        (ref_energy[k].1, ref_energy[k].2)
    };
    let e_ref0 = ref_energy[0].2;
    let mut table = Table {
        title: format!("B3: bar L = 1, W = 0.05, v0 = 0.1 (7 % strain), dt = 5e-3, to t = {t_end}"),
        columns: vec![
            "basis",
            "functions",
            "particles",
            "E_u at end",
            "total energy first off UL-FEM by 1 % at t",
            "kinetic energy first off by 1 % of E(0) at t",
            "energy change at end",
            "stable",
        ],
        rows: Vec::new(),
    };
    let mut figures = Vec::new();
    let mut energy_plot = LinePlot::new(
        format!("B3: energies of the large-deformation bar to t = {t_end}"),
        "time (s)",
        "energy (J/m)",
    );
    let mut tracked_plot = LinePlot::new(
        "B3: displacement of the particle nearest (L/2, W/2)",
        "time (s)",
        "displacement u_x (m)",
    );
    energy_plot = energy_plot.with_series(Series::line(
        "UL-FEM total",
        ref_energy.iter().map(|r| (r.0, r.2)),
    ));
    energy_plot = energy_plot.with_series(Series::line(
        "UL-FEM kinetic",
        ref_energy.iter().map(|r| (r.0, r.1)),
    ));
    let mut findings = Vec::new();
    {
        let basis = BasisKind::Ps;
        let mut s = setup(base.with_basis(basis))?;
        s.time.t_end = t_end;
        let run = run_2d(&mut tally, &s, 20)?;
        let sum = &run.outcome.summary;
        // First time the kinetic (k = 0) or total (k = 1) energy is off by 1 % of E(0).
        let first_off = |k: usize| {
            run.energy
                .iter()
                .find(|r| {
                    let (kinetic, total) = ref_at(r.0);
                    let d = if k == 0 { r.1 - kinetic } else { r.3 - total };
                    d.abs() > 0.01 * e_ref0
                })
                .map_or("never".to_string(), |r| format!("{:.1}", r.0))
        };
        let (kinetic_off, total_off) = (first_off(0), first_off(1));
        let change = (sum.energy_final - sum.energy_initial) / sum.energy_initial;
        table.rows.push(row![
            basis.name(),
            sum.functions.to_string(),
            sum.particles.to_string(),
            opt(sum.error),
            total_off,
            kinetic_off,
            format!("{:+.2} %", 100.0 * change),
            sum.stable.to_string(),
        ]);
        let name = basis.name().to_uppercase();
        energy_plot = energy_plot.with_series(Series::line(
            format!("{name} total"),
            run.energy.iter().map(|r| (r.0, r.3)),
        ));
        energy_plot = energy_plot.with_series(Series::line(
            format!("{name} kinetic"),
            run.energy.iter().map(|r| (r.0, r.1)),
        ));
        if let Some(t) = run.outcome.tracked.first() {
            if basis == BasisKind::Ps {
                tracked_plot = tracked_plot.with_series(Series::line(
                    "exact",
                    t.time
                        .iter()
                        .zip(&t.exact_displacement)
                        .step_by(4)
                        .map(|(t, u)| (*t, u[0])),
                ));
            }
            tracked_plot = tracked_plot.with_series(Series::line(
                name.clone(),
                t.time
                    .iter()
                    .zip(&t.displacement)
                    .step_by(4)
                    .map(|(t, u)| (*t, u[0])),
            ));
        }
        if basis == BasisKind::Ps {
            findings.push(format!(
                "PS total energy changes by {:+.2} % over t = {t_end}",
                100.0 * change
            ));
        }
    }
    // Small-amplitude check: v0 = 0.001 against the harmonic oscillator.
    let mut small = base.clone();
    small.reference = Some(Reference::VibratingBar { v0: 0.001 });
    small.time.t_end = t_end.min(5.0);
    let s = tally.run(&small, &mut |_| {})?;
    let amplitude = 0.001 / (std::f64::consts::PI * (50.0f64 / 25.0).sqrt() / length);
    let volume = length * width;
    let relative = s.error.unwrap_or(f64::NAN) / (amplitude * (0.5 * volume).sqrt());
    findings.push(format!(
        "small amplitude (v0 = 0.001): E_u / (amplitude · sqrt(V/2)) = {} at t = {}",
        sci(relative),
        small.time.t_end
    ));
    figures.push(Figure {
        file: "b3-energy.svg".into(),
        plot: energy_plot,
    });
    figures.push(Figure {
        file: "b3-tracked.svg".into(),
        plot: tracked_plot,
    });
    Ok(Report {
        benchmark: "b3",
        runs: tally,
        tables: vec![table],
        figures,
        findings,
    })
}
