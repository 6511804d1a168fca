//! Output: the files a user looks at after (or during) a run, apart from the method
//! that computes them. Nothing here feeds back into a simulation.
//!
//! - [`vtk`]: VTK XML `.vtu` snapshots of particles and of the triangular mesh, and
//!   ParaView `.pvd` collections that animate them over time;
//! - [`csv`]: CSV time series (a streaming writer, or named columns at once);
//! - [`dir`]: the output directory the command line's `--out DIR` writes through
//!   ([`OutputDir`](dir::OutputDir)), and [`write_file`](dir::write_file) with its
//!   error [`OutputError`](dir::OutputError);
//! - [`chart`]: SVG line plots (time series, convergence), the plotting error
//!   [`PlotError`](chart::PlotError), colours and legend shared by all figures (their
//!   axes, linear or log10 with nice ticks, are the private `axis` module);
//! - [`mesh_picture`]: the SVG picture of a Powell–Sabin mesh with its refinement and
//!   control triangles;
//! - [`basis_picture`]: the SVG picture of one basis function, shaded by value.
//!
//! # Format
//!
//! Everything is deterministic: the same inputs give byte-identical files (no time
//! stamps, no hash-map order), so output can be diffed and kept in snapshot tests.
//! In the ascii `.vtu`, the `.pvd` and the CSV files every floating-point value is written as
//! `{:e}` of an `f64` (Rust's shortest representation that reads back to the same
//! `f64`, e.g. `1.5e0`, `-2.5e-3`, `0e0`): reading a value back with any correctly
//! rounding parser (Rust, Python, NumPy, ParaView) gives exactly the value that was
//! written; the binary `.vtu` holds the bytes of the `f64` themselves. `f32` simulations are widened to `f64` (exactly) before they are written.
//! The SVG figures have integer pixel coordinates (see [`chart`]).

/// The axis coordinate of every chart, its ticks and tick labels.
mod axis;
pub mod basis_picture;
pub mod chart;
pub mod csv;
pub mod dir;
pub mod mesh_picture;
pub mod particle_picture;
pub mod vtk;

use std::io::{self, Write};

/// An `InvalidInput` io error: inconsistent data handed to a writer.
fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// Writes `x` in the round-trippable `{:e}` format.
fn write_f64<W: Write>(w: &mut W, x: f64) -> io::Result<()> {
    write!(w, "{x:e}")
}

#[cfg(test)]
mod tests {
    use super::{csv, vtk};
    use crate::particles::Particles;
    use nalgebra::{Matrix2, Vector2};

    pub(super) fn awkward_values() -> Vec<f64> {
        vec![
            0.0,
            -0.0,
            0.1,
            1.0 / 3.0,
            -2.5e-3,
            1e300,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            std::f64::consts::PI,
            123456789.0,
            -1.0,
        ]
    }

    pub(super) fn particles_2d() -> Particles<f64, 2> {
        let mut p = Particles::new(
            vec![Vector2::new(0.25, 0.5), Vector2::new(0.75, 0.125)],
            vec![0.5, 0.25],
            1000.0,
        );
        p.v[0] = Vector2::new(1.0, -2.0);
        p.u[1] = Vector2::new(0.1, 1.0 / 3.0);
        p.sigma[1] = Matrix2::new(1.0, 2.0, 3.0, 4.0);
        p
    }

    #[test]
    fn writing_twice_gives_identical_bytes() {
        let p = particles_2d();
        let mesh = psmpm_basis::mesh::generators::block_grid(0.0, 1.0, 0.0, 1.0, 2, 1).unwrap();
        let field: Vec<f64> = mesh.vertices().iter().map(|v| v.x * v.y).collect();
        let write_all = || {
            let mut bytes = Vec::new();
            for encoding in [vtk::VtuEncoding::Ascii, vtk::VtuEncoding::Binary] {
                vtk::write_particles_vtu(&mut bytes, &p, encoding).unwrap();
                vtk::write_mesh_vtu(&mut bytes, &mesh, Some(("xy", &field)), encoding).unwrap();
            }
            vtk::write_pvd(&mut bytes, &[(0.0, "a.vtu"), (0.1, "b.vtu")]).unwrap();
            csv::write_csv_columns(&mut bytes, &[("t".to_string(), awkward_values())]).unwrap();
            bytes
        };
        let (a, b) = (write_all(), write_all());
        assert_eq!(a, b);
        let text = String::from_utf8_lossy(&a);
        // The stress tensor, row-major and zero-padded.
        assert!(text.contains("\n          1e0 2e0 0e0 3e0 4e0 0e0 0e0 0e0 0e0\n"));
        assert!(text.contains("<DataSet timestep=\"1e-1\" group=\"\" part=\"0\" file=\"b.vtu\"/>"));
    }
}
