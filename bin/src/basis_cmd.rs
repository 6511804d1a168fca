//! `mpm-cli basis plot`: the pictures a teacher shows when explaining Powell–Sabin
//! splines: a mesh with its PS refinement, PS points and control triangles, or one
//! basis function as a shaded surface.

use crate::error::CliError;
use crate::run::{pair, read_scene};
use psmpm::bases::BasisKind;
use psmpm::basis::basis::linear::Linear;
use psmpm::basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::{Basis, TriMesh, Vec2};
use psmpm::output::basis_picture::{basis_function_plot, BasisPlotOptions};
use psmpm::output::mesh_picture::{mesh_plot, MeshPlotOptions};
use psmpm::scene::{parse_mirror_line, parse_split};
use std::path::PathBuf;

/// `mpm-cli basis ...`.
#[derive(Debug, clap::Subcommand)]
pub enum BasisCommand {
    /// Draw a mesh with its PS refinement and control triangles, or (with
    /// --function K) basis function K as a shaded plot, as SVG.
    ///
    /// The mesh is the block grid of --blocks, unit blocks on [0, NX] × [0, NY] (default 2x2), the
    /// mesh of a scene (--scene NAME or FILE.toml), or a Gmsh file (--mesh FILE.msh).
    Plot(PlotArgs),
}

/// Arguments of `mpm-cli basis plot`.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {
    /// Block grid NXxNY of unit blocks, on [0, NX] × [0, NY] (4 triangles per block).
    #[arg(long, value_name = "NXxNY", allow_hyphen_values = true, conflicts_with_all = ["scene", "mesh"])]
    blocks: Option<String>,
    /// Use the mesh of this scene (built-in name or FILE.toml).
    #[arg(long, conflicts_with = "mesh")]
    scene: Option<String>,
    /// Use this Gmsh mesh.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// Draw basis function K instead of the mesh.
    #[arg(long, value_name = "K", allow_hyphen_values = true, value_parser = crate::whole::<usize>("0 or more"))]
    function: Option<usize>,
    /// Basis of the function plot: ps or pl.
    #[arg(long, default_value = "ps")]
    basis: String,
    /// PS split points: incentre or centroid.
    #[arg(long, default_value = "incentre")]
    split: String,
    /// PS: the mirror line the control triangles keep where a vertex is symmetric
    /// about both axes: vertical, horizontal, diagonal or anti-diagonal.
    #[arg(long, value_name = "LINE", default_value = "vertical")]
    mirror_line: String,
    /// Draw only the part of the mesh in the rectangle [X0, X1] × [Y0, Y1] (the
    /// mesh picture shows at most 5000 triangles; a larger mesh is drawn a window
    /// at a time).
    #[arg(long, value_name = "X0,X1,Y0,Y1", allow_hyphen_values = true)]
    window: Option<String>,
    /// Output file. An existing file is refused unless --overwrite is given.
    #[arg(long, default_value = "basis.svg")]
    out: PathBuf,
    /// Replace the --out file if it exists.
    #[arg(long)]
    overwrite: bool,
}

/// Checks `out` before anything is drawn: a directory is refused, and an existing
/// file unless `overwrite` (`--overwrite`), as `run --out` refuses a directory that
/// holds an earlier run's files.
fn check_out(out: &std::path::Path, overwrite: bool) -> Result<(), CliError> {
    let shown = psmpm::scene::limits::echo(&out.display().to_string());
    if out.is_dir() {
        return Err(CliError::Input(format!(
            "output file `{shown}` is a directory; choose another --out"
        )));
    }
    if out.exists() && !overwrite {
        return Err(CliError::Input(format!(
            "output file `{shown}` already exists; pass --overwrite to replace it, or choose another --out"
        )));
    }
    Ok(())
}

fn mesh(args: &PlotArgs) -> Result<TriMesh, CliError> {
    if let Some(path) = &args.mesh {
        // The scene's bounded read: a regular file of at most 256 MiB (a FIFO
        // would block, `/dev/zero` would fill memory).
        return psmpm::scene::limits::read_mesh(&path.display().to_string())
            .map_err(CliError::Input);
    }
    if let Some(name) = &args.scene {
        let scene = read_scene(name)?;
        let located = |e: psmpm::simulation::RunError| match e {
            psmpm::simulation::RunError::Scene(e) => CliError::Input(crate::run::locate(name, &e)),
            other => CliError::Input(other.to_string()),
        };
        if scene.dim != 2 {
            return Err(CliError::Input(format!(
                "--scene: `{name}` is 1D; basis plots are 2D"
            )));
        }
        return psmpm::simulation::triangulation(&scene).map_err(located);
    }
    let (nx, ny) = pair(args.blocks.as_deref().unwrap_or("2x2"), "--blocks")?;
    // A whole picture shows at most 5000 triangles (35 × 35 blocks); with a
    // window, a grid up to 256 × 256 (262 144 triangles, about 0.5 GB of basis).
    let most = if args.window.is_some() { 256 } else { 64 };
    if nx == 0 || ny == 0 || nx > most || ny > most {
        return Err(CliError::Input(format!(
            "--blocks: each count must be in 1..={most} for a picture{}, got {nx}x{ny}",
            if args.window.is_some() {
                " with --window"
            } else {
                " (up to 256 with --window)"
            }
        )));
    }
    block_grid(0.0, nx as f64, 0.0, ny as f64, nx, ny).map_err(|e| CliError::Input(e.to_string()))
}

/// The rectangle of `--window X0,X1,Y0,Y1`.
fn window(text: &str) -> Result<(Vec2, Vec2), CliError> {
    let bad = |why: &str| {
        CliError::Input(format!(
            "--window must look like 0,2,0,1 (X0,X1,Y0,Y1 with X0 < X1 and Y0 < Y1), got `{}`: {why}",
            psmpm::scene::limits::echo(text)
        ))
    };
    let numbers = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|_| bad("four numbers"))?;
    let [x0, x1, y0, y1] = numbers[..] else {
        return Err(bad(&format!("four numbers, not {}", numbers.len())));
    };
    if !numbers.iter().all(|v| v.is_finite()) {
        return Err(bad("finite numbers"));
    }
    if !(x0 < x1 && y0 < y1) {
        return Err(bad("X0 below X1 and Y0 below Y1"));
    }
    Ok((Vec2::new(x0, y0), Vec2::new(x1, y1)))
}

/// Runs a `basis` subcommand.
pub fn basis(command: BasisCommand) -> Result<(), CliError> {
    let BasisCommand::Plot(args) = command;
    let split: SplitPoint =
        parse_split(&args.split).map_err(|m| CliError::Input(format!("--split: {m}")))?;
    let mirror_line = parse_mirror_line(&args.mirror_line)
        .map_err(|m| CliError::Input(format!("--mirror-line: {m}")))?;
    let kind =
        BasisKind::parse(&args.basis).map_err(|m| CliError::Input(format!("--basis: {m}")))?;
    if args.window.is_some() && args.function.is_some() {
        return Err(CliError::Input(
            "--window: a function picture shows the function's support; --window is for the mesh picture".into(),
        ));
    }
    let window = args.window.as_deref().map(window).transpose()?;
    check_out(&args.out, args.overwrite)?;
    let mesh = mesh(&args)?;
    let extent = {
        let (mut lo, mut hi) = (mesh.vertices()[0], mesh.vertices()[0]);
        for v in mesh.vertices() {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        format!("[{}, {}] × [{}, {}]", lo.x, hi.x, lo.y, hi.y)
    };
    let plot_error = |e: psmpm::output::chart::PlotError| {
        match e {
        psmpm::output::chart::PlotError::FunctionIndex { .. } => {
            CliError::Input(format!("--function: {e}"))
        }
        e @ psmpm::output::chart::PlotError::TooManyTriangles { .. } => {
            CliError::Input(match window {
                None => format!(
                    "{e}: draw a part of the mesh, give --window X0,X1,Y0,Y1 within the mesh's {extent}, or a coarser mesh"
                ),
                Some(_) => {
                    format!("--window: {e}: give a smaller window within the mesh's {extent}")
                }
            })
        }
        e @ psmpm::output::chart::PlotError::Empty(_) if window.is_some() => {
            CliError::Input(format!("--window: {e}: the mesh spans {extent}"))
        }
        e @ psmpm::output::chart::PlotError::InvalidOption(_) if window.is_some() => {
            CliError::Input(format!("--window: {e}"))
        }
        e => CliError::Input(format!("{}: {e}", args.out.display())),
    }
    };
    let functions = match (args.function, kind) {
        (None, BasisKind::Ps) => {
            let ps = PowellSabin::<f64>::with_mirror(mesh, split, mirror_line)
                .map_err(|e| CliError::Input(e.to_string()))?;
            let options = MeshPlotOptions {
                title: format!(
                    "Powell–Sabin refinement and control triangles ({} triangles, {} functions)",
                    ps.mesh().num_triangles(),
                    ps.num_functions()
                ),
                window,
                ..MeshPlotOptions::default()
            };
            mesh_plot(&args.out, &ps, &options).map_err(plot_error)?;
            ps.num_functions()
        }
        (None, _) => {
            return Err(CliError::Input(
                "--basis: the mesh picture shows the PS refinement; use --basis ps, or --function K for a PL function".into(),
            ))
        }
        (Some(k), BasisKind::Ps) => {
            let ps = PowellSabin::<f64>::with_mirror(mesh, split, mirror_line)
                .map_err(|e| CliError::Input(e.to_string()))?;
            basis_function_plot(&args.out, &ps, k, &BasisPlotOptions::default()).map_err(plot_error)?;
            ps.num_functions()
        }
        (Some(k), BasisKind::Pl) => {
            let pl = Linear::<f64>::new(mesh);
            basis_function_plot(&args.out, &pl, k, &BasisPlotOptions::default()).map_err(plot_error)?;
            pl.num_functions()
        }
        (Some(_), other) => {
            return Err(CliError::Input(format!(
                "--basis: `{}` is 1D; basis plots are 2D (ps or pl)",
                other.name()
            )))
        }
    };
    println!("wrote {} ({functions} functions)", args.out.display());
    Ok(())
}
