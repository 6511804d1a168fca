//! An oblique slip wall: an elastic block on a frictionless 30° incline. The wall
//! constrains the normal velocity only, through constraints that couple both
//! components of each coefficient (imposed by projection in the mass-matrix norm),
//! so the block's centre of mass must slide with acceleration `g sin θ` along the
//! incline and not move across it.

use nalgebra::{Vector2, Vector2 as V};
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::{polygon_mesh, PolygonDomain};
use psmpm::basis::Basis;
use psmpm::driver::Driver;
use psmpm::effect::{Effect, Gravity};
use psmpm::mass::{MassKind, MassStrategy};
use psmpm::material::{Elastic, LinearElastic};
use psmpm::particles::Particles;

const THETA: f64 = std::f64::consts::PI / 6.0;

fn rotate(p: V<f64>) -> V<f64> {
    let (s, c) = THETA.sin_cos();
    V::new(c * p[0] - s * p[1], s * p[0] + c * p[1])
}

fn incline() -> psmpm::basis::TriMesh {
    let corners = [(0.0, 0.0), (3.0, 0.0), (3.0, 1.0), (0.0, 1.0)];
    let domain = PolygonDomain {
        outer: corners.iter().map(|&(x, y)| rotate(V::new(x, y))).collect(),
        outer_tags: ["floor", "end", "top", "start"].map(String::from).to_vec(),
        holes: Vec::new(),
    };
    polygon_mesh(&domain, 0.2).unwrap()
}

/// Slides for 0.2 s and returns the centre of mass displacement along and across
/// the incline.
fn slide<B: Basis<f64, 2>>(basis: B, mass: MassKind) -> (f64, f64) {
    let (nx, ny) = (20, 10);
    let (hx, hy) = (1.0 / nx as f64, 0.5 / ny as f64);
    let mut positions = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            positions.push(rotate(V::new(
                1.0 + (i as f64 + 0.5) * hx,
                (j as f64 + 0.5) * hy,
            )));
        }
    }
    let n = positions.len();
    let particles = Particles::new(positions, vec![hx * hy; n], 1.0);
    let material = LinearElastic::new(Elastic::new(1e4, 0.3, 1.0).unwrap(), 2);
    let gravity: Vec<Box<dyn Effect<f64, 2>>> = vec![Box::new(Gravity {
        g: Vector2::new(0.0, -9.81),
    })];
    let mut driver: Driver<f64, 2, B, Box<dyn MassStrategy<f64>>, _> =
        Driver::new(basis, particles, material, mass.build(), &[], gravity, 1e-4).unwrap();
    let outward = rotate(V::new(0.0, -1.0));
    driver.add_slip_wall("floor", &outward).unwrap();
    let constraints = driver.basis.dirichlet("floor", &outward).unwrap();
    for _ in 0..2000 {
        driver.step().unwrap();
        // The projected velocity satisfies every wall constraint to round-off.
        let v = driver.velocity_coefficients();
        let scale = v[0].iter().chain(&v[1]).fold(0.0f64, |m, x| m.max(x.abs()));
        for c in &constraints {
            let r: f64 = c
                .terms
                .iter()
                .map(|&(i, w)| w * (outward[0] * v[0][i] + outward[1] * v[1][i]))
                .sum();
            assert!(
                r.abs() <= 1e-12 * scale.max(1e-30),
                "constraint residual {r}"
            );
        }
    }
    let p = &driver.particles;
    let mean = p.u.iter().fold(V::zeros(), |a, u| a + u) / p.len() as f64;
    (
        mean.dot(&rotate(V::new(1.0, 0.0))),
        mean.dot(&rotate(V::new(0.0, 1.0))),
    )
}

#[test]
fn a_block_slides_down_a_frictionless_incline() {
    let t: f64 = 0.2;
    let exact = -0.5 * 9.81 * THETA.sin() * t * t;
    let cases = [
        (
            "ps lumped",
            slide(
                PowellSabin::new(incline(), SplitPoint::Incentre).unwrap(),
                MassKind::Lumped,
            ),
        ),
        (
            "ps partial",
            slide(
                PowellSabin::new(incline(), SplitPoint::Incentre).unwrap(),
                MassKind::parse("partial").unwrap(),
            ),
        ),
        ("pl lumped", slide(Linear::new(incline()), MassKind::Lumped)),
    ];
    for (name, (along, across)) in &cases {
        println!("{name}: along {along:.6e} (exact {exact:.6e}), across {across:.3e}");
    }
    for (name, (along, across)) in cases {
        assert!(
            (along - exact).abs() < 1e-3 * exact.abs(),
            "{name}: along the incline {along}, exact {exact}"
        );
        assert!(across.abs() < 1e-3 * exact.abs(), "{name}: across {across}");
    }
}

/// In a scene file a slip wall is `fix = ["normal"]`; on an axis-aligned wall it
/// is the same condition as fixing the normal axis.
#[test]
fn a_normal_slip_wall_in_a_scene_equals_the_axis_fix_on_a_straight_wall() {
    use psmpm::scene::{Component, Scene};
    let mut axis = Scene::builtin("vibrating-bar").unwrap();
    axis.time.t_end = 0.5;
    let mut normal = axis.clone();
    for bc in &mut normal.boundaries {
        if bc.tag == "top" || bc.tag == "bottom" {
            bc.fix = vec![Component::Normal];
        }
    }
    let a = psmpm::simulation::run(&axis, &mut |_| {}).unwrap();
    let n = psmpm::simulation::run(&normal, &mut |_| {}).unwrap();
    let (ea, en) = (a.error.unwrap(), n.error.unwrap());
    assert!((ea - en).abs() < 1e-9 * ea, "{ea} vs {en}");
    assert!((a.energy_final - n.energy_final).abs() < 1e-9 * a.energy_final);
}
