//! The layout of Gmsh format 2.2: `$Nodes` as `id x y z` lines, `$Elements` as
//! `id type numTags tags… nodes…` lines whose first tag is the physical group.

use super::{Contents, GmshError, Reader, MAX_ELEMENTS, MAX_NODES, MAX_TAGS};

/// Reads the body of `$Nodes`: a count, then one node per line.
pub(super) fn read_nodes(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields("the $Nodes count", 1, false)?;
    let n = r.bounded(f[0], "the number of nodes", MAX_NODES)?;
    r.add_total(&mut c.node_total, n, "the number of nodes", MAX_NODES)?;
    for _ in 0..n {
        let f = r.fields("a node (tag x y z)", 4, false)?;
        let id = r.int(f[0], "a node id")?;
        let xyz = [
            r.float(f[1], "x")?,
            r.float(f[2], "y")?,
            r.float(f[3], "z")?,
        ];
        c.add_node(r, id, xyz)?;
    }
    Ok(())
}

/// Reads the body of `$Elements`: a count, then one element per line (physical
/// group 0 means none).
pub(super) fn read_elements(r: &mut Reader, c: &mut Contents) -> Result<(), GmshError> {
    let f = r.fields("the $Elements count", 1, false)?;
    let n = r.bounded(f[0], "the number of elements", MAX_ELEMENTS)?;
    r.add_total(
        &mut c.element_total,
        n,
        "the number of elements",
        MAX_ELEMENTS,
    )?;
    for _ in 0..n {
        let f = r.fields("an element (tag type numTags tags… nodes…)", 3, true)?;
        let kind = r.int(f[1], "an element type")?;
        let ntags = r.bounded(f[2], "the number of element tags", MAX_TAGS)?;
        if f.len() - 3 < ntags {
            return Err(r.error("element lists fewer tags than it announces"));
        }
        let physical = if ntags > 0 {
            Some(r.int(f[3], "a physical tag")?).filter(|&p| p != 0)
        } else {
            None
        };
        c.add_element(r, kind, &f[3 + ntags..], physical)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::mesh::gmsh::tests::{line_of, syntax_line, GOOD_22};

    #[test]
    fn malformed_2_2_files_give_located_errors() {
        assert!(syntax_line("hello\n").1.contains("$MeshFormat"));
        assert!(syntax_line("").1.contains("end of file"));
        assert!(syntax_line("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n")
            .1
            .contains("binary"));
        assert!(syntax_line("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n")
            .1
            .contains("version 3.0"));
        let (line, msg) = syntax_line(&GOOD_22.replace("2 1 0 0\n", "2 1 x 0\n"));
        assert_eq!(line, line_of(GOOD_22, "2 1 0 0"));
        assert!(msg.contains("`x`"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("2 1 0 0\n", "2 1 1e999 0\n"));
        assert_eq!(line, line_of(GOOD_22, "2 1 0 0"));
        assert!(msg.contains("finite"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("$EndNodes", "$EndNods"));
        assert_eq!(line, line_of(GOOD_22, "$EndNodes"));
        assert!(msg.contains("$EndNodes"));
        let (line, msg) = syntax_line(&GOOD_22.replace("\n4\n1 0 0 0", "\n-4\n1 0 0 0"));
        assert_eq!(line, line_of(GOOD_22, "$Nodes") + 1);
        assert!(msg.contains("non-negative"), "{msg}");
        // Counts above their limits are refused at their line.
        let (line, msg) = syntax_line(&GOOD_22.replace("\n4\n1 0 0 0", "\n10000001\n1 0 0 0"));
        assert_eq!(line, line_of(GOOD_22, "$Nodes") + 1);
        assert_eq!(
            msg,
            "the number of nodes is 10000001, above the limit of 10000000"
        );
        let (line, msg) = syntax_line(&GOOD_22.replace("\n6\n1 1", "\n20000001\n1 1"));
        assert_eq!(line, line_of(GOOD_22, "$Elements") + 1);
        assert_eq!(
            msg,
            "the number of elements is 20000001, above the limit of 20000000"
        );
        let (_, msg) =
            syntax_line(&GOOD_22.replace("\n4\n1 0 0 0", "\n18446744073709551616\n1 0 0 0"));
        assert_eq!(
            msg,
            "the number of nodes is 18446744073709551616, above the limit of 10000000"
        );
        let (_, msg) = syntax_line(
            &GOOD_22.replace("\n4\n1 0 0 0", &format!("\n+{}\n1 0 0 0", "9".repeat(50))),
        );
        assert_eq!(
            msg,
            "the number of nodes is 99999999999999999999… (50 digits), above the limit of 10000000"
        );
        let (line, msg) = syntax_line(&GOOD_22.replace("\n1\n1 7", "\n100001\n1 7"));
        assert_eq!(line, line_of(GOOD_22, "$PhysicalNames") + 1);
        assert_eq!(
            msg,
            "the number of physical names is 100001, above the limit of 100000"
        );
        let (line, msg) = syntax_line(&GOOD_22.replace("5 2 2 1 1 1 2 3", "5 2 1001 1 1 1 2 3"));
        assert_eq!(line, line_of(GOOD_22, "5 2 2 1 1 1 2 3"));
        assert_eq!(
            msg,
            "the number of element tags is 1001, above the limit of 1000"
        );
        let (line, msg) = syntax_line(&GOOD_22.replace("4 0 1 0\n", "3 0 1 0\n"));
        assert_eq!(line, line_of(GOOD_22, "4 0 1 0"));
        assert!(msg.contains("node 3 is defined twice"), "{msg}");
        // Truncated in the middle of element 5.
        let cut = &GOOD_22[..GOOD_22.find("5 2 2 1 1 1 2 3").unwrap() + 6];
        let (line, msg) = syntax_line(cut);
        assert_eq!(line, line_of(GOOD_22, "5 2 2 1 1 1 2 3"));
        assert!(msg.contains("fewer tags"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("$EndElements\n", ""));
        assert_eq!(line, GOOD_22.lines().count());
        assert!(msg.contains("end of file, expected $EndElements"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 3 2 1 1 1 3 4 2"));
        assert!(msg.contains("quadrilateral"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 9 2 1 1 1 3 4 2 1 1 1"));
        assert!(msg.contains("second-order triangle"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 99 2 1 1 1 3 4"));
        assert!(msg.contains("unknown element type 99"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 3 9"));
        assert_eq!(line, line_of(GOOD_22, "6 2 2 1 1 1 3 4"));
        assert!(msg.contains("undefined node 9"), "{msg}");
        let (line, msg) = syntax_line(&GOOD_22.replace("4 1 2 7 1 4 1", "4 1 2 7 1 4 8"));
        assert_eq!(line, line_of(GOOD_22, "4 1 2 7 1 4 1"));
        assert!(msg.contains("undefined node 8"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("6 2 2 1 1 1 3 4", "6 2 2 1 1 1 3"));
        assert!(msg.contains("needs 3 nodes"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("1 7 \"wall\"", "1 7"));
        assert!(msg.contains("quoted physical name"), "{msg}");
        let (_, msg) = syntax_line(&GOOD_22.replace("$EndElements", "$EndElements\nstray"));
        assert!(msg.contains("section header"), "{msg}");
    }
}
