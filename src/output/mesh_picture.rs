//! The SVG picture of a Powell–Sabin basis (`ps-splines.md` §1–2) with
//! [`mesh_plot`]: main triangles (thick), their refinement into six sub-triangles
//! (thin), vertices, split points `Z`, edge points `R`, PS points, and the control
//! triangles of the vertices (semi-transparent, one colour per vertex, the PS points
//! of a vertex in its colour), with a legend. Equal scales on both axes.
//!
//! Also the frame every picture of a mesh is drawn in (this one and
//! [`basis_picture`](super::basis_picture)): equal scales on both axes, a legend or
//! colour bar on the right. Output as in [`chart`](super::chart#output).

use std::path::Path;

use plotters::prelude::*;
use psmpm_basis::basis::powell_sabin::PowellSabin;
use psmpm_basis::Vec2;

use super::axis::{format_number, AxisCoord};
use super::chart::{
    check_size, colour, draw_err, legend_text_style, line_swatch, write_svg, Area, PlotError,
    LABEL_FONT, LEGEND_ROW, TITLE_FONT,
};

/// Opacity of the control triangles' fill.
const CONTROL_FILL_OPACITY: f64 = 0.12;

/// Chart area and side strip of a picture with equal scales on both axes, for data
/// in `bbox = (min, max)`.
pub(crate) struct Picture {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) side_width: u32,
}

impl Picture {
    pub(crate) const MARGIN: u32 = 12;
    pub(crate) const X_LABELS: u32 = 40;
    const Y_LABELS: u32 = 64;
    const TITLE: u32 = 48;

    /// Height for a plotting area of the data's aspect ratio (the title's height is
    /// estimated; [`equal_scale_chart`] corrects the ranges exactly).
    pub(crate) fn new(width: u32, side_width: u32, bbox: (Vec2, Vec2), min_height: u32) -> Self {
        let (dx, dy) = (bbox.1.x - bbox.0.x, bbox.1.y - bbox.0.y);
        let plot_width = width.saturating_sub(side_width + 2 * Self::MARGIN + Self::Y_LABELS);
        let plot_height = (f64::from(plot_width) * dy / dx).clamp(100.0, 2.0 * f64::from(width));
        let height = (plot_height.round() as u32 + 2 * Self::MARGIN + Self::X_LABELS + Self::TITLE)
            .max(min_height);
        Picture {
            width,
            height,
            side_width,
        }
    }
}

/// The bounding box of `points`, grown by `fraction` of its size on each side.
pub(crate) fn padded_bbox(
    points: impl IntoIterator<Item = Vec2>,
    fraction: f64,
) -> Option<(Vec2, Vec2)> {
    let mut lo = Vec2::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in points {
        if p.x.is_finite() && p.y.is_finite() {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        return None;
    }
    let size = (hi - lo).norm().max(1e-300);
    let pad = Vec2::new(fraction * size, fraction * size);
    Some((lo - pad, hi + pad))
}

/// A chart of a picture: linear axes with equal scales.
pub(crate) type PictureChart<'a> =
    ChartContext<'a, SVGBackend<'a>, Cartesian2d<AxisCoord, AxisCoord>>;

/// A chart on `area` showing `bbox` with equal scales on both axes (the shorter
/// range grows, centred), with tick labels on the left and bottom and no grid.
pub(crate) fn equal_scale_chart<'a>(
    area: &Area<'a>,
    bbox: (Vec2, Vec2),
) -> Result<(PictureChart<'a>, f64), PlotError> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(Picture::MARGIN)
        .x_label_area_size(Picture::X_LABELS)
        .y_label_area_size(Picture::Y_LABELS);
    let probe = builder
        .build_cartesian_2d(AxisCoord::linear(0.0, 1.0), AxisCoord::linear(0.0, 1.0))
        .map_err(draw_err)?;
    let (w, h) = probe.plotting_area().dim_in_pixel();
    let (pw, ph) = (f64::from(w.max(2) - 1), f64::from(h.max(2) - 1));
    let (dx, dy) = (bbox.1.x - bbox.0.x, bbox.1.y - bbox.0.y);
    let scale = (pw / dx).min(ph / dy);
    let centre = (bbox.0 + bbox.1) * 0.5;
    let (hx, hy) = (0.5 * pw / scale, 0.5 * ph / scale);
    let mut chart = builder
        .build_cartesian_2d(
            AxisCoord::linear(centre.x - hx, centre.x + hx),
            AxisCoord::linear(centre.y - hy, centre.y + hy),
        )
        .map_err(draw_err)?;
    let label = |v: &f64| format_number(*v);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&label)
        .y_label_formatter(&label)
        .label_style(("sans-serif", LABEL_FONT))
        .draw()
        .map_err(draw_err)?;
    Ok((chart, scale))
}

/// A vertical colour bar for values in `[lo, hi]` on the side strip `side`, aligned
/// with the plotting area of an [`equal_scale_chart`] beside it.
pub(crate) fn colour_bar(
    side: &Area,
    lo: f64,
    hi: f64,
    colour_of: &dyn Fn(f64) -> RGBColor,
) -> Result<(), PlotError> {
    let mut bar = ChartBuilder::on(side)
        .margin(Picture::MARGIN)
        .margin_left(16)
        .x_label_area_size(Picture::X_LABELS)
        .set_label_area_size(LabelAreaPosition::Right, 70)
        .build_cartesian_2d(AxisCoord::linear(0.0, 1.0), AxisCoord::linear(lo, hi))
        .map_err(draw_err)?;
    let steps = 128;
    bar.draw_series((0..steps).map(|k| {
        let (v0, v1) = (
            lo + (hi - lo) * k as f64 / steps as f64,
            lo + (hi - lo) * (k + 1) as f64 / steps as f64,
        );
        Rectangle::new([(0.0, v0), (1.0, v1)], colour_of(0.5 * (v0 + v1)).filled())
    }))
    .map_err(draw_err)?;
    let label = |v: &f64| format_number(*v);
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .x_labels(0)
        .y_labels(8)
        .y_label_formatter(&label)
        .label_style(("sans-serif", LABEL_FONT))
        .draw()
        .map_err(draw_err)?;
    Ok(())
}

/// A point as plotters' coordinate pair.
pub(crate) fn pt(p: Vec2) -> (f64, f64) {
    (p.x, p.y)
}

/// Which vertices get their control triangle drawn in a [`mesh_plot`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum VertexSelection {
    /// Every vertex.
    #[default]
    All,
    /// None.
    None,
    /// These vertices.
    Only(Vec<usize>),
}

/// Options of [`mesh_plot`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeshPlotOptions {
    /// Title; default `"Powell–Sabin refinement and control triangles"`.
    pub title: String,
    /// Image width in pixels (the height follows from the mesh's aspect ratio);
    /// default 1000.
    pub width: u32,
    /// Draw the six sub-triangles of each triangle, the split and edge points;
    /// default `true`.
    pub refinement: bool,
    /// Draw the PS points, in the colour of their vertex; default `true`.
    pub ps_points: bool,
    /// Vertices whose control triangles are drawn; default all.
    pub control_triangles: VertexSelection,
    /// Draw only the part of the mesh in this rectangle (lower-left and
    /// upper-right corners): the triangles, control triangles and points that
    /// meet it; default the whole mesh.
    pub window: Option<(Vec2, Vec2)>,
}

/// The most triangles a mesh picture draws: a reader no longer tells its
/// sub-triangles and points apart beyond it (a user's 17 829 triangles made a
/// 57 MB SVG); a larger mesh is drawn a window at a time.
pub const MAX_PICTURE_TRIANGLES: usize = 5000;

impl Default for MeshPlotOptions {
    fn default() -> Self {
        MeshPlotOptions {
            title: "Powell–Sabin refinement and control triangles".into(),
            width: 1000,
            refinement: true,
            ps_points: true,
            control_triangles: VertexSelection::All,
            window: None,
        }
    }
}

/// One legend entry of the mesh picture.
enum Swatch {
    Line(ShapeStyle),
    Dot(u32, ShapeStyle),
    Square(i32, ShapeStyle),
    Fill(RGBAColor, ShapeStyle),
}

fn draw_swatch(area: &Area, swatch: &Swatch, y: i32) -> Result<(), PlotError> {
    let x = 21;
    match swatch {
        Swatch::Line(style) => line_swatch(area, 6, y, *style),
        Swatch::Dot(r, style) => area
            .draw(&Circle::new((x, y), *r, *style))
            .map_err(draw_err),
        Swatch::Square(r, style) => area
            .draw(&Rectangle::new([(x - r, y - r), (x + r, y + r)], *style))
            .map_err(draw_err),
        Swatch::Fill(fill, edge) => {
            area.draw(&Rectangle::new([(6, y - 8), (36, y + 8)], fill.filled()))
                .map_err(draw_err)?;
            area.draw(&Rectangle::new([(6, y - 8), (36, y + 8)], *edge))
                .map_err(draw_err)
        }
    }
}

/// Renders the PS picture to an SVG string.
fn render_mesh_plot(
    basis: &PowellSabin<f64>,
    options: &MeshPlotOptions,
) -> Result<String, PlotError> {
    let mesh = basis.mesh();
    let refinement = basis.refinement();
    let control = basis.control_triangles();
    let nv = mesh.num_vertices();
    let selected: Vec<usize> = match &options.control_triangles {
        VertexSelection::All => (0..nv).collect(),
        VertexSelection::None => Vec::new(),
        VertexSelection::Only(v) => {
            if let Some(&bad) = v.iter().find(|&&v| v >= nv) {
                return Err(PlotError::InvalidOption(format!(
                    "vertex {bad} out of range: the mesh has vertices 0..{nv}"
                )));
            }
            v.clone()
        }
    };
    let side_width = 270;
    if options.width < side_width + 250 {
        return Err(PlotError::InvalidOption(format!(
            "image width {} pixels: at least {} needed",
            options.width,
            side_width + 250
        )));
    }
    // What the window holds: the triangles and control triangles that meet it.
    let meets = |points: &[Vec2]| match options.window {
        None => true,
        Some((lo, hi)) => {
            let (mut a, mut b) = (points[0], points[0]);
            for p in points {
                a = a.inf(p);
                b = b.sup(p);
            }
            a.x <= hi.x && b.x >= lo.x && a.y <= hi.y && b.y >= lo.y
        }
    };
    if let Some((lo, hi)) = options.window {
        if !(lo.x.is_finite() && lo.y.is_finite() && hi.x.is_finite() && hi.y.is_finite())
            || lo.x >= hi.x
            || lo.y >= hi.y
        {
            return Err(PlotError::InvalidOption(format!(
                "window [{}, {}] × [{}, {}]: give finite corners with x0 < x1 and y0 < y1",
                lo.x, hi.x, lo.y, hi.y
            )));
        }
    }
    let triangles: Vec<usize> = (0..mesh.num_triangles())
        .filter(|&t| meets(&mesh.triangle_points(t)))
        .collect();
    if triangles.is_empty() {
        return Err(PlotError::Empty(
            "no triangle of the mesh meets the window".into(),
        ));
    }
    if triangles.len() > MAX_PICTURE_TRIANGLES {
        return Err(PlotError::TooManyTriangles {
            count: triangles.len(),
            most: MAX_PICTURE_TRIANGLES,
        });
    }
    let selected: Vec<usize> = selected
        .into_iter()
        .filter(|&v| meets(&control[v]))
        .collect();
    let bbox = match options.window {
        Some(window) => window,
        None => padded_bbox(
            mesh.vertices()
                .iter()
                .copied()
                .chain(selected.iter().flat_map(|&v| control[v])),
            0.02,
        )
        .ok_or_else(|| PlotError::Empty("the mesh has no finite vertex".into()))?,
    };
    let inside = |p: &Vec2| match options.window {
        None => true,
        Some((lo, hi)) => p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y,
    };
    let picture = Picture::new(options.width, side_width, bbox, 420);
    check_size(picture.width, picture.height)?;

    let mut svg = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg, (picture.width, picture.height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let body = root
            .titled(&options.title, ("sans-serif", TITLE_FONT))
            .map_err(draw_err)?;
        let (main, legend) = body.split_horizontally(picture.width - picture.side_width);
        let (mut chart, _) = equal_scale_chart(&main, bbox)?;

        let grey = RGBColor(120, 120, 120);
        // Control triangles, filled, under everything.
        chart
            .draw_series(selected.iter().map(|&v| {
                Polygon::new(
                    control[v].map(pt).to_vec(),
                    colour(v).mix(CONTROL_FILL_OPACITY).filled(),
                )
            }))
            .map_err(draw_err)?;
        if options.refinement {
            let mut segments = Vec::new();
            for &t in &triangles {
                let z = refinement.split[t];
                let v = mesh.triangle_points(t);
                for m in 0..3 {
                    segments.push([z, v[m]]);
                    segments.push([z, refinement.local_edge_point(mesh, t, m)]);
                }
            }
            chart
                .draw_series(
                    segments
                        .iter()
                        .map(|s| PathElement::new(s.map(pt).to_vec(), grey.stroke_width(1))),
                )
                .map_err(draw_err)?;
        }
        let vertices = mesh.vertices();
        chart
            .draw_series(
                mesh.edges()
                    .iter()
                    .filter(|e| meets(&[vertices[e.vertices[0]], vertices[e.vertices[1]]]))
                    .map(|e| {
                        let [a, b] = e.vertices;
                        PathElement::new(
                            vec![pt(vertices[a]), pt(vertices[b])],
                            BLACK.stroke_width(2),
                        )
                    }),
            )
            .map_err(draw_err)?;
        chart
            .draw_series(selected.iter().map(|&v| {
                let q = control[v];
                PathElement::new(
                    vec![pt(q[0]), pt(q[1]), pt(q[2]), pt(q[0])],
                    colour(v).stroke_width(2),
                )
            }))
            .map_err(draw_err)?;
        if options.refinement {
            chart
                .draw_series(
                    refinement
                        .edge_point
                        .iter()
                        .filter(|r| inside(r))
                        .map(|&r| {
                            EmptyElement::at(pt(r))
                                + Rectangle::new([(-4, -4), (4, 4)], BLACK.stroke_width(1))
                        }),
                )
                .map_err(draw_err)?;
            chart
                .draw_series(refinement.split.iter().filter(|z| inside(z)).map(|&z| {
                    EmptyElement::at(pt(z)) + Rectangle::new([(-4, -4), (4, 4)], BLACK.filled())
                }))
                .map_err(draw_err)?;
        }
        chart
            .draw_series(
                vertices
                    .iter()
                    .filter(|v| inside(v))
                    .map(|&v| Circle::new(pt(v), 5, BLACK.filled())),
            )
            .map_err(draw_err)?;
        if options.ps_points {
            let mut points = Vec::new();
            for v in 0..nv {
                // Skip the first PS point: the vertex itself.
                for p in refinement.ps_points(mesh, v).into_iter().skip(1) {
                    if inside(&p) {
                        points.push((p, v));
                    }
                }
            }
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|&(p, v)| Circle::new(pt(p), 3, colour(v).filled())),
                )
                .map_err(draw_err)?;
        }

        // Legend and caption.
        let mut entries: Vec<(Swatch, String)> = vec![
            (Swatch::Line(BLACK.stroke_width(2)), "main triangles".into()),
            (Swatch::Dot(5, BLACK.filled()), "vertices V".into()),
        ];
        if options.refinement {
            entries.push((
                Swatch::Line(grey.stroke_width(1)),
                "PS refinement (6 per triangle)".into(),
            ));
            entries.push((Swatch::Square(4, BLACK.filled()), "split points Z".into()));
            entries.push((
                Swatch::Square(4, BLACK.stroke_width(1)),
                "edge points R".into(),
            ));
        }
        if options.ps_points {
            entries.push((
                Swatch::Dot(3, colour(0).filled()),
                "PS points (vertex colour)".into(),
            ));
        }
        if !selected.is_empty() {
            entries.push((
                Swatch::Fill(
                    colour(0).mix(CONTROL_FILL_OPACITY),
                    colour(0).stroke_width(2),
                ),
                "control triangles".into(),
            ));
        }
        let top = chart.plotting_area().get_base_pixel().1 - legend.get_base_pixel().1;
        let mut y = top + 12;
        for (swatch, text) in &entries {
            draw_swatch(&legend, swatch, y)?;
            legend
                .draw(&Text::new(text.as_str(), (44, y), legend_text_style()))
                .map_err(draw_err)?;
            y += LEGEND_ROW;
        }
        y += LEGEND_ROW / 2;
        let caption = [
            match options.window {
                None => format!("{} vertices, {} triangles", nv, mesh.num_triangles()),
                Some(_) => format!(
                    "{} of {} triangles shown",
                    triangles.len(),
                    mesh.num_triangles()
                ),
            },
            format!("{} functions (3 per vertex)", 3 * nv),
            format!("control triangles of {} vertices", selected.len()),
        ];
        for line in &caption {
            legend
                .draw(&Text::new(line.as_str(), (6, y), legend_text_style()))
                .map_err(draw_err)?;
            y += LEGEND_ROW - 4;
        }
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Draws the Powell–Sabin construction of `basis` into the SVG file `path`: main
/// triangles, PS refinement, vertices, split and edge points, PS points and control
/// triangles, with a legend and a caption, on equal scales (see the
/// [module docs](self)).
///
/// Errors: a vertex of [`VertexSelection::Only`] out of range, a width below 520
/// pixels ([`PlotError::InvalidOption`]); the file cannot be written.
pub fn mesh_plot(
    path: &Path,
    basis: &PowellSabin<f64>,
    options: &MeshPlotOptions,
) -> Result<(), PlotError> {
    let svg = render_mesh_plot(basis, options)?;
    write_svg(path, &svg)
}
