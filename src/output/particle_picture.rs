//! An SVG picture of the particles of a 2D run, coloured by a field, at several
//! times side by side (`particles.svg` of `mpm-cli run --out`: the first, middle and
//! last frame), on one colour scale, over the mesh, without ParaView.
//!
//! Each particle is a disc of diameter `√V_p` (the side of its lattice cell at the
//! start), at least two pixels wide, so that a body reads as a continuum. Pictures
//! of more than [`MAX_DRAWN`] particles draw every `k`-th particle and say so in the
//! caption (the `.vtu` frames hold them all). A non-finite value (a run that failed
//! with NaN) is drawn grey and counted in the caption rather than refused: the
//! picture of a failed run is the one a user needs most.

use std::path::Path;

use nalgebra::SMatrix;
use plotters::prelude::*;
use psmpm_basis::Vec2;

use super::chart::{check_size, draw_err, write_svg, PlotError, LABEL_FONT, TITLE_FONT};
use super::mesh_picture::{colour_bar, equal_scale_chart, padded_bbox, pt, Picture};
use crate::particles::Particles;

/// Most particles drawn per frame.
pub const MAX_DRAWN: usize = 20_000;

/// Width of one frame's panel, in pixels.
const PANEL_WIDTH: u32 = 420;
/// Width of the colour bar's strip.
const SIDE_WIDTH: u32 = 130;
/// Grey of non-finite values and of the mesh edges.
const GREY: RGBColor = RGBColor(0xB0, 0xB0, 0xB0);

/// The particle field a picture is coloured by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ParticleField {
    /// `|u_p|`.
    #[default]
    Displacement,
    /// `|v_p|`.
    Speed,
    /// `σ_xx`.
    SigmaXx,
    /// `σ_yy` (2D).
    SigmaYy,
    /// `σ_xy` (2D).
    SigmaXy,
    /// `p = −tr(σ) / d`.
    Pressure,
    /// von Mises stress `√(3/2 s:s)`, `s` the deviator of `σ` (in the plane in 2D;
    /// `|σ_xx|` in 1D, the uniaxial stress of a bar).
    VonMises,
}

impl ParticleField {
    /// Every field, in the order of [`ParticleField::name`]'s documentation.
    pub const ALL: [ParticleField; 7] = [
        ParticleField::Displacement,
        ParticleField::Speed,
        ParticleField::SigmaXx,
        ParticleField::SigmaYy,
        ParticleField::SigmaXy,
        ParticleField::Pressure,
        ParticleField::VonMises,
    ];

    /// Its name on the command line: `displacement`, `speed`, `sigma-xx`, `sigma-yy`,
    /// `sigma-xy`, `pressure`, `von-mises`.
    pub fn name(self) -> &'static str {
        match self {
            ParticleField::Displacement => "displacement",
            ParticleField::Speed => "speed",
            ParticleField::SigmaXx => "sigma-xx",
            ParticleField::SigmaYy => "sigma-yy",
            ParticleField::SigmaXy => "sigma-xy",
            ParticleField::Pressure => "pressure",
            ParticleField::VonMises => "von-mises",
        }
    }

    /// The label of its colour scale.
    pub fn label(self) -> &'static str {
        match self {
            ParticleField::Displacement => "|u|",
            ParticleField::Speed => "|v|",
            ParticleField::SigmaXx => "σ_xx",
            ParticleField::SigmaYy => "σ_yy",
            ParticleField::SigmaXy => "σ_xy",
            ParticleField::Pressure => "pressure −tr σ / d",
            ParticleField::VonMises => "von Mises stress",
        }
    }

    /// The field of `name`, which must exist in dimension `dim`.
    pub fn parse(name: &str, dim: usize) -> Result<Self, String> {
        let field = Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|f| f.name()).collect();
                format!(
                    "unknown particle field `{}`; one of {}",
                    crate::scene::limits::echo(name),
                    names.join(", ")
                )
            })?;
        if dim == 1 && matches!(field, ParticleField::SigmaYy | ParticleField::SigmaXy) {
            return Err(format!(
                "`{name}` does not exist in 1D (a 1D run has sigma-xx only)"
            ));
        }
        Ok(field)
    }

    /// The field's value at every particle.
    pub fn values<const D: usize>(self, particles: &Particles<f64, D>) -> Vec<f64> {
        let sigma = |p: usize| -> &SMatrix<f64, D, D> { &particles.sigma[p] };
        (0..particles.len())
            .map(|p| match self {
                ParticleField::Displacement => particles.u[p].norm(),
                ParticleField::Speed => particles.v[p].norm(),
                ParticleField::SigmaXx => sigma(p)[(0, 0)],
                ParticleField::SigmaYy => sigma(p)[(D.min(2) - 1, D.min(2) - 1)],
                ParticleField::SigmaXy => sigma(p)[(0, D.min(2) - 1)],
                ParticleField::Pressure => -sigma(p).trace() / D as f64,
                // A 1D bar is in uniaxial stress: its von Mises stress is |σ_xx| (the
                // deviator on the line alone would vanish).
                ParticleField::VonMises if D == 1 => sigma(p)[(0, 0)].abs(),
                ParticleField::VonMises => {
                    let s = sigma(p);
                    let mean = s.trace() / D as f64;
                    let dev = s - SMatrix::<f64, D, D>::identity() * mean;
                    (1.5 * dev.norm_squared()).sqrt()
                }
            })
            .collect()
    }
}

/// The particles at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleFrame {
    /// Time of the frame.
    pub time: f64,
    /// Positions.
    pub positions: Vec<Vec2>,
    /// The field's value per particle.
    pub values: Vec<f64>,
    /// Diameter of each particle's disc (length), `√V_p⁰` in 2D.
    pub sizes: Vec<f64>,
}

impl ParticleFrame {
    /// The frame of 2D `particles` at `time`, coloured by `field`.
    pub fn of(particles: &Particles<f64, 2>, time: f64, field: ParticleField) -> Self {
        ParticleFrame {
            time,
            positions: particles.x.iter().map(|x| Vec2::new(x[0], x[1])).collect(),
            values: field.values(particles),
            sizes: particles
                .volume0
                .iter()
                .map(|v| v.max(0.0).sqrt())
                .collect(),
        }
    }
}

/// What [`particle_plot`] draws.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticlePicture {
    /// Title above the panels.
    pub title: String,
    /// Label of the colour bar.
    pub field: String,
    /// The frames, one panel each, left to right.
    pub frames: Vec<ParticleFrame>,
    /// Mesh edges drawn under the particles.
    pub edges: Vec<[Vec2; 2]>,
}

/// Draws `picture` into the SVG file `path` (see the [module docs](self)).
///
/// Errors: no frame, more than 8 frames, a frame whose arrays differ in length, no
/// finite position at all; the file cannot be written.
pub fn particle_plot(path: &Path, picture: &ParticlePicture) -> Result<(), PlotError> {
    let svg = render(picture)?;
    write_svg(path, &svg)
}

fn render(picture: &ParticlePicture) -> Result<String, PlotError> {
    let n = picture.frames.len();
    if n == 0 || n > 8 {
        return Err(PlotError::InvalidOption(format!(
            "{n} frames: a particle picture shows 1 to 8"
        )));
    }
    for f in &picture.frames {
        if f.values.len() != f.positions.len() || f.sizes.len() != f.positions.len() {
            return Err(PlotError::InvalidOption(format!(
                "the frame at t = {} has {} positions, {} values and {} sizes",
                f.time,
                f.positions.len(),
                f.values.len(),
                f.sizes.len()
            )));
        }
    }
    let points = picture
        .frames
        .iter()
        .flat_map(|f| f.positions.iter().copied())
        .chain(picture.edges.iter().flatten().copied());
    let bbox = padded_bbox(points, 0.02)
        .ok_or_else(|| PlotError::Empty("no particle has a finite position".into()))?;
    let finite = || {
        picture
            .frames
            .iter()
            .flat_map(|f| f.values.iter().copied())
            .filter(|v| v.is_finite())
    };
    let (mut lo, mut hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo > hi {
        (lo, hi) = (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        // One value everywhere: a scale around it.
        let pad = 0.5 * hi.abs().max(1e-300);
        (lo, hi) = (lo - pad, hi + pad);
    }
    let colour_of = |v: f64| {
        if v.is_finite() {
            ViridisRGB.get_color_normalized(v.clamp(lo, hi), lo, hi)
        } else {
            GREY
        }
    };

    let width = PANEL_WIDTH * n as u32 + SIDE_WIDTH;
    let panel = Picture::new(PANEL_WIDTH, 0, bbox, 300);
    let height = panel.height + 2 * LABEL_FONT + 30;
    check_size(width, height)?;
    let total: usize = picture.frames.iter().map(|f| f.positions.len()).sum();
    let most = picture
        .frames
        .iter()
        .map(|f| f.positions.len())
        .max()
        .unwrap_or(0);
    let stride = most.div_ceil(MAX_DRAWN).max(1);
    let non_finite = total - finite().count();
    let mut caption = format!("{} particles", most);
    if stride > 1 {
        caption += &format!(", every {stride}th drawn");
    }
    if non_finite > 0 {
        caption += &format!(", {non_finite} non-finite values in grey");
    }

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let body = root
            .titled(&picture.title, ("sans-serif", TITLE_FONT))
            .map_err(draw_err)?;
        let (body, footer) = body.split_vertically(body.dim_in_pixel().1 - 2 * LABEL_FONT);
        footer
            .draw_text(
                &caption,
                &("sans-serif", LABEL_FONT).into_font().color(&BLACK),
                (Picture::MARGIN as i32 + 64, 0),
            )
            .map_err(draw_err)?;
        let (main, side) = body.split_horizontally(width - SIDE_WIDTH);
        let panels = main.split_evenly((1, n));
        for (area, frame) in panels.iter().zip(&picture.frames) {
            let area = area
                .titled(
                    &format!("t = {}", short_time(frame.time)),
                    ("sans-serif", LABEL_FONT + 4),
                )
                .map_err(draw_err)?;
            let (mut chart, scale) = equal_scale_chart(&area, bbox)?;
            chart
                .draw_series(
                    picture
                        .edges
                        .iter()
                        .map(|e| PathElement::new(e.map(pt).to_vec(), GREY.stroke_width(1))),
                )
                .map_err(draw_err)?;
            chart
                .draw_series(
                    (0..frame.positions.len())
                        .step_by(stride)
                        .filter(|&p| {
                            frame.positions[p].x.is_finite() && frame.positions[p].y.is_finite()
                        })
                        .map(|p| {
                            let radius = (0.5 * frame.sizes[p] * scale * stride as f64)
                                .clamp(1.0, 12.0)
                                .round() as i32;
                            Circle::new(
                                pt(frame.positions[p]),
                                radius,
                                colour_of(frame.values[p]).filled(),
                            )
                        }),
                )
                .map_err(draw_err)?;
        }
        let (label_area, bar_area) = side.split_vertically(LABEL_FONT + 24);
        label_area
            .draw_text(
                &picture.field,
                &("sans-serif", LABEL_FONT).into_font().color(&BLACK),
                (16, 8),
            )
            .map_err(draw_err)?;
        colour_bar(&bar_area, lo, hi, &colour_of)?;
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// A time without float noise: at most 6 significant digits.
fn short_time(t: f64) -> String {
    if t == 0.0 || !t.is_finite() {
        return format!("{t}");
    }
    format!("{}", crate::scene::limits::significant(t, 4))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn block(shift: f64) -> Particles<f64, 2> {
        let mut x = Vec::new();
        for j in 0..4 {
            for i in 0..6 {
                x.push(Vector2::new(0.1 + 0.2 * i as f64, 0.1 + 0.2 * j as f64));
            }
        }
        let mut p = Particles::new(x, vec![0.04; 24], 1.0);
        for q in 0..p.len() {
            p.u[q] = Vector2::new(shift * p.x0[q][0], 0.0);
            p.x[q] += p.u[q];
            p.sigma[q] = SMatrix::<f64, 2, 2>::new(1.0, 0.5, 0.5, -3.0 * q as f64);
        }
        p
    }

    #[test]
    fn fields_are_the_documented_quantities() {
        let p = block(0.1);
        let q = 5;
        assert_eq!(ParticleField::SigmaXx.values(&p)[q], 1.0);
        assert_eq!(ParticleField::SigmaYy.values(&p)[q], -15.0);
        assert_eq!(ParticleField::SigmaXy.values(&p)[q], 0.5);
        assert_eq!(ParticleField::Pressure.values(&p)[q], 7.0);
        // s = diag(8, −8) + offdiag 0.5: √(3/2 (64 + 64 + 0.5)) .
        let vm = ParticleField::VonMises.values(&p)[q];
        assert!((vm - (1.5f64 * 128.5).sqrt()).abs() < 1e-12);
        // A 1D bar in compression: |σ_xx|.
        let mut bar = Particles::<f64, 1>::new(vec![nalgebra::Vector1::new(0.0)], vec![1.0], 1.0);
        bar.sigma[0] = SMatrix::<f64, 1, 1>::new(-9.9e3);
        assert_eq!(ParticleField::VonMises.values(&bar), vec![9.9e3]);
        assert!((ParticleField::Displacement.values(&p)[q] - 0.1 * p.x0[q][0]).abs() < 1e-15);
        assert_eq!(
            ParticleField::parse("von-mises", 2),
            Ok(ParticleField::VonMises)
        );
        assert!(ParticleField::parse("sigma-yy", 1)
            .unwrap_err()
            .contains("1D"));
        assert!(ParticleField::parse("temperature", 2)
            .unwrap_err()
            .contains("one of"));
    }

    #[test]
    fn three_frames_draw_every_particle_in_the_colours_of_one_scale() {
        let frames: Vec<ParticleFrame> = [0.0, 0.25, 0.5]
            .iter()
            .map(|&t| ParticleFrame::of(&block(t), t, ParticleField::Displacement))
            .collect();
        let picture = ParticlePicture {
            title: "block".into(),
            field: "|u|".into(),
            frames,
            edges: vec![[Vec2::new(0.0, 0.0), Vec2::new(1.5, 0.0)]],
        };
        let svg = render(&picture).unwrap();
        std::fs::write(
            std::env::temp_dir().join("psmpm-particle-picture.svg"),
            &svg,
        )
        .unwrap();
        assert_eq!(svg.matches("<circle").count(), 3 * 24);
        for t in ["t = 0\n<", "t = 0.25\n<", "t = 0.5\n<", "24 particles"] {
            assert!(svg.contains(t), "{t}");
        }
        // The first frame (no displacement) sits at the bottom of the scale: the
        // darkest viridis colour; the last holds the top of the scale.
        let top = ViridisRGB.get_color_normalized(1.0, 0.0, 1.0);
        let hex = |c: RGBColor| format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
        assert!(svg.contains(&hex(top)), "{}", hex(top));
        // Deterministic.
        assert_eq!(svg, render(&picture).unwrap());
    }

    #[test]
    fn non_finite_values_are_grey_and_counted_and_bad_frames_are_errors() {
        let mut frame = ParticleFrame::of(&block(0.1), 1.0, ParticleField::Speed);
        frame.values[3] = f64::NAN;
        let mut picture = ParticlePicture {
            title: "failed".into(),
            field: "|v|".into(),
            frames: vec![frame],
            edges: vec![],
        };
        let svg = render(&picture).unwrap();
        assert!(svg.contains("1 non-finite values in grey"));
        picture.frames[0].values.pop();
        assert!(matches!(render(&picture), Err(PlotError::InvalidOption(_))));
        picture.frames.clear();
        assert!(matches!(render(&picture), Err(PlotError::InvalidOption(_))));
    }
}
