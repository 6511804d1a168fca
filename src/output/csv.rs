//! CSV time series, written with the `csv` crate: a header row of column names
//! (quoted as in RFC 4180 when they contain `,`, `"` or line breaks) and rows of
//! numbers separated by `,`, with `\n` line endings. Numbers are written as the [module `output`](super#format) says.
//!
//! [`CsvWriter`] streams rows to any [`Write`]; [`write_csv_columns`] writes named
//! columns at once (and [`OutputDir::write_csv`](super::dir::OutputDir::write_csv)
//! writes them to a file of an output directory).

use super::invalid;
use std::fmt::Write as _;
use std::io::{self, Write};

/// A CSV error as an io error (the writer's own errors are io errors).
fn io_error(e: ::csv::Error) -> io::Error {
    match e.into_kind() {
        ::csv::ErrorKind::Io(e) => e,
        other => io::Error::other(format!("{other:?}")),
    }
}

/// A CSV time-series writer (the `csv` crate's, quoting as RFC 4180 needs): the
/// header row on creation, then one row of `f64` per call to [`CsvWriter::row`],
/// written straight through (no allocation per row once the first is written).
#[derive(Debug)]
pub struct CsvWriter<W: Write> {
    w: ::csv::Writer<W>,
    columns: usize,
    /// One formatted value (reused).
    field: String,
}

impl<W: Write> CsvWriter<W> {
    /// Writes the header row `columns` to `w` and returns the writer.
    pub fn new<S: AsRef<str>>(w: W, columns: &[S]) -> io::Result<Self> {
        let mut w = ::csv::Writer::from_writer(w);
        w.write_record(columns.iter().map(|c| c.as_ref()))
            .map_err(io_error)?;
        Ok(CsvWriter {
            w,
            columns: columns.len(),
            field: String::new(),
        })
    }

    /// Writes one row; `InvalidInput` unless it has one value per column.
    pub fn row(&mut self, values: &[f64]) -> io::Result<()> {
        if values.len() != self.columns {
            return Err(invalid(format!(
                "CSV row has {} values but the header has {} columns",
                values.len(),
                self.columns
            )));
        }
        for &x in values {
            self.field.clear();
            write!(self.field, "{x:e}").expect("formatting into a String");
            self.w.write_field(&self.field).map_err(io_error)?;
        }
        self.w.write_record(None::<&[u8]>).map_err(io_error)
    }

    /// Number of columns.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Flushes and returns the underlying writer.
    pub fn finish(self) -> io::Result<W> {
        let mut w = self.w.into_inner().map_err(|e| {
            let kind = e.error().kind();
            io::Error::new(kind, e.error().to_string())
        })?;
        w.flush()?;
        Ok(w)
    }
}

/// Writes a set of named columns as CSV: the names as header, then row `i` holds
/// the `i`-th value of every column. `InvalidInput` when the columns have different
/// lengths. `w` is flushed at the end.
pub fn write_csv_columns<W: Write>(w: W, columns: &[(String, Vec<f64>)]) -> io::Result<()> {
    let rows = columns.first().map_or(0, |(_, c)| c.len());
    if let Some((name, c)) = columns.iter().find(|(_, c)| c.len() != rows) {
        return Err(invalid(format!(
            "CSV column `{name}` has {} values but `{}` has {rows}",
            c.len(),
            columns[0].0
        )));
    }
    let names: Vec<&str> = columns.iter().map(|(name, _)| name.as_str()).collect();
    let mut csv = CsvWriter::new(w, &names)?;
    let mut row = vec![0.0; columns.len()];
    for i in 0..rows {
        for (r, (_, c)) in row.iter_mut().zip(columns) {
            *r = c[i];
        }
        csv.row(&row)?;
    }
    csv.finish().map(drop)
}

#[cfg(test)]
mod tests {
    use super::super::tests::awkward_values;
    use super::*;

    /// Parses what [`write_csv_columns`] writes (unquoted names only).
    fn read_csv(text: &str) -> Vec<(String, Vec<f64>)> {
        let mut lines = text.lines();
        let mut columns: Vec<(String, Vec<f64>)> = lines
            .next()
            .unwrap()
            .split(',')
            .map(|n| (n.to_string(), Vec::new()))
            .collect();
        for line in lines {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), columns.len(), "row `{line}`");
            for (c, f) in columns.iter_mut().zip(fields) {
                c.1.push(f.parse().unwrap());
            }
        }
        columns
    }

    #[test]
    fn csv_round_trips_bit_for_bit() {
        let t = awkward_values();
        let e: Vec<f64> = t.iter().map(|x| x * 0.7 - 1e-17).collect();
        let columns = vec![("t".to_string(), t), ("energy".to_string(), e)];
        let mut bytes = Vec::new();
        write_csv_columns(&mut bytes, &columns).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.starts_with("t,energy\n0e0,"), "{text}");
        let back = read_csv(&text);
        assert_eq!(back.len(), columns.len());
        for ((name, values), (name2, values2)) in columns.iter().zip(&back) {
            assert_eq!(name, name2);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(values), bits(values2), "column {name}");
        }
    }

    #[test]
    fn csv_rejects_ragged_input_and_quotes_names() {
        let ragged = vec![
            ("a".to_string(), vec![1.0, 2.0]),
            ("b".to_string(), vec![1.0]),
        ];
        let err = write_csv_columns(Vec::new(), &ragged).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("`b`"), "{err}");

        let mut csv = CsvWriter::new(Vec::new(), &["x, m", "say \"hi\""]).unwrap();
        assert!(csv.row(&[1.0]).is_err());
        csv.row(&[1.0, 2.0]).unwrap();
        let text = String::from_utf8(csv.finish().unwrap()).unwrap();
        assert_eq!(text, "\"x, m\",\"say \"\"hi\"\"\"\n1e0,2e0\n");
    }
}
