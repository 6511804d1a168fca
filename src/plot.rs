//! SVG figures: line plots of time series and convergence data, the Powell–Sabin
//! construction of a mesh, and single basis functions.
//!
//! Three entry points, each writing one SVG file:
//!
//! - [`line_plot`]: a titled 2D chart with labelled axes (linear or log10, each),
//!   several named series drawn as lines, markers or both, in distinct colours
//!   ([`series_colour`]), with a legend to the right of the axes. It is meant for
//!   the figures the command line writes next to its CSV output: the displacement of
//!   a tracked particle against the exact solution (exact as a line, MPM as
//!   markers), energies over time, log-log convergence (error against `h`) and
//!   work-precision (error against wall time).
//! - [`mesh_plot`]: the picture of a Powell–Sabin basis (`ps-splines.md` §1–2):
//!   main triangles (thick), their refinement into six sub-triangles (thin), vertices,
//!   split points `Z`, edge points `R`, PS points, and the control triangles of the
//!   vertices (semi-transparent, one colour per vertex, the PS points of a vertex in
//!   its colour), with a legend. Equal scales on both axes.
//! - [`basis_function_plot`]: one function of any 2D [`Basis`], sampled on a uniform
//!   subdivision of each of its polynomial pieces and shaded with the viridis colour
//!   map, a colour bar at the right and the mesh edges on top. Equal scales.
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
//! use psmpm::plot::{line_plot, LinePlot, Scale, Series};
//! # fn main() -> Result<(), psmpm::plot::PlotError> {
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

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use psmpm_basis::basis::powell_sabin::PowellSabin;
use psmpm_basis::{Basis, BasisEval, Point, Vec2};

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
    #[error("basis function index {index} is out of range: the basis has functions 0..{count}")]
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
}

impl SeriesStyle {
    fn has_line(self) -> bool {
        matches!(self, SeriesStyle::Line | SeriesStyle::LineAndMarkers)
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
/// [`mesh_plot`]): `PALETTE[k % 10]` as `(r, g, b)`.
pub fn series_colour(k: usize) -> (u8, u8, u8) {
    PALETTE[k % PALETTE.len()]
}

fn colour(k: usize) -> RGBColor {
    let (r, g, b) = series_colour(k);
    RGBColor(r, g, b)
}

/// Radius of the markers of a series, in pixels.
const MARKER_RADIUS: u32 = 4;
/// Font sizes in plotters' units (the SVG `font-size` is this divided by 1.24).
const TITLE_FONT: u32 = 26;
const LABEL_FONT: u32 = 16;
const DESC_FONT: u32 = 18;
const LEGEND_FONT: u32 = 17;
/// Width of a character in the legend, in pixels, for sizing the legend area (an
/// estimate: the viewer chooses the font).
const LEGEND_CHAR_WIDTH: f64 = 0.5 * LEGEND_FONT as f64;
/// Height of one legend entry in pixels.
const LEGEND_ROW: i32 = 26;
/// Colour `(r, g, b)` of the element edges in a basis function plot (near-black, to
/// tell them from the axes).
pub const MESH_EDGE: (u8, u8, u8) = (0x14, 0x14, 0x14);
/// Opacity of the control triangles' fill.
const CONTROL_FILL_OPACITY: f64 = 0.12;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

fn draw_err<E: std::fmt::Display>(e: E) -> PlotError {
    PlotError::Drawing(e.to_string())
}

fn write_svg(path: &Path, svg: &str) -> Result<(), PlotError> {
    std::fs::write(path, svg).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn check_size(width: u32, height: u32) -> Result<(), PlotError> {
    if !(400..=20_000).contains(&width) || !(300..=20_000).contains(&height) {
        return Err(PlotError::InvalidOption(format!(
            "image size {width} × {height} pixels: width must be in 400..=20000 and height in 300..=20000"
        )));
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// Axes: one coordinate type for linear and log10 axes, with our own ticks.
// ---------------------------------------------------------------------------

/// A linear or log10 axis over `[lo, hi]` (`0 < lo` for log10), with nice ticks:
/// multiples of 1, 2 or 5 × 10^k on linear axes; powers of ten (or 1-2-5 values on
/// short ranges) on log axes.
#[derive(Debug, Clone, Copy)]
struct AxisCoord {
    scale: Scale,
    lo: f64,
    hi: f64,
}

impl AxisCoord {
    fn linear(lo: f64, hi: f64) -> Self {
        AxisCoord {
            scale: Scale::Linear,
            lo,
            hi,
        }
    }
    /// Position of `v` along the axis, 0 at `lo`, 1 at `hi`.
    fn fraction(&self, v: f64) -> f64 {
        let t = match self.scale {
            Scale::Linear => (v - self.lo) / (self.hi - self.lo),
            Scale::Log10 => (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10()),
        };
        // Far-off or invalid values (not produced by validated data) stay near the axes.
        if t.is_nan() {
            0.0
        } else {
            t.clamp(-2.0, 3.0)
        }
    }
}

impl AxisCoord {
    /// Whether the labels of this log axis are at powers of ten only (at least three
    /// of them in range, as [`log_ticks`] decides).
    fn decade_ticks(&self) -> bool {
        let (a, b) = (self.lo.log10(), self.hi.log10());
        a.is_finite() && b.is_finite() && (b + 1e-12).floor() - (a - 1e-12).ceil() >= 2.0
    }
}

impl Ranged for AxisCoord {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let span = f64::from(limit.1 - limit.0);
        limit.0 + (span * self.fraction(*value)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let max = hint.max_num_points();
        match self.scale {
            Scale::Linear => linear_ticks(self.lo, self.hi, max),
            Scale::Log10 => log_ticks(self.lo, self.hi, max, hint.weight().allow_light_points()),
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// `10^k`, correctly rounded for moderate `k`.
fn pow10(k: i32) -> f64 {
    if k >= 0 {
        10f64.powi(k)
    } else {
        1.0 / 10f64.powi(-k)
    }
}

/// At most `max + 1` multiples of a 1-2-5 step in `[lo, hi]`.
fn linear_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    let span = hi - lo;
    if max == 0 || span.is_nan() || span <= 0.0 || !span.is_finite() {
        return Vec::new();
    }
    let raw = span / max as f64;
    let magnitude = pow10(raw.log10().floor() as i32);
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|&s| span / s <= max as f64)
        .unwrap_or(10.0 * magnitude);
    let (first, last) = ((lo / step).ceil(), (hi / step).floor());
    if !(first.is_finite() && last.is_finite()) || last - first > 1000.0 {
        return Vec::new();
    }
    let (first, last) = (first as i64, last as i64);
    (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            if v.abs() < 1e-9 * step {
                0.0
            } else {
                v
            }
        })
        .collect()
}

/// Ticks of a log10 axis: `j · 10^k` (`j = 1..9`) when light points are asked for
/// and fit; otherwise powers of ten (thinned to fit), 1-2-5 values on ranges of about
/// a decade or less, linear ticks on very short ranges.
fn log_ticks(lo: f64, hi: f64, max: usize, light: bool) -> Vec<f64> {
    if max == 0 || !(lo > 0.0 && hi > lo) {
        return Vec::new();
    }
    let (a, b) = (lo.log10(), hi.log10());
    let (k0, k1) = (a.floor() as i32, b.ceil() as i32);
    if k1 - k0 > 600 {
        return Vec::new();
    }
    let inside = |v: f64| v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
    let multiples = |js: &[f64]| -> Vec<f64> {
        (k0..=k1)
            .flat_map(|k| js.iter().map(move |&j| j * pow10(k)))
            .filter(|&v| inside(v))
            .collect()
    };
    if light {
        let all = multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        if all.len() <= max {
            return all;
        }
    }
    let powers = multiples(&[1.0]);
    if powers.len() >= 3 {
        let stride = powers.len().div_ceil(max.max(1));
        return powers.into_iter().step_by(stride.max(1)).collect();
    }
    let nice = multiples(&[1.0, 2.0, 5.0]);
    if nice.len() >= 2 && nice.len() <= max {
        return nice;
    }
    if powers.len() >= 2 {
        return powers;
    }
    linear_ticks(lo, hi, max.min(6))
}

/// A number for a tick label: plain decimals for `1e-3 ≤ |v| < 1e5`, else
/// `m e k`, without trailing zeros.
fn format_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            format!("{v}")
        };
    }
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (1e-3..1e5).contains(&v.abs()) {
        trim(&format!("{v:.6}"))
    } else {
        let s = format!("{v:.4e}");
        match s.split_once('e') {
            Some((mantissa, exponent)) => format!("{}e{exponent}", trim(mantissa)),
            None => s,
        }
    }
}

/// `10` with the exponent `k` in Unicode superscripts.
fn power_of_ten_label(k: i32) -> String {
    const SUPERSCRIPT: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for digit in k.unsigned_abs().to_string().bytes() {
        s.push(SUPERSCRIPT[usize::from(digit - b'0')]);
    }
    s
}

/// A tick label: `10ᵏ` on log axes that span enough decades to be labelled at
/// powers of ten only, else [`format_number`].
fn tick_label(axis: &AxisCoord, v: f64) -> String {
    if axis.scale == Scale::Log10 && axis.decade_ticks() && v > 0.0 {
        let k = v.log10().round();
        if (v / pow10(k as i32) - 1.0).abs() < 1e-9 {
            return power_of_ten_label(k as i32);
        }
    }
    format_number(v)
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
    Ok(AxisCoord {
        scale: axis.scale,
        lo: back(a),
        hi: back(b),
    })
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

fn legend_text_style() -> TextStyle<'static> {
    TextStyle::from(("sans-serif", LEGEND_FONT).into_font()).pos(Pos::new(HPos::Left, VPos::Center))
}

/// A legend swatch for a line: a short thick bar (a `<rect>`, so that the `<polyline>`s
/// of the file are exactly the drawn curves).
fn line_swatch(area: &Area, x: i32, y: i32, style: ShapeStyle) -> Result<(), PlotError> {
    area.draw(&Rectangle::new(
        [(x, y - 1), (x + 30, y + 1)],
        style.filled(),
    ))
    .map_err(draw_err)
}

/// Renders a line plot to an SVG string.
fn render_line_plot(plot: &LinePlot) -> Result<String, PlotError> {
    let (width, height) = plot.size;
    check_size(width, height)?;
    check_series(plot)?;
    let x = axis_range(plot, 0)?;
    let y = axis_range(plot, 1)?;
    let legend_width = plot
        .series
        .iter()
        .map(|s| legend_text_width(&s.name) + 70)
        .max()
        .unwrap_or(0)
        .max(120)
        .min(width / 2);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
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
        // The legend, right of the axes, from the top of the plotting area.
        let top = chart.plotting_area().get_base_pixel().1;
        for (k, s) in plot.series.iter().enumerate() {
            let c = colour(k);
            let y = top + 12 + LEGEND_ROW * k as i32;
            if s.style.has_line() {
                line_swatch(&legend, 6, y, c.stroke_width(2))?;
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
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
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

// ---------------------------------------------------------------------------
// Pictures of meshes: equal scales, legend or colour bar on the right.
// ---------------------------------------------------------------------------

/// Chart area and side strip of a picture with equal scales on both axes, for data
/// in `bbox = (min, max)`.
struct Picture {
    width: u32,
    height: u32,
    side_width: u32,
}

impl Picture {
    const MARGIN: u32 = 12;
    const X_LABELS: u32 = 40;
    const Y_LABELS: u32 = 64;
    const TITLE: u32 = 48;

    /// Height for a plotting area of the data's aspect ratio (the title's height is
    /// estimated; [`equal_scale_chart`] corrects the ranges exactly).
    fn new(width: u32, side_width: u32, bbox: (Vec2, Vec2), min_height: u32) -> Self {
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
fn padded_bbox(points: impl IntoIterator<Item = Vec2>, fraction: f64) -> Option<(Vec2, Vec2)> {
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

type PictureChart<'a> = ChartContext<'a, SVGBackend<'a>, Cartesian2d<AxisCoord, AxisCoord>>;

/// A chart on `area` showing `bbox` with equal scales on both axes (the shorter
/// range grows, centred), with tick labels on the left and bottom and no grid.
fn equal_scale_chart<'a>(
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

fn pt(p: Vec2) -> (f64, f64) {
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
}

impl Default for MeshPlotOptions {
    fn default() -> Self {
        MeshPlotOptions {
            title: "Powell–Sabin refinement and control triangles".into(),
            width: 1000,
            refinement: true,
            ps_points: true,
            control_triangles: VertexSelection::All,
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
    let bbox = padded_bbox(
        mesh.vertices()
            .iter()
            .copied()
            .chain(selected.iter().flat_map(|&v| control[v])),
        0.02,
    )
    .ok_or_else(|| PlotError::Empty("the mesh has no finite vertex".into()))?;
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
            for t in 0..mesh.num_triangles() {
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
            .draw_series(mesh.edges().iter().map(|e| {
                let [a, b] = e.vertices;
                PathElement::new(
                    vec![pt(vertices[a]), pt(vertices[b])],
                    BLACK.stroke_width(2),
                )
            }))
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
                .draw_series(refinement.edge_point.iter().map(|&r| {
                    EmptyElement::at(pt(r))
                        + Rectangle::new([(-4, -4), (4, 4)], BLACK.stroke_width(1))
                }))
                .map_err(draw_err)?;
            chart
                .draw_series(refinement.split.iter().map(|&z| {
                    EmptyElement::at(pt(z)) + Rectangle::new([(-4, -4), (4, 4)], BLACK.filled())
                }))
                .map_err(draw_err)?;
        }
        chart
            .draw_series(
                vertices
                    .iter()
                    .map(|&v| Circle::new(pt(v), 5, BLACK.filled())),
            )
            .map_err(draw_err)?;
        if options.ps_points {
            let mut points = Vec::new();
            for v in 0..nv {
                // Skip the first PS point: the vertex itself.
                for p in refinement.ps_points(mesh, v).into_iter().skip(1) {
                    points.push((p, v));
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
            format!("{} vertices, {} triangles", nv, mesh.num_triangles()),
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

// ---------------------------------------------------------------------------
// Basis functions
// ---------------------------------------------------------------------------

/// Options of [`basis_function_plot`].
#[derive(Debug, Clone, PartialEq)]
pub struct BasisPlotOptions {
    /// Title; `None` for `"<basis name> basis function <index> of <count>"`.
    pub title: Option<String>,
    /// Image width in pixels (the height follows from the mesh's aspect ratio);
    /// default 900.
    pub width: u32,
    /// Each polynomial piece of the function's support is cut into `subdivisions²`
    /// similar triangles, each shaded with the value at its centroid (on top of the
    /// piece in their mean colour); 1..=64, default 12. The file holds about
    /// `6 · subdivisions²` polygons per triangle of the support (PS), one per other
    /// triangle.
    pub subdivisions: usize,
    /// Also draw the edges of the polynomial pieces (the PS sub-triangles), thin;
    /// default `false`.
    pub pieces: bool,
}

impl Default for BasisPlotOptions {
    fn default() -> Self {
        BasisPlotOptions {
            title: None,
            width: 900,
            subdivisions: 12,
            pieces: false,
        }
    }
}

/// Bit pattern of a point, to match shared corners exactly.
fn point_key(p: Vec2) -> [u64; 2] {
    [p.x.to_bits(), p.y.to_bits()]
}

/// Bit pattern of a segment, independent of its direction, to find shared edges.
fn segment_key(a: Vec2, b: Vec2) -> [u64; 4] {
    let (ka, kb) = (point_key(a), point_key(b));
    let (p, q) = if ka <= kb { (ka, kb) } else { (kb, ka) };
    [p[0], p[1], q[0], q[1]]
}

/// The polynomial pieces (triangles) of every element of `basis`.
fn element_pieces(basis: &impl Basis<f64, 2>) -> Vec<Vec<[Vec2; 3]>> {
    let mut buffer: Vec<Point<f64, 2>> = Vec::new();
    (0..basis.num_elements())
        .map(|e| {
            buffer.clear();
            basis.polynomial_pieces(e, &mut buffer);
            buffer.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        })
        .collect()
}

/// The boundary of one element as a closed loop (first point repeated at the end),
/// from the edges of its pieces that only one piece uses; `None` if those do not
/// chain into one loop (pieces of mixed orientation, a hole).
fn element_outline(pieces: &[[Vec2; 3]]) -> Option<Vec<Vec2>> {
    let edges: Vec<[Vec2; 2]> = pieces
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .collect();
    let keys: Vec<[u64; 4]> = edges.iter().map(|e| segment_key(e[0], e[1])).collect();
    let outer: Vec<[Vec2; 2]> = edges
        .iter()
        .zip(&keys)
        .filter(|(_, k)| keys.iter().filter(|other| other == k).count() == 1)
        .map(|(e, _)| *e)
        .collect();
    let first = outer.first()?;
    let mut used = vec![false; outer.len()];
    used[0] = true;
    let mut outline = vec![first[0], first[1]];
    for _ in 1..outer.len() {
        let end = point_key(*outline.last()?);
        let next = (0..outer.len()).find(|&i| !used[i] && point_key(outer[i][0]) == end)?;
        used[next] = true;
        outline.push(outer[next][1]);
    }
    (point_key(outline[0]) == point_key(*outline.last()?)).then_some(outline)
}

/// The edges between pieces of the same element (shared by two of its pieces), each
/// once, in first-seen order.
fn interior_piece_edges(pieces: &[Vec<[Vec2; 3]>]) -> Vec<[Vec2; 2]> {
    let mut out = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for element in pieces {
        let edges: Vec<[Vec2; 2]> = element
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .collect();
        let keys: Vec<[u64; 4]> = edges.iter().map(|e| segment_key(e[0], e[1])).collect();
        for (e, k) in edges.iter().zip(&keys) {
            if keys.iter().filter(|other| other == &k).count() > 1 && seen.insert(*k) {
                out.push(*e);
            }
        }
    }
    out
}

/// The convex polygon `p` grown by about `delta` on every side, by scaling about its
/// incentre (triangles) or vertex average: closes the hairline seams that
/// anti-aliasing leaves between adjacent filled polygons. Corners move at most
/// `3 delta` (slivers).
fn grown(p: &[Vec2], delta: f64) -> Vec<(f64, f64)> {
    let n = p.len();
    if n == 0 {
        return Vec::new();
    }
    let centre = if n == 3 {
        let w = [
            (p[2] - p[1]).norm(),
            (p[0] - p[2]).norm(),
            (p[1] - p[0]).norm(),
        ];
        let sum = w[0] + w[1] + w[2];
        if sum > 0.0 {
            (p[0] * w[0] + p[1] * w[1] + p[2] * w[2]) / sum
        } else {
            p[0]
        }
    } else {
        p.iter().fold(Vec2::zeros(), |s, q| s + q) / n as f64
    };
    // Distance from the centre to the nearest side, and to the farthest corner.
    let mut near = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        let d = b - a;
        let length = d.norm();
        if length > 0.0 {
            near = near.min(((centre - a).x * d.y - (centre - a).y * d.x).abs() / length);
        }
    }
    let far = p.iter().map(|q| (q - centre).norm()).fold(0.0, f64::max);
    let k = if near > 0.0 && far > 0.0 {
        1.0 + (delta / near).min(3.0 * delta / far)
    } else {
        1.0
    };
    p.iter().map(|&q| pt(centre + (q - centre) * k)).collect()
}

/// Renders one basis function to an SVG string.
fn render_basis_function_plot(
    basis: &impl Basis<f64, 2>,
    index: usize,
    options: &BasisPlotOptions,
) -> Result<String, PlotError> {
    let count = basis.num_functions();
    if index >= count {
        return Err(PlotError::FunctionIndex { index, count });
    }
    if !(1..=64).contains(&options.subdivisions) {
        return Err(PlotError::InvalidOption(format!(
            "subdivisions {}: must be in 1..=64",
            options.subdivisions
        )));
    }
    let side_width = 130;
    if options.width < side_width + 250 {
        return Err(PlotError::InvalidOption(format!(
            "image width {} pixels: at least {} needed",
            options.width,
            side_width + 250
        )));
    }
    let pieces = element_pieces(basis);
    let bbox = padded_bbox(pieces.iter().flatten().flatten().copied(), 0.02)
        .ok_or_else(|| PlotError::Empty("the basis has no element".into()))?;

    // Sample: each piece of the support cut into n² triangles, valued at centroids;
    // the other elements' pieces whole, at zero.
    let n = options.subdivisions;
    let mut in_support = vec![false; basis.num_elements()];
    for &e in basis.function_support(index) {
        if let Some(flag) = in_support.get_mut(e) {
            *flag = true;
        }
    }
    let outlines: Vec<Option<Vec<Vec2>>> = pieces.iter().map(|p| element_outline(p)).collect();
    let mut cells: Vec<(Vec<Vec2>, f64)> = Vec::new();
    let (mut node_lo, mut node_hi) = (0.0f64, 0.0f64);
    let mut eval = BasisEval::for_basis(basis);
    for (e, element) in pieces.iter().enumerate() {
        if !in_support[e] {
            // Zero: the whole element at once where its outline is known.
            if let Some(outline) = &outlines[e] {
                cells.push((outline[..outline.len() - 1].to_vec(), 0.0));
                continue;
            }
        }
        for &[a, b, c] in element {
            if !in_support[e] {
                cells.push((vec![a, b, c], 0.0));
                continue;
            }
            let (u, v) = ((b - a) / n as f64, (c - a) / n as f64);
            let at = |i: usize, j: usize| a + u * i as f64 + v * j as f64;
            let mut value_at = |x: Vec2| -> Result<f64, PlotError> {
                basis.eval(e, &x, &mut eval);
                let value = eval
                    .iter()
                    .find(|&(f, _, _)| f == index)
                    .map_or(0.0, |(_, phi, _)| phi);
                if value.is_finite() {
                    Ok(value)
                } else {
                    Err(PlotError::NonFiniteBasisValue { index, element: e })
                }
            };
            // Under the cells, the whole piece in their mean colour: shows through
            // where cells of a sliver piece do not quite meet at the pixel scale.
            let underlay = cells.len();
            cells.push((vec![a, b, c], 0.0));
            for i in 0..n {
                for j in 0..n - i {
                    let mut small = vec![[at(i, j), at(i + 1, j), at(i, j + 1)]];
                    if i + j + 1 < n {
                        small.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                    }
                    for t in small {
                        let value = value_at((t[0] + t[1] + t[2]) / 3.0)?;
                        cells.push((t.to_vec(), value));
                    }
                }
            }
            let piece_cells = &cells[underlay + 1..];
            cells[underlay].1 =
                piece_cells.iter().map(|c| c.1).sum::<f64>() / piece_cells.len() as f64;
            // The colour scale spans the values at the grid's nodes too (extrema
            // of linear functions sit at corners, not at centroids).
            for i in 0..=n {
                for j in 0..=n - i {
                    let value = value_at(at(i, j))?;
                    (node_lo, node_hi) = (node_lo.min(value), node_hi.max(value));
                }
            }
        }
    }
    let (mut lo, mut hi) = cells.iter().fold((node_lo, node_hi), |(lo, hi), &(_, v)| {
        (lo.min(v), hi.max(v))
    });
    if lo.abs() < 1e-9 * hi.abs() {
        lo = 0.0; // round-off below zero
    }
    if hi - lo <= 1e-300 {
        hi = lo + 1.0;
    }
    let colour_of = |v: f64| ViridisRGB.get_color_normalized(v.clamp(lo, hi), lo, hi);

    let picture = Picture::new(options.width, side_width, bbox, 300);
    check_size(picture.width, picture.height)?;
    let title = options.title.clone().unwrap_or_else(|| {
        format!(
            "{} basis function {index} of {count} (degree {})",
            basis.name(),
            basis.degree()
        )
    });
    let mut svg = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg, (picture.width, picture.height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let body = root
            .titled(&title, ("sans-serif", TITLE_FONT))
            .map_err(draw_err)?;
        let (main, side) = body.split_horizontally(picture.width - picture.side_width);
        let (mut chart, scale) = equal_scale_chart(&main, bbox)?;
        let delta = 1.0 / scale;
        chart
            .draw_series(
                cells
                    .iter()
                    .map(|(t, v)| Polygon::new(grown(t, delta), colour_of(*v).filled())),
            )
            .map_err(draw_err)?;
        if options.pieces {
            chart
                .draw_series(
                    interior_piece_edges(&pieces).iter().map(|s| {
                        PathElement::new(s.map(pt).to_vec(), WHITE.mix(0.6).stroke_width(1))
                    }),
                )
                .map_err(draw_err)?;
        }
        // Element edges: one closed line per element (shared edges twice), dark on a
        // light halo so that they show on every colour; piece by piece where the
        // outline is unknown.
        let lines: Vec<Vec<(f64, f64)>> = outlines
            .iter()
            .zip(&pieces)
            .flat_map(|(outline, element)| match outline {
                Some(outline) => vec![outline.iter().map(|&p| pt(p)).collect()],
                None => element
                    .iter()
                    .map(|t| [t[0], t[1], t[2], t[0]].map(pt).to_vec())
                    .collect(),
            })
            .collect();
        for style in [
            WHITE.mix(0.6).stroke_width(3),
            RGBColor(MESH_EDGE.0, MESH_EDGE.1, MESH_EDGE.2).stroke_width(1),
        ] {
            chart
                .draw_series(lines.iter().map(|l| PathElement::new(l.clone(), style)))
                .map_err(draw_err)?;
        }

        // Colour bar, aligned with the plotting area.
        let mut bar = ChartBuilder::on(&side)
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
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Draws basis function `index` of `basis` into the SVG file `path`, shaded by value
/// (viridis, with a colour bar) with the element edges on top, on equal scales (see
/// the [module docs](self)).
///
/// Errors: [`PlotError::FunctionIndex`] when `index` is not in
/// `0..basis.num_functions()`; invalid options; a non-finite value; the file cannot
/// be written.
pub fn basis_function_plot(
    path: &Path,
    basis: &impl Basis<f64, 2>,
    index: usize,
    options: &BasisPlotOptions,
) -> Result<(), PlotError> {
    let svg = render_basis_function_plot(basis, index, options)?;
    write_svg(path, &svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_nice_and_bounded() {
        assert_eq!(
            linear_ticks(0.0, 1.0, 5),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        let t = linear_ticks(-0.03, 0.97, 10);
        assert!(t.len() <= 11 && t.contains(&0.0));
        assert!(linear_ticks(0.0, 1.0, 0).is_empty());
        assert!(linear_ticks(1.0, 1.0, 5).is_empty());
    }

    #[test]
    fn log_ticks_choose_powers_or_multiples() {
        assert_eq!(
            log_ticks(1e-4, 2.0, 10, false),
            vec![1e-4, 1e-3, 1e-2, 1e-1, 1.0]
        );
        assert_eq!(log_ticks(0.15, 0.9, 10, false), vec![0.2, 0.5]);
        assert_eq!(log_ticks(1e-9, 1e9, 5, false).len(), 5);
        assert!(!log_ticks(2.1, 2.9, 10, false).is_empty());
    }

    #[test]
    fn tick_labels() {
        let decades = AxisCoord {
            scale: Scale::Log10,
            lo: 1e-4,
            hi: 1e3,
        };
        assert_eq!(tick_label(&decades, 1e-3), "10⁻³");
        assert_eq!(tick_label(&decades, 100.0), "10²");
        assert_eq!(tick_label(&decades, 1.0), "10⁰");
        assert_eq!(tick_label(&decades, 0.02), "0.02");
        // Less than three powers of ten in range: plain numbers throughout.
        let short = AxisCoord {
            scale: Scale::Log10,
            lo: 0.03,
            hi: 0.6,
        };
        assert_eq!(tick_label(&short, 0.1), "0.1");
        assert_eq!(format_number(0.6000000000000001), "0.6");
        assert_eq!(format_number(2.5e-7), "2.5e-7");
        assert_eq!(format_number(-1.0e6), "-1e6");
        assert_eq!(format_number(0.0), "0");
    }
}
