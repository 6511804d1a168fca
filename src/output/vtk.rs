//! VTK XML files for ParaView: `.vtu` snapshots of particles and of the triangular
//! mesh, and `.pvd` collections that animate snapshots over time.
//!
//! The writers ([`write_particles_vtu`], [`write_mesh_vtu`], [`write_pvd`]) write to
//! any [`Write`]; [`OutputDir`](super::dir::OutputDir) names the files and writes
//! them in a directory. Numbers are written as the [module `output`](super#format)
//! says.
//!
//! # Format
//!
//! - `.vtu` files are VTK XML `UnstructuredGrid`s, in one of two encodings
//!   ([`VtuEncoding`]): `binary` (the default: the XML header, then the arrays as
//!   little-endian bytes in one `<AppendedData encoding="base64">` block,
//!   each array compressed with zlib in blocks of 1 MiB as VTK's
//!   `vtkZLibDataCompressor` does, `header_type="UInt64"`, file version 1.0, its
//!   header and its blocks base64-encoded separately as VTK writes them), or
//!   `ascii` (one point or cell per line). Both hold the same arrays with the same
//!   values, bit for bit. Points are 3D: `z = 0`, and `y = 0` in 1D.
//! - Particle files hold one `VTK_VERTEX` cell per particle and the point data
//!   `velocity` and `displacement` (3 components, padded with zeros), `stress`
//!   (the Cauchy stress σ as a full 3 × 3 tensor of 9 components in row-major order
//!   `xx xy xz yx yy yz zx zy zz`, padded with zeros; ParaView recognises 9-component
//!   arrays as tensors and offers the components `XX` … `ZZ` and the magnitude),
//!   `volume` (current volume `V_p`) and `mass`.
//! - Mesh files hold the vertices, one `VTK_TRIANGLE` per triangle (counter-clockwise
//!   as in the mesh), the cell data `element` (the triangle index) and optionally one
//!   point-data scalar field supplied by the caller.
//! - `.pvd` files list one `<DataSet>` per snapshot with its time and file name.

use super::{invalid, write_f64};
use crate::particles::Particles;
use crate::sparse::Scalar;
use psmpm_basis::TriMesh;
use std::io::{self, Write};

/// VTK cell type of a single point.
const VTK_VERTEX: u8 = 1;
/// VTK cell type of a linear triangle.
const VTK_TRIANGLE: u8 = 5;

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

/// How the arrays of a `.vtu` file are stored.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum VtuEncoding {
    /// Little-endian binary in one base64 `<AppendedData>` block after the XML,
    /// each array compressed with zlib in blocks of [`BLOCK_SIZE`] bytes
    /// (`compressor="vtkZLibDataCompressor"`, `header_type="UInt64"`): small and
    /// fast to read (the default).
    ///
    /// Base64 rather than raw bytes: meshio (5.3) reads raw appended data by
    /// rewriting it as base64 and looking each array up by its old offset, and
    /// takes the wrong array when an earlier array's new offset equals a later
    /// one's old offset (measured: about one frame in a hundred of a column run;
    /// `tests/cli/out.rs`). Base64 costs a third more bytes and is read directly.
    #[default]
    Binary,
    /// Text, one point or cell per line: readable and diffable, about 4–5 times
    /// larger and much slower to read.
    Ascii,
}

/// Uncompressed size of the zlib blocks of a binary `.vtu`: 1 MiB (VTK writes 32 KiB
/// blocks and reads any size; readers that join the blocks by copying, as meshio
/// does, slow down with the square of the number of blocks of an array).
pub const BLOCK_SIZE: usize = 1 << 20;

/// Bytes per particle a binary particle frame holds in memory while it is written,
/// at most: its 177 raw bytes (20 `Float64` values, two `Int64` and one `UInt8`),
/// compressed (zlib adds at most 0.1 % to floats that do not compress) and encoded in
/// base64 (4 characters per 3 bytes). Two buffers of one block come on top.
pub const BINARY_BYTES_PER_PARTICLE: f64 = 240.0;

/// zlib level of the binary `.vtu`: the fastest; the floats of a simulation barely
/// compress at any level, the zero padding (`z`, the stress' third row and column)
/// compresses at all of them.
const LEVEL: u32 = 1;

const VTU_FOOTER_ASCII: &str = "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";

/// A value of a data array: its VTK type name, its text and its bytes.
trait VtkValue: Copy {
    const TYPE: &'static str;
    fn write_text<W: Write>(self, w: &mut W) -> io::Result<()>;
    fn push_bytes(self, out: &mut Vec<u8>);
}

impl VtkValue for f64 {
    const TYPE: &'static str = "Float64";
    fn write_text<W: Write>(self, w: &mut W) -> io::Result<()> {
        write_f64(w, self)
    }
    fn push_bytes(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl VtkValue for usize {
    const TYPE: &'static str = "Int64";
    fn write_text<W: Write>(self, w: &mut W) -> io::Result<()> {
        write!(w, "{self}")
    }
    fn push_bytes(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&(self as i64).to_le_bytes());
    }
}

impl VtkValue for u8 {
    const TYPE: &'static str = "UInt8";
    fn write_text<W: Write>(self, w: &mut W) -> io::Result<()> {
        write!(w, "{self}")
    }
    fn push_bytes(self, out: &mut Vec<u8>) {
        out.push(self);
    }
}

/// Writes the XML of one `.vtu` file and, for [`VtuEncoding::Binary`], gathers the
/// compressed arrays that [`Vtu::finish`] appends after it.
///
/// The binary arrays are compressed and encoded one block at a time, so that a frame
/// holds only its encoded text ([`BINARY_BYTES_PER_PARTICLE`] at most) besides two
/// buffers of one block; every buffer grows fallibly, a frame too large for the
/// memory left being an [`io::ErrorKind::OutOfMemory`] error rather than an abort.
struct Vtu<W: Write> {
    w: W,
    encoding: VtuEncoding,
    /// The `<AppendedData>` text so far (binary: base64).
    appended: Vec<u8>,
    /// One block of an array's raw bytes (binary; reused).
    raw: Vec<u8>,
    /// The compressed bytes not yet encoded: fewer than three carried from the last
    /// block, then the block just compressed (binary; reused).
    compressed: Vec<u8>,
}

impl<W: Write> Vtu<W> {
    /// Writes the XML declaration and opens the `UnstructuredGrid`.
    fn new(mut w: W, encoding: VtuEncoding) -> io::Result<Self> {
        w.write_all(b"<?xml version=\"1.0\"?>\n")?;
        match encoding {
            VtuEncoding::Ascii => w.write_all(
                b"<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n",
            )?,
            VtuEncoding::Binary => w.write_all(concat!(
                "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\"",
                " header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n"
            ).as_bytes())?,
        }
        w.write_all(b"  <UnstructuredGrid>\n")?;
        Ok(Vtu {
            w,
            encoding,
            appended: Vec::new(),
            raw: Vec::new(),
            compressed: Vec::new(),
        })
    }

    /// One `<DataArray>` (with `Name` when given, and `NumberOfComponents` when
    /// `components > 1`) of `n` lines of `per_line` values `value(i, k)`: the values
    /// inline (ascii) or its offset into the appended data (binary).
    fn data_array<V: VtkValue>(
        &mut self,
        name: Option<&str>,
        components: usize,
        per_line: usize,
        n: usize,
        mut value: impl FnMut(usize, usize) -> V,
    ) -> io::Result<()> {
        let w = &mut self.w;
        write!(w, "        <DataArray type=\"{}\"", V::TYPE)?;
        if let Some(name) = name {
            w.write_all(b" Name=\"")?;
            write_xml_escaped(w, name)?;
            w.write_all(b"\"")?;
        }
        if components > 1 {
            write!(w, " NumberOfComponents=\"{components}\"")?;
        }
        match self.encoding {
            VtuEncoding::Ascii => {
                w.write_all(b" format=\"ascii\">\n")?;
                for i in 0..n {
                    w.write_all(b"          ")?;
                    for k in 0..per_line {
                        if k > 0 {
                            w.write_all(b" ")?;
                        }
                        value(i, k).write_text(w)?;
                    }
                    w.write_all(b"\n")?;
                }
                w.write_all(b"        </DataArray>\n")
            }
            VtuEncoding::Binary => {
                writeln!(
                    w,
                    " format=\"appended\" offset=\"{}\"/>",
                    self.appended.len()
                )?;
                self.appended_array(n, per_line, value)
            }
        }
    }

    /// Appends the array of `n` lines of `per_line` values `value(i, k)` as VTK's
    /// zlib compressor does, in base64: the `UInt64` header `[blocks, BLOCK_SIZE,
    /// size of the last block if partial (else 0), compressed size of each block]`,
    /// then the zlib streams of the blocks, each of the two encoded on its own. The
    /// header's place is kept (its length is known from the number of blocks) and
    /// filled once the blocks are compressed.
    fn appended_array<V: VtkValue>(
        &mut self,
        n: usize,
        per_line: usize,
        mut value: impl FnMut(usize, usize) -> V,
    ) -> io::Result<()> {
        let raw_len = n * per_line * std::mem::size_of::<V>();
        let blocks = raw_len.div_ceil(BLOCK_SIZE);
        let header_bytes = 8 * (3 + blocks);
        let header_at = self.appended.len();
        let header_text = base64_len(header_bytes);
        grow(&mut self.appended, header_text)?;
        self.appended.resize(header_at + header_text, 0);
        let mut header: Vec<u64> = Vec::new();
        header
            .try_reserve_exact(3 + blocks)
            .map_err(|_| out_of_memory(header_bytes))?;
        header.extend([
            blocks as u64,
            BLOCK_SIZE as u64,
            (raw_len % BLOCK_SIZE) as u64,
        ]);
        self.compressed.clear();
        self.raw.clear();
        grow(&mut self.raw, BLOCK_SIZE.min(raw_len))?;
        // `BLOCK_SIZE` is a multiple of every value's size: a block ends on a value.
        for i in 0..n {
            for k in 0..per_line {
                value(i, k).push_bytes(&mut self.raw);
                if self.raw.len() == BLOCK_SIZE {
                    header.push(self.compress_block()?);
                }
            }
        }
        if !self.raw.is_empty() {
            header.push(self.compress_block()?);
        }
        self.encode(true)?;
        let header: Vec<u8> = header.iter().flat_map(|h| h.to_le_bytes()).collect();
        base64::Engine::encode_slice(
            &BASE64,
            header,
            &mut self.appended[header_at..header_at + header_text],
        )
        .map_err(io::Error::other)?;
        Ok(())
    }

    /// Compresses the block in `raw` onto `compressed`, encodes what it can and
    /// returns the block's compressed size.
    fn compress_block(&mut self) -> io::Result<u64> {
        let carried = self.compressed.len();
        // zlib's bound on a block's compressed size (`compressBound`), and a margin.
        grow(
            &mut self.compressed,
            self.raw.len() + self.raw.len() / 1000 + 64,
        )?;
        let mut z =
            flate2::write::ZlibEncoder::new(&mut self.compressed, flate2::Compression::new(LEVEL));
        z.write_all(&self.raw)?;
        z.finish()?;
        self.raw.clear();
        let size = (self.compressed.len() - carried) as u64;
        self.encode(false)?;
        Ok(size)
    }

    /// Encodes `compressed` onto `appended`: all of it with padding at the end of an
    /// array (`last`), else its whole groups of three bytes, the rest carried.
    fn encode(&mut self, last: bool) -> io::Result<()> {
        let whole = if last {
            self.compressed.len()
        } else {
            self.compressed.len() / 3 * 3
        };
        let text = base64_len(whole);
        grow(&mut self.appended, text)?;
        let at = self.appended.len();
        self.appended.resize(at + text, 0);
        base64::Engine::encode_slice(&BASE64, &self.compressed[..whole], &mut self.appended[at..])
            .map_err(io::Error::other)?;
        self.compressed.drain(..whole);
        Ok(())
    }

    /// A `Float64` data array.
    fn f64_array(
        &mut self,
        name: Option<&str>,
        components: usize,
        n: usize,
        value: impl FnMut(usize, usize) -> f64,
    ) -> io::Result<()> {
        self.data_array(name, components, components, n, value)
    }

    /// The `<Cells>` block: connectivity, offsets and types of `n` cells of
    /// `per_cell` points each, the `j`-th point of cell `i` being `point(i, j)`.
    fn cells_block(
        &mut self,
        n: usize,
        per_cell: usize,
        cell_type: u8,
        point: impl FnMut(usize, usize) -> usize,
    ) -> io::Result<()> {
        self.w.write_all(b"      <Cells>\n")?;
        self.data_array(Some("connectivity"), 1, per_cell, n, point)?;
        self.data_array(Some("offsets"), 1, 1, n, |i, _| (i + 1) * per_cell)?;
        self.data_array(Some("types"), 1, 1, n, |_, _| cell_type)?;
        self.w.write_all(b"      </Cells>\n")
    }

    /// Closes the piece and the grid, appends the data (binary) and flushes.
    fn finish(mut self) -> io::Result<()> {
        match self.encoding {
            VtuEncoding::Ascii => self.w.write_all(VTU_FOOTER_ASCII.as_bytes())?,
            VtuEncoding::Binary => {
                self.w.write_all(
                    b"    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"base64\">\n   _",
                )?;
                self.w.write_all(&self.appended)?;
                self.w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")?;
            }
        }
        self.w.flush()
    }
}

/// The base64 alphabet and padding of the appended data.
const BASE64: base64::engine::GeneralPurpose = base64::engine::general_purpose::STANDARD;

/// Length of the padded base64 text of `bytes` bytes.
fn base64_len(bytes: usize) -> usize {
    bytes.div_ceil(3) * 4
}

/// Makes room in `buffer` for `more` bytes, or says that the memory is lacking.
fn grow(buffer: &mut Vec<u8>, more: usize) -> io::Result<()> {
    buffer.try_reserve(more).map_err(|_| out_of_memory(more))
}

/// The error of a frame that does not fit in the memory left.
fn out_of_memory(more: usize) -> io::Error {
    io::Error::new(
        io::ErrorKind::OutOfMemory,
        format!(
            "no memory left for {} MB more of a compressed frame",
            more.div_ceil(1_000_000)
        ),
    )
}

// ---------------------------------------------------------------------------
// Particles and mesh.

/// Writes `particles` as a VTK XML unstructured grid (in `encoding`): 3D points (`z = 0`,
/// `y = 0` in 1D), one `VTK_VERTEX` per particle, and the point data `velocity`,
/// `displacement` (3 components), `stress` (9-component Cauchy tensor, row-major,
/// zero-padded), `volume` and `mass`. See the [module documentation](self).
///
/// Errors: io errors of `w`, and `InvalidInput` when the particle arrays have
/// different lengths. `w` is flushed at the end.
pub fn write_particles_vtu<W: Write, T: Scalar, const D: usize>(
    w: W,
    particles: &Particles<T, D>,
    encoding: VtuEncoding,
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
            "particles have {} but {} in `{name}`",
            crate::scene::limits::plural(n, "position", "positions"),
            crate::scene::limits::plural(*len, "entry", "entries")
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

    let mut vtu = Vtu::new(w, encoding)?;
    writeln!(
        vtu.w,
        "    <Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">"
    )?;
    vtu.w.write_all(
        b"      <PointData Scalars=\"volume\" Vectors=\"velocity\" Tensors=\"stress\">\n",
    )?;
    vtu.f64_array(Some("velocity"), 3, n, |i, k| vec3(&particles.v[i], k))?;
    vtu.f64_array(Some("displacement"), 3, n, |i, k| vec3(&particles.u[i], k))?;
    vtu.f64_array(Some("stress"), 9, n, |i, k| tensor(&particles.sigma[i], k))?;
    vtu.f64_array(Some("volume"), 1, n, |i, _| particles.volume[i].to_f64())?;
    vtu.f64_array(Some("mass"), 1, n, |i, _| particles.mass[i].to_f64())?;
    vtu.w.write_all(b"      </PointData>\n      <Points>\n")?;
    vtu.f64_array(None, 3, n, |i, k| vec3(&particles.x[i], k))?;
    vtu.w.write_all(b"      </Points>\n")?;
    vtu.cells_block(n, 1, VTK_VERTEX, |i, _| i)?;
    vtu.finish()
}

/// Writes the triangular `mesh` as a VTK XML unstructured grid (in `encoding`): its vertices
/// (`z = 0`), one `VTK_TRIANGLE` per triangle, the cell data `element` (the triangle
/// index, `Int64`) and, when `point_field` is `Some((name, values))`, the point-data
/// scalar `name` with one value per vertex.
///
/// Errors: io errors of `w`, and `InvalidInput` when `values` does not have one
/// entry per vertex. `w` is flushed at the end.
pub fn write_mesh_vtu<W: Write>(
    w: W,
    mesh: &TriMesh,
    point_field: Option<(&str, &[f64])>,
    encoding: VtuEncoding,
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

    let mut vtu = Vtu::new(w, encoding)?;
    writeln!(
        vtu.w,
        "    <Piece NumberOfPoints=\"{nv}\" NumberOfCells=\"{nt}\">"
    )?;
    match point_field {
        Some((name, values)) => {
            vtu.w.write_all(b"      <PointData Scalars=\"")?;
            write_xml_escaped(&mut vtu.w, name)?;
            vtu.w.write_all(b"\">\n")?;
            vtu.f64_array(Some(name), 1, nv, |i, _| values[i])?;
            vtu.w.write_all(b"      </PointData>\n")?;
        }
        None => vtu
            .w
            .write_all(b"      <PointData>\n      </PointData>\n")?,
    }
    vtu.w.write_all(b"      <CellData Scalars=\"element\">\n")?;
    vtu.data_array(Some("element"), 1, 1, nt, |t, _| t)?;
    vtu.w.write_all(b"      </CellData>\n      <Points>\n")?;
    vtu.f64_array(None, 3, nv, |i, k| match k {
        0 => vertices[i].x,
        1 => vertices[i].y,
        _ => 0.0,
    })?;
    vtu.w.write_all(b"      </Points>\n")?;
    vtu.cells_block(nt, 3, VTK_TRIANGLE, |t, j| triangles[t][j])?;
    vtu.finish()
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

#[cfg(test)]
mod tests {
    use super::super::tests::particles_2d;
    use super::*;
    use nalgebra::Vector1;

    #[test]
    fn f32_particles_are_widened_and_bad_input_is_an_error() {
        let p = Particles::<f32, 1>::new(vec![Vector1::new(0.1f32)], vec![0.5], 2.0);
        let mut bytes = Vec::new();
        write_particles_vtu(&mut bytes, &p, VtuEncoding::Ascii).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.contains(&format!("          {:e} 0e0 0e0\n", 0.1f32 as f64)));

        let mut broken = particles_2d();
        broken.mass.pop();
        let err = write_particles_vtu(Vec::new(), &broken, VtuEncoding::Binary).unwrap_err();
        assert!(err.to_string().contains("`mass`"), "{err}");

        let mesh = psmpm_basis::mesh::generators::block_grid(0.0, 1.0, 0.0, 1.0, 1, 1).unwrap();
        let err =
            write_mesh_vtu(Vec::new(), &mesh, Some(("f", &[1.0])), VtuEncoding::Ascii).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }

    /// The values of the appended `Float64` array at `offset` of a binary `.vtu`
    /// text, decoded as a reader does (header, then the zlib blocks).
    fn decode_f64_array(appended: &[u8], offset: usize) -> Vec<f64> {
        use base64::Engine as _;
        use std::io::Read as _;
        let text = &appended[offset..];
        let first = BASE64.decode(&text[..32]).unwrap();
        let blocks = u64::from_le_bytes(first[..8].try_into().unwrap()) as usize;
        let header_text = base64_len(8 * (3 + blocks));
        let header = BASE64.decode(&text[..header_text]).unwrap();
        let word = |k: usize| u64::from_le_bytes(header[8 * k..8 * k + 8].try_into().unwrap());
        let compressed: usize = (0..blocks).map(|b| word(3 + b) as usize).sum();
        let body = &text[header_text..header_text + base64_len(compressed)];
        let body = BASE64.decode(body).unwrap();
        let (mut raw, mut at) = (Vec::new(), 0);
        for b in 0..blocks {
            let size = word(3 + b) as usize;
            flate2::read::ZlibDecoder::new(&body[at..at + size])
                .read_to_end(&mut raw)
                .unwrap();
            at += size;
        }
        assert_eq!(word(1) as usize, BLOCK_SIZE);
        assert_eq!(word(2) as usize, raw.len() % BLOCK_SIZE);
        raw.chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    #[test]
    fn binary_arrays_of_many_blocks_read_back_exactly() {
        // 2 × 10⁵ particles: the 9-component stress spans 14 blocks, the last partial.
        let n = 200_000;
        let x: Vec<_> = (0..n).map(|i| Vector1::new(i as f64 / n as f64)).collect();
        let mut p = Particles::<f64, 1>::new(x, vec![1.0 / n as f64; n], 3.0);
        for (i, s) in p.sigma.iter_mut().enumerate() {
            s[(0, 0)] = (i as f64).sin();
        }
        let mut bytes = Vec::new();
        write_particles_vtu(&mut bytes, &p, VtuEncoding::Binary).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let appended = text
            .split_once("encoding=\"base64\">\n   _")
            .unwrap()
            .1
            .as_bytes();
        let offset_of = |name: &str| -> usize {
            let tag = text.split_once(&format!("Name=\"{name}\"")).unwrap().1;
            let value = tag.split_once("offset=\"").unwrap().1;
            value[..value.find('"').unwrap()].parse().unwrap()
        };
        let stress = decode_f64_array(appended, offset_of("stress"));
        assert_eq!(stress.len(), 9 * n);
        assert!((0..n).all(|i| stress[9 * i] == (i as f64).sin() && stress[9 * i + 4] == 0.0));
        let mass = decode_f64_array(appended, offset_of("mass"));
        assert_eq!(mass, p.mass);
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
