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
    Number(x).to_string()
}

/// [`format_number`] as a `Display`, written in place (`write!(out, "{}", Number(x))`: no
/// allocation per number).
#[derive(Clone, Copy, Debug)]
pub struct Number(pub f64);

impl std::fmt::Display for Number {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        if x == 0.0 {
            f.write_str("0")
        } else if x.fract() == 0.0 && x.abs() < 1e15 {
            write!(f, "{}", x as i64)
        } else {
            // Debug is Display's shortest round-trip digits, switching to an exponent for very
            // small and very large magnitudes
            write!(f, "{x:?}")
        }
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

/// What a plot says besides the trajectory.
#[derive(Clone, Debug, Default)]
pub struct PlotInfo {
    /// Title: the robot and the conditions of the run.
    pub title: String,
    /// Why the run stopped before its end (marked on the plot), if it did.
    pub stopped: Option<String>,
    /// Labels `<l>` of the prismatic joints' `q<l>` columns (plotted in metres, apart from the
    /// revolute joints' radians): `3` for `q3`, `_slider` for `q_slider`.
    pub prismatic: Vec<String>,
}

/// Drawing scale: the SVG is drawn on a canvas `SCALE` times larger than its displayed size
/// (the `viewBox`), so that the backend's whole-pixel coordinates are 1/`SCALE` of a displayed
/// pixel and curves are smooth, not stairs.
#[cfg(feature = "plot")]
const SCALE: u32 = 4;

/// Tick label of `v` on an axis spanning `span`: enough decimals for the span, no `-0`.
#[cfg(feature = "plot")]
fn tick_label(v: f64, span: f64) -> String {
    let v = if v.abs() < 1e-9 * span { 0.0 } else { v };
    if (1e-2..1e5).contains(&span) {
        let decimals = (1.0 - span.log10().floor()).clamp(0.0, 6.0) as usize;
        format!("{v:.decimals$}")
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.2e}")
    }
}

/// `x` with `digits` significant digits, without an exponent in 1e-3..1e6 (`8.494`, `-1234`).
#[cfg(feature = "plot")]
fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format_number(x);
    }
    let mag = x.abs().log10().floor();
    if (-3.0..6.0).contains(&mag) {
        let decimals = (digits as f64 - 1.0 - mag).max(0.0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

/// What stopped a run, for the plot: the last line of the error (the reason), or the first line
/// without a leading "simulation stopped at t = ..: ".
#[cfg(feature = "plot")]
fn stop_reason(e: &str) -> String {
    let lines: Vec<&str> = e.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    match lines.as_slice() {
        [] => String::new(),
        [one] => match one.strip_prefix("simulation stopped at t = ") {
            Some(rest) => rest.split_once(": ").map_or(rest, |(_, r)| r).to_string(),
            None => one.to_string(),
        },
        [.., last] => last.to_string(),
    }
}

/// A named curve: a column's header and its values.
#[cfg(feature = "plot")]
type Series = (String, Vec<f64>);

/// Colour k of n series: the ten "tab10" colours, or n evenly spaced hues when there are more
/// (no colour repeats).
#[cfg(feature = "plot")]
fn series_color(k: usize, n: usize) -> plotters::style::RGBColor {
    use plotters::style::{HSLColor, RGBColor};
    const TAB10: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    if n <= 10 {
        let (r, g, b) = TAB10[k];
        RGBColor(r, g, b)
    } else {
        let l = if k.is_multiple_of(2) { 0.38 } else { 0.55 };
        let c = HSLColor(k as f64 / n as f64, 0.75, l);
        use plotters::style::Color;
        let (r, g, b) = c.rgb();
        RGBColor(r, g, b)
    }
}

#[cfg(feature = "plot")]
/// SVG plot of a recorded trajectory, a figure for a report: a title (robot, conditions), the
/// joint positions `q<j>` against time (revolute joints in rad and prismatic joints in m in
/// separate panels, legend beside the curves, in columns when there are many joints), and the
/// energy drift E - E(0) in J with E(0) stated; a run that stopped early is marked where it
/// stopped and says why.
pub fn plot_svg(path: &Path, rec: &Recorder, info: &PlotInfo) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: String| Error::io(path.display().to_string(), std::io::Error::other(e));
    let t = rec
        .series("t")
        .ok_or_else(|| err("the trajectory has no column t".into()))?;
    if t.is_empty() {
        return Err(err("the trajectory is empty: nothing to plot".into()));
    }
    // q<frame> or q_<joint name> (`--names joint`), not qd.. / qdd..
    let is_q = |h: &str| {
        h.strip_prefix('q').is_some_and(|s| {
            (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()))
                || s.strip_prefix('_').is_some_and(|n| !n.is_empty())
        })
    };
    let (mut revolute, mut prismatic) = (Vec::new(), Vec::new());
    for h in rec.headers.iter().filter(|h| is_q(h)) {
        let v = rec.series(h).expect("column");
        if info.prismatic.iter().any(|p| h[1..] == *p) {
            prismatic.push((h.clone(), v));
        } else {
            revolute.push((h.clone(), v));
        }
    }
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
            let m = 1e-3 * (1.0 + lo.abs());
            (lo - m, hi + m)
        } else {
            let m = 0.05 * (hi - lo);
            (lo - m, hi + m)
        }
    };
    let (t0, t1) = (t[0], *t.last().unwrap());
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let ds = |e: &dyn std::fmt::Display| err(e.to_string());
    let s = SCALE as i32;
    let sf = f64::from(SCALE);
    let font = |size: f64| ("sans-serif", size * sf);
    let (w, panel_h) = (1100u32, 300u32);
    let mut panels: Vec<(&str, &str, &[Series])> = Vec::new();
    if !revolute.is_empty() {
        panels.push(("joint positions, revolute joints", "q [rad]", &revolute));
    }
    if !prismatic.is_empty() {
        panels.push(("joint positions, prismatic joints", "q [m]", &prismatic));
    }
    let header_h = if info.stopped.is_some() { 64 } else { 40 };
    let h = header_h + panel_h * (panels.len() as u32 + u32::from(energy.is_some()));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w * SCALE, h * SCALE)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| ds(&e))?;
        let (header, body) = root.split_vertically(header_h * SCALE);
        header
            .draw(&Text::new(
                info.title.clone(),
                (12 * s, 10 * s),
                font(17.0).into_font().color(&BLACK),
            ))
            .map_err(|e| ds(&e))?;
        if let Some(why) = &info.stopped {
            // the reason: an error's last line says what happened (its first repeats the time
            // and the numbers)
            let mut why = stop_reason(why);
            if why.chars().count() > 150 {
                why = why.chars().take(147).collect::<String>() + "...";
            }
            header
                .draw(&Text::new(
                    format!("stopped early at t = {}: {why}", format_number(t1)),
                    (12 * s, 36 * s),
                    font(12.0).into_font().color(&RED),
                ))
                .map_err(|e| ds(&e))?;
        }
        let areas = body.split_evenly((panels.len() + usize::from(energy.is_some()), 1));
        let legend_w = 170u32;
        let mark_stop = |chart: &mut ChartContext<
            '_,
            SVGBackend<'_>,
            Cartesian2d<
                plotters::coord::types::RangedCoordf64,
                plotters::coord::types::RangedCoordf64,
            >,
        >,
                         lo: f64,
                         hi: f64|
         -> Result<()> {
            if info.stopped.is_some() {
                chart
                    .draw_series(DashedLineSeries::new(
                        [(t1, lo), (t1, hi)],
                        8 * s,
                        5 * s,
                        RED.stroke_width(2 * SCALE),
                    ))
                    .map_err(|e| ds(&e))?;
            }
            Ok(())
        };
        for (area, (caption, ydesc, series)) in areas.iter().zip(&panels) {
            let (plot_area, legend_area) = area.split_horizontally((w - legend_w) * SCALE);
            let (lo, hi) = range(&mut series.iter().flat_map(|(_, v)| v.iter().copied()));
            let mut chart = ChartBuilder::on(&plot_area)
                .caption(*caption, font(15.0))
                .margin(8 * s)
                .x_label_area_size(38 * s)
                .y_label_area_size(70 * s)
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(|e| ds(&e))?;
            chart
                .configure_mesh()
                .x_desc("t [s]")
                .y_desc(*ydesc)
                .label_style(font(12.0))
                .axis_desc_style(font(13.0))
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.12).stroke_width(SCALE))
                .axis_style(BLACK.stroke_width(SCALE))
                .x_label_formatter(&|v| tick_label(*v, t1 - t0))
                .y_label_formatter(&|v| tick_label(*v, hi - lo))
                .draw()
                .map_err(|e| ds(&e))?;
            let n = series.len();
            for (k, (_, v)) in series.iter().enumerate() {
                let color = series_color(k, n);
                chart
                    .draw_series(LineSeries::new(
                        t.iter().copied().zip(v.iter().copied()),
                        color.stroke_width(2 * SCALE),
                    ))
                    .map_err(|e| ds(&e))?;
            }
            mark_stop(&mut chart, lo, hi)?;
            // legend beside the plot, in as many columns as the panel's height needs
            let row_h = 16 * s;
            let top = 34 * s;
            let per_col = (((panel_h * SCALE) as i32 - top - 20 * s) / row_h).max(1) as usize;
            let cols = n.div_ceil(per_col);
            let col_w = (legend_w * SCALE) as i32 / cols.max(1) as i32;
            for (k, (name, _)) in series.iter().enumerate() {
                let (c, r) = (k / per_col, k % per_col);
                let (x, y) = (c as i32 * col_w, top + r as i32 * row_h);
                let color = series_color(k, n);
                legend_area
                    .draw(&PathElement::new(
                        vec![(x + 2 * s, y), (x + 18 * s, y)],
                        color.stroke_width(3 * SCALE),
                    ))
                    .map_err(|e| ds(&e))?;
                legend_area
                    .draw(&Text::new(
                        name.clone(),
                        (x + 22 * s, y - 6 * s),
                        font(if cols > 2 { 10.0 } else { 12.0 }),
                    ))
                    .map_err(|e| ds(&e))?;
            }
        }
        if let Some(e) = energy {
            let area = areas.last().expect("energy panel");
            let (plot_area, _) = area.split_horizontally((w - legend_w) * SCALE);
            let e0 = e[0];
            let drift: Vec<f64> = e.iter().map(|x| x - e0).collect();
            let (lo, hi) = range(&mut drift.iter().copied());
            let mut chart = ChartBuilder::on(&plot_area)
                .caption(
                    format!(
                        "energy change E - E(0), E(0) = {} J (the work of torques and friction; \
                         for a free frictionless run the integration drift)",
                        significant(e0, 4)
                    ),
                    font(15.0),
                )
                .margin(8 * s)
                .x_label_area_size(38 * s)
                .y_label_area_size(70 * s)
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(|e| ds(&e))?;
            chart
                .configure_mesh()
                .x_desc("t [s]")
                .y_desc("E - E(0) [J]")
                .label_style(font(12.0))
                .axis_desc_style(font(13.0))
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.12).stroke_width(SCALE))
                .axis_style(BLACK.stroke_width(SCALE))
                .x_label_formatter(&|v| tick_label(*v, t1 - t0))
                .y_label_formatter(&|v| tick_label(*v, hi - lo))
                .draw()
                .map_err(|e| ds(&e))?;
            chart
                .draw_series(LineSeries::new(
                    t.iter().copied().zip(drift.iter().copied()),
                    RGBColor(31, 119, 180).stroke_width(2 * SCALE),
                ))
                .map_err(|e| ds(&e))?;
            mark_stop(&mut chart, lo, hi)?;
        }
        root.present().map_err(|e| ds(&e))?;
    }
    // displayed size: the canvas / SCALE (the viewBox keeps the drawing coordinates)
    let svg = svg.replacen(
        &format!("width=\"{}\" height=\"{}\"", w * SCALE, h * SCALE),
        &format!("width=\"{w}\" height=\"{h}\""),
        1,
    );
    std::fs::write(path, svg).map_err(|e| Error::io(path.display().to_string(), e))
}

#[cfg(test)]
mod tests {
    use super::format_number;

    #[cfg(feature = "plot")]
    #[test]
    fn plot_labels() {
        use super::{significant, stop_reason, tick_label};
        assert_eq!(significant(8.4937, 4), "8.494");
        assert_eq!(significant(-1234.4, 4), "-1234");
        assert_eq!(significant(0.012345, 3), "0.0123");
        assert_eq!(significant(3.0e7, 3), "3.00e7");
        // a drift axis of 1e-9 J is readable (exponents), no `-0`; 0..2 s in tenths
        assert_eq!(tick_label(2e-10, 1e-9), "2.00e-10");
        assert_eq!(tick_label(-1e-20, 1.0), "0.0");
        assert_eq!(tick_label(0.4, 2.0), "0.4");
        assert_eq!(tick_label(-40.0, 85.0), "-40");
        let e = "simulation stopped at t = 0.71: q_a = [..] cannot be reached\n  the motion \
                 reached a singular configuration";
        assert_eq!(
            stop_reason(e),
            "the motion reached a singular configuration"
        );
        assert_eq!(
            stop_reason("simulation stopped at t = 0.5: step size underflow"),
            "step size underflow"
        );
    }

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
