//! Contact walls (`kind = "contact-wall"`, `psmpm::contact`): a frictionless wall
//! that pushes the particles back instead of holding the basis functions.
//!
//! A slip wall (`fix = ["normal"]`) holds the normal velocity of the functions on
//! the wall, whose supports reach an element into the body, so it brakes a body
//! that rolls or spins along it; a contact wall lets it roll. Both let a block
//! slide down an incline as a frictionless one does.

use nalgebra::Vector2;
use psmpm::scene::Scene;
use psmpm::simulation::{self, ParticlesRef};

/// A disk (radius 0.5, E = 5e6, ρ = 1000) rolling at 2 to the right on the floor
/// of a 4 × 2 box (16 × 8 blocks), under gravity, with the floor `floor`.
fn rolling_disk(basis: &str, floor: &str) -> Scene {
    let text = format!(
        r#"
name = "rolling-disk"
dim = 2
basis = "{basis}"
[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 2.0]
blocks = [16, 8]
[material]
model = "neo-hookean"
young = 5e6
poisson = 0.3
density = 1000.0
[[body]]
shape = "disk"
centre = [1.0, 0.5]
radius = 0.5
spacing = [0.03125, 0.03125]
[initial_velocity]
kind = "linear"
value = [2.0, 0.0]
origin = [1.0, 0.5]
gradient = [[0.0, 4.0], [-4.0, 0.0]]
{floor}
[[effect]]
kind = "gravity"
g = [0.0, -9.81]
[time]
courant = 0.5
t_end = 0.3
"#
    );
    Scene::from_toml(&text, "rolling-disk.toml").unwrap()
}

const CONTACT: &str = "[[effect]]\nkind = \"contact-wall\"\ntag = \"bottom\"";
const SLIP: &str = "[[boundary]]\ntag = \"bottom\"\nfix = [\"normal\"]";

/// The angular momentum about the centre of mass and the centre of mass's
/// velocity, at every step of a run (which must not fail).
fn spin_history(scene: &Scene) -> Vec<(f64, Vector2<f64>)> {
    let mut history = Vec::new();
    let mut observer = |_: &psmpm::diagnostics::StepReport, p: ParticlesRef<'_>| {
        let ParticlesRef::Two(p) = p else {
            unreachable!()
        };
        let total: f64 = p.mass.iter().sum();
        let centre = (0..p.len()).fold(Vector2::zeros(), |c, i| c + p.x[i] * p.mass[i]) / total;
        let velocity = (0..p.len()).fold(Vector2::zeros(), |c, i| c + p.v[i] * p.mass[i]) / total;
        let spin: f64 = (0..p.len())
            .map(|i| {
                let (r, v) = (p.x[i] - centre, p.v[i] - velocity);
                p.mass[i] * (r.x * v.y - r.y * v.x)
            })
            .sum();
        history.push((spin, velocity));
    };
    let out = simulation::observe_2d(scene, &mut observer).unwrap();
    assert!(out.summary.failure.is_none(), "{:?}", out.summary.failure);
    assert!(out.summary.stable, "{:?}", out.summary);
    history
}

/// Rolling without slipping needs no friction: on a contact floor the disk keeps
/// its speed and most of its spin (−400 about its centre; the disk, started
/// without the stress of its spin and weight, lands and vibrates, and the floor's
/// normal forces on the vibrating contact patch take about 12 % of the spin within
/// 0.07 s, measured −335 to −371 after that for PS and PL). On a slip floor the
/// spin is lost within 0.03 s and turns over.
#[test]
fn a_disk_rolls_on_a_contact_floor_and_is_braked_by_a_slip_floor() {
    for basis in ["ps", "pl"] {
        let history = spin_history(&rolling_disk(basis, CONTACT));
        let spin0 = history[0].0;
        assert!((spin0 + 400.0).abs() < 2.0, "{spin0}");
        for (step, (spin, velocity)) in history.iter().enumerate() {
            assert!(
                (spin / spin0 - 1.0).abs() < 0.2,
                "{basis}: spin {spin} at step {step}"
            );
            assert!(
                (velocity.x - 2.0).abs() < 1e-6,
                "{basis}: speed {} at step {step}",
                velocity.x
            );
        }
        // At `courant = 0.25`: at 0.5 the PL disk on the slip floor gains 10 % of
        // its energy about its centre of mass, UNSTABLE since the verdict's scale
        // leaves out the steady translation (`docs/stability.md`, "A steady
        // translation does not widen the scale"); 3.3e-2 at 0.25.
        let mut slip_scene = rolling_disk(basis, SLIP);
        slip_scene.time.courant = Some(0.25);
        let slip = spin_history(&slip_scene);
        let least = slip
            .iter()
            .map(|h| h.0 / spin0)
            .fold(f64::INFINITY, f64::min);
        assert!(least < 0.0, "{basis}: a slip floor kept the spin ({least})");
    }
}

/// The stability matrix's incline (`scenes/stability/free-incline.toml`) with a
/// contact wall instead of the slip wall: the centre of mass slides
/// `½ g sin 30° t²` along it, and sinks into it only by the springs' give.
#[test]
fn a_block_slides_down_a_contact_incline_as_a_frictionless_one() {
    let text = include_str!("../scenes/stability/free-incline.toml")
        .replace(
            "[[boundary]]\ntag = \"incline\"\nfix = [\"normal\"]",
            "[[effect]]\nkind = \"contact-wall\"\ntag = \"incline\"",
        )
        .replace("mass = \"consistent\"\n", "");
    assert!(text.contains("contact-wall") && !text.contains("consistent\""));
    for basis in ["ps", "pl"] {
        let mut scene = Scene::from_toml(&text, "free-incline.toml").unwrap();
        scene.basis = psmpm::bases::BasisKind::parse(basis).unwrap();
        let out = simulation::observe_2d(&scene, &mut |_, _| {}).unwrap();
        assert!(out.summary.stable, "{:?}", out.summary);
        let p = &out.particles;
        let total: f64 = p.mass.iter().sum();
        let moved =
            (0..p.len()).fold(Vector2::zeros(), |c, i| c + (p.x[i] - p.x0[i]) * p.mass[i]) / total;
        let exact = 0.5 * 9.81 * 0.5 * 0.3f64.powi(2);
        assert!(
            (-moved.x - exact).abs() < 1e-3 * exact,
            "{basis}: slid {} against {exact}",
            -moved.x
        );
        assert!(moved.y.abs() < 2e-4, "{basis}: sank {}", moved.y);
    }
}

/// What a contact wall refuses, naming the field.
#[test]
fn contact_wall_input_errors_name_the_field() {
    let base = include_str!("../scenes/stability/free-incline.toml")
        .replace(
            "[[boundary]]\ntag = \"incline\"\nfix = [\"normal\"]",
            "[[effect]]\nkind = \"contact-wall\"\ntag = \"incline\"",
        )
        .replace("mass = \"consistent\"\n", "");
    let error = |text: &str| {
        let scene = match Scene::from_toml(text, "s.toml") {
            Ok(scene) => scene,
            Err(e) => return e.to_string(),
        };
        simulation::run(&scene, &mut |_| {})
            .unwrap_err()
            .to_string()
    };
    let e = error(&base.replace("tag = \"incline\"", "tag = \"floor\""));
    assert!(
        e.contains("effect[0].tag") && e.contains("unknown boundary tag `floor`"),
        "{e}"
    );
    let e = error(&base.replace("tag = \"incline\"", "tag = \"incline\"\nstiffness = 2.0"));
    assert!(
        e.contains("effect[0].stiffness") && e.contains("(0, 1]"),
        "{e}"
    );
    let e = error(&format!(
        "{base}\n[[boundary]]\ntag = \"incline\"\nfix = [\"normal\"]\n"
    ));
    assert!(
        e.contains("effect[0].tag") && e.contains("also held"),
        "{e}"
    );
    // The same wall twice would double its springs.
    let e = error(&format!(
        "{base}\n[[effect]]\nkind = \"contact-wall\"\ntag = \"incline\"\n"
    ));
    assert!(
        e.contains("effect[2].tag") && e.contains("already has a contact wall (effect[0])"),
        "{e}"
    );
    // Particles coarser than the mesh's longest edge.
    let e = error(&base.replace("count = [28, 14]", "count = [1, 1]"));
    assert!(e.contains("coarser than the mesh"), "{e}");
}

/// `docs/examples/disk-slope.toml` (a rubber disk, E = 5e5, released onto a 30°
/// slope in a coarse `polygon` mesh) with a contact wall, at its particle spacing
/// and at half of it: the slope holds the disk at both and the energy balance
/// closes. Springs sized on each particle's own mass softened as the particles got
/// finer, and the disk sank through the slope (a particle left the mesh at
/// step 108 with PL at the example's spacing); a particle that the lattice puts
/// inside its contact distance at the start no longer launches the disk.
#[test]
fn a_contact_slope_holds_a_soft_disk_at_any_particle_spacing() {
    let text = include_str!("../docs/examples/disk-slope.toml").replace(
        "[[boundary]]\ntag = \"slope\"\nfix = [\"normal\"]",
        "[[effect]]\nkind = \"contact-wall\"\ntag = \"slope\"",
    );
    assert!(text.contains("contact-wall"));
    for spacing in ["0.025", "0.0125"] {
        let text = text.replace(
            "spacing = [0.025, 0.025]",
            &format!("spacing = [{spacing}, {spacing}]"),
        );
        let scene = Scene::from_toml(&text, "disk-slope.toml").unwrap();
        let mut first_kinetic = None;
        let summary = simulation::run(&scene, &mut |r| {
            first_kinetic.get_or_insert(r.kinetic);
        })
        .unwrap();
        assert!(
            summary.failure.is_none(),
            "{spacing}: {:?}",
            summary.failure
        );
        // The balance closes to 1.2e-2 at most, a loss (0.79e-2 and 1.2e-2 at the
        // two spacings): springs soften, never stiffen, while compressed.
        assert!(summary.energy_drift < 2e-2, "{spacing}: {summary:?}");
        assert!(summary.energy_growth < 1e-3, "{spacing}: {summary:?}");
        // Step 1: the disk falls freely (½ m (g Δt)² ≈ 0.01), nothing launches it.
        assert!(first_kinetic.unwrap() < 0.1, "{spacing}: {first_kinetic:?}");
    }
}

/// A stiff block (E = 1e5, ρ = 1000, wave speed 10) striking a contact wall at
/// 3 m/s (30 % strain) and bouncing back, at 2.25 and 9 particles per triangle.
/// Springs sized on the grid mass around each particle were too stiff once several
/// particles pushed the same functions: the finer body gained 16 % energy (UNSTABLE).
/// Bounded by the share of each function's mass in contact, 3.7 % and 1.9 %.
#[test]
fn a_block_striking_a_contact_wall_keeps_its_energy_at_any_particle_count() {
    let scene = |spacing: f64| {
        format!(
            r#"name = "strike"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 3.0]
y = [0.0, 2.0]
blocks = [24, 16]
[material]
model = "neo-hookean"
young = 1e5
poisson = 0.3
density = 1000.0
[[body]]
min = [1.5, 0.75]
max = [2.0, 1.25]
spacing = [{spacing}, {spacing}]
[body.initial_velocity]
kind = "uniform"
value = [3.0, 0.0]
[[effect]]
kind = "contact-wall"
tag = "right"
[time]
courant = 0.3
t_end = 0.6
"#
        )
    };
    for per_block in [3.0, 6.0] {
        let scene = Scene::from_toml(&scene(0.125 / per_block), "strike.toml").unwrap();
        let out = simulation::observe_2d(&scene, &mut |_, _| {}).unwrap();
        assert!(out.summary.failure.is_none(), "{:?}", out.summary.failure);
        assert!(out.summary.stable, "{per_block}: {:?}", out.summary);
        assert!(
            out.summary.energy_drift < 4e-2,
            "{per_block}: {:?}",
            out.summary
        );
        // It has bounced: the centre of mass moves back, away from the wall.
        let p = &out.particles;
        let total: f64 = p.mass.iter().sum();
        let momentum: f64 = (0..p.len()).map(|i| p.mass[i] * p.v[i].x).sum();
        assert!(momentum / total < -1.0, "{per_block}: {}", momentum / total);
    }
}

/// A user's scene: a soft disk (E = 1e6, ρ = 1000, 177 particles) dropped 0.6 m
/// onto a contact floor of a `polygon` box, bouncing once. A particle's spring
/// `k_p = m_p (κ / Δt)² / c_p` follows the contact share `c_p`, which falls as
/// particles leave the contact: springs that stiffened while compressed gained
/// `½ Δk g²` each, and the disk gained 11.5 % of its energy at `courant = 0.25`
/// (time-centred 10.6 %, a real gain). A spring now only softens while its
/// particle stays in contact: the centred total gains nothing.
#[test]
fn a_disk_bouncing_on_a_contact_floor_gains_no_energy() {
    let text = r#"
name = "drop-disk"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [2.0, 0.0], [2.0, 3.0], [0.0, 3.0]]
tags = ["floor", "right", "top", "left"]
edge_length = 0.2
[material]
young = 1e6
poisson = 0.3
density = 1000.0
[[body]]
shape = "disk"
centre = [1.0, 1.2]
radius = 0.3
spacing = [0.04, 0.04]
[[effect]]
kind = "gravity"
g = [0.0, -9.81]
[[effect]]
kind = "contact-wall"
tag = "floor"
[[boundary]]
tag = "left"
fix = ["normal"]
[[boundary]]
tag = "right"
fix = ["normal"]
[time]
courant = 0.25
t_end = 0.9
"#;
    let scene = Scene::from_toml(text, "drop-disk.toml").unwrap();
    let mut rising = false;
    let out = simulation::observe_2d(&scene, &mut |r, _| {
        rising |= r.time > 0.5 && r.momentum()[1] > 0.0;
    })
    .unwrap();
    let s = &out.summary;
    assert!(s.failure.is_none() && s.stable, "{s:?}");
    assert!(rising, "the disk did not bounce");
    // 3e-15 with every step whole; the watch over the critical step splits 4 steps
    // in two, and the centred total's terms of second order in Δt change with it:
    // 1.4e-6.
    assert!(s.energy_growth_centred < 1e-5, "{s:?}");
    assert!(s.energy_growth < 2e-2, "{s:?}");
    assert!(s.energy_drift < 3e-2, "{s:?}");
}

/// A particle that leaves the mesh through a contact wall is told so (the wall's
/// springs too soft: lower the step or stiffen them); one that leaves through a
/// side without a wall, in a scene that has a contact wall elsewhere, is told to
/// add a wall there, not about the contact wall's springs.
#[test]
fn a_particle_leaving_the_mesh_is_told_whether_it_went_through_a_contact_wall() {
    let scene = |wall: &str, stiffness: f64| {
        format!(
            r#"
name = "strike"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 3.0]
y = [0.0, 2.0]
blocks = [24, 16]
[material]
young = 1e5
poisson = 0.3
density = 1000.0
[[body]]
min = [2.0, 0.75]
max = [2.5, 1.25]
per_block = [3, 3]
[body.initial_velocity]
kind = "uniform"
value = [6.0, 0.0]
[[effect]]
kind = "contact-wall"
tag = "{wall}"
stiffness = {stiffness}
[time]
courant = 0.3
t_end = 0.6
watch = false
"#
        )
    };
    // Without the watch: its limit on a particle's move per step
    // (`CONTACT_SHARE`) splits these steps, and the message's `courant` is that of
    // the steps as the scene gives them.
    let failure = |text: &str| {
        let scene = Scene::from_toml(text, "strike.toml").unwrap();
        simulation::run(&scene, &mut |_| {})
            .unwrap()
            .failure
            .unwrap_or_default()
    };
    let through = failure(&scene("right", 0.02));
    assert!(
        through.contains("left the mesh")
            && through
                .contains("and went through a contact wall: lower `time.courant` from 0.3 to 0.15"),
        "{through}"
    );
    // An impact at a larger step is told 0.25, not half of it (a user's disk went
    // through at 0.4 after 0.8, and held at 0.25).
    let fast = failure(&scene("right", 0.02).replace("courant = 0.3", "courant = 0.8"));
    assert!(
        fast.contains("and went through a contact wall: lower `time.courant` from 0.8 to 0.25"),
        "{fast}"
    );
    let free = failure(&scene("left", 0.5));
    assert!(
        free.contains("left the mesh")
            && free.contains("add a wall")
            && !free.contains("went through a contact wall"),
        "{free}"
    );
}

/// A block of 26 × 26 particles dropped 0.8 m onto a contact floor in a `polygon`
/// box (a user's scene): its energy gained 19 % (time-centred) in the impact while
/// the rows of functions at its edge, sampled by about one particle, switched
/// between lumped and consistent at every other step; each switch changes the mass
/// matrix at fixed momentum, and the force works against a velocity that jumps.
/// With the default's hysteresis (`RESTORE_PARTICLE_COUNT`) nothing is gained
/// (`docs/stability.md`, "Rows that switch at every other step").
#[test]
fn a_finely_sampled_block_striking_a_contact_floor_gains_no_energy() {
    let text = r#"
name = "drop-block"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
tags = ["floor", "right", "top", "left"]
edge_length = 0.1
[material]
young = 1e5
poisson = 0.3
density = 100.0
[[body]]
min = [0.8, 0.8]
max = [1.2, 1.2]
count = [26, 26]
[[effect]]
kind = "gravity"
g = [0.0, -9.81]
[[effect]]
kind = "contact-wall"
tag = "floor"
[time]
courant = 0.25
t_end = 0.6
"#;
    let scene = Scene::from_toml(text, "drop-block.toml").unwrap();
    let mut rising = false;
    let out = simulation::observe_2d(&scene, &mut |r, _| {
        rising |= r.time > 0.45 && r.momentum()[1] > 0.0;
    })
    .unwrap();
    let s = &out.summary;
    assert!(s.failure.is_none() && s.stable, "{s:?}");
    assert!(rising, "the block did not bounce");
    assert!(s.energy_growth_centred < 5e-3, "{s:?}");
}

/// A block sliding down a frictionless 30° ramp (a slip wall) and off its edge,
/// past a contact cliff below the edge (a user's scene, reduced). Its particles
/// came round the cliff's free end into the cliff's strip already nearly the
/// contact distance deep: the block gained 88 % of its energy at `courant = 0.12`
/// (more at smaller steps: the springs stiffen as `1 / Δt²`). With the wall
/// bevelled at its free ends it gains nothing and falls past the cliff.
#[test]
fn a_block_sliding_off_a_ramp_past_a_contact_cliff_gains_no_energy() {
    let text = r#"
name = "off-the-edge"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 2.0], [1.732051, 1.0], [1.732051, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0]]
tags = ["ramp", "cliff", "floor", "right", "top", "left"]
edge_length = 0.2
[material]
young = 1e6
poisson = 0.3
density = 1000.0
[[body]]
shape = "polygon"
outline = [[1.0, 1.4226], [1.3464, 1.2226], [1.5464, 1.5690], [1.2, 1.7690]]
spacing = [0.04, 0.04]
[[boundary]]
tag = "ramp"
fix = ["normal"]
[[effect]]
kind = "gravity"
g = [0.0, -9.81]
[[effect]]
kind = "contact-wall"
tag = "cliff"
[time]
courant = 0.12
t_end = 0.7
"#;
    let scene = Scene::from_toml(text, "off-the-edge.toml").unwrap();
    let mut centre = Vector2::zeros();
    let out = simulation::observe_2d(&scene, &mut |_, p| {
        let ParticlesRef::Two(p) = p else {
            return;
        };
        let mass: f64 = p.mass.iter().sum();
        centre = (0..p.len()).fold(Vector2::zeros(), |c, q| c + p.x[q] * p.mass[q]) / mass;
    })
    .unwrap();
    let s = &out.summary;
    assert!(s.failure.is_none() && s.stable, "{s:?}");
    assert!(s.energy_growth_centred < 1e-3, "{s:?}");
    assert!(
        centre.x > 1.9 && centre.y < 1.0,
        "the block did not fall past the cliff: centre of mass {centre:?}"
    );
}

/// A user's scene: a disk (radius 0.3, E = 1e6, ρ = 1000) thrown at 3 m/s at a
/// square post of side 0.4 (a hole of a `polygon` box, a contact wall), on a
/// coarse mesh (`edge_length = 0.5`, longer than the post is wide). The post's far
/// side was listed for the elements beside its near side and pushed the
/// particles there towards the post with `k_p (d + 0.4)`: the energy rose from
/// 1.26e3 to 3.0e6 and a particle reached 219 m/s by step 150. Now the disk
/// rebounds, its energy kept to 5 %.
#[test]
fn the_far_side_of_a_thin_obstacle_does_not_push() {
    let text = r#"name = "disk-post"
dim = 2
basis = "ps"
[mesh]
kind = "polygon"
outline = [[0.0, 0.0], [3.0, 0.0], [3.0, 2.0], [0.0, 2.0]]
edge_length = 0.5
[[mesh.holes]]
outline = [[2.0, 0.8], [2.4, 0.8], [2.4, 1.2], [2.0, 1.2]]
tag = "post"
[material]
young = 1.0e6
poisson = 0.3
density = 1000.0
[[body]]
shape = "disk"
centre = [0.8, 1.0]
radius = 0.3
spacing = [0.025, 0.025]
initial_velocity = { kind = "uniform", value = [3.0, 0.0] }
[[effect]]
kind = "contact-wall"
tag = "post"
[time]
courant = 0.25
t_end = 0.6
"#;
    let scene = Scene::from_toml(text, "disk-post.toml").unwrap();
    let out = simulation::observe_2d(&scene, &mut |_, _| {}).unwrap();
    assert!(out.summary.failure.is_none(), "{:?}", out.summary.failure);
    assert!(out.summary.stable, "{:?}", out.summary);
    assert!(out.summary.energy_drift < 5e-2, "{:?}", out.summary);
    // It has struck the post and bounced back.
    let p = &out.particles;
    let total: f64 = p.mass.iter().sum();
    let momentum: f64 = (0..p.len()).map(|i| p.mass[i] * p.v[i].x).sum();
    assert!(momentum / total < -1.0, "{}", momentum / total);
}
