//! `mpm-cli project`: the L² projection study (benchmark B1).

use crate::error::CliError;
use crate::table::{fixed2, sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::studies::projection::{self, MassOption, StudyError, StudyRow, MAX_LEVELS};

// `--levels` names its range as "from 1 to 6".
const _: () = assert!(MAX_LEVELS == 6);
use std::path::PathBuf;

/// Arguments of `mpm-cli project`.
#[derive(Debug, clap::Args)]
pub struct ProjectArgs {
    /// Bases to compare, comma-separated: ps, pl.
    #[arg(long, default_value = "ps,pl")]
    basis: String,
    /// Mass options, comma-separated: consistent, lumped.
    #[arg(long, default_value = "consistent,lumped")]
    mass: String,
    /// Number of refinement levels (1 to 6); the default reproduces the thesis' tables.
    #[arg(long, default_value_t = 4, allow_hyphen_values = true, value_parser = crate::whole::<usize>("from 1 to 6"))]
    levels: usize,
    /// Project on this Gmsh mesh (.msh, format 4.1 or 2.2 ASCII) instead of the unit square.
    #[arg(long, value_name = "FILE.msh")]
    mesh: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

fn parse_list<T>(
    list: &str,
    parse: impl Fn(&str) -> Result<T, String>,
) -> Result<Vec<T>, CliError> {
    list.split(',')
        .map(|s| parse(s.trim()).map_err(CliError::Input))
        .collect()
}

fn parse_mass(name: &str) -> Result<MassOption, String> {
    match name {
        "consistent" => Ok(MassOption::Consistent),
        "lumped" => Ok(MassOption::Lumped),
        _ => Err(format!(
            "unknown mass option `{}` (known: consistent, lumped)",
            psmpm::scene::limits::echo(name)
        )),
    }
}

fn study_error(e: StudyError) -> CliError {
    match e {
        StudyError::Projection(p) => CliError::Numerical(format!("projection failed: {p}")),
        other => CliError::Input(other.to_string()),
    }
}

/// Runs the study and prints it.
pub fn run(args: ProjectArgs) -> Result<(), CliError> {
    let kinds = parse_list(&args.basis, |s| {
        let k = BasisKind::parse(s)?;
        if k.dim() != 2 {
            return Err(format!(
                "basis `{s}` is one-dimensional; the projection study needs ps or pl"
            ));
        }
        Ok(k)
    })?;
    let masses = parse_list(&args.mass, parse_mass)?;
    if args.levels == 0 || args.levels > MAX_LEVELS {
        return Err(CliError::Input(format!(
            "--levels must be between 1 and {MAX_LEVELS}, got {}",
            args.levels
        )));
    }
    let mesh = match &args.mesh {
        Some(path) => Some(
            psmpm::scene::limits::read_mesh(&path.to_string_lossy()).map_err(CliError::Input)?,
        ),
        None => None,
    };
    let mut rows: Vec<StudyRow> = Vec::new();
    for &kind in &kinds {
        for &mass in &masses {
            match &mesh {
                Some(mesh) => rows.push(
                    projection::mesh_study::<f64>(kind, mass, mesh.clone()).map_err(study_error)?,
                ),
                None => {
                    let levels =
                        projection::default_levels(kind, args.levels).map_err(study_error)?;
                    rows.extend(
                        projection::unit_square_study::<f64>(kind, mass, &levels)
                            .map_err(study_error)?,
                    );
                }
            }
        }
    }
    match args.format {
        Format::Json => {
            let text = serde_json::to_string_pretty(&rows).expect("rows serialise");
            println!("{text}");
        }
        Format::Csv => {
            println!("basis,mass,n,functions,error,order,error_dx,order_dx,seconds");
            let opt = |v: Option<f64>| v.map_or_else(String::new, |x| x.to_string());
            for r in &rows {
                let record = [
                    r.basis.to_string(),
                    r.mass.to_string(),
                    r.n.map_or_else(String::new, |n| n.to_string()),
                    r.functions.to_string(),
                    r.error.to_string(),
                    opt(r.order),
                    r.error_dx.to_string(),
                    opt(r.order_dx),
                    r.seconds.to_string(),
                ];
                println!("{}", crate::out::csv_record(&record));
            }
        }
        Format::Table => {
            let mut table = Table::new(&[
                "basis",
                "mass",
                "n",
                "functions",
                "error",
                "order",
                "error_dx",
                "order_dx",
                "seconds",
            ]);
            for r in &rows {
                table.push(vec![
                    r.basis.to_string(),
                    r.mass.to_string(),
                    r.n.map_or_else(|| "-".into(), |n| n.to_string()),
                    r.functions.to_string(),
                    sci(r.error),
                    fixed2(r.order),
                    sci(r.error_dx),
                    fixed2(r.order_dx),
                    format!("{:.3}", r.seconds),
                ]);
            }
            print!("{}", table.render());
        }
    }
    Ok(())
}
