//! The layout of Gmsh format 4.1: `$Entities` (the physical group of each curve
//! and surface),
//! and `$Nodes` and `$Elements` in entity blocks, where a line element's physical
//! group is that of its curve.

use super::{Contents, GmshError, Reader};

/// Reads the body of `$Entities`: the first physical tag of each curve and surface.
pub(super) fn read_entities(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields(
        "the $Entities header (numPoints numCurves numSurfaces numVolumes)",
        4,
        false,
    )?;
    let counts: Vec<usize> = f
        .iter()
        .map(|s| r.count(s, "an entity count"))
        .collect::<Result<_, _>>()?;
    for _ in 0..counts[0] {
        r.next("a point entity")?;
    }
    for _ in 0..counts[1] {
        let f = r.fields(
            "a curve entity (tag minX minY minZ maxX maxY maxZ numPhysicalTags …)",
            8,
            true,
        )?;
        let tag = r.int(f[0], "a curve tag")?;
        let nphys = r.count(f[7], "the number of physical tags")?;
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
        let nphys = r.count(f[7], "the number of physical tags")?;
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
    Ok(())
}

/// Reads the body of `$Nodes`: entity blocks of node tags, then their coordinates.
pub(super) fn read_nodes(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields(
        "the $Nodes header (numEntityBlocks numNodes minNodeTag maxNodeTag)",
        4,
        false,
    )?;
    let blocks = r.count(f[0], "the number of node blocks")?;
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
        let n = r.count(f[3], "the number of nodes in the block")?;
        let mut ids = Vec::with_capacity(n.min(1 << 16));
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
    Ok(())
}

/// Reads the body of `$Elements`: entity blocks of one element type each.
pub(super) fn read_elements(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields(
        "the $Elements header (numEntityBlocks numElements minElementTag maxElementTag)",
        4,
        false,
    )?;
    let blocks = r.count(f[0], "the number of element blocks")?;
    for _ in 0..blocks {
        let f = r.fields(
            "a $Elements entity block header (entityDim entityTag elementType numElementsInBlock)",
            4,
            false,
        )?;
        let entity = r.int(f[1], "an entity tag")?;
        let kind = r.int(f[2], "an element type")?;
        let n = r.count(f[3], "the number of elements in the block")?;
        // Name an unsupported type at the block header.
        super::supported_element(r, kind)?;
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
        let (line, msg) = syntax_line(&GOOD_41.replace("6 10 30 40", "6 10 30"));
        assert_eq!(line, line_of(GOOD_41, "6 10 30 40"));
        assert!(msg.contains("a triangle needs 3 nodes, found 2"), "{msg}");
        // Truncated inside $Nodes.
        let cut = &GOOD_41[..GOOD_41.find("30\n40\n").unwrap()];
        let (line, msg) = syntax_line(cut);
        assert_eq!(line, cut.lines().count() + 1);
        assert!(msg.contains("end of file, expected a node tag"), "{msg}");
        // Huge counts run into the end of the section, not out of memory.
        let (_, msg) = syntax_line(
            &GOOD_41.replace("4 5 1 0\n", "4 5 9223372036854775807 9223372036854775807\n"),
        );
        assert!(
            msg.contains("a surface entity") && msg.contains("`$EndEntities`"),
            "{msg}"
        );
        let (_, msg) = syntax_line(&GOOD_41.replace("2 1 0 4", "2 1 0 9223372036854775807"));
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
