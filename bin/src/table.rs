//! Plain aligned text tables.

/// A table of strings printed with right-aligned columns.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with the given column names.
    pub fn new(header: &[&str]) -> Self {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (one string per column).
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }

    /// Renders the table, one line per row, columns separated by two spaces.
    pub fn render(&self) -> String {
        let mut width: Vec<usize> = self.header.iter().map(|h| h.chars().count()).collect();
        for row in &self.rows {
            for (w, cell) in width.iter_mut().zip(row) {
                *w = (*w).max(cell.chars().count());
            }
        }
        let line = |cells: &[String]| {
            let parts: Vec<String> = cells
                .iter()
                .zip(&width)
                .map(|(c, w)| format!("{c:>w$}"))
                .collect();
            parts.join("  ").trim_end().to_string()
        };
        let mut out = line(&self.header);
        out.push('\n');
        for row in &self.rows {
            out.push_str(&line(row));
            out.push('\n');
        }
        out
    }
}

/// A float in scientific notation with 3 significant digits.
pub fn sci(x: f64) -> String {
    format!("{x:.2e}")
}

/// An optional float with 2 decimals, `-` when absent.
pub fn fixed2(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_string(), |v| format!("{v:.2}"))
}

/// A time (or any value read by people) with at most 10 significant digits and no
/// trailing zeros: `0.102` for the `0.10200000000000001` that 102 steps of `1e-3` sum
/// to.
pub fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = 9 - x.abs().log10().floor() as i32;
    if (0..=17).contains(&digits) {
        let text = format!("{x:.*}", digits as usize);
        let text = text.trim_end_matches('0').trim_end_matches('.');
        text.to_string()
    } else {
        format!("{x:.9e}")
    }
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn short_drops_the_noise_of_summed_steps() {
        assert_eq!(short(0.10200000000000001), "0.102");
        assert_eq!(short(0.6), "0.6");
        assert_eq!(short(2.5), "2.5");
        assert_eq!(short(5.0), "5");
        assert_eq!(short(0.599959), "0.599959");
        assert_eq!(short(1234.5), "1234.5");
        assert_eq!(short(1e-12), "1.000000000e-12");
    }
}
