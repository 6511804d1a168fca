//! SVG line plots: a titled 2D chart with labelled axes (linear or log10, each),
//! several named series drawn as lines, markers or both, in distinct colours
//! ([`series_colour`]), with a legend to the right of the axes ([`line_plot`]).
//!
//! It is meant for the figures the command line writes next to its CSV output: the
//! displacement of a tracked particle against the exact solution (exact as a line,
//! MPM as markers), energies over time, log-log convergence (error against `h`) and
//! work-precision (error against wall time). The pictures of a mesh
//! ([`mesh_picture`](super::mesh_picture)) and of a basis function
//! ([`basis_picture`](super::basis_picture)) share its errors ([`PlotError`]),
//! colours, fonts and legend.
//!
//! # Output
//!
//! Files are written with the `plotters` crate's SVG backend only: no system library
//! is needed to build or to run. Text is written as SVG `<text>` elements (family
//! `sans-serif`) and laid out with plotters' built-in estimate of text extents (its
//! fallback when neither its `ttf` nor its `ab_glyph` feature is enabled), so no
//! font file is read; the viewer renders the text with its own sans-serif font.
//! Output is deterministic: the same input gives byte-identical files (pixel
//! coordinates are integers, no hash-map order, no time stamps).
//!
//! Invalid input is an error ([`PlotError`]), never a panic: no series, a series
//! without points, non-finite coordinates, non-positive values on a log axis, an
//! out-of-range basis function index, unreasonable sizes.
//!
//! # Example
//!
//! ```no_run
//! use psmpm::output::chart::{line_plot, LinePlot, Scale, Series};
//! # fn main() -> Result<(), psmpm::output::chart::PlotError> {
//! let h = [0.25, 0.125, 0.0625];
//! let plot = LinePlot::new("L² projection error", "mesh width h [m]", "L² error [m]")
//!     .x_scale(Scale::Log10)
//!     .y_scale(Scale::Log10)
//!     .with_series(Series::line_and_markers("PS", h.iter().map(|&h| (h, 0.1 * h * h * h))))
//!     .with_series(Series::line("O(h³)", h.iter().map(|&h| (h, 0.2 * h * h * h))));
//! line_plot(std::path::Path::new("convergence.svg"), &plot)?;
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::{tick_label, AxisCoord};

/// Errors of the plotting functions.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A plot without series, or a series without points.
    #[error("nothing to plot: {0}")]
    Empty(String),
    /// A point with a NaN or infinite coordinate.
    #[error("series \"{series}\": point {index} ({x}, {y}) is not finite")]
    NonFinite {
        /// Series name.
        series: String,
        /// Index of the point in the series.
        index: usize,
        /// Its x coordinate.
        x: f64,
        /// Its y coordinate.
        y: f64,
    },
    /// A value that a logarithmic axis cannot show.
    #[error(
        "the {axis} axis is logarithmic but series \"{series}\" has the non-positive \
         {axis} value {value} at point {index}; plot positive data (e.g. absolute errors) \
         or use a linear axis"
    )]
    NonPositiveOnLogAxis {
        /// `"x"` or `"y"`.
        axis: &'static str,
        /// Series name.
        series: String,
        /// Index of the point in the series.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A requested axis range that is not finite, or not positive on a log axis.
    #[error("invalid {axis} axis range [{lo}, {hi}]: {reason}")]
    InvalidRange {
        /// `"x"` or `"y"`.
        axis: &'static str,
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A basis function index not in `0..count`.
    #[error("basis function index {index} is out of range: the basis has {count} functions (indices below {count})")]
    FunctionIndex {
        /// The requested index.
        index: usize,
        /// The number of functions.
        count: usize,
    },
    /// A basis evaluated to NaN or infinity.
    #[error("basis function {index} is not finite on element {element}")]
    NonFiniteBasisValue {
        /// Function index.
        index: usize,
        /// Element where it was sampled.
        element: usize,
    },
    /// A mesh picture that would draw more triangles than a reader can tell apart
    /// (and an SVG of tens of megabytes).
    #[error(
        "{count} triangles in view, more than the {most} a picture shows readably \
         (about {} MB of SVG, 1.6 KB per triangle)",
        count * 1630 / 1_000_000
    )]
    TooManyTriangles {
        /// Triangles the picture would draw.
        count: usize,
        /// The most it draws.
        most: usize,
    },
    /// An option out of its allowed range (size, subdivisions, vertex index).
    #[error("invalid plot option: {0}")]
    InvalidOption(String),
    /// The drawing library failed (not expected when drawing into memory).
    #[error("drawing failed: {0}")]
    Drawing(String),
    /// The SVG file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// How an axis maps values to positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Evenly spaced values.
    #[default]
    Linear,
    /// Evenly spaced decades (`log10`); all values must be positive.
    Log10,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// A line through the points, in order (e.g. an exact solution).
    #[default]
    Line,
    /// A filled circle at each point (e.g. computed values).
    Markers,
    /// Both.
    LineAndMarkers,
    /// A thin grey line: a guide such as a reference slope, in no series' colour.
    Guide,
}

impl SeriesStyle {
    fn has_line(self) -> bool {
        matches!(self, SeriesStyle::Line | SeriesStyle::LineAndMarkers)
    }
    fn is_guide(self) -> bool {
        self == SeriesStyle::Guide
    }
    fn has_markers(self) -> bool {
        matches!(self, SeriesStyle::Markers | SeriesStyle::LineAndMarkers)
    }
}

/// A named sequence of `(x, y)` points.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Name shown in the legend.
    pub name: String,
    /// The points, drawn in this order.
    pub points: Vec<(f64, f64)>,
    /// Line, markers or both.
    pub style: SeriesStyle,
}

impl Series {
    /// A series of the given style.
    pub fn new(
        name: impl Into<String>,
        points: impl IntoIterator<Item = (f64, f64)>,
        style: SeriesStyle,
    ) -> Self {
        Series {
            name: name.into(),
            points: points.into_iter().collect(),
            style,
        }
    }
    /// A series drawn as a line.
    pub fn line(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(name, points, SeriesStyle::Line)
    }
    /// A series drawn as markers.
    pub fn markers(name: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(name, points, SeriesStyle::Markers)
    }
    /// A series drawn as a line with markers.
    pub fn line_and_markers(
        name: impl Into<String>,
        points: impl IntoIterator<Item = (f64, f64)>,
    ) -> Self {
        Self::new(name, points, SeriesStyle::LineAndMarkers)
    }
}

/// One axis of a [`LinePlot`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Axis {
    /// Label, with units (e.g. `"time t [s]"`).
    pub label: String,
    /// Linear or log10.
    pub scale: Scale,
    /// A range the axis must at least span (e.g. `(0.0, 0.0)` to include zero); the
    /// axis spans the union of this range and the data, so no point is ever cut off.
    pub include: Option<(f64, f64)>,
}

/// A line plot: title, two axes, series. Build with [`LinePlot::new`] and the
/// chained setters, draw with [`line_plot`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinePlot {
    /// Title above the axes.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Series, coloured by position ([`series_colour`]).
    pub series: Vec<Series>,
    /// Image size in pixels, `(width, height)`; default `(900, 560)`.
    pub size: (u32, u32),
}

impl LinePlot {
    /// An empty plot with linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        LinePlot {
            title: title.into(),
            x: Axis {
                label: x_label.into(),
                ..Axis::default()
            },
            y: Axis {
                label: y_label.into(),
                ..Axis::default()
            },
            series: Vec::new(),
            size: (900, 560),
        }
    }
    /// Sets the scale of the x axis.
    pub fn x_scale(mut self, scale: Scale) -> Self {
        self.x.scale = scale;
        self
    }
    /// Sets the scale of the y axis.
    pub fn y_scale(mut self, scale: Scale) -> Self {
        self.y.scale = scale;
        self
    }
    /// Makes the x axis span at least `[lo, hi]` (see [`Axis::include`]).
    pub fn x_include(mut self, lo: f64, hi: f64) -> Self {
        self.x.include = Some((lo, hi));
        self
    }
    /// Makes the y axis span at least `[lo, hi]` (see [`Axis::include`]).
    pub fn y_include(mut self, lo: f64, hi: f64) -> Self {
        self.y.include = Some((lo, hi));
        self
    }
    /// Sets the image size in pixels.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }
    /// Appends a series.
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
}

/// The colours of series and vertices, in order (matplotlib's "tab10": distinct
/// hues, also for the common forms of colour blindness in the first few).
pub const PALETTE: [(u8, u8, u8); 10] = [
    (0x1F, 0x77, 0xB4),
    (0xFF, 0x7F, 0x0E),
    (0x2C, 0xA0, 0x2C),
    (0xD6, 0x27, 0x28),
    (0x94, 0x67, 0xBD),
    (0x8C, 0x56, 0x4B),
    (0xE3, 0x77, 0xC2),
    (0x7F, 0x7F, 0x7F),
    (0xBC, 0xBD, 0x22),
    (0x17, 0xBE, 0xCF),
];

/// The colour of series `k` of a [`LinePlot`] (and of vertex `k` in a
/// [`mesh_plot`](super::mesh_picture::mesh_plot)): `PALETTE[k % 10]` as `(r, g, b)`.
pub fn series_colour(k: usize) -> (u8, u8, u8) {
    PALETTE[k % PALETTE.len()]
}

/// The colour of series `k` as a plotters colour.
pub(crate) fn colour(k: usize) -> RGBColor {
    let (r, g, b) = series_colour(k);
    RGBColor(r, g, b)
}

/// Radius of the markers of a series, in pixels.
const MARKER_RADIUS: u32 = 4;
/// Font sizes in plotters' units (the SVG `font-size` is this divided by 1.24).
pub(crate) const TITLE_FONT: u32 = 26;
pub(crate) const LABEL_FONT: u32 = 16;
const DESC_FONT: u32 = 18;
const LEGEND_FONT: u32 = 17;
/// Width of a character in the legend, in pixels, for sizing the legend area (an
/// estimate: the viewer chooses the font).
const LEGEND_CHAR_WIDTH: f64 = 0.5 * LEGEND_FONT as f64;
/// Height of one legend entry in pixels.
pub(crate) const LEGEND_ROW: i32 = 26;

/// A drawing area of an SVG in memory.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// A drawing failure as a [`PlotError`].
pub(crate) fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Drawing(e.to_string())
}

/// Writes `svg` to the file `path`.
pub(crate) fn write_svg(path: &Path, svg: &str) -> Result<(), PlotError> {
    std::fs::write(path, svg).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Checks an image size: width in 400..=20000, height in 300..=20000 pixels.
pub(crate) fn check_size(width: u32, height: u32) -> Result<(), PlotError> {
    if !(400..=20_000).contains(&width) || !(300..=20_000).contains(&height) {
        return Err(PlotError::InvalidOption(format!(
            "image size {width} × {height} pixels: width must be in 400..=20000 and height in 300..=20000"
        )));
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// Line plots
// ---------------------------------------------------------------------------

/// Checks the data of one axis and returns the range it spans, padded.
fn axis_range(plot: &LinePlot, which: usize) -> Result<AxisCoord, PlotError> {
    let (axis, name) = if which == 0 {
        (&plot.x, "x")
    } else {
        (&plot.y, "y")
    };
    let log = axis.scale == Scale::Log10;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in &plot.series {
        for (index, &(x, y)) in s.points.iter().enumerate() {
            let value = if which == 0 { x } else { y };
            if log && value <= 0.0 {
                return Err(PlotError::NonPositiveOnLogAxis {
                    axis: name,
                    series: s.name.clone(),
                    index,
                    value,
                });
            }
            lo = lo.min(value);
            hi = hi.max(value);
        }
    }
    // Sides set by `include` beyond the data are not padded.
    let (mut pad_lo, mut pad_hi) = (true, true);
    if let Some((a, b)) = axis.include {
        let reason = if !(a.is_finite() && b.is_finite()) {
            Some("not finite")
        } else if a > b {
            Some("lower end above upper end")
        } else if log && a <= 0.0 {
            Some("a logarithmic axis needs positive values")
        } else {
            None
        };
        if let Some(reason) = reason {
            return Err(PlotError::InvalidRange {
                axis: name,
                lo: a,
                hi: b,
                reason,
            });
        }
        if a < lo {
            lo = a;
            pad_lo = false;
        }
        if b > hi {
            hi = b;
            pad_hi = false;
        }
    }
    // Padding is computed in the axis' own coordinate: log10 on log axes.
    let (mut a, mut b) = if log {
        (lo.log10(), hi.log10())
    } else {
        (lo, hi)
    };
    let magnitude = a.abs().max(b.abs());
    if b - a <= 1e-12 * magnitude {
        // A single value: a symmetric window around it.
        let half = if log {
            0.5
        } else if magnitude > 0.0 {
            0.1 * magnitude
        } else {
            1.0
        };
        a -= half;
        b += half;
    } else {
        let pad = 0.04 * (b - a);
        if pad_lo {
            a -= pad;
        }
        if pad_hi {
            b += pad;
        }
    }
    let back = |t: f64| if log { 10f64.powf(t) } else { t };
    Ok(AxisCoord::new(axis.scale, back(a), back(b)))
}

/// Checks the series: at least one, none empty, every point finite.
fn check_series(plot: &LinePlot) -> Result<(), PlotError> {
    if plot.series.is_empty() {
        return Err(PlotError::Empty(format!(
            "line plot \"{}\" has no series",
            plot.title
        )));
    }
    for s in &plot.series {
        if s.points.is_empty() {
            return Err(PlotError::Empty(format!(
                "series \"{}\" of line plot \"{}\" has no points",
                s.name, plot.title
            )));
        }
        if let Some((index, &(x, y))) = s
            .points
            .iter()
            .enumerate()
            .find(|(_, (x, y))| !(x.is_finite() && y.is_finite()))
        {
            return Err(PlotError::NonFinite {
                series: s.name.clone(),
                index,
                x,
                y,
            });
        }
    }
    Ok(())
}

/// Estimated width in pixels of `text` in the legend font.
fn legend_text_width(text: &str) -> u32 {
    (text.chars().count() as f64 * LEGEND_CHAR_WIDTH).ceil() as u32
}

/// The text style of legend entries: left-aligned, vertically centred.
pub(crate) fn legend_text_style() -> TextStyle<'static> {
    TextStyle::from(("sans-serif", LEGEND_FONT).into_font()).pos(Pos::new(HPos::Left, VPos::Center))
}

/// A legend swatch for a line: a short thick bar (a `<rect>`, so that the `<polyline>`s
/// of the file are exactly the drawn curves).
pub(crate) fn line_swatch(area: &Area, x: i32, y: i32, style: ShapeStyle) -> Result<(), PlotError> {
    area.draw(&Rectangle::new(
        [(x, y - 1), (x + 30, y + 1)],
        style.filled(),
    ))
    .map_err(draw_err)
}

/// The stroke of a guide line ([`SeriesStyle::Guide`]).
fn guide_style() -> ShapeStyle {
    BLACK.mix(0.4).stroke_width(1)
}

/// Renders a line plot to an SVG string.
fn render_line_plot(plot: &LinePlot) -> Result<String, PlotError> {
    render_stacked(std::slice::from_ref(plot))
}

/// Renders plots one below the other (each at its own size) to an SVG string.
fn render_stacked(plots: &[LinePlot]) -> Result<String, PlotError> {
    if plots.is_empty() {
        return Err(PlotError::Empty("no panel to draw".into()));
    }
    for plot in plots {
        check_size(plot.size.0, plot.size.1)?;
        check_series(plot)?;
    }
    let width = plots.iter().map(|p| p.size.0).max().unwrap_or(0);
    let height: u32 = plots.iter().map(|p| p.size.1).sum();
    check_size(width, height)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        // One legend width for every panel, so that their time axes line up.
        let legend_width = plots
            .iter()
            .map(|p| legend_width(p, width))
            .max()
            .unwrap_or(0);
        let mut rest = root.clone();
        for plot in plots {
            let (panel, below) = rest.split_vertically(plot.size.1);
            draw_line_plot(&panel, plot, legend_width)?;
            rest = below;
        }
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Width of the legend strip of `plot` in a picture `width` pixels wide.
fn legend_width(plot: &LinePlot, width: u32) -> u32 {
    plot.series
        .iter()
        .map(|s| legend_text_width(&s.name) + 70)
        .max()
        .unwrap_or(0)
        .max(120)
        .min(width / 2)
}

/// Draws `plot` (checked) into `root`, which is `plot.size.1` pixels high, with a
/// legend strip `legend_width` pixels wide on the right.
fn draw_line_plot(root: &Area, plot: &LinePlot, legend_width: u32) -> Result<(), PlotError> {
    let width = root.dim_in_pixel().0;
    let x = axis_range(plot, 0)?;
    let y = axis_range(plot, 1)?;
    {
        let (main, legend) = root.split_horizontally(width - legend_width);
        let mut chart = ChartBuilder::on(&main)
            .caption(&plot.title, ("sans-serif", TITLE_FONT))
            .margin(14)
            .x_label_area_size(60)
            .y_label_area_size(90)
            .build_cartesian_2d(x, y)
            .map_err(draw_err)?;
        let x_label = |v: &f64| tick_label(&x, *v);
        let y_label = |v: &f64| tick_label(&y, *v);
        chart
            .configure_mesh()
            .x_desc(plot.x.label.as_str())
            .y_desc(plot.y.label.as_str())
            .x_label_formatter(&x_label)
            .y_label_formatter(&y_label)
            .x_labels(8)
            .y_labels(8)
            .max_light_lines(4)
            .label_style(("sans-serif", LABEL_FONT))
            .axis_desc_style(("sans-serif", DESC_FONT))
            .bold_line_style(BLACK.mix(0.15))
            .light_line_style(BLACK.mix(0.05))
            .draw()
            .map_err(draw_err)?;
        for (k, s) in plot.series.iter().enumerate() {
            let c = colour(k);
            if s.style.has_line() {
                chart
                    .draw_series(LineSeries::new(s.points.iter().copied(), c.stroke_width(2)))
                    .map_err(draw_err)?;
            }
            if s.style.is_guide() {
                chart
                    .draw_series(LineSeries::new(s.points.iter().copied(), guide_style()))
                    .map_err(draw_err)?;
            }
            if s.style.has_markers() {
                chart
                    .draw_series(
                        s.points
                            .iter()
                            .map(|&p| Circle::new(p, MARKER_RADIUS, c.filled())),
                    )
                    .map_err(draw_err)?;
            }
        }
        // The legend, right of the axes, from the top of the plotting area (in the
        // legend strip's own coordinates: a lower panel's strip starts lower).
        let top = chart.plotting_area().get_base_pixel().1 - legend.get_base_pixel().1;
        for (k, s) in plot.series.iter().enumerate() {
            let c = colour(k);
            let y = top + 12 + LEGEND_ROW * k as i32;
            if s.style.has_line() {
                line_swatch(&legend, 6, y, c.stroke_width(2))?;
            }
            if s.style.is_guide() {
                line_swatch(&legend, 6, y, guide_style())?;
            }
            if s.style.has_markers() {
                legend
                    .draw(&Circle::new((21, y), MARKER_RADIUS, c.filled()))
                    .map_err(draw_err)?;
            }
            legend
                .draw(&Text::new(s.name.as_str(), (44, y), legend_text_style()))
                .map_err(draw_err)?;
        }
    }
    Ok(())
}

/// Draws `plot` into the SVG file `path` (see the [module docs](self)).
///
/// Errors: no series, a series without points, a non-finite coordinate
/// ([`PlotError::Empty`], [`PlotError::NonFinite`]); a non-positive value on a log
/// axis ([`PlotError::NonPositiveOnLogAxis`]); an invalid [`Axis::include`] range or
/// image size; the file cannot be written ([`PlotError::Io`]).
pub fn line_plot(path: &Path, plot: &LinePlot) -> Result<(), PlotError> {
    let svg = render_line_plot(plot)?;
    write_svg(path, &svg)
}

/// Draws `plots` one below the other into the SVG file `path`: panels sharing one
/// picture (e.g. displacement and velocity against time), each at its own size
/// and with its own axes and legend. Errors as [`line_plot`], for any panel
/// ([`PlotError::Empty`] for no panel).
pub fn stacked_line_plots(path: &Path, plots: &[LinePlot]) -> Result<(), PlotError> {
    let svg = render_stacked(plots)?;
    write_svg(path, &svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The legend of a lower panel sits beside that panel's axes (it was drawn at
    /// twice the panel's offset, off the bottom of the picture), and the panels share
    /// one legend width so that their x axes line up.
    #[test]
    fn stacked_panels_keep_their_legends_and_line_up() {
        let top = LinePlot::new("top", "t", "u")
            .with_series(Series::line("a short name", [(0.0, 0.0), (1.0, 1.0)]));
        let bottom = LinePlot::new("bottom", "t", "v").with_series(Series::line(
            "a much longer legend name for the lower panel",
            [(0.0, 1.0), (1.0, 0.0)],
        ));
        let svg = render_stacked(&[top.clone(), bottom]).unwrap();
        let y_of = |text: &str| -> i32 {
            let at = svg.find(text).unwrap();
            let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
            let y = tag.split("y=\"").nth(1).unwrap();
            y[..y.find('"').unwrap()].parse().unwrap()
        };
        let panel = top.size.1 as i32;
        let legend = y_of("a much longer legend name");
        assert!(
            legend > panel && legend < panel + panel / 2,
            "{legend} in panel 2 of {panel}"
        );
        assert!(y_of("a short name") < panel / 2);
        // Both x axes end at the same pixel: the last x tick label of each panel.
        // (x tick labels are centred under their tick, y tick labels end at theirs)
        let x_of_last_tick = |from: usize| -> &str {
            let tag = svg[from..]
                .split("<text")
                .find(|t| t.contains("text-anchor=\"middle\"") && t.contains(">\n1\n</text>"))
                .unwrap();
            let x = tag.split("x=\"").nth(1).unwrap();
            &x[..x.find('"').unwrap()]
        };
        let second = svg.find("bottom").unwrap();
        assert_eq!(x_of_last_tick(0), x_of_last_tick(second));
    }
}
