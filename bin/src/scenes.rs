//! `mpm-cli scenes` and `mpm-cli scene show`: the built-in scenes, listed and shown as
//! scene files that `run` accepts back.

use crate::error::CliError;
use crate::run::read_scene;
use crate::table::Table;
use crate::Format;
use psmpm::scene::annotate;
use psmpm::scene::{Scene, BUILTIN};
use serde_json::json;

/// Arguments of `mpm-cli scenes`.
#[derive(Debug, clap::Args)]
pub struct ScenesArgs {
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// `mpm-cli scene ...`.
#[derive(Debug, clap::Subcommand)]
pub enum SceneCommand {
    /// Print a scene as a TOML scene file (a built-in scene with its comments; a
    /// FILE.toml normalised). Save it, edit it, and run it with `mpm-cli run FILE.toml`.
    Show {
        /// Built-in scene name or FILE.toml.
        scene: String,
    },
}

/// Lists the built-in scenes.
pub fn list(args: ScenesArgs) -> Result<(), CliError> {
    let rows: Vec<(Scene, &str)> = BUILTIN
        .iter()
        .map(|(name, line, _)| Scene::builtin(name).map(|s| (s, *line)))
        .collect::<Result<_, _>>()
        .map_err(CliError::Input)?;
    let reference = |s: &Scene| s.reference.map_or("-", |r| r.error_measure(s.dim));
    match args.format {
        Format::Json => {
            let items: Vec<_> = rows
                .iter()
                .map(|(s, line)| {
                    json!({
                        "name": s.name,
                        "dim": s.dim,
                        "basis": s.basis.name(),
                        "error": s.reference.map(|r| r.error_measure(s.dim)),
                        "description": line,
                    })
                })
                .collect();
            println!("{}", serde_json::Value::Array(items));
        }
        Format::Csv => {
            println!("name,dim,basis,error,description");
            for (s, line) in &rows {
                let record = [
                    s.name.to_string(),
                    s.dim.to_string(),
                    s.basis.name().to_string(),
                    reference(s).to_string(),
                    line.to_string(),
                ];
                println!("{}", crate::out::csv_record(&record));
            }
        }
        Format::Table => {
            let mut table = Table::new(&["name", "dim", "basis", "error", "description"]);
            for (s, line) in &rows {
                table.push(vec![
                    s.name.clone(),
                    format!("{}D", s.dim),
                    s.basis.name().to_string(),
                    reference(s).to_string(),
                    line.to_string(),
                ]);
            }
            print!("{}", table.render());
        }
    }
    Ok(())
}

/// Runs a `scene` subcommand.
pub fn scene(command: SceneCommand) -> Result<(), CliError> {
    match command {
        SceneCommand::Show { scene } => {
            match BUILTIN.iter().find(|(name, _, _)| *name == scene) {
                Some((_, _, text)) => print!("{}", annotate(text)),
                None => print!("{}", annotate(&read_scene(&scene)?.to_toml())),
            }
            Ok(())
        }
    }
}
