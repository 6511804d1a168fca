//! A scene file that teaches itself: every `key = value` line without a comment
//! gets one from the scene reference, `docs/scenes.md` (the same text a test checks
//! against the schema), saying what the key means, its range and its unit.

/// The scene reference, compiled in.
const REFERENCE: &str = include_str!("../../docs/scenes.md");

/// One documented key: the table it belongs to (`""` for the top level, `mesh`,
/// `body`, `mesh.holes`, …), the `kind` its section is about (if any), and the
/// comment to show.
struct Entry {
    table: String,
    kind: Option<String>,
    key: String,
    comment: String,
}

/// The documented keys, read from the reference's tables.
fn entries() -> Vec<Entry> {
    let mut out = Vec::new();
    let (mut table, mut kind) = (None::<String>, None::<String>);
    for line in REFERENCE.lines() {
        if line.starts_with("## ") || line.starts_with("### ") {
            let quoted: Vec<&str> = line.split('`').skip(1).step_by(2).collect();
            table = if line.contains("Top level") {
                Some(String::new())
            } else {
                quoted
                    .first()
                    .filter(|q| q.starts_with('['))
                    .map(|q| q.trim_matches(|c| c == '[' || c == ']').to_string())
            };
            kind = quoted
                .get(1)
                .and_then(|q| q.strip_prefix("kind = \""))
                .map(|q| q.trim_end_matches('"').to_string());
            continue;
        }
        let (Some(t), Some(rest)) = (&table, line.strip_prefix("| `")) else {
            continue;
        };
        let cells: Vec<&str> = rest.split(" | ").map(str::trim).collect();
        // key`, type, range, default, unit, meaning |
        if cells.len() < 6 {
            continue;
        }
        let key = cells[0].trim_end_matches('`').to_string();
        let (range, unit) = (cells[2], cells[4]);
        let meaning = cells[5].trim_end_matches('|').trim();
        let mut comment = meaning.replace('`', "");
        if !range.is_empty() && range != "any" && key != "kind" {
            comment.push_str(&format!("; {}", range.replace('`', "")));
        }
        if unit != "–" && !unit.is_empty() {
            comment.push_str(&format!(" [{unit}]"));
        }
        out.push(Entry {
            table: t.clone(),
            kind: kind.clone(),
            key,
            comment,
        });
    }
    out
}

/// `text` (a scene file) with a comment after every `key = value` line that has
/// none, from the scene reference. Lines it cannot place are left as they are.
pub fn annotate(text: &str) -> String {
    let entries = entries();
    let lines: Vec<&str> = text.lines().collect();
    let width = lines
        .iter()
        .filter(|l| !l.trim_start().starts_with('#') && l.contains(" = "))
        .map(|l| l.len())
        .max()
        .unwrap_or(0)
        .min(40);
    let mut table = String::new();
    let mut kind: Option<String> = None;
    let mut out = String::new();
    for (n, line) in lines.iter().enumerate() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            table = trimmed
                .trim_matches(|c| c == '[' || c == ']')
                .trim()
                .to_string();
            // The table's kind, wherever in the table it is written.
            kind = lines[n + 1..]
                .iter()
                .map(|l| l.trim())
                .take_while(|l| !l.starts_with('['))
                .find_map(|l| l.strip_prefix("kind = \""))
                .map(|k| k.split('"').next().unwrap_or("").to_string());
        }
        out.push_str(line);
        let key = trimmed.split(" = ").next().unwrap_or("").trim();
        let plain = trimmed.contains(" = ") && !trimmed.contains('#') && !trimmed.starts_with('#');
        if plain {
            // A body's own `[body.material]` and `[body.initial_velocity]` take the
            // keys of the scene's tables.
            let table = match table.strip_prefix("body.") {
                Some(own @ ("material" | "initial_velocity")) => own,
                _ => table.as_str(),
            };
            let found = entries
                .iter()
                .find(|e| e.table == table && e.key == key && e.kind == kind)
                .or_else(|| {
                    entries
                        .iter()
                        .find(|e| e.table == table && e.key == key && e.kind.is_none())
                });
            if let Some(e) = found {
                let pad = width.saturating_sub(line.len()) + 2;
                out.push_str(&" ".repeat(pad));
                out.push_str("# ");
                out.push_str(&e.comment);
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Scene, BUILTIN};

    #[test]
    fn every_key_of_every_builtin_scene_gets_a_comment_and_the_file_still_parses() {
        for (name, _, text) in BUILTIN {
            let shown = annotate(text);
            for line in shown.lines() {
                let t = line.trim();
                if t.contains(" = ") && !t.starts_with('#') {
                    assert!(t.contains('#'), "{name}: `{line}` has no comment");
                }
            }
            let back = Scene::from_toml(&shown, name).unwrap();
            assert_eq!(back, Scene::from_toml(text, name).unwrap(), "{name}");
        }
    }

    #[test]
    fn the_comment_follows_the_kind_of_the_table() {
        let text = "[[effect]]\nkind = \"damping\"\nalpha = 0.1\n\n[[effect]]\nkind = \"gravity\"\ng = [0.0, -9.81]\n";
        let shown = annotate(text);
        assert!(shown.contains("alpha = 0.1"), "{shown}");
        assert!(
            shown.contains("# damping factor; it makes the critical step √(1 + α) times shorter, and the estimate includes that; 0 ≤ α < 1"),
            "{shown}"
        );
        assert!(
            shown.contains("# acceleration; finite [length / time²]"),
            "{shown}"
        );
    }

    #[test]
    fn a_bodys_own_material_and_velocity_are_annotated_like_the_scenes() {
        let text = "[[body]]\nshape = \"disk\"\nradius = 0.5\n\n[body.material]\nyoung = 1e4\n\n[body.initial_velocity]\nkind = \"rigid-rotation\"\nomega = 2.0\n";
        let shown = annotate(text);
        for line in shown.lines().filter(|l| l.contains(" = ")) {
            assert!(line.contains('#'), "`{line}` has no comment:\n{shown}");
        }
        assert!(shown.contains("Young's modulus"), "{shown}");
    }
}
