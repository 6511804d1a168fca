//! Import of 2D triangle meshes from Gmsh `.msh` files (format 4.1 and 2.2, ASCII).
//!
//! Sections read: `$MeshFormat`, `$PhysicalNames`, `$Entities` (4.1: the physical
//! groups of curves), `$Nodes`, `$Elements`; others (`$Periodic`, `$NodeData`,
//! comments, …) are skipped.
//!
//! - Triangles (element type 2) form the mesh. Points (type 15) are ignored. Any
//!   other element type (quadrilaterals, second-order elements, 3D elements) is an
//!   error: psmpm reads first-order triangle meshes.
//! - Line elements (type 1) that belong to a physical group tag the boundary edge
//!   they cover, by the group's name from `$PhysicalNames` (or its number as a
//!   string when unnamed). When a curve is in several physical groups, the first
//!   one listed is used. Lines on interior curves tag nothing; a line element that
//!   is not an edge of the triangles (a curve meshed apart from the surface it
//!   should bound) is an error at its line. A physical name that is empty, or a
//!   group named twice with different names, is an error at its line.
//! - Triangles in a physical surface are reported by
//!   [`parse_msh_with_surfaces`] ([`PhysicalSurfaces`]: the group of every triangle,
//!   by the name from `$PhysicalNames` or the number), for placing material points.
//! - Nodes used by no triangle are dropped and the rest renumbered in file order.
//! - All nodes must lie in one plane `z = const` (usually `z = 0`).
//! - A mesh whose triangles are all clockwise (a surface whose normal points
//!   down, −z) is flipped to counter-clockwise; a mix of orientations is an error
//!   of the mesh validation ([`MeshError::InvertedTriangle`]).
//!
//! Every count read from the file (physical names, entities, entity blocks, nodes,
//! elements, tags) is checked against a limit ([`MAX_NODES`], [`MAX_ELEMENTS`], …)
//! before anything is allocated or read for it; a count above its limit is a syntax
//! error at its line naming the value and the limit (`mesh.msh:13: the number of
//! nodes is 9223372036854775807, above the limit of 10000000`).
//!
//! Every error names the file; syntax errors also give the 1-based line and what
//! was expected there (`mesh.msh:17: expected 4 values in a $Elements entity block
//! header (…), found 3: `2 1 2``). Binary files are rejected with a hint to save
//! them as ASCII.
//!
//! This module reads the sections both versions share (`$MeshFormat`, which decides
//! the version, `$PhysicalNames`, skipped sections), collects nodes, triangles and
//! tagged lines, and builds the mesh; the version-specific layouts of `$Entities`,
//! `$Nodes` and `$Elements` are read by `v41.rs` and `v22.rs`.

mod v22;
mod v41;

use super::{MeshError, TriMesh, Vec2};
use std::collections::HashMap;
use std::path::Path;

/// Most nodes a file may hold: in one `$Nodes` count, one entity block, and all
/// blocks together. A 256 MiB file (the largest `psmpm` reads) holds fewer.
pub const MAX_NODES: usize = 10_000_000;
/// Most elements (points, lines, triangles) a file may hold: in one `$Elements`
/// count, one entity block, and all blocks together.
pub const MAX_ELEMENTS: usize = 20_000_000;
/// Most entity blocks of a format 4.1 `$Nodes` or `$Elements` section.
pub const MAX_ENTITY_BLOCKS: usize = 1_000_000;
/// Most entities of each dimension in a format 4.1 `$Entities` section.
pub const MAX_ENTITIES: usize = 1_000_000;
/// Most entries of `$PhysicalNames`.
pub const MAX_PHYSICAL_NAMES: usize = 100_000;
/// Most tags of one element (format 2.2) or physical tags of one curve (format 4.1).
pub const MAX_TAGS: usize = 1_000;

/// Most characters of the file's text echoed in a message.
pub const MAX_SHOWN_CHARS: usize = 80;

/// Text of a file (a mesh, a scene) as a message shows it: control characters
/// escaped (`\u{1b}`) and cut to [`MAX_SHOWN_CHARS`] characters with an ellipsis,
/// so that a binary or one-line file neither garbles the terminal nor floods it.
pub fn shown(text: &str) -> String {
    let mut out = String::new();
    for (n, c) in text.chars().enumerate() {
        if n == MAX_SHOWN_CHARS {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}

/// An error reading a `.msh` file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GmshError {
    /// The file could not be read.
    #[error("{file}: cannot read: {message}")]
    Io {
        /// The path, as given.
        file: String,
        /// The operating system's message.
        message: String,
    },
    /// The file is not a valid ASCII `.msh` file of a supported kind.
    #[error("{file}:{line}: {message}")]
    Syntax {
        /// The file name.
        file: String,
        /// 1-based line number (one past the last line at end of file).
        line: usize,
        /// What was expected and what was found.
        message: String,
    },
    /// The file parsed but describes no usable mesh (no nodes, no triangles, not planar).
    #[error("{file}: {message}")]
    Content {
        /// The file name.
        file: String,
        /// What is missing or wrong.
        message: String,
    },
    /// The triangles do not form a valid mesh. The message names the file's node
    /// tags and, for a failure of one triangle, the line of its element.
    #[error("{file}{}: invalid mesh: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Mesh {
        /// The file name.
        file: String,
        /// The 1-based line of the element at fault, when one triangle is.
        line: Option<usize>,
        /// The failure in the file's terms (node tags, not the mesh's indices).
        message: String,
        /// The validation failure, in the mesh's 0-based indices.
        source: MeshError,
    },
}

/// Reads a `.msh` file (see the [module documentation](self) for what is read).
///
/// A file that is not valid UTF-8 is decoded lossily, so that a binary file is
/// reported by its `$MeshFormat` line ("binary .msh is not supported").
pub fn read_msh(path: &Path) -> Result<TriMesh, GmshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| GmshError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    parse_msh(&String::from_utf8_lossy(&bytes), &file)
}

/// A line-oriented reader that knows where it is.
struct Reader<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    pos: usize,
}

impl<'a> Reader<'a> {
    /// An error at 1-based `line`.
    fn error_at(&self, line: usize, message: impl Into<String>) -> GmshError {
        GmshError::Syntax {
            file: self.file.to_string(),
            line: line.max(1),
            message: message.into(),
        }
    }

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
                "expected {}{n} value{} in {what}, found {}: `{}`",
                if at_least { "at least " } else { "" },
                if n == 1 { "" } else { "s" },
                f.len(),
                shown(line)
            )));
        }
        Ok(f)
    }

    fn int(&self, s: &str, what: &str) -> Result<i64, GmshError> {
        s.parse::<i64>().map_err(|_| {
            self.error(format!(
                "expected an integer for {what}, found `{}`",
                shown(s)
            ))
        })
    }

    fn count(&self, s: &str, what: &str) -> Result<usize, GmshError> {
        let v = self.int(s, what)?;
        usize::try_from(v)
            .map_err(|_| self.error(format!("{what} must be non-negative, found {v}")))
    }

    /// A count of at most `limit`, checked before anything is read or allocated for it.
    /// A number of digits too large for any integer type is above the limit too.
    fn bounded(&self, s: &str, what: &str, limit: usize) -> Result<usize, GmshError> {
        let digits = s.strip_prefix('+').unwrap_or(s);
        let n = if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
            digits.parse::<usize>().ok()
        } else {
            Some(self.count(s, what)?)
        };
        match n {
            Some(n) if n <= limit => Ok(n),
            _ => {
                let shown = if digits.len() > 40 {
                    format!("{}… ({} digits)", &digits[..20], digits.len())
                } else {
                    digits.to_string()
                };
                Err(self.error(format!("{what} is {shown}, above the limit of {limit}")))
            }
        }
    }

    /// Adds `n` more items (read for `what`) to `total` and checks the sum against `limit`.
    fn add_total(
        &self,
        total: &mut usize,
        n: usize,
        what: &str,
        limit: usize,
    ) -> Result<(), GmshError> {
        *total = total.saturating_add(n);
        if *total > limit {
            return Err(self.error(format!(
                "{what} in all is {total}, above the limit of {limit}"
            )));
        }
        Ok(())
    }

    /// The number of lines not read yet (an upper bound on the items still to come).
    fn remaining(&self) -> usize {
        self.lines.len().saturating_sub(self.pos)
    }

    fn float(&self, s: &str, what: &str) -> Result<f64, GmshError> {
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error(format!(
                "expected a finite number for {what}, found `{}`",
                shown(s)
            ))),
        }
    }

    fn expect_end(&mut self, section: &str) -> Result<(), GmshError> {
        let end = format!("$End{section}");
        let line = self.next(&end)?;
        if line != end {
            return Err(self.error(format!("expected {end}, found `{}`", shown(line))));
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

/// The name and node count of an element type psmpm reads (line, triangle, point),
/// or an error naming the type.
fn supported_element(r: &Reader, kind: i64) -> Result<(&'static str, usize), GmshError> {
    match element_info(kind) {
        None => Err(r.error(format!("unknown element type {kind}"))),
        Some(info) if matches!(kind, 1 | 2 | 15) => Ok(info),
        Some((name, _)) => Err(r.error(format!(
            "{name} elements (type {kind}) are not supported: psmpm reads first-order triangle meshes"
        ))),
    }
}

/// What the sections of a file give, in either format, before the mesh is built.
#[derive(Default)]
struct Contents {
    /// Physical names by `(dimension, physical tag)`.
    names: HashMap<(i64, i64), String>,
    /// The physical tag of each curve entity that has one (4.1 `$Entities`).
    curve_physical: HashMap<i64, i64>,
    /// The physical tag of each surface entity that has one (4.1 `$Entities`).
    surface_physical: HashMap<i64, i64>,
    /// The curve and surface entities `$Entities` declares (4.1), when it was read:
    /// an element block must name one of them.
    declared: Option<[std::collections::HashSet<i64>; 2]>,
    nodes: HashMap<i64, [f64; 3]>,
    /// Node ids in file order.
    node_order: Vec<i64>,
    /// Triangles (node ids) with the line they were read on and their physical
    /// surface, if any.
    triangles: Vec<([i64; 3], usize, Option<i64>)>,
    /// Lines in a physical group: node ids, physical tag, line read on.
    lines: Vec<([i64; 2], i64, usize)>,
    /// Nodes and elements announced so far (over all blocks and sections).
    node_total: usize,
    element_total: usize,
    seen_nodes: bool,
    seen_elements: bool,
}

impl Contents {
    /// Records node `id`; a node defined twice is an error at the current line.
    fn add_node(&mut self, r: &Reader, id: i64, xyz: [f64; 3]) -> Result<(), GmshError> {
        if id < 1 {
            return Err(r.error(format!("node tag {id}: Gmsh numbers nodes from 1")));
        }
        if self.nodes.insert(id, xyz).is_some() {
            return Err(r.error(format!("node {id} is defined twice")));
        }
        self.node_order.push(id);
        Ok(())
    }

    /// Records an element of type `kind` with node tags `nodes_of`, read on the
    /// current line: triangles always (with their physical surface), lines when in a
    /// physical group, points never.
    fn add_element(
        &mut self,
        r: &Reader,
        kind: i64,
        nodes_of: &[&str],
        physical: Option<i64>,
    ) -> Result<(), GmshError> {
        let (name, count) = supported_element(r, kind)?;
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
                    self.lines.push(([ids[0], ids[1]], p, r.pos));
                }
            }
            2 => self
                .triangles
                .push(([ids[0], ids[1], ids[2]], r.pos, physical)),
            _ => {} // points
        }
        Ok(())
    }
}

/// Parses the text of a `.msh` file; `source` names it in errors.
pub fn parse_msh(text: &str, source: &str) -> Result<TriMesh, GmshError> {
    parse_msh_with_surfaces(text, source).map(|(mesh, _)| mesh)
}

/// The physical surfaces of a mesh file: the group of every triangle (in the order
/// of [`TriMesh::triangles`]) and the names of the groups.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PhysicalSurfaces {
    /// Physical surface tag of each triangle (`None` outside every group).
    pub of_triangle: Vec<Option<i64>>,
    /// Names of the physical surfaces by tag (from `$PhysicalNames`).
    pub names: HashMap<i64, String>,
}

impl PhysicalSurfaces {
    /// The tag of the physical surface `name`: a name from `$PhysicalNames`, or the
    /// tag itself written as a number, if some triangle belongs to it.
    pub fn find(&self, name: &str) -> Option<i64> {
        let by_name = self
            .names
            .iter()
            .filter(|(_, n)| n.as_str() == name)
            .map(|(&t, _)| t)
            .min();
        let tag = by_name.or_else(|| name.trim().parse::<i64>().ok())?;
        self.of_triangle.contains(&Some(tag)).then_some(tag)
    }

    /// The surfaces that have triangles, as their names (or tags when unnamed),
    /// sorted: for messages.
    pub fn listed(&self) -> Vec<String> {
        let mut tags: Vec<i64> = self.of_triangle.iter().flatten().copied().collect();
        tags.sort_unstable();
        tags.dedup();
        tags.iter()
            .map(|t| self.names.get(t).cloned().unwrap_or_else(|| t.to_string()))
            .collect()
    }
}

/// [`parse_msh`], and the physical surface of every triangle (4.1: that of its
/// surface entity in `$Entities`; 2.2: the element's first tag).
pub fn parse_msh_with_surfaces(
    text: &str,
    source: &str,
) -> Result<(TriMesh, PhysicalSurfaces), GmshError> {
    let mut r = Reader {
        file: source,
        lines: text.lines().collect(),
        pos: 0,
    };
    let mut version: Option<u32> = None; // 22 or 41
    let mut c = Contents::default();
    loop {
        let header = match r.next("a section") {
            Ok(h) => h,
            Err(_) if version.is_some() => break,
            Err(e) => return Err(e),
        };
        match header {
            "$MeshFormat" => {
                let f = r.fields("$MeshFormat (version file-type data-size)", 3, false)?;
                version = Some(match f[0] {
                    "2.2" => 22,
                    "4.1" => 41,
                    other => {
                        return Err(r.error(format!(
                            "unsupported .msh format version {} (supported: 4.1 and 2.2 ASCII)",
                            shown(other)
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
                    "expected $MeshFormat at the start of the file, found `{}`",
                    shown(header)
                )));
            }
            "$PhysicalNames" => {
                let f = r.fields("the $PhysicalNames count", 1, false)?;
                let n = r.bounded(f[0], "the number of physical names", MAX_PHYSICAL_NAMES)?;
                for _ in 0..n {
                    let line = r.next("a physical name")?;
                    let mut parts = line.splitn(3, char::is_whitespace);
                    let dim = r.int(parts.next().unwrap_or(""), "a physical dimension")?;
                    let tag = r.int(parts.next().unwrap_or(""), "a physical tag")?;
                    let raw = parts.next().unwrap_or("").trim();
                    let name = raw.trim_matches('"').to_string();
                    if raw.is_empty() {
                        return Err(r.error(
                            "expected a quoted physical name after the dimension and the tag",
                        ));
                    }
                    if name.is_empty() {
                        return Err(r.error(format!(
                            "the physical group of dimension {dim} and tag {tag} has an empty name: name it in Gmsh, or remove the line to leave it unnamed (it is then known by its number)"
                        )));
                    }
                    if let Some(earlier) = c.names.get(&(dim, tag)) {
                        if *earlier != name {
                            return Err(r.error(format!(
                                "the physical group of dimension {dim} and tag {tag} is named twice, `{}` and `{}`: keep one name per group",
                                shown(earlier),
                                shown(&name)
                            )));
                        }
                    }
                    c.names.insert((dim, tag), name);
                }
                r.expect_end("PhysicalNames")?;
            }
            "$Entities" if version == Some(41) => {
                v41::read_entities(&mut r, &mut c)?;
                r.expect_end("Entities")?;
            }
            "$Nodes" => {
                if c.seen_nodes {
                    return Err(r.error("a second $Nodes section: a .msh file holds one"));
                }
                c.seen_nodes = true;
                if version == Some(22) {
                    v22::read_nodes(&mut r, &mut c)?;
                } else {
                    v41::read_nodes(&mut r, &mut c)?;
                }
                r.expect_end("Nodes")?;
            }
            "$Elements" => {
                if c.seen_elements {
                    return Err(r.error("a second $Elements section: a .msh file holds one"));
                }
                c.seen_elements = true;
                if version == Some(22) {
                    v22::read_elements(&mut r, &mut c)?;
                } else {
                    v41::read_elements(&mut r, &mut c)?;
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
            other => {
                return Err(r.error(format!(
                    "expected a section header, found `{}`",
                    shown(other)
                )))
            }
        }
    }
    build_mesh(c, source)
}

/// The mesh of the collected contents: used nodes in file order, triangles turned
/// counter-clockwise if all are clockwise, boundary edges tagged by their lines; and
/// the physical surfaces of the triangles.
fn build_mesh(c: Contents, source: &str) -> Result<(TriMesh, PhysicalSurfaces), GmshError> {
    let Contents {
        mut names,
        nodes,
        node_order,
        triangles,
        lines,
        seen_nodes,
        seen_elements,
        ..
    } = c;
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
    let undefined = |id: i64, line: usize| GmshError::Syntax {
        file: source.to_string(),
        line,
        message: format!("element refers to undefined node {id}"),
    };
    for (ends, _, line) in &lines {
        if let Some(&id) = ends.iter().find(|id| !nodes.contains_key(id)) {
            return Err(undefined(id, *line));
        }
    }
    // Keep used nodes in file order.
    let mut used: HashMap<i64, usize> = HashMap::new();
    for (tri, line, _) in &triangles {
        for id in tri {
            if !nodes.contains_key(id) {
                return Err(undefined(*id, *line));
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
        .map(|(t, _, _)| t.map(|id| used[&id]))
        .collect();
    let area = |t: &[usize; 3]| super::signed_area(vertices[t[0]], vertices[t[1]], vertices[t[2]]);
    if tris.iter().all(|t| area(t) < 0.0) {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    let mut mesh = TriMesh::new(vertices, tris).map_err(|e| {
        let mut node_of = vec![0i64; used.len()];
        for (&id, &v) in &used {
            node_of[v] = id;
        }
        let (line, message) = in_file_terms(&e, &node_of, &triangles);
        GmshError::Mesh {
            file: source.to_string(),
            line,
            message,
            source: e,
        }
    })?;
    // The first physical group listed for an edge tags it (a curve in several
    // groups has one line element per group).
    let mut tagged = std::collections::HashSet::new();
    for ([id_a, id_b], physical, line) in lines {
        let name = names
            .get(&(1, physical))
            .cloned()
            .unwrap_or_else(|| physical.to_string());
        let (a, b) = match (used.get(&id_a), used.get(&id_b)) {
            (Some(&a), Some(&b)) => (a, b),
            // A line on nodes of no triangle: a curve apart from the surfaces.
            (None, None) => continue,
            _ => (usize::MAX, usize::MAX),
        };
        if a == b || mesh.find_edge(a, b).is_none() {
            return Err(GmshError::Syntax {
                file: source.to_string(),
                line,
                message: format!(
                    "the line element of nodes {id_a} {id_b} in physical group `{}` is not an edge of the triangles: a boundary curve must be meshed with the surfaces it bounds (its nodes shared with theirs)",
                    shown(&name)
                ),
            });
        }
        // Lines on interior curves tag nothing: only boundary edges carry tags.
        if tagged.insert((a.min(b), a.max(b))) {
            mesh.set_edge_tag(a, b, &name);
        }
    }
    let surfaces = PhysicalSurfaces {
        of_triangle: triangles.iter().map(|(_, _, p)| *p).collect(),
        names: names
            .drain()
            .filter(|((dim, _), _)| *dim == 2)
            .map(|((_, tag), name)| (tag, name))
            .collect(),
    };
    Ok((mesh, surfaces))
}

/// A validation failure of the mesh in the file's terms: the node tags of the
/// file (`node_of[v]` for the mesh's vertex `v`) and, for a failure of one
/// triangle, the line of its element (`triangles[t].1`).
fn in_file_terms(
    e: &MeshError,
    node_of: &[i64],
    triangles: &[([i64; 3], usize, Option<i64>)],
) -> (Option<usize>, String) {
    let node = |v: usize| node_of.get(v).copied().unwrap_or(v as i64);
    let element = |t: usize| {
        triangles.get(t).map(|(nodes, line, _)| {
            (
                Some(*line),
                format!(
                    "the triangle of nodes {} {} {}",
                    nodes[0], nodes[1], nodes[2]
                ),
            )
        })
    };
    let at_triangle = |t: usize, what: &str| match element(t) {
        Some((line, named)) => (line, format!("{named} {what}")),
        None => (None, format!("triangle {t} {what}")),
    };
    match *e {
        MeshError::RepeatedVertex { triangle, .. } => {
            at_triangle(triangle, "repeats a node")
        }
        MeshError::DegenerateTriangle { triangle, area } => at_triangle(
            triangle,
            &format!("is degenerate (signed area {area:e} relative to the mesh size): its nodes lie on one line"),
        ),
        MeshError::InvertedTriangle { triangle } => at_triangle(
            triangle,
            "runs clockwise while other triangles run counter-clockwise (surfaces meshed with opposite normals): reverse that surface's mesh in Gmsh (`ReverseMesh`) or list the element's nodes the other way round",
        ),
        MeshError::Overlap { a, b } => match (element(a), element(b)) {
            (Some((line, first)), Some((other_line, second))) => (
                line,
                format!(
                    "{first} overlaps {second} (line {}): the file holds triangles laid over others (a surface meshed twice, or two surfaces over one region); mesh each region once",
                    other_line.unwrap_or(0)
                ),
            ),
            _ => (None, e.to_string()),
        },
        MeshError::NonFiniteVertex { vertex } => {
            (None, format!("node {} has a non-finite coordinate", node(vertex)))
        }
        MeshError::NonManifoldEdge { a, b } => (
            None,
            format!(
                "the edge from node {} to node {} is shared by more than two triangles, or by two that overlap (non-manifold): remove the duplicate or overlapping elements",
                node(a),
                node(b)
            ),
        ),
        MeshError::NonManifoldVertex { vertex } => (
            None,
            format!(
                "node {} is where two separate fans of triangles touch (non-manifold): regions of the mesh meet at that node only; join them along an edge or mesh them apart",
                node(vertex)
            ),
        ),
        MeshError::DuplicateVertex { a, b, x, y } => (
            None,
            format!(
                "nodes {} and {} coincide at ({x}, {y}): the surfaces meeting there do not share their nodes (`Coherence Mesh;` in Gmsh merges them)",
                node(a),
                node(b)
            ),
        ),
        ref other => (None, other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn data(name: &str) -> std::path::PathBuf {
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data")).join(name)
    }

    #[test]
    fn physical_surfaces_are_read_in_both_formats() {
        for file in ["square.msh", "square_v22.msh"] {
            let text = std::fs::read_to_string(data(file)).unwrap();
            let (mesh, s) = parse_msh_with_surfaces(&text, file).unwrap();
            assert_eq!(s.of_triangle.len(), mesh.num_triangles(), "{file}");
            let tag = s.find("domain").unwrap_or_else(|| panic!("{file}: {s:?}"));
            assert!(s.of_triangle.iter().all(|&t| t == Some(tag)), "{file}");
            assert_eq!(s.find(&tag.to_string()), Some(tag));
            assert_eq!(s.find("nowhere"), None);
            assert_eq!(s.listed(), vec!["domain".to_string()]);
        }
    }

    pub(super) fn area(m: &TriMesh) -> f64 {
        (0..m.num_triangles()).map(|t| m.area(t)).sum()
    }

    pub(super) fn sorted_tags(m: &TriMesh) -> Vec<String> {
        let mut tags = m.tags().to_vec();
        tags.sort();
        tags
    }

    /// A unit square in format 2.2: lines tagged by physical group 7 (`wall`).
    pub(super) const GOOD_22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 7 \"wall\"\n$EndPhysicalNames\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n$Elements\n6\n1 1 2 7 1 1 2\n2 1 2 7 1 2 3\n3 1 2 7 1 3 4\n4 1 2 7 1 4 1\n5 2 2 1 1 1 2 3\n6 2 2 1 1 1 3 4\n$EndElements\n";

    /// A unit square in format 4.1: node tags 10…40 and an unused node 25 between
    /// them; curves 1–3 and the interior diagonal 5 in physical group 7 (`wall`),
    /// curve 4 in the unnamed group 8; a point element; a comment section.
    pub(super) const GOOD_41: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
1 7 \"wall\"
$EndPhysicalNames
$Comments
anything at all
$EndComments
$Entities
4 5 1 0
1 0 0 0 0
2 1 0 0 0
3 1 1 0 0
4 0 1 0 0
1 0 0 0 1 0 0 1 7 2 1 -2
2 1 0 0 1 1 0 1 7 2 2 -3
3 0 1 0 1 1 0 1 7 2 3 -4
4 0 0 0 0 1 0 1 8 2 4 -1
5 0 0 0 1 1 0 1 7 2 1 -3
1 0 0 0 1 1 0 0 4 1 2 3 4
$EndEntities
$Nodes
2 5 10 40
0 1 0 1
10
0 0 0
2 1 0 4
20
25
30
40
1 0 0
0.5 0.25 0
1 1 0
0 1 0
$EndNodes
$Elements
7 8 1 9
0 1 15 1
9 10
1 1 1 1
1 10 20
1 2 1 1
2 20 30
1 3 1 1
3 30 40
1 4 1 1
4 40 10
1 5 1 1
7 10 30
2 1 2 2
5 10 20 30
6 10 30 40
$EndElements
";

    /// The 1-based number of the first line equal to `needle`.
    pub(super) fn line_of(text: &str, needle: &str) -> usize {
        1 + text
            .lines()
            .position(|l| l.trim() == needle)
            .unwrap_or_else(|| panic!("`{needle}` not in the text"))
    }

    pub(super) fn syntax(err: GmshError) -> (usize, String) {
        match err {
            GmshError::Syntax { line, message, .. } => (line, message),
            other => panic!("expected a syntax error, got {other}"),
        }
    }

    pub(super) fn syntax_line(text: &str) -> (usize, String) {
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

    fn tag_of(m: &TriMesh, e: &crate::mesh::Edge) -> String {
        m.tags()[e.tag.expect("boundary edge tagged")].clone()
    }

    /// Every boundary edge on a side of the unit square carries that side's name.
    fn assert_unit_square_sides(m: &TriMesh) {
        for e in m.edges().iter().filter(|e| e.is_boundary()) {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            let side = if a.x == 0.0 && b.x == 0.0 {
                "left"
            } else if a.x == 1.0 && b.x == 1.0 {
                "right"
            } else if a.y == 0.0 && b.y == 0.0 {
                "bottom"
            } else if a.y == 1.0 && b.y == 1.0 {
                "top"
            } else {
                continue;
            };
            assert_eq!(tag_of(m, e), side, "edge {a:?}–{b:?}");
        }
    }

    #[test]
    fn reads_the_square_in_both_formats() {
        let a = read_msh(&data("square.msh")).unwrap();
        let b = read_msh(&data("square_v22.msh")).unwrap();
        assert_eq!(a.vertices(), b.vertices());
        assert_eq!(a.triangles(), b.triangles());
        assert_eq!(a.tags(), b.tags());
        assert!((50..=400).contains(&a.num_triangles()));
        assert!((area(&a) - 1.0).abs() < 1e-12);
        a.require_tagged_boundary().unwrap();
        assert_eq!(sorted_tags(&a), ["bottom", "left", "right", "top"]);
        assert_unit_square_sides(&a);
        assert_unit_square_sides(&b);
    }

    #[test]
    fn reads_the_square_with_a_hole_in_both_formats() {
        let m = read_msh(&data("square_hole.msh")).unwrap();
        let v22 = read_msh(&data("square_hole_v22.msh")).unwrap();
        assert_eq!(m.vertices(), v22.vertices());
        assert_eq!(m.triangles(), v22.triangles());
        assert!((50..=400).contains(&m.num_triangles()));
        m.require_tagged_boundary().unwrap();
        assert_eq!(sorted_tags(&m), ["bottom", "hole", "left", "right", "top"]);
        assert_unit_square_sides(&m);
        // The hole's edges: on the circle, enclosing the polygon whose area is missing.
        let hole = m.tag_id("hole").unwrap();
        let mut enclosed = 0.0;
        let mut count = 0;
        for e in m.edges().iter().filter(|e| e.tag == Some(hole)) {
            let [a, b] = e.vertices.map(|v| m.vertices()[v]);
            for p in [a, b] {
                assert!(((p - Vec2::new(0.5, 0.5)).norm() - 0.2).abs() < 1e-9);
            }
            enclosed += 0.5 * (a.x * b.y - a.y * b.x);
            count += 1;
        }
        assert!(count >= 12);
        // Boundary edges run counter-clockwise around the domain: clockwise round the hole.
        assert!(enclosed < 0.0);
        assert!((area(&m) - (1.0 + enclosed)).abs() < 1e-12);
        assert!((-enclosed - std::f64::consts::PI * 0.04).abs() < 0.01);
    }

    #[test]
    fn reads_the_l_shape() {
        let l = read_msh(&data("lshape.msh")).unwrap();
        l.require_tagged_boundary().unwrap();
        assert_eq!(l.tags(), ["wall"]);
        assert!((area(&l) - 0.75).abs() < 1e-12);
        assert!(l.vertices().contains(&Vec2::new(0.5, 0.5)));
    }

    #[test]
    fn rejects_binary_files_and_quadrilaterals_with_their_line() {
        let binary = data("square_binary.msh");
        match read_msh(&binary).unwrap_err() {
            GmshError::Syntax {
                file,
                line,
                message,
            } => {
                assert_eq!(file, binary.display().to_string());
                assert_eq!(line, 2);
                assert!(
                    message.contains("binary .msh is not supported"),
                    "{message}"
                );
                assert!(message.contains("Mesh.Binary = 0"), "{message}");
            }
            other => panic!("expected a syntax error, got {other}"),
        }
        let quads = data("quads.msh");
        let text = std::fs::read_to_string(&quads).unwrap();
        let err = read_msh(&quads).unwrap_err();
        let (line, message) = syntax(err);
        assert_eq!(line, line_of(&text, "2 1 3 78"));
        assert!(
            message.contains("quadrilateral elements (type 3) are not supported"),
            "{message}"
        );
        let missing = read_msh(Path::new("/nonexistent/mesh.msh")).unwrap_err();
        assert!(matches!(missing, GmshError::Io { .. }));
        assert!(missing
            .to_string()
            .starts_with("/nonexistent/mesh.msh: cannot read"));
    }

    #[test]
    fn handwritten_files_parse_in_both_formats() {
        let a = parse_msh(GOOD_22, "good.msh").unwrap();
        assert_eq!(a.num_triangles(), 2);
        assert_eq!(a.tags(), ["wall"]);
        a.require_tagged_boundary().unwrap();

        let b = parse_msh(GOOD_41, "good.msh").unwrap();
        // Node 25 is dropped; the rest keep file order.
        assert_eq!(b.vertices(), a.vertices());
        assert_eq!(b.triangles(), a.triangles());
        b.require_tagged_boundary().unwrap();
        // Unnamed group 8 tags the left side by its number; the interior diagonal tags nothing.
        assert_eq!(sorted_tags(&b), ["8", "wall"]);
        let left = b.tag_id("8").unwrap();
        let tagged: Vec<_> = b.edges().iter().filter(|e| e.tag == Some(left)).collect();
        assert_eq!(tagged.len(), 1);
        assert_eq!(tagged[0].vertices.map(|v| b.vertices()[v].x), [0.0, 0.0]);
        assert!(b.edges().iter().all(|e| e.is_boundary() || e.tag.is_none()));
    }

    #[test]
    fn clockwise_meshes_are_flipped_and_mixed_ones_rejected() {
        let cw = GOOD_22
            .replace("5 2 2 1 1 1 2 3", "5 2 2 1 1 1 3 2")
            .replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 4 3");
        let m = parse_msh(&cw, "cw.msh").unwrap();
        assert_eq!(m.num_triangles(), 2);
        assert!((area(&m) - 1.0).abs() < 1e-15);
        m.require_tagged_boundary().unwrap();
        let mixed = GOOD_22.replace("5 2 2 1 1 1 2 3", "5 2 2 1 1 1 3 2");
        let error = parse_msh(&mixed, "mixed.msh").unwrap_err();
        assert!(matches!(
            error,
            GmshError::Mesh {
                source: MeshError::InvertedTriangle { triangle: 0 },
                ..
            }
        ));
        // Named by the element's line and the file's node tags.
        assert!(
            error.to_string().starts_with(
                "mixed.msh:21: invalid mesh: the triangle of nodes 1 3 2 runs clockwise"
            ),
            "{error}"
        );
    }

    /// Physical lines that are not edges of the triangles, and physical names that
    /// are empty or given twice, are errors at their line (they were dropped, or
    /// the last name won, in silence).
    #[test]
    fn physical_lines_and_names_must_fit_the_mesh() {
        let error = |text: &str| parse_msh(text, "m.msh").unwrap_err().to_string();
        // Nodes 2 and 4 share no triangle; line elements are lines 17–20.
        let across = GOOD_22.replace("3 1 2 7 1 3 4", "3 1 2 7 1 2 4");
        assert!(
            error(&across).starts_with(
                "m.msh:19: the line element of nodes 2 4 in physical group `wall` is not an edge"
            ),
            "{}",
            error(&across)
        );
        let point = GOOD_22.replace("3 1 2 7 1 3 4", "3 1 2 7 1 3 3");
        assert!(
            error(&point).starts_with("m.msh:19: the line element of nodes 3 3"),
            "{}",
            error(&point)
        );
        let empty = GOOD_22.replace("1 7 \"wall\"", "1 7 \"\"");
        assert!(
            error(&empty)
                .contains("m.msh:6: the physical group of dimension 1 and tag 7 has an empty name"),
            "{}",
            error(&empty)
        );
        let twice = GOOD_22.replace(
            "$PhysicalNames\n1\n1 7 \"wall\"",
            "$PhysicalNames\n2\n1 7 \"wall\"\n1 7 \"side\"",
        );
        assert!(error(&twice).contains("m.msh:7: the physical group of dimension 1 and tag 7 is named twice, `wall` and `side`"), "{}", error(&twice));
        // The same name again is no conflict.
        let again = GOOD_22.replace(
            "$PhysicalNames\n1\n1 7 \"wall\"",
            "$PhysicalNames\n2\n1 7 \"wall\"\n1 7 \"wall\"",
        );
        assert!(parse_msh(&again, "m.msh").is_ok());
    }

    /// Node tag 0 (Gmsh numbers from 1) and a second `$Nodes` or `$Elements`
    /// section are errors at their line (they were accepted).
    #[test]
    fn node_tags_start_at_one_and_sections_come_once() {
        let error = |text: &str| parse_msh(text, "m.msh").unwrap_err().to_string();
        let zero = GOOD_22
            .replace("1 0 0 0\n2 1 0 0", "0 0 0 0\n2 1 0 0")
            .replace(" 1 2\n", " 0 2\n");
        assert!(
            error(&zero).starts_with("m.msh:10: node tag 0: Gmsh numbers nodes from 1"),
            "{}",
            error(&zero)
        );
        let twice = GOOD_22.replace("$EndNodes\n", "$EndNodes\n$Nodes\n0\n$EndNodes\n");
        assert!(
            error(&twice).starts_with("m.msh:15: a second $Nodes section"),
            "{}",
            error(&twice)
        );
        let elements = format!("{GOOD_22}$Elements\n0\n$EndElements\n");
        assert!(
            error(&elements).contains("a second $Elements section"),
            "{}",
            error(&elements)
        );
    }

    /// The mesh's validation failures name the file's node tags (not the mesh's
    /// 0-based vertices) and, for one triangle, the line of its element.
    #[test]
    fn invalid_meshes_are_named_in_the_files_terms() {
        // Node 5 at the place of node 3, used by the second triangle.
        let doubled = GOOD_22
            .replace("$Nodes\n4\n", "$Nodes\n5\n")
            .replace("4 0 1 0\n$EndNodes", "4 0 1 0\n5 1 1 0\n$EndNodes")
            .replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 5 4");
        let error = parse_msh(&doubled, "doubled.msh").unwrap_err().to_string();
        assert!(
            error.starts_with("doubled.msh: invalid mesh: nodes 3 and 5 coincide at (1, 1)"),
            "{error}"
        );
        assert!(error.contains("Coherence Mesh"), "{error}");
        // The second triangle's third node on the line through its first two.
        let flat = GOOD_22
            .replace("$Nodes\n4\n", "$Nodes\n5\n")
            .replace("4 0 1 0\n$EndNodes", "4 0 1 0\n5 2 2 0\n$EndNodes")
            .replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 3 4\n7 2 2 1 1 1 3 5");
        let flat = flat.replace("$Elements\n6\n", "$Elements\n7\n");
        let error = parse_msh(&flat, "flat.msh").unwrap_err().to_string();
        assert!(
            error.starts_with(
                "flat.msh:24: invalid mesh: the triangle of nodes 1 3 5 is degenerate"
            ),
            "{error}"
        );
    }

    #[test]
    fn nodes_must_be_planar() {
        // Constant z is fine.
        let lifted = GOOD_41
            .replace("0 0 0\n2 1", "0 0 0.5\n2 1")
            .replace("1 0 0\n0.5", "1 0 0.5\n0.5")
            .replace("1 1 0\n0 1 0\n", "1 1 0.5\n0 1 0.5\n");
        assert_eq!(parse_msh(&lifted, "z.msh").unwrap().num_triangles(), 2);
        let z = GOOD_22.replace("3 1 1 0\n", "3 1 1 0.5\n");
        match parse_msh(&z, "z.msh").unwrap_err() {
            GmshError::Content { file, message } => {
                assert_eq!(file, "z.msh");
                assert!(message.contains("z = 0.5"), "{message}");
            }
            other => panic!("expected a content error, got {other}"),
        }
    }

    #[test]
    fn totals_over_blocks_and_sections_are_bounded() {
        let r = Reader {
            file: "t.msh",
            lines: vec!["a", "b", "c"],
            pos: 2,
        };
        let mut total = 0;
        r.add_total(&mut total, MAX_NODES - 1, "the number of nodes", MAX_NODES)
            .unwrap();
        r.add_total(&mut total, 1, "the number of nodes", MAX_NODES)
            .unwrap();
        let err = r
            .add_total(&mut total, 1, "the number of nodes", MAX_NODES)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "t.msh:2: the number of nodes in all is 10000001, above the limit of 10000000"
        );
        r.add_total(&mut total, usize::MAX, "x", MAX_NODES)
            .unwrap_err();
        assert_eq!(r.remaining(), 1);
    }

    #[test]
    fn no_truncation_or_deleted_line_panics() {
        for text in [GOOD_22, GOOD_41] {
            for end in 0..text.len() {
                let _ = parse_msh(&text[..end], "cut.msh");
            }
            let lines: Vec<&str> = text.lines().collect();
            for skip in 0..lines.len() {
                let mut without = lines.clone();
                without.remove(skip);
                let _ = parse_msh(&without.join("\n"), "skip.msh");
            }
        }
    }
}
