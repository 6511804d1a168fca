//! SVG plots (`psmpm::output::{chart, mesh_picture, basis_picture}`): well-formed files, legends, one drawn curve per line
//! series, one control-triangle polygon per vertex, errors instead of panics.
//!
//! The SVGs go to a fresh directory under the system's temp dir, removed at the end;
//! with `PSMPM_PLOT_DIR` set, copies are also kept there (to look at them).

mod common;

use common::TempDir;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use psmpm::bases;
use psmpm::basis::mesh::generators::block_grid;
use psmpm::basis::Basis;
use psmpm::output::basis_picture::{basis_function_plot, BasisPlotOptions, MESH_EDGE};
use psmpm::output::chart::{line_plot, series_colour, LinePlot, PlotError, Scale, Series};
use psmpm::output::mesh_picture::{mesh_plot, MeshPlotOptions, VertexSelection};

/// Copies `path` into `$PSMPM_PLOT_DIR` when that is set.
fn keep(path: &Path) {
    if let Some(dir) = std::env::var_os("PSMPM_PLOT_DIR") {
        let dir = PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(path, dir.join(path.file_name().unwrap())).unwrap();
    }
}

/// One SVG element: tag name, attributes, and its text content (for `<text>`).
#[derive(Debug, Clone)]
struct Element {
    tag: String,
    attributes: BTreeMap<String, String>,
    text: String,
}

impl Element {
    fn attr(&self, name: &str) -> &str {
        self.attributes.get(name).map_or("", String::as_str)
    }
    /// Number of points of a `<polyline>`/`<polygon>`.
    fn num_points(&self) -> usize {
        self.attr("points").split_whitespace().count()
    }
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// A minimal XML reader for the SVG that plotters writes: checks that the document
/// is one `<svg>` root with properly nested and closed tags and quoted attributes,
/// and returns its elements in document order.
fn parse_svg(svg: &str) -> Vec<Element> {
    let trimmed = svg.trim();
    assert!(trimmed.starts_with("<svg"), "does not start with <svg");
    assert!(trimmed.ends_with("</svg>"), "does not end with </svg>");
    let mut elements: Vec<Element> = Vec::new();
    let mut stack: Vec<(String, usize)> = Vec::new();
    let mut rest = trimmed;
    let mut roots = 0;
    while let Some(open) = rest.find('<') {
        let text = &rest[..open];
        if let Some((_, index)) = stack.last() {
            elements[*index].text.push_str(&unescape(text.trim()));
        } else {
            assert!(text.trim().is_empty(), "text outside the root: {text:?}");
        }
        let close = rest[open..].find('>').expect("unclosed tag") + open;
        let inner = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if let Some(name) = inner.strip_prefix('/') {
            let (top, _) = stack.pop().expect("closing tag without opening tag");
            assert_eq!(top, name.trim(), "mismatched closing tag");
            continue;
        }
        let self_closing = inner.ends_with('/');
        let inner = inner.trim_end_matches('/');
        let name_end = inner
            .find(|c: char| c.is_whitespace())
            .unwrap_or(inner.len());
        let tag = inner[..name_end].to_string();
        assert!(
            !tag.is_empty() && tag.chars().all(|c| c.is_ascii_alphanumeric()),
            "bad tag name {tag:?}"
        );
        let mut attributes = BTreeMap::new();
        let mut attrs = inner[name_end..].trim();
        while !attrs.is_empty() {
            let eq = attrs.find('=').expect("attribute without value");
            let key = attrs[..eq].trim().to_string();
            let value = &attrs[eq + 1..];
            assert!(value.starts_with('"'), "unquoted attribute {key}");
            let end = value[1..].find('"').expect("unterminated attribute") + 1;
            assert!(
                attributes
                    .insert(key.clone(), unescape(&value[1..end]))
                    .is_none(),
                "duplicate attribute {key}"
            );
            attrs = value[end + 1..].trim_start();
        }
        if stack.is_empty() {
            roots += 1;
        }
        elements.push(Element {
            tag: tag.clone(),
            attributes,
            text: String::new(),
        });
        if !self_closing {
            stack.push((tag, elements.len() - 1));
        }
    }
    assert!(rest.trim().is_empty(), "text after the root");
    assert!(stack.is_empty(), "unclosed tags {stack:?}");
    assert_eq!(roots, 1, "more than one root element");
    assert_eq!(elements[0].tag, "svg");
    elements
}

fn read_svg(path: &Path) -> (String, Vec<Element>) {
    let svg = std::fs::read_to_string(path).unwrap();
    assert!(svg.len() > 500, "suspiciously small SVG: {svg}");
    let elements = parse_svg(&svg);
    (svg, elements)
}

fn hex((r, g, b): (u8, u8, u8)) -> String {
    format!("#{r:02X}{g:02X}{b:02X}")
}

fn texts(elements: &[Element]) -> Vec<&str> {
    elements
        .iter()
        .filter(|e| e.tag == "text")
        .map(|e| e.text.as_str())
        .collect()
}

fn count(elements: &[Element], tag: &str, keep: impl Fn(&Element) -> bool) -> usize {
    elements.iter().filter(|e| e.tag == tag && keep(e)).count()
}

/// Exact solution as a line, computed values as markers, a third as both.
fn sample_plot() -> LinePlot {
    let exact = (0..=100).map(|k| {
        let t = 0.02 * k as f64;
        (t, 0.1 * (std::f64::consts::PI * t).cos())
    });
    let computed = (0..=12).map(|k| {
        let t = 2.0 * k as f64 / 12.0;
        (t, 0.1 * (std::f64::consts::PI * t).cos() * 0.98)
    });
    let third = (0..=6).map(|k| (k as f64 / 3.0, -0.05 + 0.01 * k as f64));
    LinePlot::new("tracked particle", "time t [s]", "displacement u_x [m]")
        .with_series(Series::line("exact", exact))
        .with_series(Series::markers("MPM (PS)", computed))
        .with_series(Series::line_and_markers("MPM (linear)", third))
}

#[test]
fn line_plot_draws_one_curve_per_line_series_and_names_them_in_the_legend() {
    let dir = TempDir::created("line");
    let plot = sample_plot();
    let path = dir.join("displacement.svg");
    line_plot(&path, &plot).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);

    let labels = texts(&elements);
    for wanted in [
        "tracked particle",
        "time t [s]",
        "displacement u_x [m]",
        "exact",
        "MPM (PS)",
        "MPM (linear)",
    ] {
        assert_eq!(
            labels.iter().filter(|&&t| t == wanted).count(),
            1,
            "text {wanted:?} in {labels:?}"
        );
    }
    // Every series colour is distinct.
    let colours: Vec<String> = (0..3).map(|k| hex(series_colour(k))).collect();
    assert!(colours[0] != colours[1] && colours[1] != colours[2] && colours[0] != colours[2]);
    for (k, s) in plot.series.iter().enumerate() {
        let c = &colours[k];
        // The curve: one polyline through all the points, in the series colour.
        let curves: Vec<&Element> = elements
            .iter()
            .filter(|e| e.tag == "polyline" && e.attr("stroke") == c)
            .collect();
        let wants_line = k != 1;
        assert_eq!(curves.len(), usize::from(wants_line), "series {k}");
        if wants_line {
            assert_eq!(curves[0].num_points(), s.points.len());
        }
        // The markers: one per point, plus one in the legend.
        let markers = count(&elements, "circle", |e| e.attr("fill") == c);
        let wants_markers = k != 0;
        assert_eq!(
            markers,
            if wants_markers { s.points.len() + 1 } else { 0 },
            "series {k}"
        );
    }
    // No other coloured curve: all polylines besides the series are grey/black.
    let coloured = count(&elements, "polyline", |e| {
        colours.iter().any(|c| e.attr("stroke") == c)
    });
    assert_eq!(coloured, 2);
    // Same input, same bytes.
    let again = dir.join("again.svg");
    line_plot(&again, &plot).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        std::fs::read(&again).unwrap()
    );
}

#[test]
fn log_log_convergence_plot_has_power_of_ten_ticks() {
    let dir = TempDir::created("loglog");
    let h: Vec<f64> = (1..=5).map(|k| 0.5f64.powi(k)).collect();
    let plot = LinePlot::new("L² projection error", "mesh width h [m]", "error [m]")
        .x_scale(Scale::Log10)
        .y_scale(Scale::Log10)
        .with_series(Series::line_and_markers(
            "PS",
            h.iter().map(|&h| (h, 0.3 * h.powi(3))),
        ))
        .with_series(Series::line_and_markers(
            "PL",
            h.iter().map(|&h| (h, 0.5 * h * h)),
        ))
        .with_series(Series::line(
            "O(h³)",
            h.iter().map(|&h| (h, 0.6 * h.powi(3))),
        ));
    let path = dir.join("convergence.svg");
    line_plot(&path, &plot).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    let labels = texts(&elements);
    assert!(labels.contains(&"10⁻³"), "{labels:?}");
    assert!(labels.contains(&"O(h³)"));
    for k in 0..3 {
        let c = hex(series_colour(k));
        assert_eq!(count(&elements, "polyline", |e| e.attr("stroke") == c), 1);
    }
}

#[test]
fn log_axes_reject_non_positive_values() {
    let dir = TempDir::created("logerr");
    let path = dir.join("bad.svg");
    let plot = LinePlot::new("errors", "h [m]", "error [m]")
        .y_scale(Scale::Log10)
        .with_series(Series::markers(
            "PS",
            [(0.5, 1e-3), (0.25, 0.0), (0.125, 1e-5)],
        ));
    let err = line_plot(&path, &plot).unwrap_err();
    match &err {
        PlotError::NonPositiveOnLogAxis {
            axis,
            series,
            index,
            value,
        } => {
            assert_eq!(
                (*axis, series.as_str(), *index, *value),
                ("y", "PS", 1, 0.0)
            );
        }
        other => panic!("unexpected error {other:?}"),
    }
    assert!(err.to_string().contains("logarithmic"), "{err}");
    let plot = LinePlot::new("errors", "h [m]", "error [m]")
        .x_scale(Scale::Log10)
        .with_series(Series::line("PS", [(-0.5, 1.0), (0.5, 2.0)]));
    assert!(matches!(
        line_plot(&path, &plot),
        Err(PlotError::NonPositiveOnLogAxis { axis: "x", .. })
    ));
    // The same data is fine on linear axes.
    let plot = plot.x_scale(Scale::Linear);
    line_plot(&path, &plot).unwrap();
    // An `include` range must be positive on a log axis.
    let plot = LinePlot::new("e", "t [s]", "E [J]")
        .y_scale(Scale::Log10)
        .y_include(0.0, 1.0)
        .with_series(Series::line("E", [(0.0, 1.0), (1.0, 2.0)]));
    assert!(matches!(
        line_plot(&path, &plot),
        Err(PlotError::InvalidRange { axis: "y", .. })
    ));
}

#[test]
fn empty_and_non_finite_data_are_errors() {
    let dir = TempDir::created("empty");
    let path = dir.join("bad.svg");
    let plot = LinePlot::new("nothing", "x", "y");
    assert!(matches!(line_plot(&path, &plot), Err(PlotError::Empty(_))));
    let plot = plot.with_series(Series::line("none", []));
    assert!(matches!(line_plot(&path, &plot), Err(PlotError::Empty(_))));
    for bad in [f64::NAN, f64::INFINITY] {
        let plot =
            LinePlot::new("nan", "x", "y").with_series(Series::line("s", [(0.0, 1.0), (1.0, bad)]));
        assert!(matches!(
            line_plot(&path, &plot),
            Err(PlotError::NonFinite { index: 1, .. })
        ));
    }
    assert!(!path.exists());
    // A single point (zero range on both axes) and a constant series are fine.
    let plot = LinePlot::new("one", "x", "y").with_series(Series::markers("p", [(1.0, 2.0)]));
    line_plot(&path, &plot).unwrap();
    let plot =
        LinePlot::new("flat", "x", "y").with_series(Series::line("zero", [(0.0, 0.0), (1.0, 0.0)]));
    line_plot(&path, &plot).unwrap();
    read_svg(&path);
    // Empty labels, the smallest size, long names; a size below it is an error.
    let long = "a series with a name far too long for any legend, and then some more";
    let plot = LinePlot::new("", "", "")
        .size(400, 300)
        .with_series(Series::line_and_markers(long, [(0.0, 1.0), (1.0, 3.0)]));
    line_plot(&path, &plot).unwrap();
    let (_, elements) = read_svg(&path);
    assert!(texts(&elements).contains(&long));
    let plot = plot.size(399, 300);
    assert!(matches!(
        line_plot(&path, &plot),
        Err(PlotError::InvalidOption(_))
    ));
}

#[test]
fn mesh_plot_draws_one_control_triangle_per_vertex() {
    let dir = TempDir::created("mesh");
    let mesh = block_grid(0.0, 1.0, 0.0, 1.0, 2, 2).unwrap();
    let ps = bases::powell_sabin::<f64>(mesh).unwrap();
    let nv = ps.mesh().num_vertices();
    assert_eq!(nv, 13);
    let path = dir.join("ps-mesh.svg");
    mesh_plot(&path, &ps, &MeshPlotOptions::default()).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    // Each control triangle is one filled triangle; nothing else is a polygon.
    let polygons: Vec<&Element> = elements.iter().filter(|e| e.tag == "polygon").collect();
    assert_eq!(polygons.len(), nv);
    assert!(polygons.iter().all(|p| p.num_points() == 3));
    let opacity: f64 = polygons[0].attr("opacity").parse().unwrap();
    assert!(
        opacity > 0.0 && opacity < 0.5,
        "semi-transparent: {opacity}"
    );
    // The main edges: thick black segments, one per edge.
    let edges = count(&elements, "polyline", |e| {
        e.attr("stroke") == "#000000" && e.attr("stroke-width") == "2" && e.num_points() == 2
    });
    assert_eq!(edges, ps.mesh().edges().len());
    let labels = texts(&elements);
    for wanted in [
        "main triangles",
        "split points Z",
        "PS points (vertex colour)",
        "control triangles",
    ] {
        assert!(labels.contains(&wanted), "{wanted:?} in {labels:?}");
    }

    // A selection of vertices, and one out of range.
    let options = MeshPlotOptions {
        control_triangles: VertexSelection::Only(vec![0, 4, 12]),
        ..MeshPlotOptions::default()
    };
    let some = dir.join("some.svg");
    mesh_plot(&some, &ps, &options).unwrap();
    let (_, elements) = read_svg(&some);
    assert_eq!(count(&elements, "polygon", |_| true), 3);
    let options = MeshPlotOptions {
        control_triangles: VertexSelection::Only(vec![13]),
        ..MeshPlotOptions::default()
    };
    let err = mesh_plot(&some, &ps, &options).unwrap_err();
    assert!(err.to_string().contains("0..13"), "{err}");
    // The narrowest picture, and one too narrow.
    let narrow = MeshPlotOptions {
        width: 520,
        ..MeshPlotOptions::default()
    };
    mesh_plot(&some, &ps, &narrow).unwrap();
    read_svg(&some);
    let narrow = MeshPlotOptions {
        width: 519,
        ..narrow
    };
    assert!(matches!(
        mesh_plot(&some, &ps, &narrow),
        Err(PlotError::InvalidOption(_))
    ));
}

/// A mesh picture draws at most `MAX_PICTURE_TRIANGLES` (a user's 17 829
/// triangles made a 57 MB SVG); a window draws the part of a larger mesh that
/// meets it: the main edges, control triangles and points there, nothing else.
#[test]
fn a_mesh_picture_of_a_large_mesh_is_drawn_a_window_at_a_time() {
    use psmpm::output::mesh_picture::MAX_PICTURE_TRIANGLES;
    use psmpm_basis::Vec2;
    let dir = TempDir::created("mesh-window");
    // 40 × 40 blocks of four triangles: 6 400 triangles, above the limit.
    let mesh = block_grid(0.0, 40.0, 0.0, 40.0, 40, 40).unwrap();
    let ps = bases::powell_sabin::<f64>(mesh).unwrap();
    assert!(ps.mesh().num_triangles() > MAX_PICTURE_TRIANGLES);
    let path = dir.join("whole.svg");
    let err = mesh_plot(&path, &ps, &MeshPlotOptions::default()).unwrap_err();
    assert!(
        matches!(
            err,
            PlotError::TooManyTriangles {
                count: 6400,
                most: MAX_PICTURE_TRIANGLES
            }
        ),
        "{err}"
    );
    assert!(!path.exists());
    // The window [10.5, 12.5] × [20.5, 21.5] meets blocks 10–12 by 20–21: 3 × 2
    // blocks, 24 triangles, the main edges among them and around them, and the
    // control triangles of the vertices near it.
    let window = MeshPlotOptions {
        window: Some((Vec2::new(10.5, 20.5), Vec2::new(12.5, 21.5))),
        ..MeshPlotOptions::default()
    };
    mesh_plot(&path, &ps, &window).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    let labels = texts(&elements);
    assert!(labels.contains(&"24 of 6400 triangles shown"), "{labels:?}");
    let polygons = count(&elements, "polygon", |_| true);
    assert!((6..=60).contains(&polygons), "{polygons} control triangles");
    let edges = count(&elements, "polyline", |e| {
        e.attr("stroke") == "#000000" && e.attr("stroke-width") == "2" && e.num_points() == 2
    });
    assert!((30..=80).contains(&edges), "{edges} main edges");
    assert!(std::fs::metadata(&path).unwrap().len() < 200_000);
    // A window that is not a rectangle.
    let flat = MeshPlotOptions {
        window: Some((Vec2::new(1.0, 1.0), Vec2::new(1.0, 2.0))),
        ..MeshPlotOptions::default()
    };
    assert!(matches!(
        mesh_plot(&path, &ps, &flat),
        Err(PlotError::InvalidOption(_))
    ));
}

#[test]
fn basis_function_plot_shades_one_function_with_mesh_edges_on_top() {
    let dir = TempDir::created("basis");
    let mesh = block_grid(0.0, 1.0, 0.0, 1.0, 2, 2).unwrap();
    let ps = bases::powell_sabin::<f64>(mesh.clone()).unwrap();
    // Vertex 4 is the centre of the square: its first function.
    let index = 3 * 4;
    let path = dir.join("ps-basis-12.svg");
    basis_function_plot(&path, &ps, index, &BasisPlotOptions::default()).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    // The support (the triangles around the vertex) is cut into 6 pieces, each drawn
    // whole and then as 12² cells; every other triangle is one polygon.
    let support = ps.function_support(index).len();
    assert!(support > 0 && support < ps.num_elements());
    let others = ps.num_elements() - support;
    let cells = count(&elements, "polygon", |_| true);
    assert_eq!(cells, support * 6 * (1 + 144) + others);
    // The element edges on top: one closed line per triangle through its corners and
    // edge points (V R V R V R V).
    let mesh_edge = format!("#{:02X}{:02X}{:02X}", MESH_EDGE.0, MESH_EDGE.1, MESH_EDGE.2);
    let outlines: Vec<&Element> = elements
        .iter()
        .filter(|e| e.tag == "polyline" && e.attr("stroke") == mesh_edge)
        .collect();
    assert_eq!(outlines.len(), ps.num_elements());
    assert!(outlines.iter().all(|e| e.num_points() == 7));
    assert!(texts(&elements)
        .iter()
        .any(|t| t.contains("basis function 12")));
    // The colour bar starts at zero.
    assert!(texts(&elements).contains(&"0"));

    // A piecewise-linear basis through the same generic code.
    let pl = bases::linear::<f64>(mesh).unwrap();
    let path = dir.join("pl-basis.svg");
    let options = BasisPlotOptions {
        subdivisions: 4,
        pieces: true,
        ..BasisPlotOptions::default()
    };
    basis_function_plot(&path, &pl, 4, &options).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    let support = pl.function_support(4).len();
    assert_eq!(
        count(&elements, "polygon", |_| true),
        support * (1 + 16) + (pl.num_elements() - support)
    );
    let outlines = count(&elements, "polyline", |e| {
        e.attr("stroke") == mesh_edge && e.num_points() == 4
    });
    assert_eq!(outlines, pl.num_elements());

    // On a large mesh the picture zooms to the support and a ring of elements
    // around it: every element of the support drawn, far fewer than the mesh's.
    let large = block_grid(0.0, 16.0, 0.0, 16.0, 16, 16).unwrap();
    let ps_large = bases::powell_sabin::<f64>(large).unwrap();
    let index = 300;
    let path = dir.join("ps-basis-large.svg");
    basis_function_plot(&path, &ps_large, index, &BasisPlotOptions::default()).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    let outlines = count(&elements, "polyline", |e| e.attr("stroke") == mesh_edge);
    let support = ps_large.function_support(index).len();
    assert!(
        outlines >= support && outlines <= ps_large.num_elements() / 8,
        "{outlines} elements drawn for a support of {support} in {}",
        ps_large.num_elements()
    );
    let cells = count(&elements, "polygon", |_| true);
    assert!(cells >= support * 6 * (1 + 144), "{cells}");

    // The narrowest picture, and bad options.
    let narrow = BasisPlotOptions {
        width: 400,
        subdivisions: 1,
        ..BasisPlotOptions::default()
    };
    basis_function_plot(&path, &ps, 0, &narrow).unwrap();
    read_svg(&path);
    for bad in [
        BasisPlotOptions {
            width: 399,
            ..narrow.clone()
        },
        BasisPlotOptions {
            subdivisions: 0,
            ..narrow.clone()
        },
    ] {
        assert!(matches!(
            basis_function_plot(&path, &ps, 0, &bad),
            Err(PlotError::InvalidOption(_))
        ));
    }

    // Out of range.
    let n = ps.num_functions();
    let err = basis_function_plot(&path, &ps, n, &BasisPlotOptions::default()).unwrap_err();
    assert!(matches!(err, PlotError::FunctionIndex { index, count } if index == n && count == n));
    assert!(
        err.to_string()
            .contains(&format!("the basis has {n} functions (indices below {n})")),
        "{err}"
    );
}

#[test]
fn plots_of_an_unstructured_rectangle_keep_its_aspect_ratio() {
    let dir = TempDir::created("jittered");
    let mesh = psmpm::basis::mesh::generators::jittered_lattice_delaunay(
        7,
        4,
        (0.0, 2.0, 0.0, 1.0),
        0.3,
        7,
    )
    .unwrap();
    let ps = bases::powell_sabin::<f64>(mesh).unwrap();
    // Control triangles of an interior vertex, a corner and a boundary vertex.
    let interior = (0..ps.mesh().num_vertices())
        .find(|&v| {
            let p = ps.mesh().vertices()[v];
            p.x > 0.5 && p.x < 1.5 && p.y > 0.3 && p.y < 0.7
        })
        .unwrap();
    let options = MeshPlotOptions {
        control_triangles: VertexSelection::Only(vec![0, 2, interior]),
        ..MeshPlotOptions::default()
    };
    let path = dir.join("jittered-mesh.svg");
    mesh_plot(&path, &ps, &options).unwrap();
    keep(&path);
    let (_, elements) = read_svg(&path);
    assert_eq!(count(&elements, "polygon", |_| true), 3);
    // Equal scales: the domain's 2 × 1 box spans twice as many pixels across as up.
    let corners: Vec<(f64, f64)> = elements
        .iter()
        .filter(|e| e.tag == "circle" && e.attr("r") == "5" && e.attr("fill") == "#000000")
        .map(|e| (e.attr("cx").parse().unwrap(), e.attr("cy").parse().unwrap()))
        .collect();
    assert_eq!(corners.len(), ps.mesh().num_vertices() + 1); // + the legend's
    let span = |f: fn(&(f64, f64)) -> f64| {
        let v: Vec<f64> = corners[..corners.len() - 1].iter().map(f).collect();
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let (wide, high) = (span(|p| p.0), span(|p| p.1));
    assert!((wide / high - 2.0).abs() < 0.02, "{wide} × {high}");

    let path = dir.join("jittered-basis.svg");
    basis_function_plot(&path, &ps, 3 * interior + 1, &BasisPlotOptions::default()).unwrap();
    keep(&path);
    read_svg(&path);
}
