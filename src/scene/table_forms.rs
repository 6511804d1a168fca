//! The form of each table of a scene file: one table (`[material]`, or
//! `material = { … }`) or an array of tables (`[[body]]` for each body, or
//! `body = [{ … }]`), as `docs/scenes.md` defines each key. A key written in the
//! other form (`[[material]]`, `[body]`, `[[body.material]]`, `body = { … }`) got
//! the parser's words ("wanted exactly 1 element", "invalid type: map, expected a
//! sequence"), which name no field and no fix: [`wrong_table_form`] finds it in the
//! parsed file and says which field it is, where its header (or inline value) is,
//! and how the field is written. The other form is never accepted, not even an
//! array of one table where one table is meant.

use super::locate;

/// How a key of the schema is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TableForm {
    /// One table: `[key]`, or `key = { … }`.
    OneTable,
    /// An array of tables: `[[key]]` for each entry, or `key = [{ … }, …]`; the
    /// noun of one entry (`body`, `hole`).
    ArrayOfTables { entry: &'static str },
}

/// The tables of the top level, with their forms.
const TOP_LEVEL_TABLES: [(&str, TableForm); 11] = [
    ("mesh", TableForm::OneTable),
    ("material", TableForm::OneTable),
    ("body", TableForm::ArrayOfTables { entry: "body" }),
    ("initial_velocity", TableForm::OneTable),
    ("boundary", TableForm::ArrayOfTables { entry: "boundary" }),
    ("effect", TableForm::ArrayOfTables { entry: "effect" }),
    ("time", TableForm::OneTable),
    ("reference", TableForm::OneTable),
    ("output", TableForm::OneTable),
    (
        "resolution",
        TableForm::ArrayOfTables {
            entry: "resolution",
        },
    ),
    ("study", TableForm::OneTable),
];

/// The tables inside `[mesh]`, with their forms.
const MESH_TABLES: [(&str, TableForm); 1] = [("holes", TableForm::ArrayOfTables { entry: "hole" })];

/// The tables inside each `[[body]]`, with their forms.
const BODY_TABLES: [(&str, TableForm); 2] = [
    ("material", TableForm::OneTable),
    ("initial_velocity", TableForm::OneTable),
];

/// A table of the scene written in the other form.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct WrongTableForm {
    /// Byte offset of the offending header (the first `[[material]]`) or of the
    /// inline value (`[{` of `material = [{ … }]`).
    pub at: usize,
    /// Dotted path of the field (`material`, `body`, `body[1].material`,
    /// `mesh.holes`).
    pub field: String,
    /// What is wrong and how the field is written, starting with the field.
    pub message: String,
}

/// The first table (by its place in the file) of the scene file `text` written in
/// the other form; `None` when every table has its form or the text is not TOML
/// (the parser then reports the syntax error).
pub(super) fn wrong_table_form(text: &str) -> Option<WrongTableForm> {
    let document = text.parse::<toml::Table>().ok()?;
    let mut wrong = Vec::new();
    check_tables(text, &document, "", "", &TOP_LEVEL_TABLES, &mut wrong);
    if let Some(mesh) = document.get("mesh").and_then(toml::Value::as_table) {
        check_tables(text, mesh, "mesh.", "mesh.", &MESH_TABLES, &mut wrong);
    }
    if let Some(bodies) = document.get("body").and_then(toml::Value::as_array) {
        for (index, body) in bodies.iter().enumerate() {
            if let Some(body) = body.as_table() {
                let path = format!("body[{index}].");
                check_tables(text, body, &path, "body.", &BODY_TABLES, &mut wrong);
            }
        }
    }
    wrong.into_iter().min_by_key(|w| w.at)
}

/// Checks the keys `tables` of `table` (at the field path `path_prefix`, whose
/// headers are written with `header_prefix`: `body[1].` and `body.`), pushing each
/// key written in the other form onto `wrong`.
fn check_tables(
    text: &str,
    table: &toml::Table,
    path_prefix: &str,
    header_prefix: &str,
    tables: &[(&str, TableForm)],
    wrong: &mut Vec<WrongTableForm>,
) {
    for &(key, form) in tables {
        let Some(value) = table.get(key) else {
            continue;
        };
        let field = format!("{path_prefix}{key}");
        let header = format!("{header_prefix}{key}");
        match form {
            TableForm::OneTable if value.is_array() => {
                // The first `[[T]]` header, or the inline array's value.
                let at = locate::field_offset(text, &format!("{field}[0]"));
                let message = if written_inline(text, at) {
                    format!("{field}: a table, written `[{header}]` or `{key} = {{ … }}`, not an array `{key} = [{{ … }}]`")
                } else {
                    format!("{field}: a table, written `[{header}]`, not an array of tables `[[{header}]]`")
                };
                wrong.push(WrongTableForm { at, field, message });
            }
            TableForm::ArrayOfTables { entry } if value.is_table() => {
                let at = locate::field_offset(text, &field);
                let message = if written_inline(text, at) {
                    format!("{field}: an array of tables, written `{key} = [{{ … }}]` or `[[{header}]]` for each {entry}, not one table `{key} = {{ … }}`")
                } else {
                    format!("{field}: an array of tables, written `[[{header}]]` for each {entry}, not `[{header}]`")
                };
                wrong.push(WrongTableForm { at, field, message });
            }
            _ => {}
        }
    }
}

/// Whether byte offset `at` of `text` is in a `key = value` line (an inline table
/// or array), not at a table header.
fn written_inline(text: &str, at: usize) -> bool {
    let at = at.min(text.len());
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    text.get(line_start..at)
        .is_some_and(|before| before.contains('='))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The field, the 1-based line and column, and the message of `text`'s wrong form.
    fn wrong(text: &str) -> (String, (usize, usize), String) {
        let w = wrong_table_form(text).expect("a wrong form");
        (w.field, locate::line_column(text, w.at), w.message)
    }

    #[test]
    fn a_table_written_as_an_array_of_tables_is_named_at_its_first_header() {
        let text = "name = \"a\"\n\n[[material]]\nyoung = 1.0\ndensity = 1.0\n";
        assert_eq!(
            wrong(text),
            (
                "material".to_string(),
                (3, 1),
                "material: a table, written `[material]`, not an array of tables `[[material]]`"
                    .to_string()
            )
        );
    }

    #[test]
    fn an_array_of_tables_written_as_a_table_is_named_at_its_header() {
        let text = "name = \"a\"\n\n[body]\nmin = [0.0]\nmax = [1.0]\n";
        assert_eq!(
            wrong(text),
            (
                "body".to_string(),
                (3, 1),
                "body: an array of tables, written `[[body]]` for each body, not `[body]`"
                    .to_string()
            )
        );
    }

    #[test]
    fn inline_forms_are_named_at_their_values() {
        let text = "name = \"a\"\ntime = [{ t_end = 1.0 }]\n";
        assert_eq!(
            wrong(text),
            (
                "time".to_string(),
                (2, 8),
                "time: a table, written `[time]` or `time = { … }`, not an array `time = [{ … }]`"
                    .to_string()
            )
        );
        let text = "name = \"a\"\nboundary = { tag = \"left\", fix = [\"x\"] }\n";
        let (field, at, message) = wrong(text);
        assert_eq!((field.as_str(), at), ("boundary", (2, 12)));
        assert!(
            message.contains("not one table `boundary = { … }`"),
            "{message}"
        );
    }

    #[test]
    fn a_table_of_a_later_body_is_named_with_its_body() {
        let text = "[[body]]\nmin = [0.0]\n\n[body.material]\nyoung = 1.0\n\n[[body]]\nmin = [1.0]\n\n[[body.material]]\nyoung = 1.0\n";
        assert_eq!(
            wrong(text),
            (
                "body[1].material".to_string(),
                (10, 1),
                "body[1].material: a table, written `[body.material]`, not an array of tables `[[body.material]]`"
                    .to_string()
            )
        );
    }

    #[test]
    fn the_first_wrong_form_in_the_file_is_named() {
        let text =
            "[[time]]\nt_end = 1.0\n\n[mesh]\nkind = \"polygon\"\n\n[mesh.holes]\ntag = \"h\"\n";
        assert_eq!(wrong(text).0, "time");
        // An array `mesh` is named, and its `holes` are not looked into.
        let text = "[[mesh]]\nkind = \"polygon\"\nholes = { tag = \"h\" }\n";
        assert_eq!(wrong(text).0, "mesh");
        let text =
            "[mesh]\nkind = \"polygon\"\n\n[mesh.holes]\ntag = \"h\"\n\n[[time]]\nt_end = 1.0\n";
        assert_eq!(wrong(text).0, "mesh.holes");
        assert_eq!(wrong(text).1, (4, 1));
    }

    #[test]
    fn tables_of_their_forms_and_text_that_is_not_toml_pass() {
        let scene = super::super::Scene::builtin("column-small")
            .unwrap()
            .to_toml();
        assert_eq!(wrong_table_form(&scene), None);
        assert_eq!(wrong_table_form("[[material]"), None);
        // A value of neither form is the parser's to report.
        assert_eq!(wrong_table_form("material = 3\nbody = 4\n"), None);
    }
}
