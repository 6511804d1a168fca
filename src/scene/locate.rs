//! Finding things in a scene's TOML text for error messages: the line and column of
//! a byte offset, the line that sets a key, the value a message quotes, the dotted
//! field a line sets, the value of a field path. A small line scanner over the text
//! as written (the TOML parser reports spans, not fields).

/// 1-based line and column of byte offset `at` in `text`.
pub(super) fn line_column(text: &str, at: usize) -> (usize, usize) {
    let mut at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    // Columns count characters, not bytes.
    let column = before[before.rfind('\n').map_or(0, |i| i + 1)..]
        .chars()
        .count()
        + 1;
    (line, column)
}

/// Byte offset of the first line at or after `from` that sets `key`.
fn key_line_after(text: &str, from: usize, key: &str) -> Option<usize> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        if offset + line.len() > from
            && line
                .split_once('=')
                .is_some_and(|(k, _)| k.trim() == key && !line.trim_start().starts_with('#'))
        {
            return Some(offset + line.len() - line.trim_start().len());
        }
        offset += line.len();
    }
    None
}

/// Byte offset of the first value at or after `from` (in a `key = value` line of the
/// table whose header is the first at or after `from`, or of the tables of the same
/// array `[[T]]` that follow it) that contains `value`.
fn value_after(text: &str, from: usize, value: &str, whole_number: bool) -> Option<usize> {
    // A key whose whole value is the one quoted first (`traction = 2.0` where a
    // sequence was expected, not the `2.0` inside `max = [2.0]` above it), then
    // a value holding it as a number of its own (not `11.5` for `1.5`): where a
    // whole number was expected, first among the keys that take whole numbers
    // (`blocks = [1.5, 30]` under `y = [0.0, 1.5]`: a user was pointed at `y`).
    let whole = |_: &str, v: &str| {
        (v.split('#').next().unwrap_or("").trim() == value).then(|| v.len() - v.trim_start().len())
    };
    let holding = |v: &str| {
        let is_number = |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-' | '+');
        v.match_indices(value)
            .map(|(i, _)| i)
            .find(|&i| !v[..i].ends_with(is_number) && !v[i + value.len()..].starts_with(is_number))
    };
    let integer_key = |key: &str, v: &str| {
        whole_number_rule(key.trim())
            .is_some()
            .then(|| holding(v))
            .flatten()
    };
    keyed_value_after(text, from, whole)
        .or_else(|| {
            whole_number
                .then(|| keyed_value_after(text, from, integer_key))
                .flatten()
        })
        .or_else(|| keyed_value_after(text, from, |_, v| holding(v)))
        .or_else(|| keyed_value_after(text, from, |_, v| v.find(value)))
}

/// The byte offset in the value text (after `=`) of the first key line from
/// `from` on, within the first table there (or the next elements of the same
/// array of tables), where `wanted` finds what it looks for (its offset within
/// the value text).
fn keyed_value_after(
    text: &str,
    from: usize,
    wanted: impl Fn(&str, &str) -> Option<usize>,
) -> Option<usize> {
    let mut offset = 0;
    let mut header: Option<&str> = None;
    for line in text.split_inclusive('\n') {
        if offset >= from {
            let trimmed = line.trim();
            if trimmed.starts_with('[') {
                // The first header, or the next element of the same array.
                match header {
                    None => header = Some(trimmed),
                    Some(h) if h == trimmed && h.starts_with("[[") => {}
                    Some(_) => return None,
                }
            } else if let Some(eq) = line.find('=') {
                if let Some(i) = wanted(&line[..eq], &line[eq + 1..]) {
                    return Some(offset + eq + 1 + i);
                }
            }
        }
        offset += line.len();
    }
    None
}

/// The table (`mesh`, `effect[1]`, `body[1].initial_velocity`; `None` at the top
/// level) of the line of byte offset `at`, a header line naming its own table, and
/// that line. A sub-table of an array of tables (`[body.initial_velocity]`) belongs
/// to the array's last element.
fn table_at(text: &str, at: usize) -> Option<(Option<String>, &str)> {
    let mut table: Option<String> = None;
    let mut counts = std::collections::HashMap::<String, usize>::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim();
        if let Some(name) = trimmed.strip_prefix("[[").and_then(|r| r.split_once("]]")) {
            let name = name.0.trim().to_string();
            let count = counts.entry(name.clone()).or_insert(0);
            table = Some(format!("{name}[{count}]"));
            *count += 1;
        } else if let Some(name) = trimmed.strip_prefix('[').and_then(|r| r.split_once(']')) {
            let name = name.0.trim();
            let element = name.split_once('.').and_then(|(array, rest)| {
                let count = counts.get(array.trim())?;
                Some(format!("{}[{}].{}", array.trim(), count - 1, rest.trim()))
            });
            table = Some(element.unwrap_or_else(|| name.to_string()));
        }
        if at < offset + line.len() {
            return Some((table, line));
        }
        offset += line.len();
    }
    None
}

/// The dotted field (`mesh.blocks`, `effect[1].kind`, `basis`) set on the line of
/// byte offset `at`, if that line is a `key = value` line.
fn field_at(text: &str, at: usize) -> Option<String> {
    let (table, line) = table_at(text, at)?;
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    if key.is_empty()
        || key.starts_with('#')
        || !key
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
    {
        return None;
    }
    Some(match table {
        Some(t) => format!("{t}.{key}"),
        None => key.to_string(),
    })
}

/// The name of a table header line (`mesh.holes` of `[[mesh.holes]]`) and whether
/// it is an array of tables; `None` for other lines (a line of a multi-line array
/// such as `[0.0, 1.0],` is not a header).
fn header(line: &str) -> Option<(String, bool)> {
    let trimmed = line.trim();
    let (inner, array) = match trimmed.strip_prefix("[[") {
        Some(rest) => (rest.split_once("]]")?, true),
        None => (trimmed.strip_prefix('[')?.split_once(']')?, false),
    };
    let (name, after) = inner;
    let after = after.trim();
    let name = name.trim();
    let bare = name
        .chars()
        .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | ' ' | '"'));
    let starts = name
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_' || c == '"');
    (bare && starts && (after.is_empty() || after.starts_with('#'))).then(|| {
        (
            name.split('.').map(str::trim).collect::<Vec<_>>().join("."),
            array,
        )
    })
}

/// Byte offset of the value of field `path` (`time.dt`, `body[1].count`,
/// `body[0].material.young`, `mesh.holes[1].outline`, `mesh`) in the TOML `text`,
/// found by walking its tables (arrays of tables numbered, sub-tables such as
/// `[body.material]` taken as part of the last `[[body]]`, inline tables searched
/// for the key). When the field itself is not written, the nearest enclosing table
/// or key that is (its header, or its value); the start of the file if none is.
pub(super) fn field_offset(text: &str, path: &str) -> usize {
    // Whether `loc` is `path` or encloses it (`body[1]` encloses `body[1].count`).
    let encloses = |loc: &str| {
        path.strip_prefix(loc)
            .is_some_and(|rest| rest.is_empty() || rest.starts_with(['.', '[']))
    };
    // The longest enclosing location so far: its length and offset.
    let mut best: Option<(usize, usize)> = None;
    let consider = |loc: &str, at: usize, best: &mut Option<(usize, usize)>| {
        if encloses(loc) && best.is_none_or(|(len, _)| loc.len() > len) {
            *best = Some((loc.len(), at));
        }
    };
    // The current table's path (`""` at the top level), and per array of tables
    // (by its path without the last index) the index of its last element.
    let mut table = String::new();
    let mut last_index = std::collections::HashMap::<String, usize>::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim();
        if let Some((name, array)) = header(line) {
            // Resolve `a.b.c`: each enclosing array of tables at its last element.
            let mut resolved = String::new();
            for segment in name.split('.') {
                if !resolved.is_empty() {
                    resolved.push('.');
                }
                resolved.push_str(segment);
                if let Some(i) = last_index.get(&resolved) {
                    resolved = format!("{resolved}[{i}]");
                }
            }
            if array {
                // `resolved` ends in the previous element's index, if any.
                let plain = resolved
                    .strip_suffix(']')
                    .and_then(|r| r.rsplit_once('['))
                    .filter(|(head, _)| last_index.contains_key(*head))
                    .map_or(resolved.clone(), |(head, _)| head.to_string());
                let i = last_index.get(&plain).map_or(0, |i| i + 1);
                last_index.insert(plain.clone(), i);
                // Arrays nested in this element start anew.
                last_index.retain(|k, _| !k.starts_with(&format!("{plain}[")));
                resolved = format!("{plain}[{i}]");
            }
            if resolved == path {
                return offset;
            }
            consider(&resolved, offset, &mut best);
            table = resolved;
        } else if let Some((key, value)) = trimmed.split_once('=') {
            let key = key.trim();
            if key.is_empty() || key.starts_with('#') {
                offset += line.len();
                continue;
            }
            let loc = if table.is_empty() {
                key.to_string()
            } else {
                format!("{table}.{key}")
            };
            let eq = line.find('=').unwrap_or(0);
            let value_at = offset + eq + 1 + (value.len() - value.trim_start().len());
            if loc == path {
                return value_at;
            }
            if encloses(&loc) {
                // An inline table: `reference = { kind = "…", v0 = 0.1 }`.
                if let Some(next) = path[loc.len()..]
                    .strip_prefix('.')
                    .map(|rest| rest.split(['.', '[']).next().unwrap_or(rest))
                {
                    let after = &line[eq + 1..];
                    let found = after
                        .find(&format!("{next} "))
                        .or_else(|| after.find(&format!("{next}=")));
                    if let Some(at) = found {
                        return offset + eq + 1 + at;
                    }
                }
                consider(&loc, value_at, &mut best);
            }
        }
        offset += line.len();
    }
    best.map_or(0, |(_, at)| at)
}

/// Where a TOML parse error `e` in `text` belongs (a byte offset), the field it is
/// about (when it is about a key or a value, not about the syntax between them) and
/// its message, prefixed with that field.
pub(super) fn parse_error(text: &str, e: &toml::de::Error) -> (usize, Option<String>, String) {
    let at = e.span().map_or(0, |s| s.start);
    let message = e.message().trim().to_string();
    let at = if message.starts_with("missing field") {
        failing_effect(text, &message)
            .or_else(|| failing_hole(text, &message))
            .unwrap_or(at)
    } else {
        at
    };
    let (at, field, message) = located(text, at, super::names::did_you_mean(message));
    // The type's lower bound is not the field's: say the field's range.
    let message = match field.as_deref().and_then(whole_number_rule) {
        Some(rule) => message.replace(WHOLE_NUMBER, &rule),
        None => message,
    };
    (at, field, message)
}

/// How the parser's message words an unsigned integer (the type's range).
const WHOLE_NUMBER: &str = "a whole number, 0 or more";

/// What the integer field `field` takes, in place of [`WHOLE_NUMBER`], when it is
/// not every whole number (`mesh.blocks`: each in 1..=4096, not 0).
fn whole_number_rule(field: &str) -> Option<String> {
    use super::limits::{MAX_BLOCKS_PER_AXIS, MAX_ELEMENTS_1D};
    let key = field.rsplit('.').next().unwrap_or(field);
    Some(match key {
        "dim" if field == "dim" => "1 or 2".to_string(),
        "blocks" if field == "mesh.blocks" => {
            format!("a whole number in 1..={MAX_BLOCKS_PER_AXIS} along each axis")
        }
        "blocks" => "a whole number, 1 or more, along each axis (as `mesh.blocks`)".to_string(),
        "elements" => format!("a whole number in 1..={MAX_ELEMENTS_1D}"),
        "per_block" => "a whole number in 1..=1000 along each axis".to_string(),
        "count" => "a whole number in 1..=100000 along each axis".to_string(),
        "per_triangle" => "1 or 3".to_string(),
        "subdivide" => format!("a whole number in 0..={}", super::bodies::MAX_SUBDIVIDE),
        _ => return None,
    })
}

/// A missing field of a tagged table is reported by the parser at the header of the
/// first `[[effect]]`, whichever effect lacks it: the header of the first effect
/// that fails alone with the same message.
fn failing_effect(text: &str, message: &str) -> Option<usize> {
    let table: toml::Table = text.parse().ok()?;
    let effects = table.get("effect")?.as_array()?;
    let k = effects.iter().position(|effect| {
        effect
            .clone()
            .try_into::<super::EffectSpec>()
            .is_err_and(|e| e.message().trim() == message)
    })?;
    Some(field_offset(text, &format!("effect[{k}]")))
}

/// Likewise a missing field of a `[[mesh.holes]]` table is reported at the header
/// of `[mesh]` (the tagged table around it): the header of the first hole that
/// fails alone with the same message.
fn failing_hole(text: &str, message: &str) -> Option<usize> {
    let table: toml::Table = text.parse().ok()?;
    let holes = table.get("mesh")?.get("holes")?.as_array()?;
    let k = holes.iter().position(|hole| {
        hole.clone()
            .try_into::<super::Hole>()
            .is_err_and(|e| e.message().trim() == message)
    })?;
    Some(field_offset(text, &format!("mesh.holes[{k}]")))
}

/// [`parse_error`] from the position and message of the error.
fn located(text: &str, at: usize, message: String) -> (usize, Option<String>, String) {
    let mut at = at;
    let mut message = message;
    // An integer beyond 64 bits: say so instead of the parser's internal type.
    if let Some(value) = message
        .strip_prefix("invalid type: integer `")
        .and_then(|r| r.split_once("` as i128"))
        .map(|(v, _)| v.to_string())
    {
        message =
            format!("the integer `{value}` is out of range (integers in a scene file are 64-bit)");
    }
    // A tagged table given as something else: say what it must be.
    if let Some((head, _)) = message.split_once("expected internally tagged enum") {
        message = format!("{head}expected a table with a `kind` key");
    }
    // Rust's type names in the scene's words.
    for (rust, words) in [
        ("expected usize", "expected a whole number, 0 or more"),
        ("expected u64", "expected a whole number, 0 or more"),
        ("expected u32", "expected a whole number, 0 or more"),
        ("expected f64", "expected a number"),
    ] {
        if let Some(head) = message.strip_suffix(rust) {
            message = format!("{head}{words}");
        }
    }
    // Errors of a value in a buffered (tagged) table that quote no value: at
    // their key.
    let key = (message == super::MESH_HOLE_AS_CORNERS).then_some("holes");
    // An unknown field is reported at its table's header: find its line.
    if let Some(offset) = key.and_then(|key| key_line_after(text, at, key)) {
        at = offset;
    } else if let Some(name) = message
        .strip_prefix("unknown field `")
        .and_then(|r| r.split_once('`'))
        .map(|(n, _)| n)
    {
        if let Some(offset) = key_line_after(text, at, name) {
            at = offset;
        }
    } else if text[at.min(text.len())..].starts_with('[')
        && [
            "invalid type",
            "invalid value",
            "unknown variant",
            "invalid length",
        ]
        .iter()
        .any(|m| message.starts_with(m))
    {
        // A value error inside a tagged table is reported at the header of the
        // first table of its kind: find the value the message quotes (`…`, or a
        // string "…" with its quotes, as written).
        let quoted = message.split('`').nth(1).map(str::to_string).or_else(|| {
            let rest = message.split_once("string \"")?.1;
            rest.rfind('"').map(|end| format!("\"{}\"", &rest[..end]))
        });
        if let Some(offset) = quoted.as_ref().and_then(|value| {
            value_after(text, at, value, message.contains("expected a whole number"))
        }) {
            at = offset;
            // A number where a list was expected (a 1D vector): show the list.
            if message.starts_with("invalid type: floating point")
                || message.starts_with("invalid type: integer")
            {
                if let Some(value) = quoted.filter(|_| message.ends_with("expected a sequence")) {
                    // In 2D a vector has two entries (`g = -9.81` for `[0.0, -9.81]`).
                    message = if declared_dim(text) == Some(2) {
                        format!(
                            "{message}: write it as a list of its x and y entries, e.g. `[0.0, {value}]`"
                        )
                    } else {
                        format!("{message}: write it as a list, `[{value}]`")
                    };
                }
            }
        } else if message.starts_with("invalid type: sequence") {
            // An array where a number was expected, with nothing quoted: an
            // array of arrays (`traction = [[2.0]]` for `[2.0]`) is the likely one.
            let nested = |_: &str, v: &str| {
                let value = v.trim_start();
                (value.starts_with('[') && value[1..].trim_start().starts_with('['))
                    .then(|| v.len() - value.len())
            };
            if let Some(offset) = keyed_value_after(text, at, nested) {
                at = offset;
            }
        }
    }
    // A missing field, or an array of the wrong length, inside a table is reported
    // at the table's header: name the table and the field.
    if let Some((table, field)) = header_field(text, at, &message) {
        let name = format!("{table}.{field}");
        // A value that is there is pointed at; a missing one at its table.
        let at = if message.starts_with("missing field") {
            at
        } else {
            key_line_after(text, at, &field).unwrap_or(at)
        };
        return (at, Some(name.clone()), format!("{name}: {message}"));
    }
    // A table header given twice (`[material]` … `[material]`): name the table.
    if message.starts_with("duplicate key") {
        let line_start = text[..at.min(text.len())].rfind('\n').map_or(0, |i| i + 1);
        let line = text[line_start..].lines().next().unwrap_or("");
        if let Some((name, false)) = header(line) {
            return (
                line_start + (line.len() - line.trim_start().len()),
                Some(name.clone()),
                format!("{name}: duplicate table `[{name}]`: give each table once"),
            );
        }
    }
    // Name the field when the error is about a key or a value (not about the
    // syntax between them).
    let about_value = {
        let line_start = text[..at.min(text.len())].rfind('\n').map_or(0, |i| i + 1);
        text[line_start..at.min(text.len())].contains('=')
    };
    let about_key = message.starts_with("unknown field")
        || message.starts_with("duplicate key")
        || key.is_some();
    match field_at(text, at) {
        Some(field) if about_value || about_key => {
            let message = if message.starts_with(&field) {
                message
            } else {
                format!("{field}: {message}")
            };
            (at, Some(field), message)
        }
        _ => (at, None, message),
    }
}

/// For an error reported at a table header `[T]` (or the `k`-th `[[T]]`): the
/// table's path and the field it is about, when the message says: `missing field
/// `X`` names `X`; `invalid length N, …` names the one key of the table whose
/// value is an array of `N` entries.
fn header_field(text: &str, at: usize, message: &str) -> Option<(String, String)> {
    let (table, line) = table_at(text, at)?;
    if !line.trim_start().starts_with('[') {
        return None;
    }
    let path = table?;
    if let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|r| r.split_once('`'))
        .map(|(f, _)| f)
    {
        return Some((path, field.to_string()));
    }
    let length: usize = message
        .strip_prefix("invalid length ")?
        .split(|c: char| !c.is_ascii_digit())
        .next()?
        .parse()
        .ok()?;
    // The table's own lines, up to the next header.
    let line_end = text[..at.min(text.len())].rfind('\n').map_or(0, |i| i + 1) + line.len();
    let body = &text[line_end.min(text.len())..];
    let body = body.find("\n[").map_or(body, |end| &body[..end]);
    let table: toml::Table = body.parse().ok()?;
    let mut keys = table
        .iter()
        .filter(|(_, v)| v.as_array().is_some_and(|a| a.len() == length))
        .map(|(k, _)| k.clone());
    match (keys.next(), keys.next()) {
        (Some(key), None) => Some((path, key)),
        _ => None,
    }
}

/// The scene's `dim = N` from its text (a top-level line), if written.
fn declared_dim(text: &str) -> Option<u32> {
    text.lines()
        .map(str::trim)
        .take_while(|line| !line.starts_with('['))
        .find_map(|line| {
            let (key, value) = line.split_once('=')?;
            (key.trim() == "dim").then(|| value.split('#').next()?.trim().parse().ok())?
        })
}
