//! Grid crossing on the vibrating bar's demo grids (thesis §4.1): PL 12 × 1 blocks
//! (38 functions) and PS 4 × 1 blocks (42 functions), 6 × 96 particles in total.
//!
//! Roughness of a particle's velocity history: the RMS of its second differences
//! `v_{n+1} − 2 v_n + v_{n−1}`, divided by that of the smooth exact motion
//! (`≈ ω² Δt² |v|`). A smooth history scores about 1; jumps from particles
//! crossing element edges (PL gradients jump there) score far more. The score of a
//! run is the largest over all particles.

use psmpm::bases::BasisKind;
use psmpm::scene::{Reference, Scene};
use psmpm::simulation::run_2d;

fn roughness(basis: BasisKind, v0: f64) -> f64 {
    let mut s = Scene::builtin("vibrating-bar").unwrap();
    s.basis = basis;
    s.reference = Some(Reference::VibratingBar { v0 });
    s.set_dt(1e-3);
    s.time.t_end = 5.0;
    let (blocks, per_block) = match basis {
        BasisKind::Pl => ((12, 1), [8, 6]),
        _ => ((4, 1), [24, 6]),
    };
    s.set_blocks(blocks.0, blocks.1).unwrap();
    s.set_particles_per_block(per_block);
    // Track every particle of the middle row.
    s.output.tracked = (0..96)
        .map(|i| vec![(i as f64 + 0.5) * 25.0 / 96.0, 2.0 * 3.5 / 6.0])
        .collect();
    let out = run_2d(&s, &mut |_| {}).unwrap();
    let omega = std::f64::consts::PI * 10.0 / 25.0;
    let mut worst = 0.0f64;
    for t in &out.tracked {
        let v: Vec<f64> = t.velocity.iter().map(|v| v[0]).collect();
        let second: Vec<f64> = v.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
        let rms = (second.iter().map(|d| d * d).sum::<f64>() / second.len() as f64).sqrt();
        let smooth_rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
            * (omega * 1e-3f64).powi(2);
        if smooth_rms > 0.0 {
            worst = worst.max(rms / smooth_rms);
        }
    }
    worst
}

#[test]
fn ps_is_free_of_the_grid_crossing_noise_pl_shows() {
    let (pl, ps) = (roughness(BasisKind::Pl, 0.1), roughness(BasisKind::Ps, 0.1));
    let (pl_small, ps_small) = (
        roughness(BasisKind::Pl, 0.025),
        roughness(BasisKind::Ps, 0.025),
    );
    println!(
        "v0 = 0.1: PL {pl:.3e}, PS {ps:.3e}; v0 = 0.025: PL {pl_small:.3e}, PS {ps_small:.3e}"
    );
    assert!(pl > 10.0 * ps, "PL roughness {pl} vs PS {ps}");
    assert!(ps < 3.0, "PS velocity is smooth: {ps}");
    assert!(
        pl_small < 3.0,
        "with v0 = 0.025 no particle crosses an edge: {pl_small}"
    );
    insta::assert_snapshot!(format!(
        "v0=0.1: pl {pl:.2e} ps {ps:.2e}\nv0=0.025: pl {pl_small:.2e} ps {ps_small:.2e}\n"
    ));
}
