//! The layout of Gmsh format 4.1: `$Entities` (the physical group of each curve
//! and surface),
//! and `$Nodes` and `$Elements` in entity blocks, where a line element's physical
//! group is that of its curve.

use super::{
    Contents, GmshError, Reader, MAX_ELEMENTS, MAX_ENTITIES, MAX_ENTITY_BLOCKS, MAX_NODES, MAX_TAGS,
};

/// Reads the body of `$Entities`: the first physical tag of each curve and surface.
pub(super) fn read_entities(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields(
        "the $Entities header (numPoints numCurves numSurfaces numVolumes)",
        4,
        false,
    )?;
    let counts: Vec<usize> = f
        .iter()
        .map(|s| r.bounded(s, "an entity count", MAX_ENTITIES))
        .collect::<Result<_, _>>()?;
    for _ in 0..counts[0] {
        r.next("a point entity")?;
    }
    let mut declared: [std::collections::HashSet<i64>; 2] = Default::default();
    for _ in 0..counts[1] {
        let f = r.fields(
            "a curve entity (tag minX minY minZ maxX maxY maxZ numPhysicalTags …)",
            8,
            true,
        )?;
        let tag = r.int(f[0], "a curve tag")?;
        declared[0].insert(tag);
        let nphys = r.bounded(f[7], "the number of physical tags", MAX_TAGS)?;
        if f.len() - 8 < nphys {
            return Err(r.error("curve entity lists fewer physical tags than it announces"));
        }
        if nphys > 0 {
            c.curve_physical.insert(tag, r.int(f[8], "a physical tag")?);
        }
    }
    for _ in 0..counts[2] {
        let f = r.fields(
            "a surface entity (tag minX minY minZ maxX maxY maxZ numPhysicalTags …)",
            8,
            true,
        )?;
        let tag = r.int(f[0], "a surface tag")?;
        declared[1].insert(tag);
        let nphys = r.bounded(f[7], "the number of physical tags", MAX_TAGS)?;
        if f.len() - 8 < nphys {
            return Err(r.error("surface entity lists fewer physical tags than it announces"));
        }
        if nphys > 0 {
            c.surface_physical
                .insert(tag, r.int(f[8], "a physical tag")?);
        }
    }
    for _ in 0..counts[3] {
        r.next("a volume entity")?;
    }
    c.declared = Some(declared);
    Ok(())
}

/// Reads the body of `$Nodes`: entity blocks of node tags, then their coordinates.
pub(super) fn read_nodes(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields(
        "the $Nodes header (numEntityBlocks numNodes minNodeTag maxNodeTag)",
        4,
        false,
    )?;
    let blocks = r.bounded(f[0], "the number of node blocks", MAX_ENTITY_BLOCKS)?;
    let declared = r.bounded(f[1], "the number of nodes", MAX_NODES)?;
    let (header, before) = (r.pos, c.node_total);
    for _ in 0..blocks {
        let f = r.fields(
            "a $Nodes entity block header (entityDim entityTag parametric numNodesInBlock)",
            4,
            false,
        )?;
        let parametric = r.int(f[2], "the parametric flag")?;
        if parametric != 0 {
            return Err(r.error("parametric nodes are not supported"));
        }
        let n = r.bounded(f[3], "the number of nodes in the block", MAX_NODES)?;
        r.add_total(&mut c.node_total, n, "the number of nodes", MAX_NODES)?;
        // Each node takes a line: the file's length bounds the allocation too.
        let mut ids = Vec::with_capacity(n.min(r.remaining()));
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
            c.add_node(r, id, xyz)?;
        }
    }
    let held = c.node_total - before;
    if held != declared {
        return Err(r.error_at(
            header,
            format!("the $Nodes header announces {declared} nodes, its blocks hold {held}"),
        ));
    }
    Ok(())
}

/// Reads the body of `$Elements`: entity blocks of one element type each.
pub(super) fn read_elements(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields(
        "the $Elements header (numEntityBlocks numElements minElementTag maxElementTag)",
        4,
        false,
    )?;
    let blocks = r.bounded(f[0], "the number of element blocks", MAX_ENTITY_BLOCKS)?;
    let declared = r.bounded(f[1], "the number of elements", MAX_ELEMENTS)?;
    let (header, before) = (r.pos, c.element_total);
    for _ in 0..blocks {
        let f = r.fields(
            "a $Elements entity block header (entityDim entityTag elementType numElementsInBlock)",
            4,
            false,
        )?;
        let dim = r.int(f[0], "an entity dimension")?;
        let entity = r.int(f[1], "an entity tag")?;
        let kind = r.int(f[2], "an element type")?;
        let n = r.bounded(f[3], "the number of elements in the block", MAX_ELEMENTS)?;
        r.add_total(
            &mut c.element_total,
            n,
            "the number of elements",
            MAX_ELEMENTS,
        )?;
        // Name an unsupported type at the block header.
        super::supported_element(r, kind)?;
        // The block's entity: of the element type's dimension, and declared.
        let element_dim = match kind {
            1 => 1,
            2 => 2,
            _ => 0,
        };
        if dim != element_dim {
            return Err(r.error(format!(
                "the block's entity dimension is {dim}, but its elements (type {kind}) are of dimension {element_dim}"
            )));
        }
        if let Some(declared) = c.declared.as_ref().filter(|_| element_dim > 0) {
            if !declared[element_dim as usize - 1].contains(&entity) {
                let what = if element_dim == 1 { "curve" } else { "surface" };
                return Err(r.error(format!(
                    "the block's {what} {entity} is not declared in $Entities: the file is inconsistent (write it again from Gmsh)"
                )));
            }
        }
        let physical = match kind {
            1 => c.curve_physical.get(&entity).copied(),
            2 => c.surface_physical.get(&entity).copied(),
            _ => None,
        };
        for _ in 0..n {
            let f = r.fields("an element (tag nodes…)", 2, true)?;
            c.add_element(r, kind, &f[1..], physical)?;
        }
    }
    let held = c.element_total - before;
    if held != declared {
        return Err(r.error_at(
            header,
            format!("the $Elements header announces {declared} elements, its blocks hold {held}"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::mesh::gmsh::tests::{line_of, syntax_line, GOOD_41};
    use crate::mesh::gmsh::{parse_msh, GmshError};
    use crate::mesh::MeshError;

    #[test]
    fn malformed_4_1_files_give_located_errors() {
        let (line, msg) = syntax_line(&GOOD_41.replace("1 2 1 1\n", "1 2 1\n"));
        assert_eq!(line, line_of(GOOD_41, "1 2 1 1"));
        assert!(
            msg.starts_with("expected 4 values in a $Elements entity block header"),
            "{msg}"
        );
        assert!(msg.contains("found 3: `1 2 1`"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_41.replace("0.5 0.25 0", "0.5 0,25 0"));
        assert_eq!(line, line_of(GOOD_41, "0.5 0.25 0"));
        assert!(msg.contains("`0,25`"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_41.replace("6 10 30 40", "6 10 30 41"));
        assert_eq!(line, line_of(GOOD_41, "6 10 30 40"));
        assert!(msg.contains("undefined node 41"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_41.replace("2 1 0 4", "2 1 1 4"));
        assert_eq!(line, line_of(GOOD_41, "2 1 0 4"));
        assert!(msg.contains("parametric"), "{msg}");
        let (line, msg) =
            syntax_line(&GOOD_41.replace("1 0 0 0 1 0 0 1 7 2 1 -2", "1 0 0 0 1 0 0 5 7"));
        assert_eq!(line, line_of(GOOD_41, "1 0 0 0 1 0 0 1 7 2 1 -2"));
        assert!(msg.contains("fewer physical tags"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_41.replace("2 1 2 2\n", "2 1 3 2\n"));
        assert_eq!(line, line_of(GOOD_41, "2 1 2 2"));
        assert!(
            msg.contains("quadrilateral elements (type 3) are not supported"),
            "{msg}"
        );
        // A block of an entity `$Entities` does not declare, or of another
        // dimension than its elements.
        let (line, msg) = syntax_line(&GOOD_41.replace("2 1 2 2\n", "2 9 2 2\n"));
        assert_eq!(line, line_of(GOOD_41, "2 1 2 2"));
        assert!(
            msg.contains("the block's surface 9 is not declared in $Entities"),
            "{msg}"
        );
        let (line, msg) = syntax_line(&GOOD_41.replace("1 5 1 1\n", "1 6 1 1\n"));
        assert_eq!(line, line_of(GOOD_41, "1 5 1 1"));
        assert!(msg.contains("the block's curve 6 is not declared"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_41.replace("2 1 2 2\n", "1 1 2 2\n"));
        assert_eq!(line, line_of(GOOD_41, "2 1 2 2"));
        assert!(
            msg.contains(
                "the block's entity dimension is 1, but its elements (type 2) are of dimension 2"
            ),
            "{msg}"
        );
        let (line, msg) = syntax_line(&GOOD_41.replace("6 10 30 40", "6 10 30"));
        assert_eq!(line, line_of(GOOD_41, "6 10 30 40"));
        assert!(msg.contains("a triangle needs 3 nodes, found 2"), "{msg}");
        // Truncated inside $Nodes.
        let cut = &GOOD_41[..GOOD_41.find("30\n40\n").unwrap()];
        let (line, msg) = syntax_line(cut);
        assert_eq!(line, cut.lines().count() + 1);
        assert!(msg.contains("end of file, expected a node tag"), "{msg}");
        // Counts above their limits are refused at their line, before anything is read.
        let huge = "9223372036854775807";
        for (from, to, message) in [
            (
                "4 5 1 0",
                format!("4 5 {huge} {huge}"),
                format!("an entity count is {huge}, above the limit of 1000000"),
            ),
            (
                "2 5 10 40",
                format!("2 {huge} 10 40"),
                format!("the number of nodes is {huge}, above the limit of 10000000"),
            ),
            (
                "2 5 10 40",
                "1000001 5 10 40".into(),
                "the number of node blocks is 1000001, above the limit of 1000000".into(),
            ),
            (
                "2 1 0 4",
                format!("2 1 0 {huge}"),
                format!("the number of nodes in the block is {huge}, above the limit of 10000000"),
            ),
            (
                "2 1 0 4",
                "2 1 0 10000000".into(),
                "the number of nodes in all is 10000001, above the limit of 10000000".into(),
            ),
            (
                "2 1 0 4",
                "2 1 0 10000001".into(),
                "the number of nodes in the block is 10000001, above the limit of 10000000".into(),
            ),
            (
                "7 8 1 9",
                "7 20000001 1 9".into(),
                "the number of elements is 20000001, above the limit of 20000000".into(),
            ),
            (
                "7 8 1 9",
                "1000001 9 1 9".into(),
                "the number of element blocks is 1000001, above the limit of 1000000".into(),
            ),
            (
                "2 1 2 2",
                format!("2 1 2 {huge}"),
                format!(
                    "the number of elements in the block is {huge}, above the limit of 20000000"
                ),
            ),
            (
                "1 0 0 0 1 0 0 1 7 2 1 -2",
                "1 0 0 0 1 0 0 1001 7 2 1 -2".into(),
                "the number of physical tags is 1001, above the limit of 1000".into(),
            ),
        ] {
            let (line, msg) =
                syntax_line(&GOOD_41.replacen(&format!("\n{from}\n"), &format!("\n{to}\n"), 1));
            assert_eq!(line, line_of(GOOD_41, from), "{to}");
            assert_eq!(msg, message);
        }
        // Headers whose totals disagree with their blocks (a user's files: 30 nodes
        // announced for 25, 999 elements for 36), named at the header.
        for (from, to, message) in [
            (
                "2 5 10 40",
                "2 6 10 40",
                "the $Nodes header announces 6 nodes, its blocks hold 5",
            ),
            (
                "7 8 1 9",
                "7 999 1 9",
                "the $Elements header announces 999 elements, its blocks hold 8",
            ),
        ] {
            let (line, msg) =
                syntax_line(&GOOD_41.replacen(&format!("\n{from}\n"), &format!("\n{to}\n"), 1));
            assert_eq!(line, line_of(GOOD_41, from), "{to}");
            assert_eq!(msg, message);
        }
        // A count that keeps the total at its limit is read (and runs into the coordinates).
        let (line, msg) = syntax_line(&GOOD_41.replace("\n2 1 0 4\n", "\n2 1 0 9999999\n"));
        assert_eq!(line, line_of(GOOD_41, "1 0 0"));
        assert!(
            msg.contains("expected 1 value in a node tag, found 3"),
            "{msg}"
        );
        // Sections missing.
        let start = GOOD_41.find("$Nodes").unwrap();
        let end = GOOD_41.find("$Elements").unwrap();
        let no_nodes = format!("{}{}", &GOOD_41[..start], &GOOD_41[end..]);
        match parse_msh(&no_nodes, "x.msh").unwrap_err() {
            GmshError::Content { message, .. } => {
                assert!(message.contains("no $Nodes"), "{message}")
            }
            other => panic!("expected a content error, got {other}"),
        }
        let no_elements = &GOOD_41[..end];
        match parse_msh(no_elements, "x.msh").unwrap_err() {
            GmshError::Content { message, .. } => {
                assert!(message.contains("no triangles"), "{message}")
            }
            other => panic!("expected a content error, got {other}"),
        }
        let degenerate = GOOD_41.replace("1 1 0\n0 1 0\n", "2 0 0\n0 1 0\n");
        assert!(matches!(
            parse_msh(&degenerate, "x.msh"),
            Err(GmshError::Mesh {
                source: MeshError::DegenerateTriangle { .. },
                ..
            })
        ));
    }
}
