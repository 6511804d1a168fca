//! The output files read back by an independent reader: Python's `meshio`
//! (pinned in `.ci/run`), so that what ParaView-style tools see is what was written.
//!
//! These tests need `python3` with `meshio`; they fail (never skip) without them.

mod common;

use common::meshio::{array, read_back};
use common::TempDir;
use nalgebra::{Matrix1, Matrix2, Vector1, Vector2};
use psmpm::output::dir::{is_frame, prepare_dir, OutputDir, OutputError};
use psmpm::output::vtk::VtuEncoding;
use psmpm::particles::Particles;
use psmpm_basis::mesh::generators::block_grid;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The `.vtu` entry of the reader's JSON for `path`.
fn vtu<'a>(json: &'a Value, path: &Path) -> &'a Value {
    &json["vtu"][path.to_str().unwrap()]
}

/// Bit-for-bit equality of float arrays (so `-0.0` and `0.0` differ).
fn assert_exact(name: &str, got: &[f64], expected: &[f64]) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(
        bits(got),
        bits(expected),
        "{name}: read {got:?}, wrote {expected:?}"
    );
}

/// The cell blocks as `(type, connectivity)`.
fn cells(value: &Value) -> Vec<(String, Vec<Vec<usize>>)> {
    serde_json::from_value(value["cells"].clone()).unwrap()
}

/// Checks a particle file against `p`: points, one vertex per particle, and each
/// point-data array in the documented layout.
fn check_particles<const D: usize>(file: &Value, p: &Particles<f64, D>) {
    let n = p.len();
    let pad =
        |v: &[f64]| -> Vec<f64> { (0..3).map(|k| v.get(k).copied().unwrap_or(0.0)).collect() };
    let vec3 = |vs: &[nalgebra::SVector<f64, D>]| -> Vec<f64> {
        vs.iter().flat_map(|v| pad(v.as_slice())).collect()
    };

    let (shape, points) = array(&file["points"]);
    assert_eq!(shape, [n, 3]);
    assert_exact("points", &points, &vec3(&p.x));

    let expected_cells: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
    assert_eq!(cells(file), [("vertex".to_string(), expected_cells)]);

    let data = file["point_data"].as_object().unwrap();
    let mut names: Vec<&str> = data.keys().map(|k| k.as_str()).collect();
    names.sort();
    assert_eq!(
        names,
        ["displacement", "mass", "stress", "velocity", "volume"]
    );
    for (name, components, expected) in [
        ("velocity", 3, vec3(&p.v)),
        ("displacement", 3, vec3(&p.u)),
        ("volume", 0, p.volume.clone()),
        ("mass", 0, p.mass.clone()),
        (
            "stress",
            9,
            p.sigma
                .iter()
                .flat_map(|s| {
                    (0..9).map(move |k| {
                        let (r, c) = (k / 3, k % 3);
                        if r < D && c < D {
                            s[(r, c)]
                        } else {
                            0.0
                        }
                    })
                })
                .collect(),
        ),
    ] {
        let (shape, values) = array(&data[name]);
        let expected_shape = if components == 0 {
            vec![n]
        } else {
            vec![n, components]
        };
        assert_eq!(shape, expected_shape, "shape of {name}");
        assert_exact(name, &values, &expected);
    }
}

/// Three 2D particles whose every value differs (and a non-symmetric stress, to
/// pin the component order).
fn particles_2d(shift: f64) -> Particles<f64, 2> {
    let mut p = Particles::new(
        vec![
            Vector2::new(0.1 + shift, 0.2),
            Vector2::new(0.7, 1.0 / 3.0),
            Vector2::new(-1.5e-7, 9.75),
        ],
        vec![0.01, 0.02, 1.0 / 7.0],
        1000.0,
    );
    for i in 0..3 {
        let a = i as f64 + shift;
        p.v[i] = Vector2::new(1.0 + a, -2.0 - a / 3.0);
        p.u[i] = Vector2::new(1e-5 * (a + 1.0), -0.0 - a);
        p.sigma[i] = Matrix2::new(1e5 * (a + 1.0), 2.5 + a, -3.25 - a, 4e-3 * a);
        p.volume[i] *= 1.0 + 0.1 * a;
    }
    p
}

#[test]
fn particles_2d_mesh_and_collection_read_back_with_meshio() {
    let dir = TempDir::new("2d");
    let mut out = OutputDir::create(dir.join("run"), 2).unwrap();

    // Steps 0..=4 at cadence 2: frames at steps 0, 2, 4.
    let dt = 0.125;
    let mut written = Vec::new();
    for step in 0..=4 {
        let p = particles_2d(step as f64);
        if out.particles_frame(step, step as f64 * dt, &p).unwrap() {
            written.push((step as f64 * dt, p));
        }
    }
    assert_eq!(written.len(), 3);

    let mesh = block_grid(0.0, 1.0, 0.0, 1.0, 2, 2).unwrap();
    let field: Vec<f64> = mesh
        .vertices()
        .iter()
        .map(|v| v.x * v.x - v.y / 3.0)
        .collect();
    let mesh_path = out
        .write_mesh(&mesh, Some(("temperature", &field)))
        .unwrap();
    let pvd = out.finish().unwrap();
    assert_eq!(mesh_path, dir.join("run/mesh.vtu"));
    assert_eq!(pvd, dir.join("run/particles.pvd"));

    let frames: Vec<PathBuf> = (0..3)
        .map(|i| dir.join(format!("run/particles_{i:05}.vtu")))
        .collect();
    let mut files = frames.clone();
    files.push(mesh_path.clone());
    files.push(pvd.clone());
    let json = read_back(&files);

    for (path, (_, p)) in frames.iter().zip(&written) {
        check_particles(vtu(&json, path), p);
    }

    // The mesh: vertices, triangles, the element index and the caller's field.
    let m = vtu(&json, &mesh_path);
    let (shape, points) = array(&m["points"]);
    assert_eq!(shape, [mesh.num_vertices(), 3]);
    let expected: Vec<f64> = mesh
        .vertices()
        .iter()
        .flat_map(|v| [v.x, v.y, 0.0])
        .collect();
    assert_exact("mesh points", &points, &expected);
    let triangles: Vec<Vec<usize>> = mesh.triangles().iter().map(|t| t.to_vec()).collect();
    assert_eq!(triangles.len(), 16);
    assert_eq!(cells(m), [("triangle".to_string(), triangles)]);
    let element: Vec<Vec<usize>> =
        serde_json::from_value(m["cell_data"]["element"].clone()).unwrap();
    assert_eq!(element, [(0..16).collect::<Vec<usize>>()]);
    let (shape, values) = array(&m["point_data"]["temperature"]);
    assert_eq!(shape, [mesh.num_vertices()]);
    assert_exact("temperature", &values, &field);

    // The collection: times and relative file names, in order, files present.
    let entries: Vec<(String, String)> =
        serde_json::from_value(json["pvd"][pvd.to_str().unwrap()].clone()).unwrap();
    assert_eq!(entries.len(), 3);
    for (i, ((time, file), (t, _))) in entries.iter().zip(&written).enumerate() {
        assert_eq!(time.parse::<f64>().unwrap(), *t);
        assert_eq!(*file, format!("particles_{i:05}.vtu"));
        assert!(dir.join("run").join(file).is_file());
    }
    let text = std::fs::read_to_string(&pvd).unwrap();
    assert!(text.contains("<VTKFile type=\"Collection\""));
    assert_eq!(text.matches("<DataSet ").count(), 3);
    assert!(text.contains("timestep=\"2.5e-1\""), "{text}");
    assert_eq!(out.frames().len(), 3);
}

#[test]
fn particles_1d_read_back_with_meshio() {
    let dir = TempDir::new("1d");
    let mut out = OutputDir::create(dir.path(), 1).unwrap();
    let mut p = Particles::new(
        vec![
            Vector1::new(0.125),
            Vector1::new(2.5),
            Vector1::new(-1.0 / 3.0),
            Vector1::new(7.0),
        ],
        vec![0.25, 0.5, 0.75, 1.0],
        7800.0,
    );
    for i in 0..p.len() {
        let a = i as f64;
        p.v[i] = Vector1::new(0.3 * a - 1.0);
        p.u[i] = Vector1::new(-1e-9 * (a + 1.0));
        p.sigma[i] = Matrix1::new(-2e8 + a);
        p.volume[i] = 0.25 * (a + 1.0) * (1.0 + 1e-3 * a);
    }
    let path = out.write_particles(0.5, &p).unwrap();
    let pvd = out.finish().unwrap();
    let json = read_back(&[path.clone(), pvd.clone()]);
    check_particles(vtu(&json, &path), &p);
    let entries: Vec<(String, String)> =
        serde_json::from_value(json["pvd"][pvd.to_str().unwrap()].clone()).unwrap();
    assert_eq!(
        entries,
        [("0.5".to_string(), "particles_00000.vtu".to_string())]
    );
}

#[test]
fn an_output_directory_that_cannot_be_created_is_an_error() {
    let dir = TempDir::new("blocked");
    std::fs::create_dir_all(dir.path()).unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "not a directory").unwrap();
    let err = OutputDir::create(file.join("out"), 1).unwrap_err();
    assert!(matches!(err, OutputError::CreateDir { .. }), "{err:?}");
    let message = err.to_string();
    assert!(message.contains("a-file"), "{message}");
    assert!(
        message.starts_with("cannot create output directory"),
        "{message}"
    );
    // The path of an existing file is named as such.
    let err = OutputDir::create(&file, 1).unwrap_err();
    assert!(matches!(err, OutputError::NotADirectory { .. }), "{err:?}");
    assert!(
        err.to_string()
            .contains("a-file` exists and is not a directory"),
        "{err}"
    );
    let err = prepare_dir(&file, true, |_| true).unwrap_err();
    assert!(matches!(err, OutputError::NotADirectory { .. }), "{err:?}");
}

#[test]
fn binary_and_ascii_frames_read_back_the_same() {
    let dir = TempDir::new("encodings");
    let mesh = block_grid(0.0, 1.0, 0.0, 1.0, 3, 2).unwrap();
    let field: Vec<f64> = mesh.vertices().iter().map(|v| v.x - v.y / 7.0).collect();
    // More than one 1 MiB block per array: 20000 particles × 9 stress components.
    let n = 20000;
    let mut p = Particles::new(
        (0..n)
            .map(|i| Vector2::new(i as f64 / 3.0, (i as f64).sqrt()))
            .collect(),
        vec![1.0 / 3.0; n],
        1000.0,
    );
    for i in 0..n {
        let a = i as f64;
        p.v[i] = Vector2::new(a.sin(), -a.cos() / 3.0);
        p.u[i] = Vector2::new(1e-7 * a, -0.0);
        p.sigma[i] = Matrix2::new(a, 1.0 / (a + 1.0), -a * 1e5, 2.5);
    }
    let mut files = Vec::new();
    for (name, encoding) in [
        ("binary", VtuEncoding::Binary),
        ("ascii", VtuEncoding::Ascii),
    ] {
        let mut out = OutputDir::create(dir.join(name), 1)
            .unwrap()
            .with_encoding(encoding);
        assert_eq!(out.encoding(), encoding);
        files.push(out.write_particles(0.0, &p).unwrap());
        files.push(out.write_mesh(&mesh, Some(("f", &field))).unwrap());
    }
    let binary = std::fs::read(&files[0]).unwrap();
    let ascii = std::fs::read(&files[2]).unwrap();
    assert!(
        binary.len() * 3 < ascii.len(),
        "{} vs {}",
        binary.len(),
        ascii.len()
    );
    let head = String::from_utf8_lossy(&binary[..400]);
    assert!(head.contains("header_type=\"UInt64\""), "{head}");
    assert!(
        head.contains("compressor=\"vtkZLibDataCompressor\""),
        "{head}"
    );
    assert!(String::from_utf8_lossy(&ascii).contains("format=\"ascii\""));

    let json = read_back(&files);
    check_particles(vtu(&json, &files[0]), &p);
    check_particles(vtu(&json, &files[2]), &p);
    assert_eq!(vtu(&json, &files[0]), vtu(&json, &files[2]));
    assert_eq!(vtu(&json, &files[1]), vtu(&json, &files[3]));
}

#[test]
fn a_directory_is_reused_only_when_it_holds_output_files() {
    let dir = TempDir::new("reuse");
    let owned = |name: &str| is_frame(name) || name == "particles.pvd";
    // A new directory is created; an empty one is used as it is.
    assert!(prepare_dir(dir.path(), false, owned).unwrap().is_empty());
    assert!(prepare_dir(dir.path(), false, owned).unwrap().is_empty());
    for name in [
        "particles_00000.vtu",
        "particles_00001.vtu",
        "particles.pvd",
    ] {
        std::fs::write(dir.join(name), "x").unwrap();
    }
    // Files of an earlier run: refused without overwrite, naming the directory.
    let err = prepare_dir(dir.path(), false, owned).unwrap_err();
    assert!(
        matches!(err, OutputError::NotEmpty { files: 3, .. }),
        "{err:?}"
    );
    let message = err.to_string();
    assert!(message.contains(dir.path().to_str().unwrap()), "{message}");
    assert!(message.contains("particles_00000.vtu"), "{message}");
    // A file of someone else: refused even with overwrite, and nothing removed.
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let err = prepare_dir(dir.path(), true, owned).unwrap_err();
    assert!(
        matches!(err, OutputError::Foreign { files: 1, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("notes.txt"), "{err}");
    assert!(dir.join("particles_00001.vtu").is_file());
    // With overwrite and only output files: they are removed.
    std::fs::remove_file(dir.join("notes.txt")).unwrap();
    let removed = prepare_dir(dir.path(), true, owned).unwrap();
    assert_eq!(removed.len(), 3);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    assert!(is_frame("particles_123456.vtu"));
    assert!(!is_frame("particles_.vtu") && !is_frame("particles_1a.vtu"));
}
