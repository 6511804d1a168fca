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

/// A block `[0.25, 0.75]²` in a PS mesh of 4 × 4 blocks (its edge functions are
/// covered below 0.75, so the hybrid lumps their rows; every element it occupies
/// is filled, so their particles pin affine fields), unstressed, with velocity `v`.
fn hybrid_block(
    mass: &str,
    v: impl Fn(nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64>,
) -> HybridDriver {
    hybrid_block_with(mass, v, &[])
}

type HybridDriver = super::Driver<
    f64,
    2,
    psmpm_basis::basis::powell_sabin::PowellSabin<f64>,
    Box<dyn crate::mass::MassStrategy<f64>>,
    NeoHookean,
>;

/// [`hybrid_block`] with `extra` particles (of the block's volume) beside it.
fn hybrid_block_with(
    mass: &str,
    v: impl Fn(nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64>,
    extra: &[nalgebra::Vector2<f64>],
) -> HybridDriver {
    let h = 0.05;
    let x: Vec<_> = lattice(10, h, (0.25, 0.25))
        .chain(extra.iter().copied())
        .collect();
    ps_driver(1.0, 4, x, h * h, 1e3, mass, v)
}

/// An `n × n` lattice of spacing `h`, its cells' centres, from `corner`.
fn lattice(n: usize, h: f64, corner: (f64, f64)) -> impl Iterator<Item = nalgebra::Vector2<f64>> {
    (0..n * n).map(move |p| {
        nalgebra::Vector2::new(
            corner.0 + ((p % n) as f64 + 0.5) * h,
            corner.1 + ((p / n) as f64 + 0.5) * h,
        )
    })
}

/// A PS driver on `[0, extent]²` in `blocks × blocks` blocks, neo-Hookean
/// (E = 1e4, ν = 0.3, `density`), with particles at `x` of volume `volume` each,
/// velocity `v`, and the mass strategy `mass`.
fn ps_driver(
    extent: f64,
    blocks: usize,
    x: Vec<nalgebra::Vector2<f64>>,
    volume: f64,
    density: f64,
    mass: &str,
    v: impl Fn(nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64>,
) -> HybridDriver {
    use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
    let mesh = psmpm_basis::mesh::generators::block_grid(0.0, extent, 0.0, extent, blocks, blocks)
        .unwrap();
    let basis = PowellSabin::<f64>::new(mesh, SplitPoint::Incentre).unwrap();
    let np = x.len();
    let constants = Elastic::new(1e4, 0.3, density).unwrap();
    let mut particles = crate::particles::Particles::new(x, vec![volume; np], constants.density);
    for p in 0..np {
        particles.v[p] = v(particles.x[p]);
    }
    let strategy = crate::mass::MassKind::parse(mass).unwrap().build();
    super::Driver::new(
        basis,
        particles,
        NeoHookean::new(constants, 2),
        strategy,
        &[],
        Vec::new(),
        1e-9,
    )
    .unwrap()
}

/// `v̂(x_p) = Σ_i v̂_i phi_i(x_p)` at every particle, from the last step's evaluations.
fn projected_at_particles<B, M>(
    driver: &super::Driver<f64, 2, B, M, NeoHookean>,
) -> Vec<nalgebra::Vector2<f64>>
where
    B: psmpm_basis::Basis<f64, 2>,
    M: crate::mass::MassStrategy<f64>,
{
    (0..driver.particles.len())
        .map(|p| {
            let mut v = nalgebra::Vector2::zeros();
            for (s, i) in driver.evals.entries(p) {
                for k in 0..2 {
                    v[k] += driver.velocity[k][i] * driver.evals.phi[s];
                }
            }
            v
        })
        .collect()
}

/// The largest `|v̂(x_p) − v(x_p)|` after one step from `v̂ⁿ` holding the
/// coefficients of `v` (`c_i = v(ξ_i)`, linear precision), with unstressed
/// particles (no acceleration), and whether rows were lumped.
fn projection_error(
    mass: &str,
    field: fn(nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64>,
) -> (f64, bool) {
    let (errors, lumped) = projection_errors(mass, field, &[]);
    (errors.into_iter().fold(0.0, f64::max), lumped)
}

/// [`projection_error`] per particle, with `extra` particles beside the block.
fn projection_errors(
    mass: &str,
    field: fn(nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64>,
    extra: &[nalgebra::Vector2<f64>],
) -> (Vec<f64>, bool) {
    use psmpm_basis::Basis;
    let mut driver = hybrid_block_with(mass, field, extra);
    for i in 0..driver.basis.num_functions() {
        let xi = driver.basis.function_point(i);
        let v = field(nalgebra::Vector2::new(xi[0], xi[1]));
        for k in 0..2 {
            driver.velocity[k][i] = v[k];
        }
    }
    driver.velocity_known = true;
    let dt = driver.dt();
    driver.step().unwrap();
    let at = projected_at_particles(&driver);
    let errors = (0..at.len())
        .map(|p| (at[p] - field(driver.particles.x[p] - at[p] * dt)).norm())
        .collect();
    (errors, driver.report().mass_report.lumped_rows > 0)
}

/// The corrections of lumped rows: a rigid motion projects exactly with the
/// affine-preserving lumping in the mass (the default), the affine momentum
/// correction (`phases::Affine`, APIC) and the rigid one (RPIC), a general affine
/// field with the first two only; without a correction both are missed by
/// percents.
#[test]
fn the_corrections_project_rigid_and_affine_fields_exactly_through_lumped_rows() {
    fn rigid(x: nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64> {
        nalgebra::Vector2::new(0.3 - 2.0 * (x.y - 0.5), 0.1 + 2.0 * (x.x - 0.5))
    }
    fn affine(x: nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64> {
        rigid(x) + nalgebra::Vector2::new(0.5 * x.x, -0.3 * x.y + 0.2 * x.x)
    }
    for (mass, field, exact) in [
        ("extended-hybrid-rpic", rigid as fn(_) -> _, true),
        ("extended-hybrid-apic", rigid, true),
        ("extended-hybrid-apic", affine, true),
        ("extended-hybrid", rigid, true),
        ("extended-hybrid", affine, true),
        ("extended-hybrid-rpic", affine, false),
        ("extended-hybrid-plain", rigid, false),
        ("extended-hybrid-plain", affine, false),
    ] {
        let (worst, lumped) = projection_error(mass, field);
        assert!(lumped, "{mass}: rows are lumped");
        if exact {
            assert!(worst < 1e-9, "{mass}: {worst:e}");
        } else {
            assert!(worst > 1e-3, "{mass}: {worst:e}");
        }
    }
}

/// An element holding one or two particles does not pin an affine field by
/// itself; beside elements that do (a body's corner sweeping the mesh), their
/// particles pin it, and the default projects affine fields exactly there too
/// (before, such an element kept the share `θ` of plain lumping, and a spinning
/// square lost a tenth of its angular momentum, `docs/stability.md`). Two
/// particles in an element that shares no vertex with the block keep the share,
/// and the projection misses the field (here by about 2 %, in the block too:
/// their functions are extended through its functions).
#[test]
fn elements_with_too_few_particles_beside_the_body_project_affine_fields_exactly() {
    fn rigid(x: nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64> {
        nalgebra::Vector2::new(-2.0 * (x.y - 0.5), 2.0 * (x.x - 0.5))
    }
    fn affine(x: nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64> {
        rigid(x) + nalgebra::Vector2::new(0.5 * x.x + 0.1, -0.3 * x.y + 0.2 * x.x)
    }
    let v = nalgebra::Vector2::new;
    // One particle in the left triangle of block (3, 1), two in the lower one of
    // block (1, 3): each element shares two vertices with the block's elements.
    let beside = [v(0.8, 0.4), v(0.35, 0.8), v(0.45, 0.79)];
    // Two in the upper triangle of block (3, 3), which shares none.
    let apart = [v(0.86, 0.93), v(0.89, 0.95)];
    for field in [rigid as fn(_) -> _, affine] {
        let (errors, lumped) = projection_errors("extended-hybrid", field, &beside);
        assert!(lumped, "rows are lumped");
        let worst = errors.iter().fold(0.0, |a: f64, &b| a.max(b));
        assert!(
            worst < 1e-9,
            "the block and the particles beside it: {worst:e}"
        );
        let (errors, _) = projection_errors("extended-hybrid", field, &apart);
        let worst = errors.iter().fold(0.0, |a: f64, &b| a.max(b));
        assert!(
            worst > 1e-6 && worst < 0.1,
            "two particles apart: {worst:e}"
        );
    }
}

/// The momentum correction enters each decoupled pair with opposite signs, and
/// the affine-preserving lumping keeps the row sums of `M`: the total momentum `Σ_p m_p v̂(x_p) = Σ_p m_p v_p` is kept for any field (to the
/// conjugate-gradient tolerance where functions are extended).
#[test]
fn the_affine_correction_keeps_the_total_momentum() {
    let field = |x: nalgebra::Vector2<f64>| {
        nalgebra::Vector2::new((3.0 * x.x).sin() + x.y * x.y, (2.0 * x.y).cos() - x.x)
    };
    for mass in ["extended-hybrid-apic", "extended-hybrid"] {
        let mut driver = hybrid_block(mass, field);
        for _ in 0..3 {
            driver.step().unwrap();
            assert!(driver.report().mass_report.lumped_rows > 0, "{mass}");
            let at = projected_at_particles(&driver);
            let (mut grid, mut particles) =
                (nalgebra::Vector2::zeros(), nalgebra::Vector2::zeros());
            for p in 0..at.len() {
                grid += at[p] * driver.particles.mass[p];
                particles += driver.particles.v[p] * driver.particles.mass[p];
            }
            assert!(
                (grid - particles).norm() < 1e-10 * particles.norm(),
                "{mass}: {grid} against {particles}"
            );
        }
    }
}

/// A body whose particles all lie on the mesh's edges and vertices (a lattice of
/// half the block size started on a block line, 1.3 particles per element, as a
/// user wrote it): a particle on a PS vertex sees only the vertex's three
/// functions, whose coefficients are always those of the tangent plane there,
/// so the affine-preserving lumping adds nothing for it. Counted as pinning an
/// affine field, such particles left the default's system singular (the start's
/// critical step not estimated, condition 2.5e16); counted out (they sit on vertices),
/// their elements keep a share of the plain lumping and the system is well
/// conditioned.
#[test]
fn a_body_sampled_on_the_mesh_edges_keeps_the_default_system_definite() {
    let h = 0.125;
    let x: Vec<_> = (0..49)
        .map(|p| nalgebra::Vector2::new(0.25 + (p % 7) as f64 * h, 0.25 + (p / 7) as f64 * h))
        .collect();
    let mut driver = ps_driver(2.0, 8, x, h * h, 1.0, "default", |_| {
        nalgebra::Vector2::zeros()
    });
    let critical = driver
        .critical_time_step()
        .expect("the start's mass system solves");
    assert!(critical.is_finite() && critical > 0.0, "{critical}");
    driver.step().unwrap();
    let condition = driver.mass.condition_estimate(&driver.pattern);
    assert!(condition < 1e4, "condition {condition:e}");
}

/// A small body crossing elements of a mostly empty mesh, with the default mass
/// (extension, lumped rows, the affine-preserving term), runs through the lists of
/// live functions and occupied elements; the same run with every list switched
/// off passes over every function and element. The state after every step is the
/// same to the last bit.
#[test]
fn a_small_body_runs_the_same_through_the_lists_as_over_the_whole_mesh() {
    use super::binning::LISTS_OFF;
    use std::sync::atomic::Ordering;
    let run = |lists: bool| {
        let h = 0.035;
        let centre = nalgebra::Vector2::new(2.14, 2.23);
        let spin = |x: nalgebra::Vector2<f64>| {
            let r = x - centre;
            nalgebra::Vector2::new(2.0 - 3.0 * r.y, -1.0 + 3.0 * r.x)
        };
        let x = lattice(12, h, (1.93, 2.02)).collect();
        let mut driver = ps_driver(4.0, 40, x, h * h, 1e3, "default", spin);
        driver.set_dt(1e-3);
        LISTS_OFF.store(!lists, Ordering::SeqCst);
        let mut states = Vec::new();
        let mut listed_steps = 0;
        for _ in 0..60 {
            let report = driver.step().unwrap();
            listed_steps += driver.gather.live_list().is_some() as usize;
            let p = &driver.particles;
            let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
            let flat = |m: &[nalgebra::Matrix2<f64>]| {
                bits(&m.iter().flat_map(|a| a.iter().copied()).collect::<Vec<_>>())
            };
            let vec2 = |m: &[nalgebra::Vector2<f64>]| {
                bits(&m.iter().flat_map(|a| a.iter().copied()).collect::<Vec<_>>())
            };
            states.push((
                vec2(&p.x),
                vec2(&p.v),
                flat(&p.f),
                format!("{:?}", (report.total_energy(), report.substeps)),
            ));
        }
        LISTS_OFF.store(false, Ordering::SeqCst);
        (
            states,
            listed_steps,
            driver.last_report.lumped_rows + driver.last_report.extended,
        )
    };
    let (listed, listed_steps, treated) = run(true);
    let (whole, whole_steps, _) = run(false);
    assert_eq!(
        listed_steps, 60,
        "the small body's steps ran through the lists"
    );
    assert_eq!(whole_steps, 0, "the lists were switched off");
    assert!(treated > 0, "the default treated no function");
    for (step, (a, b)) in listed.iter().zip(&whole).enumerate() {
        assert!(a == b, "step {}: the states differ", step + 1);
    }
}

/// A strategy as `inner`, except that it never reports solving `M` itself: the
/// driver then takes the two solves apart with the particle pass between them.
struct TwoPasses(Box<dyn crate::mass::MassStrategy<f64>>);

impl crate::mass::MassStrategy<f64> for TwoPasses {
    fn spec(&self) -> String {
        self.0.spec()
    }
    fn needs(&self) -> crate::mass::Needs {
        self.0.needs()
    }
    fn prepare(&mut self, setup: &crate::mass::MassSetup) {
        self.0.prepare(setup)
    }
    fn factorize(
        &mut self,
        pattern: &crate::sparse::SymmetricPattern,
        values: &[f64],
        context: crate::mass::StepContext,
    ) -> Result<crate::mass::MassReport, crate::mass::MassError> {
        self.0.factorize(pattern, values, context)
    }
    fn solve(&mut self, k: usize, rhs: &mut [f64]) -> Result<(), crate::mass::MassError> {
        self.0.solve(k, rhs)
    }
    fn solve_all(&mut self, rhs: &mut [Vec<f64>]) -> Result<(), crate::mass::MassError> {
        self.0.solve_all(rhs)
    }
    fn condition_estimate(&mut self, pattern: &crate::sparse::SymmetricPattern) -> f64 {
        self.0.condition_estimate(pattern)
    }
}

/// Where the strategy solves `M` itself, the step solves `M a = F` and
/// `M w = P(vⁿ)` together and takes `v̂ = w + Δt a`, which equals the projection
/// of the updated particle velocities `M⁻¹ P(vⁿ⁺¹)` (eqs. (18), (20)) in exact
/// arithmetic: the same run through both orders agrees to round-off, for the
/// strategies that take the fused order (a body over part of the mesh, with
/// empty functions held at zero; the default on a body filling its mesh).
#[test]
fn the_fused_projection_equals_the_projection_of_the_updated_velocities() {
    use crate::mass::MassStrategy;
    fn swirl(x: nalgebra::Vector2<f64>) -> nalgebra::Vector2<f64> {
        nalgebra::Vector2::new(0.4 - 1.5 * (x.y - 0.5), 0.2 + 2.0 * (x.x - 0.5) * x.y)
    }
    // The default solves `M` itself where its body fills the mesh (no row lumped).
    for (mass, n, corner) in [
        ("consistent", 20, 0.25),
        ("deactivate:1e-9", 20, 0.25),
        ("extended-hybrid", 40, 0.0),
    ] {
        let h = 0.025;
        let x: Vec<_> = lattice(n, h, (corner, corner)).collect();
        let mut fused = ps_driver(1.0, 4, x.clone(), h * h, 1e3, mass, swirl);
        let strategy = crate::mass::MassKind::parse(mass).unwrap().build();
        let mut apart = super::Driver::new(
            fused.basis.clone(),
            fused.particles.clone(),
            fused.material,
            TwoPasses(strategy),
            &[],
            Vec::new(),
            1e-9,
        )
        .unwrap();
        fused.set_dt(2e-4);
        apart.set_dt(2e-4);
        let mut took_fused = 0;
        for _ in 0..40 {
            fused.step().unwrap();
            apart.step().unwrap();
            took_fused += fused.mass.solves_mass_itself() as usize;
        }
        assert!(took_fused > 0, "{mass}: the fused order was never taken");
        let scale = |v: &[nalgebra::Vector2<f64>]| v.iter().map(|a| a.norm()).fold(0.0, f64::max);
        let (vs, xs) = (scale(&apart.particles.v), scale(&apart.particles.x));
        for p in 0..x.len() {
            let dv = (fused.particles.v[p] - apart.particles.v[p]).norm();
            let dx = (fused.particles.x[p] - apart.particles.x[p]).norm();
            let df = (fused.particles.f[p] - apart.particles.f[p]).norm();
            assert!(
                dv < 1e-11 * vs,
                "{mass}: particle {p} velocity differs by {dv:e}"
            );
            assert!(
                dx < 1e-12 * xs,
                "{mass}: particle {p} position differs by {dx:e}"
            );
            assert!(df < 1e-11, "{mass}: particle {p} F differs by {df:e}");
        }
        // The particles moved and strained: the comparison is not of a state at rest.
        let strained = (0..x.len())
            .map(|p| (apart.particles.f[p] - nalgebra::Matrix2::identity()).norm())
            .fold(0.0, f64::max);
        assert!(strained > 1e-3, "{mass}: strain {strained:e}");
    }
}
