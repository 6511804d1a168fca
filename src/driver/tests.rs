use super::phases::update_deformation_gradient;
use crate::material::{Elastic, Material, NeoHookean};
use nalgebra::Matrix2;

/// A rigid rotation at angular velocity ω has `∇v = [[0, −ω], [ω, 0]]`. The full
/// update turns `F` with the body and leaves a hyperelastic material unstressed;
/// the symmetric-part update of paper eq. (24) leaves `F = I` behind.
#[test]
fn rigid_rotation_creates_no_stress() {
    let omega = 1.0;
    let (steps, dt) = (10_000, 1e-4); // one radian in total
    let grad_v = Matrix2::new(0.0, -omega, omega, 0.0);
    let sym = (grad_v + grad_v.transpose()) * 0.5;
    let (mut full, mut symmetric) = (Matrix2::<f64>::identity(), Matrix2::<f64>::identity());
    for _ in 0..steps {
        full = update_deformation_gradient(&full, &grad_v, dt);
        symmetric = update_deformation_gradient(&symmetric, &sym, dt);
    }
    let theta: f64 = omega * dt * steps as f64;
    let rotation = Matrix2::new(theta.cos(), -theta.sin(), theta.sin(), theta.cos());
    assert!((full - rotation).norm() < 1e-3, "full update: {full}");
    assert!(
        (symmetric - rotation).norm() > 0.5,
        "the symmetric update misses the rotation"
    );
    let neo = NeoHookean::new(Elastic::new(1e4, 0.3, 1.0).unwrap(), 2);
    let sigma: Matrix2<f64> = neo.stress(&full);
    // Forward Euler stretches by (1 + ω²Δt²)^(n/2): stress of order E ω² Δt t.
    assert!(sigma.norm() < 1e4 * 2e-4, "stress {sigma}");
}
