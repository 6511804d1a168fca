//! The output directory of a run, and writing one file with its path in the error.
//!
//! The command line's `--out DIR` writes through an [`OutputDir`]: it creates the
//! directory, writes `mesh.vtu` once, `particles_NNNNN.vtu` every `every` steps
//! (`NNNNN` is the frame number, 0, 1, 2, …) and `particles.pvd` at the end, so that
//! opening `particles.pvd` in ParaView plays the simulation back with the right
//! times. The files are written by the writers of [`vtk`](super::vtk) and [`csv`](super::csv),
//! the `.vtu` files in the directory's [`VtuEncoding`] (binary unless
//! [`OutputDir::with_encoding`] says otherwise).
//!
//! [`prepare_dir`] applies the rules of a directory that is written again: an
//! existing directory must be empty, or hold only files of an earlier run (which
//! it then removes, when allowed to overwrite); files the caller did not write are
//! never removed nor mixed with a new run.

use super::csv::write_csv_columns;
use super::vtk::{write_mesh_vtu, write_particles_vtu, write_pvd, VtuEncoding};
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
    /// The path names an existing entry that is not a directory (a file, a link to
    /// one, a device).
    #[error(
        "output directory `{}` exists and is not a directory: give the path of a new or empty directory",
        path.display()
    )]
    NotADirectory {
        /// The path.
        path: PathBuf,
    },
    /// The directory holds files of an earlier run and overwriting was not asked for.
    #[error(
        "output directory `{}` is not empty: it holds {} of an earlier run ({})",
        path.display(), count(*files), listing(names)
    )]
    NotEmpty {
        /// The directory.
        path: PathBuf,
        /// How many files it holds.
        files: usize,
        /// The first few of them, sorted.
        names: Vec<String>,
    },
    /// The directory holds entries that are not output files (never removed).
    #[error(
        "output directory `{}` holds {} that this command does not write ({}); they are never removed or mixed with its files",
        path.display(), count(*files), listing(names)
    )]
    Foreign {
        /// The directory.
        path: PathBuf,
        /// How many such entries it holds.
        files: usize,
        /// The first few of them, sorted.
        names: Vec<String>,
    },
    /// An entry of the directory could not be listed or removed.
    #[error("cannot clear output directory `{}`: {source}", path.display())]
    Clear {
        /// The directory or file.
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

/// How many names [`OutputError::NotEmpty`] and [`OutputError::Foreign`] list.
const LISTED: usize = 5;

fn count(n: usize) -> String {
    if n == 1 {
        "1 file".to_string()
    } else {
        format!("{n} files")
    }
}

fn listing(names: &[String]) -> String {
    names.join(", ")
}

/// Makes `path` ready for a new run: creates it if needed; an empty directory is
/// used as it is. A directory holding only files `owned` recognises (the files of an
/// earlier run) is an [`OutputError::NotEmpty`] unless `overwrite`, when those files
/// are removed first (so no stale frame of a longer earlier run is left). A
/// directory holding anything else (a file `owned` does not recognise, a
/// sub-directory) is an [`OutputError::Foreign`], with or without `overwrite`:
/// nothing is removed then. Returns the names of the files removed, sorted.
pub fn prepare_dir(
    path: &Path,
    overwrite: bool,
    owned: impl Fn(&str) -> bool,
) -> Result<Vec<String>, OutputError> {
    let clear = |p: &Path| {
        let p = p.to_path_buf();
        move |source| OutputError::Clear { path: p, source }
    };
    if path.is_dir() {
        let mut ours = Vec::new();
        let mut foreign = Vec::new();
        for entry in std::fs::read_dir(path).map_err(clear(path))? {
            let entry = entry.map_err(clear(path))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let is_file = entry.file_type().map_err(clear(path))?.is_file();
            if is_file && owned(&name) {
                ours.push(name);
            } else {
                foreign.push(name);
            }
        }
        ours.sort();
        foreign.sort();
        let first = |names: &[String]| names.iter().take(LISTED).cloned().collect::<Vec<_>>();
        if !foreign.is_empty() {
            return Err(OutputError::Foreign {
                path: path.to_path_buf(),
                files: foreign.len(),
                names: first(&foreign),
            });
        }
        if !ours.is_empty() && !overwrite {
            return Err(OutputError::NotEmpty {
                path: path.to_path_buf(),
                files: ours.len(),
                names: first(&ours),
            });
        }
        for name in &ours {
            let file = path.join(name);
            std::fs::remove_file(&file).map_err(clear(&file))?;
        }
        return Ok(ours);
    }
    if std::fs::metadata(path).is_ok() {
        return Err(OutputError::NotADirectory {
            path: path.to_path_buf(),
        });
    }
    std::fs::create_dir_all(path).map_err(|source| OutputError::CreateDir {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(Vec::new())
}

/// Whether `name` is a particle frame `particles_NNNNN.vtu` (any number of digits).
pub fn is_frame(name: &str) -> bool {
    name.strip_prefix("particles_")
        .and_then(|rest| rest.strip_suffix(".vtu"))
        .is_some_and(|digits| !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
}

/// Creates (truncates) the file at `path`, hands a buffered writer to `write`, and
/// flushes it; any io error is reported as [`OutputError::Write`] naming `path`, and
/// the file, written in part, is removed.
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), OutputError> {
    let wrap = |source| OutputError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut w = BufWriter::new(File::create(path).map_err(wrap)?);
    let written = write(&mut w).and_then(|()| w.flush());
    if let Err(e) = written {
        // A half-written file would read as a truncated one: it is removed.
        drop(w);
        let _ = std::fs::remove_file(path);
        return Err(wrap(e));
    }
    Ok(())
}

/// An output directory: `mesh.vtu`, `particles_NNNNN.vtu` frames written at a
/// cadence, `particles.pvd` (written by [`OutputDir::finish`]) and any CSV files.
#[derive(Debug)]
pub struct OutputDir {
    path: PathBuf,
    every: usize,
    frames: Vec<(f64, String)>,
    encoding: VtuEncoding,
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
        if std::fs::metadata(&path).is_ok_and(|m| !m.is_dir()) {
            return Err(OutputError::NotADirectory { path });
        }
        if let Err(source) = std::fs::create_dir_all(&path) {
            return Err(OutputError::CreateDir { path, source });
        }
        Ok(OutputDir {
            path,
            every,
            frames: Vec::new(),
            encoding: VtuEncoding::default(),
        })
    }

    /// The directory writing its `.vtu` files in `encoding`.
    pub fn with_encoding(mut self, encoding: VtuEncoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// The encoding of the `.vtu` files.
    pub fn encoding(&self) -> VtuEncoding {
        self.encoding
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
        write_file(&path, |w| {
            write_mesh_vtu(w, mesh, point_field, self.encoding)
        })?;
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
        write_file(&path, |w| write_particles_vtu(w, particles, self.encoding))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_whose_writing_fails_is_removed() {
        let dir = std::env::temp_dir().join(format!("psmpm-write-fails-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("half.vtu");
        let err = write_file(&path, |w| {
            w.write_all(b"<?xml")?;
            Err(io::Error::new(io::ErrorKind::OutOfMemory, "no memory"))
        })
        .unwrap_err();
        assert!(matches!(err, OutputError::Write { .. }), "{err}");
        assert!(!path.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
