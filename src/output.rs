//! Files a user can look at: VTK XML `.vtu` snapshots of particles and of the
//! triangular mesh, ParaView `.pvd` collections that animate them over time, and
//! CSV time series.
//!
//! The command line's `--out DIR` writes through an [`OutputDir`]: it creates the
//! directory, writes `mesh.vtu` once, `particles_NNNNN.vtu` every `every` steps
//! (`NNNNN` is the frame number, 0, 1, 2, …) and `particles.pvd` at the end, so that
//! opening `particles.pvd` in ParaView plays the simulation back with the right
//! times. The lower-level writers ([`write_particles_vtu`], [`write_mesh_vtu`],
//! [`write_pvd`], [`CsvWriter`], [`write_csv_columns`]) write to any [`Write`] and
//! can be used on their own.
//!
//! # Format
//!
//! Everything is plain text and deterministic: the same inputs give byte-identical
//! files (no time stamps, no hash-map order), so output can be diffed and kept in
//! snapshot tests.
//!
//! - Every floating-point value is written as `{:e}` of an `f64` (Rust's shortest
//!   representation that reads back to the same `f64`, e.g. `1.5e0`, `-2.5e-3`,
//!   `0e0`): reading a value back with any correctly rounding parser (Rust, Python,
//!   NumPy, ParaView) gives exactly the value that was written. `f32` simulations
//!   are widened to `f64` (exactly) before they are written.
//! - `.vtu` files are VTK XML `UnstructuredGrid`s in the `ascii` format, one point
//!   or cell per line. Points are 3D: `z = 0`, and `y = 0` in 1D.
//! - Particle files hold one `VTK_VERTEX` cell per particle and the point data
//!   `velocity` and `displacement` (3 components, padded with zeros), `stress`
//!   (the Cauchy stress σ as a full 3 × 3 tensor of 9 components in row-major order
//!   `xx xy xz yx yy yz zx zy zz`, padded with zeros; ParaView recognises 9-component
//!   arrays as tensors and offers the components `XX` … `ZZ` and the magnitude),
//!   `volume` (current volume `V_p`) and `mass`.
//! - Mesh files hold the vertices, one `VTK_TRIANGLE` per triangle (counter-clockwise
//!   as in the mesh), the cell data `element` (the triangle index) and optionally one
//!   point-data scalar field supplied by the caller.
//! - CSV files have a header row of column names (quoted as in RFC 4180 when they
//!   contain `,`, `"` or line breaks) and rows of numbers separated by `,`, with `\n`
//!   line endings.

use crate::particles::Particles;
use crate::sparse::Scalar;
use psmpm_basis::TriMesh;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// VTK cell type of a single point.
const VTK_VERTEX: u8 = 1;
/// VTK cell type of a linear triangle.
const VTK_TRIANGLE: u8 = 5;

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

// ---------------------------------------------------------------------------
// Small formatting helpers.

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// Writes `x` in the round-trippable `{:e}` format.
fn write_f64<W: Write>(w: &mut W, x: f64) -> io::Result<()> {
    write!(w, "{x:e}")
}

/// Writes `s` with the five XML special characters escaped (for attribute values).
fn write_xml_escaped<W: Write>(w: &mut W, s: &str) -> io::Result<()> {
    let mut rest = s;
    while let Some(i) = rest.find(['&', '<', '>', '"', '\'']) {
        w.write_all(&rest.as_bytes()[..i])?;
        let entity = match rest.as_bytes()[i] {
            b'&' => "&amp;",
            b'<' => "&lt;",
            b'>' => "&gt;",
            b'"' => "&quot;",
            _ => "&apos;",
        };
        w.write_all(entity.as_bytes())?;
        rest = &rest[i + 1..];
    }
    w.write_all(rest.as_bytes())
}

/// Writes a CSV field, quoted when it contains `,`, `"` or a line break.
fn write_csv_field<W: Write>(w: &mut W, s: &str) -> io::Result<()> {
    if s.contains([',', '"', '\n', '\r']) {
        w.write_all(b"\"")?;
        w.write_all(s.replace('"', "\"\"").as_bytes())?;
        w.write_all(b"\"")
    } else {
        w.write_all(s.as_bytes())
    }
}

const VTU_HEADER: &str = concat!(
    "<?xml version=\"1.0\"?>\n",
    "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n",
    "  <UnstructuredGrid>\n",
);
const VTU_FOOTER: &str = "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";

/// Opens a `<DataArray>` of `vtk_type` (with `Name` when given, and
/// `NumberOfComponents` when `components > 1`), writes `n` lines of `per_line`
/// values `value(i, k)`, and closes it.
#[allow(clippy::too_many_arguments)]
fn data_array<W: Write, V: std::fmt::Display>(
    w: &mut W,
    vtk_type: &str,
    name: Option<&str>,
    components: usize,
    per_line: usize,
    n: usize,
    mut value: impl FnMut(usize, usize) -> V,
) -> io::Result<()> {
    write!(w, "        <DataArray type=\"{vtk_type}\"")?;
    if let Some(name) = name {
        w.write_all(b" Name=\"")?;
        write_xml_escaped(w, name)?;
        w.write_all(b"\"")?;
    }
    if components > 1 {
        write!(w, " NumberOfComponents=\"{components}\"")?;
    }
    w.write_all(b" format=\"ascii\">\n")?;
    for i in 0..n {
        w.write_all(b"          ")?;
        for k in 0..per_line {
            if k > 0 {
                w.write_all(b" ")?;
            }
            write!(w, "{}", value(i, k))?;
        }
        w.write_all(b"\n")?;
    }
    w.write_all(b"        </DataArray>\n")
}

/// A `Float64` data array, each value in the round-trippable format.
fn f64_array<W: Write>(
    w: &mut W,
    name: Option<&str>,
    components: usize,
    n: usize,
    mut value: impl FnMut(usize, usize) -> f64,
) -> io::Result<()> {
    // `LowerExp` formatting through a wrapper keeps `data_array` generic.
    struct Exp(f64);
    impl std::fmt::Display for Exp {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "{:e}", self.0)
        }
    }
    data_array(w, "Float64", name, components, components, n, |i, k| {
        Exp(value(i, k))
    })
}

/// The `<Cells>` block: connectivity, offsets and types of `n` cells of
/// `per_cell` points each, the `j`-th point of cell `i` being `point(i, j)`.
fn cells_block<W: Write>(
    w: &mut W,
    n: usize,
    per_cell: usize,
    cell_type: u8,
    point: impl FnMut(usize, usize) -> usize,
) -> io::Result<()> {
    w.write_all(b"      <Cells>\n")?;
    data_array(w, "Int64", Some("connectivity"), 1, per_cell, n, point)?;
    data_array(w, "Int64", Some("offsets"), 1, 1, n, |i, _| {
        (i + 1) * per_cell
    })?;
    data_array(w, "UInt8", Some("types"), 1, 1, n, |_, _| cell_type)?;
    w.write_all(b"      </Cells>\n")
}

// ---------------------------------------------------------------------------
// Particles and mesh.

/// Writes `particles` as a VTK XML unstructured grid (ascii): 3D points (`z = 0`,
/// `y = 0` in 1D), one `VTK_VERTEX` per particle, and the point data `velocity`,
/// `displacement` (3 components), `stress` (9-component Cauchy tensor, row-major,
/// zero-padded), `volume` and `mass`. See the [module documentation](self).
///
/// Errors: io errors of `w`, and `InvalidInput` when the particle arrays have
/// different lengths. `w` is flushed at the end.
pub fn write_particles_vtu<W: Write, T: Scalar, const D: usize>(
    mut w: W,
    particles: &Particles<T, D>,
) -> io::Result<()> {
    let n = particles.len();
    let lengths = [
        ("v", particles.v.len()),
        ("u", particles.u.len()),
        ("sigma", particles.sigma.len()),
        ("volume", particles.volume.len()),
        ("mass", particles.mass.len()),
    ];
    if let Some((name, len)) = lengths.iter().find(|(_, len)| *len != n) {
        return Err(invalid(format!(
            "particles have {n} positions but {len} entries in `{name}`"
        )));
    }
    // Component k of a D-vector, zero beyond D (and beyond 3).
    let vec3 = |v: &nalgebra::SVector<T, D>, k: usize| if k < D { v[k].to_f64() } else { 0.0 };
    let tensor = |s: &nalgebra::SMatrix<T, D, D>, k: usize| {
        let (r, c) = (k / 3, k % 3);
        if r < D && c < D {
            s[(r, c)].to_f64()
        } else {
            0.0
        }
    };

    w.write_all(VTU_HEADER.as_bytes())?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">"
    )?;
    w.write_all(b"      <PointData Scalars=\"volume\" Vectors=\"velocity\" Tensors=\"stress\">\n")?;
    f64_array(&mut w, Some("velocity"), 3, n, |i, k| {
        vec3(&particles.v[i], k)
    })?;
    f64_array(&mut w, Some("displacement"), 3, n, |i, k| {
        vec3(&particles.u[i], k)
    })?;
    f64_array(&mut w, Some("stress"), 9, n, |i, k| {
        tensor(&particles.sigma[i], k)
    })?;
    f64_array(&mut w, Some("volume"), 1, n, |i, _| {
        particles.volume[i].to_f64()
    })?;
    f64_array(&mut w, Some("mass"), 1, n, |i, _| {
        particles.mass[i].to_f64()
    })?;
    w.write_all(b"      </PointData>\n      <Points>\n")?;
    f64_array(&mut w, None, 3, n, |i, k| vec3(&particles.x[i], k))?;
    w.write_all(b"      </Points>\n")?;
    cells_block(&mut w, n, 1, VTK_VERTEX, |i, _| i)?;
    w.write_all(VTU_FOOTER.as_bytes())?;
    w.flush()
}

/// Writes the triangular `mesh` as a VTK XML unstructured grid (ascii): its vertices
/// (`z = 0`), one `VTK_TRIANGLE` per triangle, the cell data `element` (the triangle
/// index, `Int64`) and, when `point_field` is `Some((name, values))`, the point-data
/// scalar `name` with one value per vertex.
///
/// Errors: io errors of `w`, and `InvalidInput` when `values` does not have one
/// entry per vertex. `w` is flushed at the end.
pub fn write_mesh_vtu<W: Write>(
    mut w: W,
    mesh: &TriMesh,
    point_field: Option<(&str, &[f64])>,
) -> io::Result<()> {
    let (nv, nt) = (mesh.num_vertices(), mesh.num_triangles());
    if let Some((name, values)) = point_field {
        if values.len() != nv {
            return Err(invalid(format!(
                "point field `{name}` has {} values but the mesh has {nv} vertices",
                values.len()
            )));
        }
    }
    let vertices = mesh.vertices();
    let triangles = mesh.triangles();

    w.write_all(VTU_HEADER.as_bytes())?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{nv}\" NumberOfCells=\"{nt}\">"
    )?;
    match point_field {
        Some((name, values)) => {
            w.write_all(b"      <PointData Scalars=\"")?;
            write_xml_escaped(&mut w, name)?;
            w.write_all(b"\">\n")?;
            f64_array(&mut w, Some(name), 1, nv, |i, _| values[i])?;
            w.write_all(b"      </PointData>\n")?;
        }
        None => w.write_all(b"      <PointData>\n      </PointData>\n")?,
    }
    w.write_all(b"      <CellData Scalars=\"element\">\n")?;
    data_array(&mut w, "Int64", Some("element"), 1, 1, nt, |t, _| t)?;
    w.write_all(b"      </CellData>\n      <Points>\n")?;
    f64_array(&mut w, None, 3, nv, |i, k| match k {
        0 => vertices[i].x,
        1 => vertices[i].y,
        _ => 0.0,
    })?;
    w.write_all(b"      </Points>\n")?;
    cells_block(&mut w, nt, 3, VTK_TRIANGLE, |t, j| triangles[t][j])?;
    w.write_all(VTU_FOOTER.as_bytes())?;
    w.flush()
}

// ---------------------------------------------------------------------------
// ParaView collections.

/// Writes a ParaView `.pvd` collection: one `<DataSet>` per `(time, file)` entry, in
/// the order given, `file` being relative to the `.pvd` file. ParaView shows the
/// files as one data set animated over `time`. `w` is flushed at the end.
pub fn write_pvd<W: Write, S: AsRef<str>>(mut w: W, entries: &[(f64, S)]) -> io::Result<()> {
    w.write_all(
        concat!(
            "<?xml version=\"1.0\"?>\n",
            "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n",
            "  <Collection>\n",
        )
        .as_bytes(),
    )?;
    for (time, file) in entries {
        w.write_all(b"    <DataSet timestep=\"")?;
        write_f64(&mut w, *time)?;
        w.write_all(b"\" group=\"\" part=\"0\" file=\"")?;
        write_xml_escaped(&mut w, file.as_ref())?;
        w.write_all(b"\"/>\n")?;
    }
    w.write_all(b"  </Collection>\n</VTKFile>\n")?;
    w.flush()
}

// ---------------------------------------------------------------------------
// CSV.

/// A CSV time-series writer: the header row on creation, then one row of `f64` per
/// call to [`CsvWriter::row`], written straight through (no allocation per row).
#[derive(Debug)]
pub struct CsvWriter<W: Write> {
    w: W,
    columns: usize,
}

impl<W: Write> CsvWriter<W> {
    /// Writes the header row `columns` to `w` and returns the writer.
    pub fn new<S: AsRef<str>>(mut w: W, columns: &[S]) -> io::Result<Self> {
        for (k, name) in columns.iter().enumerate() {
            if k > 0 {
                w.write_all(b",")?;
            }
            write_csv_field(&mut w, name.as_ref())?;
        }
        w.write_all(b"\n")?;
        Ok(CsvWriter {
            w,
            columns: columns.len(),
        })
    }

    /// Writes one row; `InvalidInput` unless it has one value per column.
    pub fn row(&mut self, values: &[f64]) -> io::Result<()> {
        if values.len() != self.columns {
            return Err(invalid(format!(
                "CSV row has {} values but the header has {} columns",
                values.len(),
                self.columns
            )));
        }
        for (k, &x) in values.iter().enumerate() {
            if k > 0 {
                self.w.write_all(b",")?;
            }
            write_f64(&mut self.w, x)?;
        }
        self.w.write_all(b"\n")
    }

    /// Number of columns.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Flushes and returns the underlying writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.w.flush()?;
        Ok(self.w)
    }
}

/// Writes a set of named columns as CSV: the names as header, then row `i` holds
/// the `i`-th value of every column. `InvalidInput` when the columns have different
/// lengths. `w` is flushed at the end.
pub fn write_csv_columns<W: Write>(w: W, columns: &[(String, Vec<f64>)]) -> io::Result<()> {
    let rows = columns.first().map_or(0, |(_, c)| c.len());
    if let Some((name, c)) = columns.iter().find(|(_, c)| c.len() != rows) {
        return Err(invalid(format!(
            "CSV column `{name}` has {} values but `{}` has {rows}",
            c.len(),
            columns[0].0
        )));
    }
    let names: Vec<&str> = columns.iter().map(|(name, _)| name.as_str()).collect();
    let mut csv = CsvWriter::new(w, &names)?;
    let mut row = vec![0.0; columns.len()];
    for i in 0..rows {
        for (r, (_, c)) in row.iter_mut().zip(columns) {
            *r = c[i];
        }
        csv.row(&row)?;
    }
    csv.finish().map(drop)
}

// ---------------------------------------------------------------------------
// Output directory.

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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector1, Vector2};

    /// Parses what [`write_csv_columns`] writes (unquoted names only).
    fn read_csv(text: &str) -> Vec<(String, Vec<f64>)> {
        let mut lines = text.lines();
        let mut columns: Vec<(String, Vec<f64>)> = lines
            .next()
            .unwrap()
            .split(',')
            .map(|n| (n.to_string(), Vec::new()))
            .collect();
        for line in lines {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), columns.len(), "row `{line}`");
            for (c, f) in columns.iter_mut().zip(fields) {
                c.1.push(f.parse().unwrap());
            }
        }
        columns
    }

    fn awkward_values() -> Vec<f64> {
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

    #[test]
    fn csv_round_trips_bit_for_bit() {
        let t = awkward_values();
        let e: Vec<f64> = t.iter().map(|x| x * 0.7 - 1e-17).collect();
        let columns = vec![("t".to_string(), t), ("energy".to_string(), e)];
        let mut bytes = Vec::new();
        write_csv_columns(&mut bytes, &columns).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.starts_with("t,energy\n0e0,"), "{text}");
        let back = read_csv(&text);
        assert_eq!(back.len(), columns.len());
        for ((name, values), (name2, values2)) in columns.iter().zip(&back) {
            assert_eq!(name, name2);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(values), bits(values2), "column {name}");
        }
    }

    #[test]
    fn csv_rejects_ragged_input_and_quotes_names() {
        let ragged = vec![
            ("a".to_string(), vec![1.0, 2.0]),
            ("b".to_string(), vec![1.0]),
        ];
        let err = write_csv_columns(Vec::new(), &ragged).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("`b`"), "{err}");

        let mut csv = CsvWriter::new(Vec::new(), &["x, m", "say \"hi\""]).unwrap();
        assert!(csv.row(&[1.0]).is_err());
        csv.row(&[1.0, 2.0]).unwrap();
        let text = String::from_utf8(csv.finish().unwrap()).unwrap();
        assert_eq!(text, "\"x, m\",\"say \"\"hi\"\"\"\n1e0,2e0\n");
    }

    fn particles_2d() -> Particles<f64, 2> {
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
            write_particles_vtu(&mut bytes, &p).unwrap();
            write_mesh_vtu(&mut bytes, &mesh, Some(("xy", &field))).unwrap();
            write_pvd(&mut bytes, &[(0.0, "a.vtu"), (0.1, "b.vtu")]).unwrap();
            write_csv_columns(&mut bytes, &[("t".to_string(), awkward_values())]).unwrap();
            bytes
        };
        let (a, b) = (write_all(), write_all());
        assert_eq!(a, b);
        let text = String::from_utf8(a).unwrap();
        // The stress tensor, row-major and zero-padded.
        assert!(text.contains("\n          1e0 2e0 0e0 3e0 4e0 0e0 0e0 0e0 0e0\n"));
        assert!(text.contains("<DataSet timestep=\"1e-1\" group=\"\" part=\"0\" file=\"b.vtu\"/>"));
    }

    #[test]
    fn f32_particles_are_widened_and_bad_input_is_an_error() {
        let p = Particles::<f32, 1>::new(vec![Vector1::new(0.1f32)], vec![0.5], 2.0);
        let mut bytes = Vec::new();
        write_particles_vtu(&mut bytes, &p).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.contains(&format!("          {:e} 0e0 0e0\n", 0.1f32 as f64)));

        let mut broken = particles_2d();
        broken.mass.pop();
        let err = write_particles_vtu(Vec::new(), &broken).unwrap_err();
        assert!(err.to_string().contains("`mass`"), "{err}");

        let mesh = psmpm_basis::mesh::generators::block_grid(0.0, 1.0, 0.0, 1.0, 1, 1).unwrap();
        let err = write_mesh_vtu(Vec::new(), &mesh, Some(("f", &[1.0]))).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }

    #[test]
    fn xml_names_are_escaped() {
        let mut bytes = Vec::new();
        write_xml_escaped(&mut bytes, "a<b & \"c\" 'd'>").unwrap();
        assert_eq!(
            String::from_utf8(bytes).unwrap(),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;"
        );
    }
}
