//! Property: a scene whose every value lies inside the range `docs/scenes.md` gives
//! it either runs or stops with a typed error ([`SceneFileError`] from the parser,
//! [`RunError`] from the set-up), never a panic; a run that starts ends with a
//! summary (a numerical failure is part of it, not a panic).
//!
//! The scenes are written as TOML text and read by `Scene::from_toml`, so the
//! parser, validation, set-up and the time loop are all exercised. Sizes are small
//! (at most 6 × 6 blocks, a few dozen particles) and every run is stopped after
//! [`MAX_STEPS`] steps through the stop flag of `observe_*_until`, so that a case
//! takes milliseconds whatever its time step. The seed is fixed: the same 64 cases
//! run everywhere (`PROPTEST_CASES` changes the number).
//!
//! Combinations the ranges allow but the scene does not (a `per_block` body on a
//! polygon mesh, `exact` velocity without a reference, a slip wall on a curve, a
//! `dt` above the critical step, …) are meant to give typed errors; the test counts
//! them but only the absence of panics is the property.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, RngSeed};
use psmpm::scene::Scene;
use psmpm::simulation::{self, ParticlesRef};
use std::fmt::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// Steps a case runs at most.
const MAX_STEPS: usize = 4;

/// A finite number, log-uniform in magnitude between `10^lo` and `10^hi`.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> + Clone {
    (lo..=hi).prop_map(|e: f64| 10f64.powf(e))
}

/// A finite number of either sign, of magnitude up to `10^hi` (or zero).
fn signed(hi: f64) -> impl Strategy<Value = f64> + Clone {
    prop_oneof![
        1 => Just(0.0),
        4 => (log_uniform(-3.0, hi), any::<bool>()).prop_map(|(v, neg)| if neg { -v } else { v }),
    ]
}

/// `[a, b]` with `0 ≤ a < b ≤ 1`, at least 0.05 apart.
fn sub_interval() -> impl Strategy<Value = (f64, f64)> {
    (0.0..0.95f64, 0.05..1.0f64).prop_map(|(a, len)| (a, (a + len).min(1.0)))
}

fn list(values: &[f64]) -> String {
    let shown: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", shown.join(", "))
}

/// The mesh: its TOML section, its bounding box (`[x0, x1, y0, y1]`; y unused in
/// 1D), its boundary tags, and its blocks (for `per_block` bodies) if it has them.
#[derive(Debug, Clone)]
struct Mesh {
    toml: String,
    bbox: [f64; 4],
    tags: Vec<String>,
    blocks: Option<[usize; 2]>,
}

fn data(name: &str) -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/").to_string() + name
}

fn mesh_2d() -> impl Strategy<Value = Mesh> {
    let origin = (signed(1.0), signed(1.0));
    let size = (log_uniform(-1.0, 1.5), log_uniform(-1.0, 1.5));
    let blocks = (
        origin.clone(),
        size.clone(),
        1..=6usize,
        1..=6usize,
        prop_oneof![Just("four-triangles"), Just("delaunay")],
    )
        .prop_map(|((x0, y0), (w, h), nx, ny, layout)| Mesh {
            toml: format!(
                "[mesh]\nkind = \"blocks\"\nx = {}\ny = {}\nblocks = [{nx}, {ny}]\nlayout = \"{layout}\"\n",
                list(&[x0, x0 + w]),
                list(&[y0, y0 + h])
            ),
            bbox: [x0, x0 + w, y0, y0 + h],
            tags: ["bottom", "right", "top", "left"].map(String::from).to_vec(),
            blocks: Some([nx, ny]),
        });
    let tag_names = prop::collection::vec(prop_oneof![Just("floor"), Just("wall"), Just("top")], 6);
    let polygon = (
        origin,
        size,
        0.2..1.5f64,
        any::<bool>(),
        any::<bool>(),
        tag_names,
    )
        .prop_map(|((x0, y0), (w, h), f, l_shape, hole, names)| {
            let (x1, y1) = (x0 + w, y0 + h);
            let (xm, ym) = (x0 + 0.5 * w, y0 + 0.5 * h);
            let outline: Vec<[f64; 2]> = if l_shape {
                vec![[x0, y0], [x1, y0], [x1, ym], [xm, ym], [xm, y1], [x0, y1]]
            } else {
                vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
            };
            let tags: Vec<String> = names[..outline.len()]
                .iter()
                .map(|s| s.to_string())
                .collect();
            let points: Vec<String> = outline.iter().map(|p| list(p)).collect();
            let quoted: Vec<String> = tags.iter().map(|t| format!("\"{t}\"")).collect();
            let mut toml = format!(
                "[mesh]\nkind = \"polygon\"\noutline = [{}]\ntags = [{}]\nedge_length = {:?}\n",
                points.join(", "),
                quoted.join(", "),
                // At most about 150 triangles, whatever the aspect ratio.
                (f * w.min(h) / 2.0).max(w.max(h) / 12.0)
            );
            let mut all_tags = tags;
            if hole && !l_shape {
                let (hx, hy) = (0.1 * w, 0.1 * h);
                let _ = write!(
                    toml,
                    "\n[[mesh.holes]]\noutline = [{}, {}, {}, {}]\ntag = \"hole\"\n",
                    list(&[xm - hx, ym - hy]),
                    list(&[xm + hx, ym - hy]),
                    list(&[xm + hx, ym + hy]),
                    list(&[xm - hx, ym + hy])
                );
                all_tags.push("hole".into());
            }
            Mesh {
                toml,
                bbox: [x0, x1, y0, y1],
                tags: all_tags,
                blocks: None,
            }
        });
    let gmsh = prop_oneof![
        Just(("square.msh", vec!["bottom", "right", "top", "left"])),
        Just(("square_v22.msh", vec!["bottom", "right", "top", "left"])),
        Just((
            "square_hole.msh",
            vec!["bottom", "right", "top", "left", "hole"]
        )),
        Just(("lshape.msh", vec!["wall"])),
    ]
    .prop_map(|(file, tags)| Mesh {
        toml: format!("[mesh]\nkind = \"gmsh\"\nfile = \"{}\"\n", data(file)),
        bbox: [0.0, 1.0, 0.0, 1.0],
        tags: tags.into_iter().map(String::from).collect(),
        blocks: None,
    });
    prop_oneof![3 => blocks, 2 => polygon, 1 => gmsh]
}

fn mesh_1d() -> impl Strategy<Value = Mesh> {
    (signed(1.0), log_uniform(-1.0, 1.5), 1..=12usize).prop_map(|(x0, w, n)| Mesh {
        toml: format!(
            "[mesh]\nkind = \"interval\"\nx = {}\nelements = {n}\n",
            list(&[x0, x0 + w])
        ),
        bbox: [x0, x0 + w, 0.0, 0.0],
        tags: vec!["left".into(), "right".into()],
        blocks: Some([n, 1]),
    })
}

fn mass() -> impl Strategy<Value = String> {
    let fraction = 0.01..0.99f64;
    prop_oneof![
        Just("default".to_string()),
        Just("consistent".to_string()),
        Just("lumped".to_string()),
        Just("partial".to_string()),
        log_uniform(-4.0, 0.0).prop_map(|t| format!("partial:{t:?}")),
        fraction
            .clone()
            .prop_map(|c| format!("partial-coverage:{c:?}")),
        Just("deactivate".to_string()),
        log_uniform(-4.0, 0.0).prop_map(|t| format!("deactivate:{t:?}")),
        Just("extended".to_string()),
        fraction.clone().prop_map(|c| format!("extended:{c:?}")),
        Just("extended-hybrid".to_string()),
        (fraction.clone(), fraction).prop_map(|(a, b)| format!(
            "extended-hybrid:{:?}:{:?}",
            a.min(b),
            a.max(b)
        )),
        (0..=64usize).prop_map(|k| format!("fmpm:{k}")),
    ]
}

fn material() -> impl Strategy<Value = String> {
    (
        prop_oneof![
            Just("corotational"),
            Just("corotated"),
            Just("linear-elastic"),
            Just("paper-linear"),
            Just("neo-hookean")
        ],
        log_uniform(-2.0, 9.0),
        -0.99..0.49f64,
        log_uniform(-3.0, 4.0),
    )
        .prop_map(|(model, young, poisson, density)| {
            format!(
                "[material]\nmodel = \"{model}\"\nyoung = {young:?}\npoisson = {poisson:?}\ndensity = {density:?}\n"
            )
        })
}

/// A point of the box `bbox` at fractions `f` (dim coordinates).
fn at(bbox: &[f64; 4], dim: usize, f: [f64; 2]) -> Vec<f64> {
    let p = [
        bbox[0] + f[0] * (bbox[1] - bbox[0]),
        bbox[2] + f[1] * (bbox[3] - bbox[2]),
    ];
    p[..dim].to_vec()
}

/// The inputs of one `[[body]]`: fractions of the mesh's box (or blocks), a count
/// or per-block count, jitter and seed.
type BodyDraw = ((f64, f64), (f64, f64), bool, [usize; 2], f64, i64);

/// Body `index` of `bodies` keeps to its own slice `[index, index + 1] / bodies` of
/// the mesh along x (bodies must not overlap; they may touch).
fn body(mesh: &Mesh, dim: usize, draw: BodyDraw, index: usize, bodies: usize) -> String {
    let ((ax, bx), (ay, by), per_block, n, jitter, seed) = draw;
    let slice = |a: f64| (index as f64 + a) / bodies as f64;
    let (ax, bx) = (slice(ax), slice(bx));
    let mut min = at(&mesh.bbox, dim, [ax, ay]);
    let mut max = at(&mesh.bbox, dim, [bx, by]);
    // Whole blocks of the body's slice along x (all blocks along y).
    let slice_blocks = |cells: f64, k: usize| -> (f64, f64) {
        if k == 0 {
            (
                (index as f64 * cells / bodies as f64).floor(),
                ((index + 1) as f64 * cells / bodies as f64).floor(),
            )
        } else {
            (0.0, cells)
        }
    };
    let whole_blocks = mesh.blocks.filter(|blocks| {
        (0..dim).all(|k| {
            let (lo, hi) = slice_blocks(blocks[k] as f64, k);
            hi > lo
        })
    });
    let counts = if let (true, Some(blocks)) = (per_block, whole_blocks) {
        // Whole blocks, so that the lattice cells are whole.
        for k in 0..dim {
            let (a, b) = if k == 0 { (ax, bx) } else { (ay, by) };
            let cells = blocks[k] as f64;
            let (first, last) = slice_blocks(cells, k);
            let i0 = (a * cells).floor().clamp(first, last - 1.0);
            let i1 = (b * cells).ceil().clamp(i0 + 1.0, last);
            let (lo, hi) = (mesh.bbox[2 * k], mesh.bbox[2 * k + 1]);
            min[k] = lo + i0 / cells * (hi - lo);
            max[k] = if i1 >= cells {
                hi
            } else {
                lo + i1 / cells * (hi - lo)
            };
        }
        format!("per_block = {}", list_usize(&n[..dim]))
    } else {
        format!(
            "count = {}",
            list_usize(&n[..dim].iter().map(|c| 2 * c).collect::<Vec<_>>())
        )
    };
    format!(
        "[[body]]\nmin = {}\nmax = {}\n{counts}\njitter = {jitter:?}\nseed = {seed}\n",
        list(&min),
        list(&max)
    )
}

fn list_usize(values: &[usize]) -> String {
    let shown: Vec<String> = values.iter().map(|v| v.to_string()).collect();
    format!("[{}]", shown.join(", "))
}

fn body_draw() -> impl Strategy<Value = BodyDraw> {
    (
        sub_interval(),
        sub_interval(),
        any::<bool>(),
        [1..=3usize, 1..=3usize],
        prop_oneof![Just(0.0), 0.0..0.49f64],
        0..=i64::MAX,
    )
}

fn vector(dim: usize, v: [f64; 2]) -> String {
    list(&v[..dim])
}

/// The inputs of one `[[effect]]`.
#[derive(Debug, Clone)]
enum EffectDraw {
    Gravity([f64; 2]),
    Damping(f64),
    Traction((f64, f64), (f64, f64), [f64; 2], f64, f64),
    BodyForce([f64; 2]),
    Manufactured,
    Geostatic(f64, f64),
}

fn effect_draw() -> impl Strategy<Value = EffectDraw> {
    prop_oneof![
        3 => [signed(2.0), signed(2.0)].prop_map(EffectDraw::Gravity),
        1 => (0.0..0.99f64).prop_map(EffectDraw::Damping),
        1 => (prop_oneof![Just((0.0, 1.0)), sub_interval()], prop_oneof![Just((0.0, 1.0)), sub_interval()], [signed(3.0), signed(3.0)], log_uniform(-2.0, 2.0), prop_oneof![Just(0.0), log_uniform(-3.0, 0.0)])
            .prop_map(|(a, b, t, l, r)| EffectDraw::Traction(a, b, t, l, r)),
        1 => [signed(2.0), signed(2.0)].prop_map(EffectDraw::BodyForce),
        1 => Just(EffectDraw::Manufactured),
        1 => (0.0..1.2f64, signed(1.0)).prop_map(|(s, k0)| EffectDraw::Geostatic(s, k0)),
    ]
}

fn effect(mesh: &Mesh, dim: usize, draw: &EffectDraw) -> String {
    let head = "[[effect]]\nkind = ";
    match draw {
        EffectDraw::Gravity(g) => format!("{head}\"gravity\"\ng = {}\n", vector(dim, *g)),
        EffectDraw::Damping(a) => format!("{head}\"damping\"\nalpha = {a:?}\n"),
        EffectDraw::Traction((ax, bx), (ay, by), t, length, ramp) => format!(
            "{head}\"traction\"\nmin = {}\nmax = {}\ntraction = {}\nlength = {length:?}\nramp = {ramp:?}\n",
            list(&at(&mesh.bbox, dim, [*ax, *ay])),
            list(&at(&mesh.bbox, dim, [*bx, *by])),
            vector(dim, *t)
        ),
        EffectDraw::BodyForce(v) => format!("{head}\"body-force\"\nvalue = {}\n", vector(dim, *v)),
        EffectDraw::Manufactured => format!("{head}\"manufactured-body-force\"\n"),
        EffectDraw::Geostatic(s, k0) => {
            // Needs gravity: the gravity of the scene's ground.
            let gravity = format!("{head}\"gravity\"\ng = {}\n\n", vector(dim, [0.0, -9.81]));
            let surface = mesh.bbox[2] + s * (mesh.bbox[3] - mesh.bbox[2]);
            let surface = if dim == 1 { mesh.bbox[0] + s * (mesh.bbox[1] - mesh.bbox[0]) } else { surface };
            format!("{gravity}{head}\"geostatic-stress\"\nsurface = {surface:?}\nk0 = {k0:?}\n")
        }
    }
}

fn velocity(dim: usize) -> impl Strategy<Value = String> {
    prop_oneof![
        2 => Just(String::new()),
        1 => Just("[initial_velocity]\nkind = \"rest\"\n".to_string()),
        2 => [signed(2.0), signed(2.0)].prop_map(move |v| format!("[initial_velocity]\nkind = \"uniform\"\nvalue = {}\n", vector(dim, v))),
        1 => signed(2.0).prop_map(|v0| format!("[initial_velocity]\nkind = \"sine-mode\"\nv0 = {v0:?}\n")),
        1 => Just("[initial_velocity]\nkind = \"exact\"\n".to_string()),
    ]
}

fn reference() -> impl Strategy<Value = String> {
    prop_oneof![
        8 => Just(String::new()),
        1 => signed(1.0).prop_map(|v0| format!("[reference]\nkind = \"vibrating-bar\"\nv0 = {v0:?}\n")),
        1 => Just("[reference]\nkind = \"column-self-weight\"\n".to_string()),
        1 => signed(-1.0).prop_map(|u0| format!("[reference]\nkind = \"axis-aligned\"\nu0 = {u0:?}\n")),
        1 => Just("[reference]\nkind = \"column-equilibrium\"\n".to_string()),
    ]
}

fn time() -> impl Strategy<Value = String> {
    prop_oneof![
        (
            log_uniform(-6.0, -1.0),
            1..=50u32,
            prop::bool::weighted(0.75)
        )
            .prop_map(|(dt, k, above)| {
                format!(
                    "[time]\ndt = {dt:?}\nt_end = {:?}\nallow_above_critical = {above}\n",
                    dt * f64::from(k)
                )
            }),
        (0.01..1.5f64, log_uniform(-2.0, 0.0))
            .prop_map(|(c, t_end)| { format!("[time]\ncourant = {c:?}\nt_end = {t_end:?}\n") }),
    ]
}

fn boundary_draw() -> impl Strategy<Value = Vec<(prop::sample::Index, usize)>> {
    prop::collection::vec((any::<prop::sample::Index>(), 0..4usize), 0..=3)
}

fn boundary(mesh: &Mesh, dim: usize, draws: &[(prop::sample::Index, usize)]) -> String {
    let mut out = String::new();
    for (tag, fix) in draws {
        let fix = if dim == 1 {
            "[\"x\"]"
        } else {
            ["[\"x\"]", "[\"y\"]", "[\"x\", \"y\"]", "[\"normal\"]"][*fix]
        };
        let _ = write!(
            out,
            "[[boundary]]\ntag = \"{}\"\nfix = {fix}\n\n",
            tag.get(&mesh.tags)
        );
    }
    out
}

fn output(dim: usize, bbox: [f64; 4]) -> impl Strategy<Value = String> {
    (
        any::<bool>(),
        0..=5usize,
        prop::collection::vec((0.0..1.0f64, 0.0..1.0f64), 0..=2),
    )
        .prop_map(move |(condition, every, points)| {
            let tracked: Vec<String> = points
                .iter()
                .map(|&(a, b)| list(&at(&bbox, dim, [a, b])))
                .collect();
            format!(
                "[output]\ncondition = {condition}\ndiagnostics_every = {every}\ntracked = [{}]\n",
                tracked.join(", ")
            )
        })
}

/// A whole scene as TOML text.
fn scene() -> impl Strategy<Value = String> {
    let two = (prop_oneof![Just("ps"), Just("pl")], mesh_2d(), Just(2usize));
    let one = (
        prop_oneof![Just("bspline"), Just("pl1d")],
        mesh_1d(),
        Just(1usize),
    );
    prop_oneof![3 => two, 1 => one].prop_flat_map(|(basis, mesh, dim)| {
        (
            (
                Just(basis),
                Just(mesh.clone()),
                Just(dim),
                prop_oneof![Just("incentre"), Just("centroid")],
                mass(),
                material(),
            ),
            (
                prop::collection::vec(body_draw(), 1..=2),
                velocity(dim),
                boundary_draw(),
                prop::collection::vec(effect_draw(), 0..=2),
                time(),
                reference(),
                output(dim, mesh.bbox),
            ),
        )
            .prop_map(
                |((basis, mesh, dim, split, mass, material), (bodies, vel, bc, effects, time, reference, output))| {
                    let mut s = format!(
                        "name = \"property\"\ndim = {dim}\nbasis = \"{basis}\"\nsplit = \"{split}\"\nmass = \"{mass}\"\n\n{}\n{material}\n",
                        mesh.toml
                    );
                    let count = bodies.len();
                    for (i, b) in bodies.into_iter().enumerate() {
                        s += &body(&mesh, dim, b, i, count);
                        s.push('\n');
                    }
                    s += &vel;
                    s.push('\n');
                    s += &boundary(&mesh, dim, &bc);
                    for e in &effects {
                        s += &effect(&mesh, dim, e);
                        s.push('\n');
                    }
                    s += &time;
                    s.push('\n');
                    s += &reference;
                    s.push('\n');
                    s += &output;
                    s
                },
            )
    })
}

/// Runs `text` for at most [`MAX_STEPS`] steps: `Ok(steps)` or the typed error's text.
fn attempt(text: &str) -> Result<usize, String> {
    let scene = Scene::from_toml(text, "property.toml").map_err(|e| e.to_string())?;
    let stop = AtomicBool::new(false);
    let mut steps = 0;
    let mut observer = |r: &psmpm::driver::StepReport, _: ParticlesRef<'_>| {
        steps = r.step;
        if r.step >= MAX_STEPS {
            stop.store(true, Ordering::Relaxed);
        }
    };
    let summary = if scene.dim == 2 {
        simulation::observe_2d_until(&scene, &mut observer, &stop).map(|o| o.summary)
    } else {
        simulation::observe_1d_until(&scene, &mut observer, &stop).map(|o| o.summary)
    }
    .map_err(|e| e.to_string())?;
    assert!(summary.steps <= MAX_STEPS, "{} steps", summary.steps);
    Ok(steps)
}

fn config() -> Config {
    Config {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(64),
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x5053_4d50_4d31),
        failure_persistence: None,
        // A failing case is shrunk, but not for long (each case runs a simulation).
        max_shrink_iters: 200,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config())]

    /// Every scene inside the documented ranges runs or gives a typed error.
    #[test]
    fn scenes_in_range_run_or_give_typed_errors(text in scene()) {
        match attempt(&text) {
            Ok(_) => {}
            Err(message) => prop_assert!(!message.is_empty(), "an empty error for\n{}", text),
        }
    }
}

/// The generator reaches runs as well as errors (so the property is not vacuous):
/// of the first cases, some run and some are refused.
#[test]
fn the_generator_reaches_runs_and_errors() {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::new(config());
    let (mut ran, mut refused) = (0, 0);
    for _ in 0..24 {
        let text = scene().new_tree(&mut runner).unwrap().current();
        match attempt(&text) {
            Ok(steps) if steps > 0 => ran += 1,
            Ok(_) => {}
            Err(_) => refused += 1,
        }
    }
    assert!(ran >= 6 && refused >= 1, "{ran} ran, {refused} refused");
}
