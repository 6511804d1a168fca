//! Limits on every size that untrusted input (a scene file, a mesh file, the command
//! line) controls, checked before anything of that size is allocated or computed.
//!
//! [`Scene::validate`](super::Scene::validate) checks them, so every command that
//! reads a scene gets them; the command line checks its overrides against the same
//! constants. An error names the value and the limit.

use std::io::Read;
use std::path::Path;

/// Most time steps a run may take (`t_end / dt`, with command-line overrides).
pub const MAX_STEPS: usize = 10_000_000;
/// Most particles a scene may have.
pub const MAX_PARTICLES: usize = 10_000_000;
/// Most blocks a `blocks` mesh may have in all.
pub const MAX_BLOCKS: usize = 1_000_000;
/// Most blocks of a `blocks` mesh along one axis.
pub const MAX_BLOCKS_PER_AXIS: usize = 4096;
/// Most elements of a 1D `interval` mesh.
pub const MAX_ELEMENTS_1D: usize = 1_000_000;
/// Most triangles a `polygon` mesh may be expected to have (estimated from the area
/// of the outline's bounding box and the edge length, before meshing).
pub const MAX_TRIANGLES: usize = 4_000_000;
/// Most corners of a `polygon` mesh's outline and holes together.
pub const MAX_OUTLINE_CORNERS: usize = 100_000;
/// Most point-in-polygon edge tests the polygon bodies may cost: placing a polygon
/// body's particles and checking that no other body's particle lies inside it test
/// up to every particle of the scene against every corner of the polygon (about 10 s
/// at the limit).
pub const MAX_POLYGON_TESTS: f64 = 1e10;
/// Most points `output.tracked` may list (the nearest particle of each is found
/// among all particles, and each is recorded every step).
pub const MAX_TRACKED: usize = 1000;
/// Most samples of the tracked particles' history a run may record: tracked points
/// × steps (each sample holds the time, the displacement and the velocity, and with
/// a reference the exact ones: 72 bytes, so 720 MB at the limit; 1000 points over
/// 100 steps took 81 MB, over 1000 steps 714 MB). One point over [`MAX_STEPS`]
/// steps is within it.
pub const MAX_TRACKED_SAMPLES: usize = 10_000_000;

/// The error of `points` tracked points over `steps` steps when their history
/// ([`MAX_TRACKED_SAMPLES`]) would be too large; `how` says where the steps come
/// from (`t_end / dt`, or the Courant number).
pub fn check_tracked_history(points: usize, steps: usize, how: &str) -> Result<(), String> {
    let samples = points.saturating_mul(steps);
    if samples > MAX_TRACKED_SAMPLES {
        return Err(format!(
            "{points} tracked points over {steps} steps ({how}) record {samples} samples, above the limit of {MAX_TRACKED_SAMPLES} (points × steps, each kept in memory for tracked.csv): track fewer points, or take fewer steps (a shorter `t_end` or a longer step)"
        ));
    }
    Ok(())
}

/// Most particle frames `run --out` writes.
pub const MAX_FRAMES: usize = 100_000;
/// Most rows `run --format table` collects (it aligns them at the end); more need
/// `--format csv` or `json`, which stream.
pub const MAX_TABLE_ROWS: usize = 100_000;
/// Most threads `--threads` may ask for.
pub const MAX_THREADS: usize = 1024;
/// Largest initial speed of a body, m/s (a third of the speed of light: beyond it a
/// value is a unit slip, not a continuum's motion).
pub const MAX_SPEED: f64 = 1e8;
/// Largest Gmsh mesh file read, in bytes.
pub const MAX_MESH_FILE_BYTES: u64 = 256 * 1024 * 1024;
/// Largest scene file read, in bytes.
pub const MAX_SCENE_FILE_BYTES: u64 = 4 * 1024 * 1024;
/// Most characters of user text echoed in a message (longer text is cut).
pub const MAX_ECHO_CHARS: usize = psmpm_basis::mesh::gmsh::MAX_SHOWN_CHARS;

/// Reads the regular file `path` of at most `limit` bytes. Devices, FIFOs and
/// sockets are refused before they are opened (so that `/dev/zero` or a FIFO can
/// neither exhaust memory nor block), a directory fails to read; the size is checked
/// again while reading. The error says what is wrong (`cannot read: …`, `is N bytes,
/// above the limit …`) without the path.
pub fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let cannot = |e: std::io::Error| format!("cannot read: {e}");
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() && !meta.is_dir() {
        return Err("cannot read: not a regular file (a device, FIFO or socket)".into());
    }
    let too_big = |size: u64| format!("is {size} bytes, above the limit of {limit} bytes");
    if meta.is_file() && meta.len() > limit {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(cannot)?;
    let mut bytes = Vec::with_capacity(meta.len().min(limit) as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > limit {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Reads a Gmsh `.msh` file: a regular file of at most [`MAX_MESH_FILE_BYTES`] (the
/// error names the file).
pub fn read_mesh(file: &str) -> Result<psmpm_basis::TriMesh, String> {
    let bytes = read_bounded(Path::new(file), MAX_MESH_FILE_BYTES)
        .map_err(|e| format!("{}: {e}", echo(file)))?;
    psmpm_basis::mesh::gmsh::parse_msh(&String::from_utf8_lossy(&bytes), file)
        .map_err(|e| e.to_string())
}

/// Most characters of a scene's `name` (printed in tables and titles).
pub const MAX_NAME_CHARS: usize = 200;

/// Most characters of a scene's `description` (one line).
pub const MAX_DESCRIPTION_CHARS: usize = 2000;

/// User text as it is echoed in messages: control characters escaped (`\n`,
/// `\u{1b}`, …) and cut to [`MAX_ECHO_CHARS`] characters with an ellipsis, as
/// the Gmsh reader shows a mesh file's text
/// ([`psmpm_basis::mesh::gmsh::shown`]).
pub fn echo(text: &str) -> String {
    psmpm_basis::mesh::gmsh::shown(text)
}

/// Names of the mesh (tags, physical groups) as a message lists them: each
/// [`echo`]ed in backticks, at most 20 of them and then how many more; for no
/// name at all, what a mesh file needs to have one.
pub fn echo_tags(tags: &[String]) -> String {
    if tags.is_empty() {
        return "none (a .msh file tags boundary edges with physical curve groups; \
                format 4.1 lists them in `$Entities`)"
            .to_string();
    }
    let mut shown: Vec<String> = tags
        .iter()
        .take(20)
        .map(|t| format!("`{}`", echo(t)))
        .collect();
    if tags.len() > 20 {
        shown.push(format!("and {} more", tags.len() - 20));
    }
    shown.join(", ")
}

/// A number as it is echoed in messages: Rust's shortest round-trip digits, in
/// exponent notation outside `1e-4 ≤ |x| < 1e16`, so that no value (`1e-320`,
/// `1e300`) is printed as hundreds of digits.
pub fn echo_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` rounded to `digits` significant digits (at least 1), so that `{}` prints it
/// without the noise of the last bits (`0.0526996739197737` to 3: `0.0527`).
pub fn significant(x: f64, digits: usize) -> f64 {
    format!("{x:.*e}", digits.max(1) - 1).parse().unwrap_or(x)
}

/// [`echo_number`] of `x` rounded to `digits` significant digits ([`significant`]).
pub fn echo_significant(x: f64, digits: usize) -> String {
    echo_number(significant(x, digits))
}

/// `n` with the noun that agrees with it, for messages: `1 entry`, `2 entries`,
/// `0 entries`.
pub fn plural(n: usize, one: &str, many: &str) -> String {
    if n == 1 {
        format!("1 {one}")
    } else {
        format!("{n} {many}")
    }
}

/// A number with `decimals` fixed decimals in a message (`{:.2}`), in exponent
/// notation with as many decimals from 1e6 up, so that a huge value is not printed
/// with hundreds of digits.
pub fn echo_fixed(x: f64, decimals: usize) -> String {
    if x.abs() < 1e6 || !x.is_finite() {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.decimals$e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plural_agrees_with_the_count() {
        assert_eq!(plural(1, "entry", "entries"), "1 entry");
        assert_eq!(plural(2, "entry", "entries"), "2 entries");
        assert_eq!(plural(0, "entry", "entries"), "0 entries");
    }

    #[test]
    fn echo_number_is_short() {
        assert_eq!(echo_number(-100.0), "-100");
        assert_eq!(echo_number(0.25), "0.25");
        assert_eq!(echo_number(0.0), "0");
        assert_eq!(echo_number(f64::NAN), "NaN");
        assert_eq!(echo_number(1e-320), "1e-320");
        assert_eq!(echo_number(-2.5e300), "-2.5e300");
        assert_eq!(echo_number(1e15), "1000000000000000");
    }

    #[test]
    fn mesh_tags_are_listed_escaped_and_bounded() {
        assert_eq!(
            echo_tags(&["a".into(), "b\u{1b}".into()]),
            "`a`, `b\\u{1b}`"
        );
        let many: Vec<String> = (0..25).map(|i| i.to_string()).collect();
        assert!(echo_tags(&many).ends_with("`19`, and 5 more"));
        assert!(echo_tags(&[]).contains("$Entities"));
    }

    #[test]
    fn numbers_are_rounded_to_significant_digits() {
        assert_eq!(significant(0.0526996739197737, 3), 0.0527);
        assert_eq!(echo_significant(1886.97, 4), "1887");
        assert_eq!(echo_significant(4.63654203317802, 3), "4.64");
        assert_eq!(echo_significant(1.2345e300, 2), "1.2e300");
    }

    #[test]
    fn echo_escapes_and_cuts() {
        assert_eq!(echo("a\nb\u{1b}[31m"), "a\\nb\\u{1b}[31m");
        let long = "x".repeat(200);
        let e = echo(&long);
        assert_eq!(e.chars().count(), MAX_ECHO_CHARS + 1);
        assert!(e.ends_with('…'));
        assert_eq!(echo("ok"), "ok");
    }

    #[test]
    fn read_bounded_refuses_directories_and_big_files() {
        let dir = std::env::temp_dir();
        assert!(read_bounded(&dir, 10).unwrap_err().contains("cannot read"));
        assert!(read_bounded(Path::new("/dev/zero"), 10)
            .unwrap_err()
            .contains("not a regular file"));
        let file = dir.join(format!("psmpm-limits-{}", std::process::id()));
        std::fs::write(&file, b"0123456789ab").unwrap();
        assert!(read_bounded(&file, 10).unwrap_err().contains("limit of 10"));
        assert_eq!(read_bounded(&file, 12).unwrap().len(), 12);
        let _ = std::fs::remove_file(&file);
    }
}
