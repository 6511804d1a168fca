//! The output directory of a run, and writing one file with its path in the error.
//!
//! The command line's `--out DIR` writes through an [`OutputDir`]: it creates the
//! directory, writes `mesh.vtu` once, `particles_NNNNN.vtu` every `every` steps
//! (`NNNNN` is the frame number, 0, 1, 2, …) and `particles.pvd` at the end, so that
//! opening `particles.pvd` in ParaView plays the simulation back with the right
//! times. The files are written by the writers of [`vtk`](super::vtk) and [`csv`](super::csv).

use super::csv::write_csv_columns;
use super::vtk::{write_mesh_vtu, write_particles_vtu, write_pvd};
use crate::particles::Particles;
use crate::sparse::Scalar;
use psmpm_basis::TriMesh;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Why writing output failed. Every variant names the path and carries the io error.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The output directory could not be created.
    #[error("cannot create output directory `{}`: {source}", path.display())]
    CreateDir {
        /// The directory that could not be created.
        path: PathBuf,
        /// What the operating system said.
        source: io::Error,
    },
    /// A file could not be created or written.
    #[error("cannot write `{}`: {source}", path.display())]
    Write {
        /// The file being written.
        path: PathBuf,
        /// What the operating system (or the writer, for inconsistent data) said.
        source: io::Error,
    },
}

/// Creates (truncates) the file at `path`, hands a buffered writer to `write`, and
/// flushes it; any io error is reported as [`OutputError::Write`] naming `path`.
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), OutputError> {
    let wrap = |source| OutputError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut w = BufWriter::new(File::create(path).map_err(wrap)?);
    write(&mut w).map_err(wrap)?;
    w.flush().map_err(wrap)
}

/// An output directory: `mesh.vtu`, `particles_NNNNN.vtu` frames written at a
/// cadence, `particles.pvd` (written by [`OutputDir::finish`]) and any CSV files.
#[derive(Debug)]
pub struct OutputDir {
    path: PathBuf,
    every: usize,
    frames: Vec<(f64, String)>,
}

impl OutputDir {
    /// File name of the mesh.
    pub const MESH_FILE: &'static str = "mesh.vtu";
    /// File name of the particle collection.
    pub const PVD_FILE: &'static str = "particles.pvd";

    /// Creates the directory `path` (and its parents) if needed. Particle frames will
    /// be written every `every` steps by [`OutputDir::particles_frame`]; `every = 0`
    /// writes none there ([`OutputDir::write_particles`] still does).
    pub fn create(path: impl Into<PathBuf>, every: usize) -> Result<Self, OutputError> {
        let path = path.into();
        if let Err(source) = std::fs::create_dir_all(&path) {
            return Err(OutputError::CreateDir { path, source });
        }
        Ok(OutputDir {
            path,
            every,
            frames: Vec::new(),
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The frame cadence in steps (0: none).
    pub fn every(&self) -> usize {
        self.every
    }

    /// The frames written so far, as `(time, file name)`.
    pub fn frames(&self) -> &[(f64, String)] {
        &self.frames
    }

    /// The path of `file` inside the directory.
    pub fn file(&self, file: &str) -> PathBuf {
        self.path.join(file)
    }

    /// Writes `mesh.vtu` (see [`write_mesh_vtu`]) and returns its path.
    pub fn write_mesh(
        &self,
        mesh: &TriMesh,
        point_field: Option<(&str, &[f64])>,
    ) -> Result<PathBuf, OutputError> {
        let path = self.file(Self::MESH_FILE);
        write_file(&path, |w| write_mesh_vtu(w, mesh, point_field))?;
        Ok(path)
    }

    /// Writes the next frame `particles_NNNNN.vtu` when `step` is a multiple of the
    /// cadence, recording `time` for the collection. Returns whether it wrote.
    pub fn particles_frame<T: Scalar, const D: usize>(
        &mut self,
        step: usize,
        time: f64,
        particles: &Particles<T, D>,
    ) -> Result<bool, OutputError> {
        if self.every == 0 || step % self.every != 0 {
            return Ok(false);
        }
        self.write_particles(time, particles)?;
        Ok(true)
    }

    /// Writes the next frame `particles_NNNNN.vtu` unconditionally (e.g. the final
    /// state), records `time` for the collection, and returns the file's path.
    pub fn write_particles<T: Scalar, const D: usize>(
        &mut self,
        time: f64,
        particles: &Particles<T, D>,
    ) -> Result<PathBuf, OutputError> {
        let name = format!("particles_{:05}.vtu", self.frames.len());
        let path = self.file(&name);
        write_file(&path, |w| write_particles_vtu(w, particles))?;
        self.frames.push((time, name));
        Ok(path)
    }

    /// Writes `name` (e.g. `energy.csv`) from named columns (see [`write_csv_columns`]).
    pub fn write_csv(
        &self,
        name: &str,
        columns: &[(String, Vec<f64>)],
    ) -> Result<PathBuf, OutputError> {
        let path = self.file(name);
        write_file(&path, |w| write_csv_columns(w, columns))?;
        Ok(path)
    }

    /// Writes `particles.pvd` listing the frames written so far and returns its path.
    /// May be called again after more frames (it rewrites the file).
    pub fn finish(&self) -> Result<PathBuf, OutputError> {
        let path = self.file(Self::PVD_FILE);
        write_file(&path, |w| write_pvd(w, &self.frames))?;
        Ok(path)
    }
}
