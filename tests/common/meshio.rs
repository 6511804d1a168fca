//! The independent reader of output files: `.vtu` with Python's `meshio` (the
//! version `tests/requirements.txt` pins), `.pvd` and SVG with `xml.etree` (which
//! rejects a file that is not well-formed XML). Floats come back as Python `repr`
//! strings, an exact round trip. The tests that use it fail (never skip) without
//! `python3` and `meshio`.

use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

/// The meshio version `tests/requirements.txt` installs.
pub const MESHIO: &str = "5.3.5";

const SCRIPT: &str = r#"
import json, sys
try:
    import meshio
except ImportError as e:
    print(f"cannot import meshio: {e}", file=sys.stderr)
    sys.exit(3)
import xml.etree.ElementTree as ET

def floats(a):
    return [repr(float(x)) for x in a.ravel()]

def local(tag):
    return tag.rsplit("}", 1)[-1]

out = {"meshio": meshio.__version__, "vtu": {}, "pvd": {}, "svg": {}}
for path in sys.argv[1:]:
    if path.endswith(".pvd"):
        root = ET.parse(path).getroot()
        assert root.tag == "VTKFile" and root.get("type") == "Collection", root.attrib
        out["pvd"][path] = [[repr(float(d.get("timestep"))), d.get("file")]
                            for d in root.find("Collection").findall("DataSet")]
    elif path.endswith(".svg"):
        root = ET.parse(path).getroot()
        assert local(root.tag) == "svg", root.tag
        elements = list(root.iter())
        out["svg"][path] = {
            "polyline_strokes": [e.get("stroke") for e in elements if local(e.tag) == "polyline"],
            "circles": sum(1 for e in elements if local(e.tag) == "circle"),
            "texts": ["".join(e.itertext()).strip() for e in elements if local(e.tag) == "text"],
        }
    else:
        m = meshio.read(path)
        out["vtu"][path] = {
            "points": {"shape": list(m.points.shape), "values": floats(m.points)},
            "cells": [[c.type, [[int(i) for i in cell] for cell in c.data]] for c in m.cells],
            "cell_counts": [[c.type, len(c.data)] for c in m.cells],
            "point_data": {k: {"shape": list(v.shape), "values": floats(v)}
                           for k, v in m.point_data.items()},
            "cell_data": {k: [[int(i) for i in block.ravel()] for block in v]
                          for k, v in m.cell_data.items()},
        }
print(json.dumps(out))
"#;

/// What to do when the reader cannot run.
pub fn install_hint() -> String {
    format!(
        "these tests read the output back with meshio: run `python3 -m pip install meshio=={MESHIO}` (or `-r tests/requirements.txt`)"
    )
}

/// Reads `files` (`.vtu`, `.pvd`, `.svg`) and returns the reader's JSON:
/// `{"vtu": {path: {points, cells, cell_counts, point_data, cell_data}},
/// "pvd": {path: [[time, file]]}, "svg": {path: {polyline_strokes, circles, texts}}}`.
pub fn read_back(files: &[PathBuf]) -> Value {
    let output = Command::new("python3")
        .arg("-c")
        .arg(SCRIPT)
        .args(files)
        .output()
        .unwrap_or_else(|e| panic!("cannot run python3 ({e}); {}", install_hint()));
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.code() == Some(3) {
        panic!("{}; {}", stderr.trim(), install_hint());
    }
    assert!(
        output.status.success(),
        "the reader failed ({}):\n{stderr}",
        output.status
    );
    serde_json::from_slice(&output.stdout).expect("the reader prints JSON")
}

/// A float array of the reader's JSON (`{"shape", "values"}`), with its shape.
pub fn array(value: &Value) -> (Vec<usize>, Vec<f64>) {
    let shape = value["shape"]
        .as_array()
        .unwrap_or_else(|| panic!("no array in {value}"))
        .iter()
        .map(|s| s.as_u64().unwrap() as usize)
        .collect();
    let values = value["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().parse::<f64>().unwrap())
        .collect();
    (shape, values)
}
