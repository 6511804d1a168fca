//! Import of 2D triangle meshes from Gmsh `.msh` files (format 4.1 and 2.2, ASCII).
//!
//! Triangles (element type 2) form the mesh; line elements (type 1) that belong to a
//! physical group tag the boundary edges they cover, by the group's name (or its
//! number when unnamed). Nodes used by no triangle are dropped and the rest
//! renumbered in file order. A mesh whose triangles are all clockwise (a surface
//! with a downward normal) is flipped; a mix of orientations is an error.
//! Every error names the file and, for syntax errors, the line.

use super::{MeshError, TriMesh, Vec2};
use std::collections::HashMap;
use std::path::Path;

/// An error reading a `.msh` file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GmshError {
    /// The file could not be read.
    #[error("{file}: cannot read: {message}")]
    Io { file: String, message: String },
    /// The file is not a valid ASCII `.msh` file of a supported kind.
    #[error("{file}:{line}: {message}")]
    Syntax {
        file: String,
        line: usize,
        message: String,
    },
    /// The file parsed but describes no valid mesh.
    #[error("{file}: {message}")]
    Content { file: String, message: String },
    /// The triangles do not form a valid mesh.
    #[error("{file}: invalid mesh: {source}")]
    Mesh { file: String, source: MeshError },
}

/// Reads a `.msh` file.
pub fn read_msh(path: &Path) -> Result<TriMesh, GmshError> {
    let file = path.display().to_string();
    let text = std::fs::read(path).map_err(|e| GmshError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    let text = String::from_utf8(text).map_err(|_| GmshError::Content {
        file: file.clone(),
        message:
            "not a text file (binary .msh is not supported: save as ASCII with Mesh.Binary = 0)"
                .into(),
    })?;
    parse_msh(&text, &file)
}

/// A line-oriented reader that knows where it is.
struct Reader<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    pos: usize,
}

impl<'a> Reader<'a> {
    fn error(&self, message: impl Into<String>) -> GmshError {
        GmshError::Syntax {
            file: self.file.to_string(),
            line: self.pos.max(1),
            message: message.into(),
        }
    }

    /// The next non-empty line (1-based position kept in `pos`), or an error naming `what`.
    fn next(&mut self, what: &str) -> Result<&'a str, GmshError> {
        while self.pos < self.lines.len() {
            let line = self.lines[self.pos].trim();
            self.pos += 1;
            if !line.is_empty() {
                return Ok(line);
            }
        }
        self.pos = self.lines.len() + 1;
        Err(self.error(format!("unexpected end of file, expected {what}")))
    }

    /// The next line split into exactly `n` (or at least `n` when `at_least`) fields.
    fn fields(&mut self, what: &str, n: usize, at_least: bool) -> Result<Vec<&'a str>, GmshError> {
        let line = self.next(what)?;
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() < n || (!at_least && f.len() != n) {
            return Err(self.error(format!(
                "expected {}{n} fields in {what}, found {}: `{line}`",
                if at_least { "at least " } else { "" },
                f.len()
            )));
        }
        Ok(f)
    }

    fn int(&self, s: &str, what: &str) -> Result<i64, GmshError> {
        s.parse::<i64>()
            .map_err(|_| self.error(format!("expected an integer for {what}, found `{s}`")))
    }

    fn count(&self, s: &str, what: &str) -> Result<usize, GmshError> {
        let v = self.int(s, what)?;
        usize::try_from(v)
            .map_err(|_| self.error(format!("{what} must be non-negative, found {v}")))
    }

    fn float(&self, s: &str, what: &str) -> Result<f64, GmshError> {
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error(format!("expected a finite number for {what}, found `{s}`"))),
        }
    }

    fn expect_end(&mut self, section: &str) -> Result<(), GmshError> {
        let end = format!("$End{section}");
        let line = self.next(&end)?;
        if line != end {
            return Err(self.error(format!("expected {end}, found `{line}`")));
        }
        Ok(())
    }
}

/// Element types: name for messages, number of nodes.
fn element_info(kind: i64) -> Option<(&'static str, usize)> {
    Some(match kind {
        1 => ("line", 2),
        2 => ("triangle", 3),
        3 => ("quadrilateral", 4),
        4 => ("tetrahedron", 4),
        5 => ("hexahedron", 8),
        6 => ("prism", 6),
        7 => ("pyramid", 5),
        8 => ("second-order line", 3),
        9 => ("second-order triangle", 6),
        10 => ("second-order quadrilateral", 9),
        15 => ("point", 1),
        16 => ("8-node quadrilateral", 8),
        _ => return None,
    })
}

/// Parses the text of a `.msh` file; `source` names it in errors.
pub fn parse_msh(text: &str, source: &str) -> Result<TriMesh, GmshError> {
    let mut r = Reader {
        file: source,
        lines: text.lines().collect(),
        pos: 0,
    };
    let mut version: Option<u32> = None; // 22 or 41
    let mut names: HashMap<(i64, i64), String> = HashMap::new();
    let mut curve_physical: HashMap<i64, i64> = HashMap::new();
    let mut nodes: HashMap<i64, [f64; 3]> = HashMap::new();
    let mut node_order: Vec<i64> = Vec::new();
    let mut triangles: Vec<([i64; 3], usize)> = Vec::new();
    let mut lines: Vec<([i64; 2], i64)> = Vec::new(); // nodes, physical tag
    let mut seen_nodes = false;
    let mut seen_elements = false;
    loop {
        let header = match r.next("a section") {
            Ok(h) => h,
            Err(_) if version.is_some() => break,
            Err(e) => return Err(e),
        };
        match header {
            "$MeshFormat" => {
                let f = r.fields("$MeshFormat", 3, false)?;
                version = Some(match f[0] {
                    "2.2" => 22,
                    "4.1" => 41,
                    other => {
                        return Err(r.error(format!(
                            "unsupported .msh format version {other} (supported: 4.1 and 2.2 ASCII)"
                        )))
                    }
                });
                if f[1] != "0" {
                    return Err(
                        r.error("binary .msh is not supported: save as ASCII (Mesh.Binary = 0)")
                    );
                }
                r.expect_end("MeshFormat")?;
            }
            _ if version.is_none() => {
                return Err(r.error(format!(
                    "expected $MeshFormat at the start of the file, found `{header}`"
                )));
            }
            "$PhysicalNames" => {
                let f = r.fields("the number of physical names", 1, false)?;
                let n = r.count(f[0], "the number of physical names")?;
                for _ in 0..n {
                    let line = r.next("a physical name")?;
                    let mut parts = line.splitn(3, char::is_whitespace);
                    let dim = r.int(parts.next().unwrap_or(""), "a physical dimension")?;
                    let tag = r.int(parts.next().unwrap_or(""), "a physical tag")?;
                    let name = parts
                        .next()
                        .unwrap_or("")
                        .trim()
                        .trim_matches('"')
                        .to_string();
                    if name.is_empty() {
                        return Err(r.error("expected a quoted physical name"));
                    }
                    names.insert((dim, tag), name);
                }
                r.expect_end("PhysicalNames")?;
            }
            "$Entities" if version == Some(41) => {
                let f = r.fields("$Entities counts", 4, false)?;
                let counts: Vec<usize> = f
                    .iter()
                    .map(|s| r.count(s, "an entity count"))
                    .collect::<Result<_, _>>()?;
                for _ in 0..counts[0] {
                    r.next("a point entity")?;
                }
                for _ in 0..counts[1] {
                    let f = r.fields("a curve entity", 8, true)?;
                    let tag = r.int(f[0], "a curve tag")?;
                    let nphys = r.count(f[7], "the number of physical tags")?;
                    if f.len() < 8 + nphys {
                        return Err(
                            r.error("curve entity lists fewer physical tags than it announces")
                        );
                    }
                    if nphys > 0 {
                        curve_physical.insert(tag, r.int(f[8], "a physical tag")?);
                    }
                }
                for _ in 0..counts[2] + counts[3] {
                    r.next("a surface or volume entity")?;
                }
                r.expect_end("Entities")?;
            }
            "$Nodes" => {
                seen_nodes = true;
                if version == Some(22) {
                    let f = r.fields("the number of nodes", 1, false)?;
                    let n = r.count(f[0], "the number of nodes")?;
                    for _ in 0..n {
                        let f = r.fields("a node (id x y z)", 4, false)?;
                        let id = r.int(f[0], "a node id")?;
                        let xyz = [
                            r.float(f[1], "x")?,
                            r.float(f[2], "y")?,
                            r.float(f[3], "z")?,
                        ];
                        if nodes.insert(id, xyz).is_some() {
                            return Err(r.error(format!("node {id} is defined twice")));
                        }
                        node_order.push(id);
                    }
                } else {
                    let f = r.fields("$Nodes header (4 integers)", 4, false)?;
                    let blocks = r.count(f[0], "the number of node blocks")?;
                    for _ in 0..blocks {
                        let f = r.fields("a node block header (4 integers)", 4, false)?;
                        let parametric = r.int(f[2], "the parametric flag")?;
                        if parametric != 0 {
                            return Err(r.error("parametric nodes are not supported"));
                        }
                        let n = r.count(f[3], "the number of nodes in the block")?;
                        let mut ids = Vec::with_capacity(n);
                        for _ in 0..n {
                            let f = r.fields("a node tag", 1, false)?;
                            ids.push(r.int(f[0], "a node tag")?);
                        }
                        for id in ids {
                            let f = r.fields("node coordinates (x y z)", 3, false)?;
                            let xyz = [
                                r.float(f[0], "x")?,
                                r.float(f[1], "y")?,
                                r.float(f[2], "z")?,
                            ];
                            if nodes.insert(id, xyz).is_some() {
                                return Err(r.error(format!("node {id} is defined twice")));
                            }
                            node_order.push(id);
                        }
                    }
                }
                r.expect_end("Nodes")?;
            }
            "$Elements" => {
                seen_elements = true;
                let mut push = |r: &Reader, kind: i64, nodes_of: &[&str], physical: Option<i64>| {
                    let (name, count) = element_info(kind)
                        .ok_or_else(|| r.error(format!("unknown element type {kind}")))?;
                    if nodes_of.len() != count {
                        return Err(r.error(format!(
                            "a {name} needs {count} nodes, found {}",
                            nodes_of.len()
                        )));
                    }
                    let ids: Vec<i64> = nodes_of
                        .iter()
                        .map(|s| r.int(s, "a node tag"))
                        .collect::<Result<_, _>>()?;
                    match kind {
                        1 => {
                            if let Some(p) = physical {
                                lines.push(([ids[0], ids[1]], p));
                            }
                        }
                        2 => triangles.push(([ids[0], ids[1], ids[2]], r.pos)),
                        15 => {}
                        _ => {
                            return Err(r.error(format!(
                                "{name} elements are not supported: psmpm reads first-order triangle meshes"
                            )))
                        }
                    }
                    Ok(())
                };
                if version == Some(22) {
                    let f = r.fields("the number of elements", 1, false)?;
                    let n = r.count(f[0], "the number of elements")?;
                    for _ in 0..n {
                        let f = r.fields("an element", 3, true)?;
                        let kind = r.int(f[1], "an element type")?;
                        let ntags = r.count(f[2], "the number of element tags")?;
                        if f.len() < 3 + ntags {
                            return Err(r.error("element lists fewer tags than it announces"));
                        }
                        let physical = if ntags > 0 {
                            Some(r.int(f[3], "a physical tag")?).filter(|&p| p != 0)
                        } else {
                            None
                        };
                        push(&r, kind, &f[3 + ntags..], physical)?;
                    }
                } else {
                    let f = r.fields("$Elements header (4 integers)", 4, false)?;
                    let blocks = r.count(f[0], "the number of element blocks")?;
                    for _ in 0..blocks {
                        let f = r.fields("an element block header (4 integers)", 4, false)?;
                        let entity = r.int(f[1], "an entity tag")?;
                        let kind = r.int(f[2], "an element type")?;
                        let n = r.count(f[3], "the number of elements in the block")?;
                        let physical = if kind == 1 {
                            curve_physical.get(&entity).copied()
                        } else {
                            None
                        };
                        for _ in 0..n {
                            let f = r.fields("an element", 2, true)?;
                            push(&r, kind, &f[1..], physical)?;
                        }
                    }
                }
                r.expect_end("Elements")?;
            }
            other if other.starts_with("$") && !other.starts_with("$End") => {
                // Skip sections we do not use.
                let end = format!("$End{}", &other[1..]);
                loop {
                    if r.next(&end)? == end {
                        break;
                    }
                }
            }
            other => return Err(r.error(format!("expected a section header, found `{other}`"))),
        }
    }
    let content = |message: String| GmshError::Content {
        file: source.to_string(),
        message,
    };
    if !seen_nodes {
        return Err(content("no $Nodes section".into()));
    }
    if !seen_elements || triangles.is_empty() {
        return Err(content("no triangles (element type 2) in the file".into()));
    }
    // Keep used nodes in file order.
    let mut used: HashMap<i64, usize> = HashMap::new();
    for (tri, line) in &triangles {
        for id in tri {
            if !nodes.contains_key(id) {
                return Err(GmshError::Syntax {
                    file: source.to_string(),
                    line: *line,
                    message: format!("element refers to undefined node {id}"),
                });
            }
            used.insert(*id, 0);
        }
    }
    let mut vertices = Vec::new();
    let mut z0: Option<f64> = None;
    for id in &node_order {
        if let Some(slot) = used.get_mut(id) {
            *slot = vertices.len();
            let [x, y, z] = nodes[id];
            match z0 {
                None => z0 = Some(z),
                Some(z0) if (z - z0).abs() > 1e-12 * (1.0 + z0.abs()) => {
                    return Err(content(format!(
                        "node {id} has z = {z} but others have z = {z0}: only planar meshes in a z = const plane are supported"
                    )))
                }
                _ => {}
            }
            vertices.push(Vec2::new(x, y));
        }
    }
    let mut tris: Vec<[usize; 3]> = triangles
        .iter()
        .map(|(t, _)| t.map(|id| used[&id]))
        .collect();
    let area = |t: &[usize; 3]| super::signed_area(vertices[t[0]], vertices[t[1]], vertices[t[2]]);
    if tris.iter().all(|t| area(t) < 0.0) {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    let mut mesh = TriMesh::new(vertices, tris).map_err(|e| GmshError::Mesh {
        file: source.to_string(),
        source: e,
    })?;
    for ([a, b], physical) in lines {
        let (Some(&a), Some(&b)) = (used.get(&a), used.get(&b)) else {
            continue;
        };
        let name = names
            .get(&(1, physical))
            .cloned()
            .unwrap_or_else(|| physical.to_string());
        // Lines on interior curves tag nothing: only boundary edges carry tags.
        mesh.set_edge_tag(a, b, &name);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data")
            .join(name)
    }

    fn area(m: &TriMesh) -> f64 {
        (0..m.num_triangles()).map(|t| m.area(t)).sum()
    }

    #[test]
    fn reads_the_square_in_both_formats() {
        let a = read_msh(&data("square.msh")).unwrap();
        let b = read_msh(&data("square_v22.msh")).unwrap();
        assert_eq!(a.vertices(), b.vertices());
        assert_eq!(a.triangles(), b.triangles());
        assert!((area(&a) - 1.0).abs() < 1e-12);
        a.require_tagged_boundary().unwrap();
        b.require_tagged_boundary().unwrap();
        let mut tags = a.tags().to_vec();
        tags.sort();
        assert_eq!(tags, ["bottom", "left", "right", "top"]);
    }

    #[test]
    fn reads_the_square_with_a_hole_and_the_l_shape() {
        let m = read_msh(&data("square_hole.msh")).unwrap();
        m.require_tagged_boundary().unwrap();
        let hole = m.tag_id("hole").unwrap();
        let hole_edges: Vec<_> = m.edges().iter().filter(|e| e.tag == Some(hole)).collect();
        assert!(hole_edges.len() >= 12);
        for e in hole_edges {
            for v in e.vertices {
                assert!(((m.vertices()[v] - Vec2::new(0.5, 0.5)).norm() - 0.2).abs() < 1e-9);
            }
        }
        // Area of the square minus the inscribed polygon of the circle.
        let expected = 1.0 - std::f64::consts::PI * 0.04;
        assert!((area(&m) - expected).abs() < 0.01);
        assert_eq!(m.locate(Vec2::new(0.5, 0.5), None), None);
        let l = read_msh(&data("lshape.msh")).unwrap();
        l.require_tagged_boundary().unwrap();
        assert!((area(&l) - 0.75).abs() < 1e-12);
        assert_eq!(l.locate(Vec2::new(0.75, 0.75), None), None);
    }

    const GOOD_22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 7 \"wall\"\n$EndPhysicalNames\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n$Elements\n6\n1 1 2 7 1 1 2\n2 1 2 7 1 2 3\n3 1 2 7 1 3 4\n4 1 2 7 1 4 1\n5 2 2 1 1 1 2 3\n6 2 2 1 1 1 3 4\n$EndElements\n";

    fn syntax_line(text: &str) -> (usize, String) {
        match parse_msh(text, "bad.msh").unwrap_err() {
            GmshError::Syntax {
                line,
                message,
                file,
            } => {
                assert_eq!(file, "bad.msh");
                (line, message)
            }
            other => panic!("expected a syntax error, got {other}"),
        }
    }

    #[test]
    fn a_small_handwritten_file_parses() {
        let m = parse_msh(GOOD_22, "good.msh").unwrap();
        assert_eq!(m.num_triangles(), 2);
        m.require_tagged_boundary().unwrap();
        // Clockwise input is flipped.
        let cw = GOOD_22
            .replace("5 2 2 1 1 1 2 3", "5 2 2 1 1 1 3 2")
            .replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 4 3");
        assert_eq!(parse_msh(&cw, "cw.msh").unwrap().num_triangles(), 2);
    }

    #[test]
    fn malformed_files_give_located_errors() {
        assert!(syntax_line("hello\n").1.contains("$MeshFormat"));
        assert!(syntax_line("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n")
            .1
            .contains("binary"));
        assert!(syntax_line("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n")
            .1
            .contains("version"));
        let (line, msg) = syntax_line(&GOOD_22.replace("2 1 0 0\n", "2 1 x 0\n"));
        assert_eq!(line, 11);
        assert!(msg.contains("`x`"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("$EndNodes", "$EndNods"));
        assert_eq!(line, 14);
        assert!(msg.contains("$EndNodes"));
        // Truncated in the middle of element 5.
        let (line, msg) = syntax_line(&GOOD_22[..GOOD_22.len() - 40]);
        assert_eq!(line, 21);
        assert!(msg.contains("fewer tags"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22[..GOOD_22.len() - 13]);
        assert!(msg.contains("end of file"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 3 2 1 1 1 3 4 2"));
        assert!(msg.contains("quadrilateral"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 3 9"));
        assert_eq!(line, 22);
        assert!(msg.contains("undefined node 9"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 3"));
        assert!(msg.contains("needs 3 nodes"), "{msg}");
        let no_tri = GOOD_22
            .replace("5 2 2 1 1 1 2 3\n6 2 2 1 1 1 3 4\n", "")
            .replace("\n6\n1 1", "\n4\n1 1");
        assert!(matches!(
            parse_msh(&no_tri, "x.msh"),
            Err(GmshError::Content { .. })
        ));
        let z = GOOD_22.replace("3 1 1 0\n", "3 1 1 0.5\n");
        assert!(matches!(
            parse_msh(&z, "x.msh"),
            Err(GmshError::Content { .. })
        ));
        let degenerate = GOOD_22.replace("3 1 1 0\n", "3 2 0 0\n");
        assert!(matches!(
            parse_msh(&degenerate, "x.msh"),
            Err(GmshError::Mesh { .. })
        ));
        let missing = read_msh(Path::new("/nonexistent/mesh.msh")).unwrap_err();
        assert!(missing
            .to_string()
            .starts_with("/nonexistent/mesh.msh: cannot read"));
    }
}
