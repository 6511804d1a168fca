//! The coordinate of every chart axis: linear or log10, with our own ticks and tick
//! labels (multiples of 1, 2 or 5 × 10^k; powers of ten written `10ᵏ` on log axes
//! spanning enough decades).

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

use super::chart::Scale;

/// A linear or log10 axis over `[lo, hi]` (`0 < lo` for log10), with nice ticks:
/// multiples of 1, 2 or 5 × 10^k on linear axes; powers of ten (or 1-2-5 values on
/// short ranges) on log axes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AxisCoord {
    scale: Scale,
    lo: f64,
    hi: f64,
}

impl AxisCoord {
    /// An axis of `scale` over `[lo, hi]`.
    pub(crate) fn new(scale: Scale, lo: f64, hi: f64) -> Self {
        AxisCoord { scale, lo, hi }
    }
    /// A linear axis over `[lo, hi]`.
    pub(crate) fn linear(lo: f64, hi: f64) -> Self {
        Self::new(Scale::Linear, lo, hi)
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
pub(crate) fn format_number(v: f64) -> String {
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
pub(crate) fn tick_label(axis: &AxisCoord, v: f64) -> String {
    if axis.scale == Scale::Log10 && axis.decade_ticks() && v > 0.0 {
        let k = v.log10().round();
        if (v / pow10(k as i32) - 1.0).abs() < 1e-9 {
            return power_of_ten_label(k as i32);
        }
    }
    format_number(v)
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
