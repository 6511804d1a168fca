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

#[cfg(test)]
mod tests {
    use super::super::tests::particles_2d;
    use super::*;
    use nalgebra::Vector1;

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
