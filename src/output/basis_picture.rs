//! The SVG picture of one function of any 2D [`Basis`] with
//! [`basis_function_plot`]: sampled on a uniform subdivision of each of its
//! polynomial pieces and shaded with the viridis colour map, a colour bar at the
//! right and the mesh edges on top. Equal scales on both axes. A support small
//! against the mesh (its box, grown by three quarters of its size on each side,
//! under a quarter of the mesh's) is shown with the elements around it only, so
//! that it is not lost on a large mesh. Output as in
//! [`chart`](super::chart#output).

use std::path::Path;

use plotters::prelude::*;
use psmpm_basis::{Basis, BasisEval, Point, Vec2};

use super::chart::{check_size, draw_err, write_svg, PlotError, TITLE_FONT};
use super::mesh_picture::{colour_bar, equal_scale_chart, padded_bbox, pt, Picture};

/// Colour `(r, g, b)` of the element edges in a basis function plot (near-black, to
/// tell them from the axes).
pub const MESH_EDGE: (u8, u8, u8) = (0x14, 0x14, 0x14);

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

/// Which elements the picture of a function with support `support` shows: all of
/// them, or, where the support's box (grown by [`ZOOM_MARGIN`] of its size on each
/// side) covers less than [`ZOOM_BELOW`] of the mesh's box, the elements inside
/// that grown box: the support and a ring of elements around it.
fn shown_elements(pieces: &[Vec<[Vec2; 3]>], support: &[usize]) -> Vec<bool> {
    let boxed = |elements: &mut dyn Iterator<Item = &Vec<[Vec2; 3]>>| {
        padded_bbox(elements.flatten().flatten().copied(), 0.0)
    };
    let all = vec![true; pieces.len()];
    let (Some((lo, hi)), Some((slo, shi))) = (
        boxed(&mut pieces.iter()),
        boxed(&mut support.iter().filter_map(|&e| pieces.get(e))),
    ) else {
        return all;
    };
    let size = shi - slo;
    let (vlo, vhi) = (
        (slo - size * ZOOM_MARGIN).sup(&lo),
        (shi + size * ZOOM_MARGIN).inf(&hi),
    );
    let area = |a: Vec2, b: Vec2| (b.x - a.x).max(0.0) * (b.y - a.y).max(0.0);
    if area(vlo, vhi) >= ZOOM_BELOW * area(lo, hi) {
        return all;
    }
    let tol = 1e-9 * (hi - lo).norm();
    let inside = |p: &Vec2| {
        p.x >= vlo.x - tol && p.x <= vhi.x + tol && p.y >= vlo.y - tol && p.y <= vhi.y + tol
    };
    pieces
        .iter()
        .map(|element| element.iter().flatten().all(inside))
        .collect()
}

/// The share of the mesh's box below which a function's picture zooms to its
/// support ([`shown_elements`]).
const ZOOM_BELOW: f64 = 0.25;
/// The margin around the support's box in a zoomed picture, as a share of the
/// support's size on each side.
const ZOOM_MARGIN: f64 = 0.75;

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
    let all_pieces = element_pieces(basis);
    if all_pieces.is_empty() {
        return Err(PlotError::Empty("the basis has no element".into()));
    }
    // A support small against the mesh is shown with the elements around it
    // (on a large mesh it would be a few pixels); the others are left out.
    let shown = shown_elements(&all_pieces, basis.function_support(index));
    let pieces: Vec<Vec<[Vec2; 3]>> = all_pieces
        .into_iter()
        .zip(&shown)
        .map(|(p, &keep)| if keep { p } else { Vec::new() })
        .collect();
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

        colour_bar(&side, lo, hi, &colour_of)?;
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
