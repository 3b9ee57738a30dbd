//! Where trajectory rows go: a CSV stream (rows written as they are computed, so a simulation
//! that stops keeps what it wrote), an in-memory recorder, and the SVG plot.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Receives the trajectory: the column names once, then one row per output time.
pub trait TrajectorySink {
    /// Receive the column names.
    fn begin(&mut self, headers: &[String]) -> Result<()>;
    /// Receive one row.
    fn row(&mut self, values: &[f64]) -> Result<()>;
    /// Flush; called at the end and when the simulation stops on an error.
    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}

/// A number as CSV and tables write it: the shortest decimal that reads back to the same `f64`
/// (Rust's shortest round-trip digits), an exponent outside [1e-5, 1e16) (`1e49`, `2.5e-7`, never
/// 49 digits), whole numbers below 1e15 as integers (`1`, `-3`), and `0` for both zeros (no `-0`).
/// Non-finite values are `NaN`, `inf`, `-inf`.
pub fn format_number(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{}", x as i64)
    } else {
        // Debug is Display's shortest round-trip digits, switching to an exponent for very
        // small and very large magnitudes
        format!("{x:?}")
    }
}

/// CSV stream with a header line; numbers by [`format_number`]; flushed after each row.
pub struct CsvSink<W: Write> {
    out: W,
    name: String,
}

impl CsvSink<std::io::BufWriter<std::fs::File>> {
    /// Create (truncate) a CSV file.
    pub fn create(path: &Path) -> Result<Self> {
        let f =
            std::fs::File::create(path).map_err(|e| Error::io(path.display().to_string(), e))?;
        Ok(CsvSink::new(
            std::io::BufWriter::new(f),
            path.display().to_string(),
        ))
    }
}

impl<W: Write> CsvSink<W> {
    /// Stream to any writer; `name` is used in error messages.
    pub fn new(out: W, name: impl Into<String>) -> Self {
        CsvSink {
            out,
            name: name.into(),
        }
    }

    /// The writer.
    pub fn into_inner(self) -> W {
        self.out
    }

    fn io(&self, e: std::io::Error) -> Error {
        Error::io(self.name.clone(), e)
    }
}

impl<W: Write> TrajectorySink for CsvSink<W> {
    fn begin(&mut self, headers: &[String]) -> Result<()> {
        writeln!(self.out, "{}", headers.join(",")).map_err(|e| self.io(e))
    }
    fn row(&mut self, values: &[f64]) -> Result<()> {
        let mut first = true;
        for &v in values {
            let v = format_number(v);
            let r = if first {
                write!(self.out, "{v}")
            } else {
                write!(self.out, ",{v}")
            };
            r.map_err(|e| self.io(e))?;
            first = false;
        }
        writeln!(self.out).map_err(|e| self.io(e))?;
        // rows reach the file as they are computed (a long or stopped run keeps them)
        self.out.flush().map_err(|e| self.io(e))
    }
    fn finish(&mut self) -> Result<()> {
        self.out.flush().map_err(|e| self.io(e))
    }
}

/// Keeps the trajectory in memory.
#[derive(Clone, Debug, Default)]
pub struct Recorder {
    /// Column names.
    pub headers: Vec<String>,
    /// Rows.
    pub rows: Vec<Vec<f64>>,
}

impl Recorder {
    /// Index of a column.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }

    /// All values of a column.
    pub fn series(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.column(name)?;
        Some(self.rows.iter().map(|r| r[c]).collect())
    }
}

impl TrajectorySink for Recorder {
    fn begin(&mut self, headers: &[String]) -> Result<()> {
        self.headers = headers.to_vec();
        Ok(())
    }
    fn row(&mut self, values: &[f64]) -> Result<()> {
        self.rows.push(values.to_vec());
        Ok(())
    }
}

/// Sends every row to two sinks.
pub struct Tee<'a>(
    pub &'a mut dyn TrajectorySink,
    pub &'a mut dyn TrajectorySink,
);

impl TrajectorySink for Tee<'_> {
    fn begin(&mut self, headers: &[String]) -> Result<()> {
        self.0.begin(headers)?;
        self.1.begin(headers)
    }
    fn row(&mut self, values: &[f64]) -> Result<()> {
        self.0.row(values)?;
        self.1.row(values)
    }
    fn finish(&mut self) -> Result<()> {
        let a = self.0.finish();
        let b = self.1.finish();
        a.and(b)
    }
}

#[cfg(feature = "plot")]
/// SVG plot of a recorded trajectory: the joint positions `q<j>` (top) and the total energy
/// (bottom) against time.
pub fn plot_svg(path: &Path, rec: &Recorder) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: String| Error::io(path.display().to_string(), std::io::Error::other(e));
    let t = rec
        .series("t")
        .ok_or_else(|| err("the trajectory has no column t".into()))?;
    if t.is_empty() {
        return Err(err("the trajectory is empty: nothing to plot".into()));
    }
    let qcols: Vec<(String, Vec<f64>)> = rec
        .headers
        .iter()
        .filter(|h| {
            h.strip_prefix('q')
                .is_some_and(|s| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()))
        })
        .map(|h| (h.clone(), rec.series(h).unwrap()))
        .collect();
    let energy = rec.series("energy");
    let range = |vals: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = vals
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if !lo.is_finite() {
            (-1.0, 1.0)
        } else if hi - lo < 1e-12 * (1.0 + lo.abs()) {
            (lo - 0.5 - 1e-3 * lo.abs(), hi + 0.5 + 1e-3 * hi.abs())
        } else {
            let m = 0.05 * (hi - lo);
            (lo - m, hi + m)
        }
    };
    let (t0, t1) = (t[0], *t.last().unwrap());
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let ds = |e: &dyn std::fmt::Display| err(e.to_string());
    let root = SVGBackend::new(path, (1000, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| ds(&e))?;
    let areas = root.split_evenly((2, 1));
    let (qlo, qhi) = range(&mut qcols.iter().flat_map(|(_, v)| v.iter().copied()));
    let mut chart = ChartBuilder::on(&areas[0])
        .caption("joint positions", ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, qlo..qhi)
        .map_err(|e| ds(&e))?;
    chart
        .configure_mesh()
        .x_desc("t [s]")
        .y_desc("q")
        .draw()
        .map_err(|e| ds(&e))?;
    for (k, (name, v)) in qcols.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        chart
            .draw_series(LineSeries::new(
                t.iter().copied().zip(v.iter().copied()),
                color.stroke_width(2),
            ))
            .map_err(|e| ds(&e))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| ds(&e))?;
    if let Some(e) = energy {
        let (elo, ehi) = range(&mut e.iter().copied());
        let mut chart = ChartBuilder::on(&areas[1])
            .caption("total energy", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, elo..ehi)
            .map_err(|e| ds(&e))?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc("E [J]")
            .draw()
            .map_err(|e| ds(&e))?;
        chart
            .draw_series(LineSeries::new(
                t.iter().copied().zip(e.iter().copied()),
                BLUE.stroke_width(2),
            ))
            .map_err(|e| ds(&e))?;
    }
    root.present().map_err(|e| ds(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::format_number;

    /// Every finite f64 (random bit patterns, fixed seed, and edge cases) reads back exactly,
    /// in at most 24 characters; whole numbers are integers; no `-0`.
    #[test]
    fn format_number_round_trips_short() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut values = vec![
            1e49,
            -1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            0.1 + 0.2,
            1e15,
            1e15 - 1.0,
            123456.0,
            -0.5,
        ];
        for _ in 0..20000 {
            // xorshift64
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(f64::from_bits(x));
        }
        for v in values.into_iter().filter(|v| v.is_finite()) {
            let s = format_number(v);
            assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
            assert!(s.len() <= 24, "{v:e} written as {s}");
        }
        assert_eq!(format_number(-0.0), "0");
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(1.0), "1");
        assert_eq!(format_number(-3.0), "-3");
        assert_eq!(format_number(1e49), "1e49");
        assert_eq!(format_number(2.5e-7), "2.5e-7");
        assert_eq!(format_number(0.1 + 0.2), "0.30000000000000004");
        assert_eq!(format_number(1e300), "1e300");
    }
}
