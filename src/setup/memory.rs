//! The memory a run will need, checked against what the process may use before the
//! large arrays are allocated.
//!
//! The scene's limits ([`crate::scene::MAX_PARTICLES`], the mesh generators' and the
//! Gmsh reader's) keep a mistyped value from asking for terabytes, but a valid scene
//! under them can still need more memory than the process may have: 9e6 PS
//! particles need about 4 GB, and a run that cannot have it aborts at an allocation
//! ("memory allocation of … bytes failed") with no word of the cause. The set-up
//! therefore estimates the run's peak from the counts the scene fixes,
//! [`Footprint`], and refuses the run when that is above the memory the process can
//! see it may use ([`room`]): its address-space limit (`ulimit -v`), its
//! control group's limit, or the machine's memory and swap. The estimate is checked
//! three times, each before what it would allocate: from the scene for a generated
//! mesh, once the mesh is built (before the basis), and once the particles are
//! placed (before the driver).
//!
//! The bytes per particle and per element are peaks measured with
//! `/usr/bin/time -f %M` (`docs/scaling.md`, "The memory a run needs"), the upper
//! figure of the runs measured, and the check adds [`HEADROOM`] and
//! [`HEADROOM_BYTES`] on top (an address-space limit counts what the allocator
//! and the threads reserve besides what is resident): a run the check lets
//! through must not end at an allocation failing part way, an abort without a
//! cause. (With the lower figures and no headroom, runs within 15–35 % of the
//! limit passed the check and aborted.)

use super::regions::count_field;
use crate::bases::BasisKind;
use crate::mass::MassKind;
use crate::scene::limits::echo_number;
use crate::scene::{BodyShape, ErrorKind, MeshSpec, Scene, SceneError};

/// A run's peak memory per particle and per element, by basis and mass strategy
/// (measured peaks, `docs/scaling.md`, "The memory a run needs").
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Footprint {
    /// Bytes per particle: state, basis values and gradients, the step's buffers.
    pub per_particle: f64,
    /// Bytes per element of the mesh and the basis (PS: the refinement, the
    /// sub-triangles' coordinates and the Bézier ordinates kept per function),
    /// allocated before the particles are placed.
    pub basis_per_element: f64,
    /// Bytes per element the driver allocates: the mass pattern, the factorisation
    /// and the per-function buffers.
    pub driver_per_element: f64,
    /// [`Footprint::driver_per_element`] for a body that covers under a quarter
    /// of the functions ([`certainly_compact`]): the masked strategies factorise
    /// only the rows a body covers (`mass::masked`), so their factor stays small.
    pub compact_driver_per_element: f64,
}

/// Whether `particles` on a mesh of `elements` elements certainly cover under a
/// quarter of the functions, wherever they go, so that the masked mass systems,
/// factorised on the rows a body covers (`mass::masked`), stay far smaller than
/// the whole pattern's: a particle touches at most the functions of the elements
/// around one vertex (about 21 for PS and 7 for PL, on the usual 6 triangles
/// there), against about 1.5 functions per triangle (PS; 0.5 for PL), so the
/// rows a body covers are at most 14 times its particles over the elements, as a
/// share.
pub(crate) fn certainly_compact(particles: f64, elements: f64) -> bool {
    14.0 * particles < 0.25 * elements
}

impl Footprint {
    /// The footprint of `basis` with `mass` (lumping assembles no matrix, so its
    /// elements cost less).
    pub fn of(basis: BasisKind, mass: MassKind) -> Footprint {
        let lumped = mass == MassKind::Lumped;
        // (per particle, basis per element, driver per element: lumped, a
        // body over the whole mesh factorised, a body under a quarter of it.)
        let (per_particle, basis_per_element, (lumped_driver, whole, compact)) = match basis {
            BasisKind::Ps => (450.0, 2_100.0, (700.0, 3_200.0, 1_800.0)),
            BasisKind::Pl => (330.0, 500.0, (150.0, 600.0, 450.0)),
            BasisKind::Bspline | BasisKind::Pl1d => (240.0, 150.0, (260.0, 900.0, 900.0)),
        };
        Footprint {
            per_particle,
            basis_per_element,
            driver_per_element: if lumped { lumped_driver } else { whole },
            compact_driver_per_element: if lumped { lumped_driver } else { compact },
        }
    }

    /// Bytes per element still to allocate: all of them before the basis is built,
    /// the driver's after; `compact`: the body certainly covers under a quarter
    /// of the functions ([`certainly_compact`]).
    pub fn per_element(&self, basis_built: bool, compact: bool) -> f64 {
        let driver = if compact {
            self.compact_driver_per_element
        } else {
            self.driver_per_element
        };
        driver
            + if basis_built {
                0.0
            } else {
                self.basis_per_element
            }
    }
}

/// The share added to the estimate before it is compared with the room.
pub(crate) const HEADROOM: f64 = 0.15;

/// Bytes added to the estimate before it is compared with the room: the
/// allocator's arenas and the threads' stacks, reserved address space.
pub(crate) const HEADROOM_BYTES: f64 = 64e6;

/// Address space the allocator reserves for a thread's arena (glibc on 64-bit
/// Linux: `HEAP_MAX_SIZE`), which an address-space limit counts.
pub(crate) const ARENA_BYTES: f64 = 64.0 * 1024.0 * 1024.0;

/// The memory the process may still allocate, as the code can see it, and which
/// limit sets it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Room {
    /// Bytes.
    pub bytes: f64,
    /// The limit, in words a user can act on.
    pub limit: &'static str,
}

/// The smallest room of the limits the process can see (Linux: the address-space
/// limit less the address space in use, the control group's memory limit less its
/// use, the machine's memory and swap); `None` where none can be read.
pub(crate) fn room() -> Option<Room> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let mut rooms = Vec::new();
    if let (Some(limits), Some(status)) = (read("/proc/self/limits"), read("/proc/self/status")) {
        if let (Some(limit), Some(used)) =
            (address_space_limit(&limits), kb_field(&status, "VmSize:"))
        {
            rooms.push(Room {
                bytes: limit - used,
                limit: ADDRESS_SPACE_LIMIT,
            });
        }
    }
    if let Some((limit, used)) = cgroup_limit(&read) {
        rooms.push(Room {
            bytes: limit - used,
            limit: "its control group's memory limit (a container's or a job's)",
        });
    }
    if let Some(meminfo) = read("/proc/meminfo") {
        if let (Some(memory), Some(swap)) = (
            kb_field(&meminfo, "MemTotal:"),
            kb_field(&meminfo, "SwapTotal:"),
        ) {
            rooms.push(Room {
                bytes: memory + swap,
                limit: "the machine's memory and swap",
            });
        }
    }
    rooms.into_iter().min_by(|a, b| a.bytes.total_cmp(&b.bytes))
}

/// [`Room::limit`] of the address-space limit.
const ADDRESS_SPACE_LIMIT: &str = "its address-space limit (`ulimit -v`)";

/// Whether this process has an address-space limit (`/proc/self/limits`).
pub(crate) fn address_space_limit_set() -> bool {
    std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|limits| address_space_limit(&limits))
        .is_some()
}

/// The soft address-space limit in bytes of a `/proc/self/limits` text, `None`
/// when unlimited or absent.
fn address_space_limit(limits: &str) -> Option<f64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft = line["Max address space".len()..]
        .split_whitespace()
        .next()?;
    soft.parse::<f64>().ok()
}

/// A `Name:   N kB` field of `/proc/self/status` or `/proc/meminfo`, in bytes.
fn kb_field(text: &str, name: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kb: f64 = line[name.len()..].split_whitespace().next()?.parse().ok()?;
    Some(kb * 1024.0)
}

/// The memory limit and use in bytes of the process's control group (v2, then v1),
/// `None` when unlimited or unreadable.
fn cgroup_limit(read: &dyn Fn(&str) -> Option<String>) -> Option<(f64, f64)> {
    // Above this a v1 "limit" is the kernel's way of saying none.
    const UNLIMITED: f64 = (1u64 << 60) as f64;
    let number = |text: Option<String>| text.and_then(|t| t.trim().parse::<f64>().ok());
    let own = read("/proc/self/cgroup")
        .and_then(|c| {
            c.lines()
                .find_map(|l| l.strip_prefix("0::").map(str::to_string))
        })
        .unwrap_or_default();
    for dir in [
        format!("/sys/fs/cgroup{}", own.trim_end_matches('/')),
        "/sys/fs/cgroup".into(),
    ] {
        if let Some(limit) = number(read(&format!("{dir}/memory.max"))) {
            let used = number(read(&format!("{dir}/memory.current"))).unwrap_or(0.0);
            return (limit < UNLIMITED).then_some((limit, used));
        }
    }
    let limit = number(read("/sys/fs/cgroup/memory/memory.limit_in_bytes"))?;
    let used = number(read("/sys/fs/cgroup/memory/memory.usage_in_bytes")).unwrap_or(0.0);
    (limit < UNLIMITED).then_some((limit, used))
}

/// What is counted: the particles of each body so far (its field and count) and
/// the elements of the mesh.
pub(crate) struct Counts {
    /// `(field, particles)` of each body counted (the field that sets its lattice).
    pub bodies: Vec<(String, f64)>,
    /// Elements of the mesh (triangles in 2D).
    pub elements: f64,
    /// `elements` is the fewest a mesher can make, counted before it runs.
    pub elements_at_least: bool,
    /// Whether the bodies not counted yet (placed later) exist.
    pub partial: bool,
    /// Whether the mesh and the basis are built (their memory is in use, not to
    /// come).
    pub basis_built: bool,
}

impl Counts {
    /// The particles of `scene`'s box bodies (exact from the scene; the other
    /// shapes are counted once placed, [`Counts::placed`]) on `elements` elements.
    pub fn from_scene(scene: &Scene, elements: usize) -> Counts {
        let mut bodies = Vec::new();
        let mut partial = false;
        for (b, body) in scene.bodies.iter().enumerate() {
            if body.shape == BodyShape::Box {
                bodies.push((
                    count_field(b, body),
                    scene.estimated_particles(body).round(),
                ));
            } else {
                partial = true;
            }
        }
        Counts {
            bodies,
            elements: elements as f64,
            elements_at_least: false,
            partial,
            basis_built: false,
        }
    }

    /// The particles placed in each body, `body_sizes[b]` in body `b`, on
    /// `elements` elements.
    pub fn placed(scene: &Scene, body_sizes: &[usize], elements: usize) -> Counts {
        Counts {
            bodies: scene
                .bodies
                .iter()
                .zip(body_sizes)
                .enumerate()
                .map(|(b, (body, &n))| (count_field(b, body), n as f64))
                .collect(),
            elements: elements as f64,
            elements_at_least: false,
            partial: false,
            basis_built: true,
        }
    }
}

/// The elements of a generated mesh, known from the scene before it is built
/// (`None` for a polygon or Gmsh mesh: counted once built).
pub(crate) fn generated_elements(scene: &Scene) -> Option<usize> {
    match scene.mesh {
        // Four triangles per block (`four-triangles`; `delaunay` of corners and
        // centres makes about as many).
        MeshSpec::Blocks { blocks, .. } => Some(4 * blocks[0] * blocks[1]),
        MeshSpec::Interval { elements, .. } => Some(elements),
        MeshSpec::Polygon { .. } | MeshSpec::Gmsh { .. } => None,
    }
}

/// The field of the scene's mesh that sets its number of elements.
pub(crate) fn mesh_field(scene: &Scene) -> &'static str {
    match scene.mesh {
        MeshSpec::Blocks { .. } => "mesh.blocks",
        MeshSpec::Polygon { .. } => "mesh.edge_length",
        MeshSpec::Gmsh { .. } => "mesh.file",
        MeshSpec::Interval { .. } => "mesh.elements",
    }
}

/// Refuses the run of `scene` when the lower bound of its memory for `counts` is
/// above the [`room`] the process can see; the error names the field that weighs
/// most (the largest body's lattice, or the mesh) and what to change.
pub(crate) fn check(scene: &Scene, counts: &Counts) -> Result<(), SceneError> {
    check_against(scene, counts, room())
}

/// [`check`] against a given room (`None`: no limit seen, nothing refused).
pub(crate) fn check_against(
    scene: &Scene,
    counts: &Counts,
    room: Option<Room>,
) -> Result<(), SceneError> {
    let Some(room) = room else {
        return Ok(());
    };
    let mut footprint = Footprint::of(scene.basis, scene.mass);
    let output = scene.output.output_bytes_per_particle.max(0.0);
    footprint.per_particle += output;
    // (`+ 0.0`: the sum of no body is −0, which would print as "-0 particles".)
    let particles: f64 = counts.bodies.iter().map(|b| b.1).sum::<f64>() + 0.0;
    // Until every body is placed (`partial`), the driver counts as for a compact
    // system (the bodies to come may be small): the check once they are, before
    // the driver allocates, counts what the bodies need; the mesh and basis are
    // counted whole at every check.
    let compact = counts.partial || certainly_compact(particles, counts.elements);
    let per_element = footprint.per_element(counts.basis_built, compact);
    let element_bytes = counts.elements * per_element;
    let need =
        (particles * footprint.per_particle + element_bytes) * (1.0 + HEADROOM) + HEADROOM_BYTES;
    if need <= room.bytes {
        return Ok(());
    }
    let largest = counts
        .bodies
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|b| b.1 * footprint.per_particle >= element_bytes);
    // With an address-space limit, every thread's allocator arena reserves up to
    // 64 MB of address space (glibc) that the limit counts before anything is
    // resident: a user's 64-triangle scene under `ulimit -v 400000` was refused
    // with `--threads 8` and ran with 2, told to coarsen its mesh.
    let threads = crate::threads::current();
    let arenas = threads.saturating_sub(1) as f64 * ARENA_BYTES;
    let by_threads =
        room.limit == ADDRESS_SPACE_LIMIT && threads > 1 && need <= room.bytes.max(0.0) + arenas;
    let (field, fix) = match largest {
        Some((field, _)) => (
            field.clone(),
            "give fewer particles (a larger spacing or fewer per block or per triangle)"
                .to_string(),
        ),
        None => (
            mesh_field(scene).to_string(),
            format!(
                "give a coarser mesh (fewer elements: it is the larger part){}",
                if scene.basis == BasisKind::Ps {
                    ", or `basis = \"pl\"`, whose elements need several times less memory"
                } else {
                    ""
                }
            ),
        ),
    };
    let fix = if by_threads {
        format!(
            "run with fewer threads (`--threads 1` or 2: each of the {threads} reserves up to 64 MB of address space for its allocator, which the limit counts), or {fix}"
        )
    } else {
        fix
    };
    let element = if scene.dim == 1 {
        "elements"
    } else {
        "triangles"
    };
    let (need_text, room_text) = two_amounts(need, room.bytes.max(0.0));
    Err(SceneError::new(
        field,
        ErrorKind::Value,
        format!(
            "the run would need about {}{} ({} particles at {} B each{}, {}{} {element}{} at {} B each, `{}` basis, `{}` mass{}; and {} % more, and 64 MB, that the allocator and threads reserve), more than the {} this process may still use by {}: {fix}, or run where more memory is allowed",
            need_text,
            if counts.basis_built { " besides its mesh and basis" } else { "" },
            echo_number(particles),
            footprint.per_particle,
            if output > 0.0 {
                format!(", {output} of them to write the output")
            } else {
                String::new()
            },
            if counts.elements_at_least { "at least " } else { "" },
            echo_number(counts.elements),
            if counts.elements_at_least {
                " (the domain's area over the largest triangle the mesher leaves, √3/4 · edge_length²; counted before meshing)"
            } else {
                ""
            },
            per_element,
            scene.basis.name(),
            scene.mass.spec(),
            if counts.partial {
                "; bodies not yet placed are not counted"
            } else {
                ""
            },
            HEADROOM * 100.0,
            room_text,
            room.limit,
        ),
    ))
}

/// Bytes in the unit a reader takes in at a glance, with `extra` more digits.
fn bytes(b: f64, extra: usize) -> String {
    if b >= 1e9 {
        format!("{:.*} GB", 1 + extra, b / 1e9)
    } else {
        format!("{:.*} MB", extra, b / 1e6)
    }
}

/// The need and the room in [`bytes`], with as many more digits (up to 3) as it
/// takes for a need above the room not to print as the same amount ("about 1.0
/// GB …, more than the 1.0 GB").
fn two_amounts(need: f64, room: f64) -> (String, String) {
    let mut extra = 0;
    while extra < 3 && bytes(need, extra) == bytes(room, extra) {
        extra += 1;
    }
    (bytes(need, extra), bytes(room, extra))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_address_space_limit_is_read_from_the_limits_file() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max stack size            8388608              unlimited            bytes     \n\
                      Max address space         1536000000           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limits), Some(1536000000.0));
        let unlimited = limits.replace("1536000000", "unlimited");
        assert_eq!(address_space_limit(&unlimited), None);
        assert_eq!(
            kb_field("VmSize:\t  123 kB\n", "VmSize:"),
            Some(123.0 * 1024.0)
        );
    }

    #[test]
    fn a_control_group_without_a_limit_is_no_limit() {
        let files = |max: &'static str| {
            move |path: &str| match path {
                "/proc/self/cgroup" => Some("0::/job\n".to_string()),
                "/sys/fs/cgroup/job/memory.max" => Some(format!("{max}\n")),
                "/sys/fs/cgroup/job/memory.current" => Some("1000\n".to_string()),
                _ => None,
            }
        };
        assert_eq!(cgroup_limit(&files("max")), None);
        assert_eq!(cgroup_limit(&files("5000")), Some((5000.0, 1000.0)));
    }

    fn scene() -> Scene {
        Scene::from_toml(
            r#"
name = "big"
dim = 2
basis = "ps"
[mesh]
kind = "blocks"
x = [0.0, 4.0]
y = [0.0, 4.0]
blocks = [64, 64]
[material]
model = "linear-elastic"
young = 1e5
poisson = 0.3
density = 1000.0
[[body]]
min = [1.0, 1.0]
max = [3.0, 3.0]
per_block = [8, 8]
[time]
dt = 1e-5
t_end = 1e-4
"#,
            "big.toml",
        )
        .unwrap()
    }

    /// A run above the room names the weightier part and the limit; one below it,
    /// or without a limit seen, runs.
    #[test]
    fn a_run_that_cannot_fit_names_its_weightiest_part() {
        let scene = scene();
        let room = |bytes: f64| {
            Some(Room {
                bytes,
                limit: "a test's limit",
            })
        };
        let many_particles = Counts {
            bodies: vec![("body[0].per_block".into(), 9e6)],
            elements: 16384.0,
            elements_at_least: false,
            partial: false,
            basis_built: false,
        };
        let e = check_against(&scene, &many_particles, room(1.5e9)).unwrap_err();
        assert_eq!(e.field, "body[0].per_block");
        assert!(e.message.contains("about 4.8 GB ("), "{}", e.message);
        assert!(
            e.message
                .contains("1.5 GB this process may still use by a test's limit"),
            "{}",
            e.message
        );
        assert!(e.message.contains("fewer particles"), "{}", e.message);
        assert!(check_against(&scene, &many_particles, room(5e9)).is_ok());
        assert!(check_against(&scene, &many_particles, None).is_ok());
        let big_mesh = Counts {
            bodies: vec![("body[0].per_block".into(), 65536.0)],
            elements: 1e6,
            elements_at_least: false,
            partial: true,
            basis_built: false,
        };
        let e = check_against(&scene, &big_mesh, room(1.5e9)).unwrap_err();
        assert_eq!(e.field, "mesh.blocks");
        assert!(e.message.contains("coarser mesh"), "{}", e.message);
        assert!(
            e.message.contains("bodies not yet placed are not counted"),
            "{}",
            e.message
        );
        // A small body on that mesh covers under a quarter of the functions: the compact
        // figure, unless bodies placed later may cover more.
        let small_body = Counts {
            bodies: vec![("body[0].per_block".into(), 144.0)],
            elements: 4e5,
            elements_at_least: false,
            partial: false,
            basis_built: true,
        };
        let compact = check_against(&scene, &small_body, room(5e8)).unwrap_err();
        assert!(
            compact.message.contains("at 1800 B each"),
            "{}",
            compact.message
        );
        // A body large enough to make it: the whole factorisation; until every
        // body is placed, the compact figure (the last check counts them all).
        let large_body = Counts {
            bodies: vec![("body[0].per_block".into(), 1e5)],
            ..small_body
        };
        let whole = check_against(&scene, &large_body, room(5e8)).unwrap_err();
        assert!(
            whole.message.contains("at 3200 B each"),
            "{}",
            whole.message
        );
        let later = Counts {
            partial: true,
            ..large_body
        };
        let early = check_against(&scene, &later, room(5e8)).unwrap_err();
        assert!(
            early.message.contains("at 1800 B each"),
            "{}",
            early.message
        );
        assert!(certainly_compact(144.0, 4e5) && !certainly_compact(144.0, 2500.0));
        // A need just above the room prints with the digits that tell them apart.
        assert_eq!(
            two_amounts(1.04e9, 1.01e9),
            ("1.04 GB".to_string(), "1.01 GB".to_string())
        );
        assert_eq!(
            two_amounts(4.9e9, 1.4e9),
            ("4.9 GB".to_string(), "1.4 GB".to_string())
        );
        assert_eq!(
            two_amounts(7.2e8, 6.9e8),
            ("720 MB".to_string(), "690 MB".to_string())
        );
        // No body placed yet (a disk, placed after the mesh): 0 particles, not −0.
        let no_body = Counts {
            bodies: Vec::new(),
            ..big_mesh
        };
        let e = check_against(&scene, &no_body, room(1.5e9)).unwrap_err();
        assert!(e.message.contains("(0 particles at "), "{}", e.message);
    }

    /// This machine's room is read and is positive.
    #[test]
    #[cfg(target_os = "linux")]
    fn the_room_is_seen_on_linux() {
        let room = room().expect("/proc is readable");
        assert!(room.bytes > 0.0, "{room:?}");
    }
}
