//! The cache of reference runs: the key of a run, its file name, and the JSON
//! files of [`History`].

use super::config::{InitialVelocity, UlFemConfig, UlFemError};
use super::history::{reference_history, validate_run, History};
use std::path::Path;

/// Version of the cache format and of the solver; part of every key.
pub const CACHE_VERSION: u32 = 1;

/// The deterministic key of a reference run: every input, floats in Rust's
/// shortest round-trip form.
pub fn history_key(
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> String {
    let c = config;
    format!(
        "psmpm-ulfem v{CACHE_VERSION}; length={:?}; elements={}; young={:?}; density={:?}; \
         gravity={:?}; left={:?}; right={:?}; dt={:?}; mass={:?}; initial={:?}; \
         samples={:?}; output_every={}; t_end={:?}",
        c.length,
        c.elements,
        c.young,
        c.density,
        c.gravity,
        c.left,
        c.right,
        c.dt,
        c.mass,
        initial_velocity,
        sample_points,
        output_every,
        t_end
    )
}

/// 64-bit FNV-1a hash (offset basis `0xcbf29ce484222325`, prime `0x100000001b3`):
/// deterministic across runs and platforms, unlike std's hasher.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// File name of a cached history: `ulfem-<fnv1a64(key) in 16 hex digits>.json`.
pub fn cache_file_name(key: &str) -> String {
    format!("ulfem-{:016x}.json", fnv1a64(key.as_bytes()))
}

/// [`reference_history`], read from or stored in the cache directory `dir` (`None`:
/// no cache, the history is computed). The library never chooses the directory:
/// `mpm-cli` resolves it from the environment (see the module documentation).
/// The directory is created if needed; the file is written to a temporary name and
/// renamed, so concurrent runs never read a partial file. Cache failures are silent:
/// the history is then computed.
pub fn cached_reference_history(
    dir: Option<&Path>,
    config: &UlFemConfig,
    initial_velocity: InitialVelocity,
    sample_points: &[f64],
    output_every: usize,
    t_end: f64,
) -> Result<History, UlFemError> {
    validate_run(config, initial_velocity, sample_points, output_every, t_end)?;
    let key = history_key(config, initial_velocity, sample_points, output_every, t_end);
    let path = dir.map(|d| d.join(cache_file_name(&key)));
    if let Some(path) = &path {
        if let Some(history) = std::fs::read(path)
            .ok()
            .and_then(|bytes| serde_json::from_slice::<History>(&bytes).ok())
            .filter(|h| h.key == key)
        {
            return Ok(history);
        }
    }
    let history = reference_history(config, initial_velocity, sample_points, output_every, t_end)?;
    if let (Some(dir), Some(path)) = (dir, &path) {
        let _ = write_atomically(dir, path, &history);
    }
    Ok(history)
}

fn write_atomically(dir: &Path, path: &Path, history: &History) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let bytes = serde_json::to_vec(history).map_err(std::io::Error::other)?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    let tmp = path.with_extension(format!("json.tmp-{}-{nanos}", std::process::id()));
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::ulfem::fixtures::small;
    use crate::studies::ulfem::{End, UlMass};

    #[test]
    fn fnv1a_reference_values() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn key_lists_every_input() {
        let c = small(UlMass::Lumped);
        let rest = InitialVelocity::Rest;
        let base = history_key(&c, rest, &[1.0], 1, 1.0);
        let variants = [
            history_key(&UlFemConfig { length: 2.5, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { elements: 11, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { young: 101.0, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { density: 3.0, ..c }, rest, &[1.0], 1, 1.0),
            history_key(&UlFemConfig { gravity: 0.0, ..c }, rest, &[1.0], 1, 1.0),
            history_key(
                &UlFemConfig {
                    left: End::Free,
                    ..c
                },
                rest,
                &[1.0],
                1,
                1.0,
            ),
            history_key(
                &UlFemConfig {
                    right: End::Fixed,
                    ..c
                },
                rest,
                &[1.0],
                1,
                1.0,
            ),
            history_key(&UlFemConfig { dt: 2e-4, ..c }, rest, &[1.0], 1, 1.0),
            history_key(
                &UlFemConfig {
                    mass: UlMass::Consistent,
                    ..c
                },
                rest,
                &[1.0],
                1,
                1.0,
            ),
            history_key(&c, InitialVelocity::SineMode { v0: 0.0 }, &[1.0], 1, 1.0),
            history_key(&c, rest, &[1.0 + 1e-15], 1, 1.0),
            history_key(&c, rest, &[1.0], 2, 1.0),
            history_key(&c, rest, &[1.0], 1, 1.5),
        ];
        let mut names: Vec<String> = variants.iter().map(|k| cache_file_name(k)).collect();
        names.push(cache_file_name(&base));
        for k in &variants {
            assert_ne!(k, &base);
        }
        names.sort();
        names.dedup();
        assert_eq!(names.len(), variants.len() + 1);
        assert_eq!(base, history_key(&c, rest, &[1.0], 1, 1.0));
    }
}
