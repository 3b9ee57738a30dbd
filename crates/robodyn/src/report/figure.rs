//! Figures for a report: time series in stacked panels sharing the time axis, drawn as SVG by
//! plotters. Every figure of the library and the CLI (simulation, identification fit,
//! excitation trajectory) is a [`Figure`] written by [`write_svg`], so they share one look:
//!
//! - a title (and an optional note in red, e.g. why a run stopped);
//! - one panel per quantity *and unit*: each panel says what it shows and its y label carries
//!   its own unit (`q [rad]`, `tau [N m]`); revolute and prismatic joints never share an axis;
//! - ticks chosen by the figure (steps 1, 2 or 5 x 10^k), the axes extended to the ticks around
//!   the data so that the first and last ticks enclose every sample; one light grid line per
//!   tick, no minor grid; tick labels with the decimals of the step (no `-0`, no `e0`);
//! - the legend beside each panel, outside the data (in columns when there are many curves);
//! - line styles that carry meaning: [`Style::Solid`] for a measured or simulated quantity,
//!   [`Style::Dashed`] for a reference or a prediction, [`Style::Dotted`] for a passive joint;
//!   a curve keeps its colour across panels (joint k is colour k everywhere);
//! - an optional vertical red dashed mark (where a run stopped).
//!
//! The SVG is drawn on a canvas [`SCALE`] times larger than its displayed size (plotters rounds
//! coordinates to whole pixels) and declared at the displayed size: 1100 px wide, fonts of 13 to
//! 18 px, for a screen at 100 % or a page.

use crate::error::{Error, Result};
use crate::report::number::Sig;
use std::path::Path;

/// How a curve is drawn (see the [module](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A measured or simulated quantity: solid, 2 px.
    Solid,
    /// A reference or a prediction: dashed, 2 px.
    Dashed,
    /// A passive joint of a closed chain: dotted, 2 px.
    Dotted,
}

/// One curve of a panel: y over the figure's x.
#[derive(Clone, Debug)]
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// Values, one per x (non-finite values are skipped).
    pub y: Vec<f64>,
    /// Colour: index into the palette of [`Figure::colors`] entries (the same index in two
    /// panels is the same colour; an index beyond it is near-black).
    pub color: usize,
    /// Line style.
    pub style: Style,
    /// Whether the legend lists it (a reference drawn in its joint's colour is explained by a
    /// key of the panel instead).
    pub listed: bool,
}

impl Curve {
    /// A curve, listed in the legend.
    pub fn new(label: impl Into<String>, y: Vec<f64>, color: usize, style: Style) -> Curve {
        Curve {
            label: label.into(),
            y,
            color,
            style,
            listed: true,
        }
    }

    /// The curve without a legend entry of its own.
    pub fn unlisted(mut self) -> Curve {
        self.listed = false;
        self
    }
}

/// One panel: a title, a y label with its unit, curves.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// What the panel shows (above it).
    pub title: String,
    /// The y axis: quantity and unit, `q [rad]`.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
    /// Line-style keys listed after the curves, drawn in grey (`("dashed: reference",
    /// Style::Dashed)`).
    pub keys: Vec<(String, Style)>,
}

/// A figure: panels stacked over a shared x axis.
#[derive(Clone, Debug, Default)]
pub struct Figure {
    /// Title (the robot and the conditions).
    pub title: String,
    /// A line under the title in red (e.g. why a run stopped early).
    pub note: Option<String>,
    /// The x axis: quantity and unit (`t [s]`).
    pub x_label: String,
    /// The panels, top to bottom.
    pub panels: Vec<Panel>,
    /// A vertical red dashed mark at this x on every panel (where a run stopped).
    pub mark: Option<f64>,
    /// Number of distinct colours the curves use (the palette: ten "tab10" colours, or that
    /// many evenly spaced hues when there are more).
    pub colors: usize,
}

/// Drawing scale: the canvas is `SCALE` times the displayed size.
pub const SCALE: u32 = 4;
/// Displayed width (px).
const WIDTH: u32 = 1100;
/// Displayed height of a panel (px).
const PANEL_H: u32 = 260;
/// Width of the legend column beside each panel (px).
const LEGEND_W: u32 = 170;

/// Colour k of a palette of n: the ten "tab10" colours, or n evenly spaced hues (alternating
/// lightness) when there are more, so no colour repeats; k >= n is near-black (a curve that is
/// no joint's, such as the energy).
pub fn color(k: usize, n: usize) -> plotters::style::RGBColor {
    use plotters::style::{HSLColor, RGBColor};
    if k >= n {
        return RGBColor(40, 40, 40);
    }
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
        let (r, g, b) = TAB10[k % 10];
        RGBColor(r, g, b)
    } else {
        let l = if k.is_multiple_of(2) { 0.38 } else { 0.55 };
        use plotters::style::Color;
        let (r, g, b) = HSLColor(k as f64 / n as f64, 0.75, l).rgb();
        RGBColor(r, g, b)
    }
}

/// Ticks of an axis over the data range [lo, hi]: a step of 1, 2 or 5 x 10^k giving 4 to 10
/// intervals, and the axis range extended to the ticks at or around the data (the first and
/// last ticks enclose every value). `margin` (a fraction of the span) is added around the data
/// first. A flat or empty range gets a small span around its value.
pub fn ticks(lo: f64, hi: f64, margin: f64) -> Ticks {
    let (lo, hi) = if !(lo.is_finite() && hi.is_finite()) {
        (-1.0, 1.0)
    } else if hi - lo <= 1e-12 * lo.abs().max(hi.abs()).max(1e-300) {
        let m = if lo == 0.0 { 1.0 } else { 1e-3 * lo.abs() };
        (lo - m, hi + m)
    } else {
        let m = margin * (hi - lo);
        (lo - m, hi + m)
    };
    // step = f 10^e, f in {1, 2, 5}; tick k is k f 10^e, computed as an integer over a power
    // of ten so that it is the double nearest the decimal (0.2 * 27 would be 5.4000000000000004)
    let e0 = ((hi - lo) / 6.0).log10().floor() as i32;
    let at = |k: f64, f: f64, e: i32| {
        if e < 0 {
            k * f / 10f64.powi(-e)
        } else {
            k * f * 10f64.powi(e)
        }
    };
    let (f, e) = [(1.0, e0), (2.0, e0), (5.0, e0), (1.0, e0 + 1)]
        .into_iter()
        .find(|&(f, e)| (hi - lo) / at(1.0, f, e) <= 10.0)
        .unwrap_or((2.0, e0 + 1));
    let step = at(1.0, f, e);
    // a tick within 1e-9 steps of the data bound is the bound (rounding of t = k dt)
    let first = (lo / step + 1e-9).floor();
    let last = (hi / step - 1e-9).ceil().max(first + 1.0);
    let values: Vec<f64> = (0..=(last - first) as i64)
        .map(|k| at(first + k as f64, f, e))
        .collect();
    let decimals = (-e).max(0) as usize;
    Ticks {
        lo: values[0],
        hi: *values.last().expect("at least two ticks"),
        values,
        step,
        decimals,
    }
}

/// An axis's ticks: see [`ticks`].
#[derive(Clone, Debug, PartialEq)]
pub struct Ticks {
    /// Axis start (the first tick).
    pub lo: f64,
    /// Axis end (the last tick).
    pub hi: f64,
    /// The tick values, lo to hi.
    pub values: Vec<f64>,
    /// Their step.
    pub step: f64,
    /// Decimals of the labels in plain form.
    pub decimals: usize,
}

impl Ticks {
    /// The label of tick value `v`: plain with the step's decimals, or in the report form of
    /// [`Sig`] for steps below 1e-4 or values of 1e6 and more; `0` for zero (never `-0`).
    pub fn label(&self, v: f64) -> String {
        let v = if v.abs() < 1e-9 * self.step { 0.0 } else { v };
        let big = self.lo.abs().max(self.hi.abs()) >= 1e6;
        if self.step < 1e-4 || big {
            Sig(v, 3).to_string()
        } else {
            format!("{v:.*}", self.decimals)
        }
    }
}

/// An axis with exactly these ticks (plotters' own choice of key points would not end on them).
impl plotters::coord::ranged1d::Ranged for Ticks {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let r = (v - self.lo) / (self.hi - self.lo);
        let len = f64::from(limit.1 - limit.0);
        if !r.is_finite() {
            return limit.0;
        }
        // clamp far outside values (plotters draws in i32)
        limit.0 + (len * r.clamp(-10.0, 10.0)).round() as i32
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        // one grid line per tick: no light (minor) lines
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.values.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// Write a figure as SVG, `x` the shared abscissa (at least two values).
pub fn write_svg(path: &Path, x: &[f64], fig: &Figure) -> Result<()> {
    let svg = render(x, fig).map_err(|e| Error::io(path.display().to_string(), e))?;
    std::fs::write(path, svg).map_err(|e| Error::io(path.display().to_string(), e))
}

/// The SVG text of a figure.
pub fn render(x: &[f64], fig: &Figure) -> std::io::Result<String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| std::io::Error::other(e.to_string());
    if x.len() < 2 {
        return Err(std::io::Error::other("fewer than two samples to plot"));
    }
    if fig.panels.is_empty() {
        return Err(std::io::Error::other("nothing to plot"));
    }
    let s = SCALE as i32;
    let header_h = if fig.note.is_some() { 66 } else { 42 };
    let h = header_h + PANEL_H * fig.panels.len() as u32;
    let xt = ticks(x[0], *x.last().expect("two samples"), 0.0);
    let mut svg = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg, (WIDTH * SCALE, h * SCALE)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (header, body) = root.split_vertically(header_h * SCALE);
        header
            .draw(&Text::new(
                fig.title.clone(),
                (14 * s, 12 * s),
                font(18.0).into_font().color(&BLACK),
            ))
            .map_err(|e| err(&e))?;
        if let Some(note) = &fig.note {
            header
                .draw(&Text::new(
                    note.clone(),
                    (14 * s, 40 * s),
                    font(14.0).into_font().color(&RED),
                ))
                .map_err(|e| err(&e))?;
        }
        let areas = body.split_evenly((fig.panels.len(), 1));
        // one y label width for every panel, so that the stacked time axes line up
        let yts: Vec<Ticks> = fig.panels.iter().map(y_ticks).collect();
        let label_w = yts
            .iter()
            .flat_map(|t| t.values.iter().map(|&v| t.label(v).chars().count()))
            .max()
            .unwrap_or(1) as u32;
        let last = fig.panels.len() - 1;
        for (k, ((area, panel), yt)) in areas.iter().zip(&fig.panels).zip(&yts).enumerate() {
            let axes = Axes {
                x: &xt,
                y: yt,
                label_w,
                bottom: k == last,
            };
            draw_panel(area, x, &axes, fig, panel).map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    // displayed size: the canvas / SCALE (the viewBox keeps the drawing coordinates)
    Ok(svg.replacen(
        &format!("width=\"{}\" height=\"{}\"", WIDTH * SCALE, h * SCALE),
        &format!("width=\"{WIDTH}\" height=\"{h}\""),
        1,
    ))
}

/// Font of a displayed size in px, on the scaled canvas.
fn font(size: f64) -> (&'static str, f64) {
    ("sans-serif", size * f64::from(SCALE))
}

type Area<'a> =
    plotters::drawing::DrawingArea<plotters::backend::SVGBackend<'a>, plotters::coord::Shift>;
type DrawResult = std::result::Result<(), plotters::drawing::DrawingAreaErrorKind<std::io::Error>>;

/// The y ticks of a panel: around its finite values, 3 % margin.
fn y_ticks(p: &Panel) -> Ticks {
    let (lo, hi) = p
        .curves
        .iter()
        .flat_map(|c| c.y.iter().copied())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    ticks(lo, hi, 0.03)
}

/// The axes of a panel: the figure's x ticks, the panel's y ticks, the width (characters) of
/// the y tick labels of the figure, and whether the panel is the bottom one (the panels share
/// the x axis, named under the bottom one only).
struct Axes<'a> {
    x: &'a Ticks,
    y: &'a Ticks,
    label_w: u32,
    bottom: bool,
}

/// One panel: axes, curves, mark, legend.
fn draw_panel(area: &Area<'_>, x: &[f64], axes: &Axes<'_>, fig: &Figure, p: &Panel) -> DrawResult {
    use plotters::prelude::*;
    let s = SCALE as i32;
    let (xt, yt, bottom) = (axes.x, axes.y, axes.bottom);
    let label_w = axes.label_w;
    let (plot_area, legend_area) = area.split_horizontally((WIDTH - LEGEND_W) * SCALE);
    let mut chart = ChartBuilder::on(&plot_area)
        .caption(p.title.as_str(), font(15.0))
        .margin_top(4 * SCALE)
        .margin_bottom(4 * SCALE)
        .margin_left(8 * SCALE)
        // room for half of the last x tick label
        .margin_right(24 * SCALE)
        .x_label_area_size(if bottom { 38 } else { 24 } * SCALE)
        .y_label_area_size((label_w * 8 + 36) * SCALE)
        .build_cartesian_2d(xt.clone(), yt.clone())?;
    chart
        .configure_mesh()
        .x_desc(if bottom { fig.x_label.as_str() } else { "" })
        .y_desc(p.y_label.as_str())
        .label_style(font(13.0))
        .axis_desc_style(font(14.0))
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.12).stroke_width(SCALE))
        .axis_style(BLACK.stroke_width(SCALE))
        .x_label_formatter(&|v| xt.label(*v))
        .y_label_formatter(&|v| yt.label(*v))
        .draw()?;
    for c in &p.curves {
        let style = color(c.color, fig.colors).stroke_width(2 * SCALE);
        let points: Vec<(f64, f64)> = x
            .iter()
            .copied()
            .zip(c.y.iter().copied())
            .filter(|(_, y)| y.is_finite())
            .collect();
        match c.style {
            Style::Solid => {
                chart.draw_series(LineSeries::new(points, style))?;
            }
            Style::Dashed => {
                chart.draw_series(DashedLineSeries::new(points, 9 * s, 5 * s, style))?;
            }
            Style::Dotted => {
                chart.draw_series(DashedLineSeries::new(points, 2 * s, 4 * s, style))?;
            }
        }
    }
    if let Some(at) = fig.mark {
        chart.draw_series(DashedLineSeries::new(
            [(at, yt.lo), (at, yt.hi)],
            8 * s,
            5 * s,
            RED.stroke_width(2 * SCALE),
        ))?;
    }
    draw_legend(&legend_area, fig, p)
}

/// The legend of a panel in its column: one row per curve, a sample of its line (style
/// included) and its label; in several columns when the panel's height needs them.
fn draw_legend(area: &Area<'_>, fig: &Figure, p: &Panel) -> DrawResult {
    use plotters::prelude::*;
    let s = SCALE as i32;
    let grey = RGBColor(90, 90, 90);
    let entries: Vec<(&str, RGBColor, Style)> = p
        .curves
        .iter()
        .filter(|c| c.listed)
        .map(|c| (c.label.as_str(), color(c.color, fig.colors), c.style))
        .chain(p.keys.iter().map(|(l, st)| (l.as_str(), grey, *st)))
        .collect();
    let n = entries.len();
    let row_h = 18 * s;
    let top = 36 * s;
    let per_col = (((PANEL_H * SCALE) as i32 - top - 24 * s) / row_h).max(1) as usize;
    let cols = n.div_ceil(per_col).max(1);
    let col_w = (LEGEND_W * SCALE) as i32 / cols as i32;
    let size = if cols > 2 { 11.0 } else { 13.0 };
    for (k, (label, rgb, style)) in entries.into_iter().enumerate() {
        let (col, row) = (k / per_col, k % per_col);
        let (x, y) = (col as i32 * col_w, top + row as i32 * row_h);
        let stroke = rgb.stroke_width(3 * SCALE);
        // the sample: 22 px of the curve's pattern
        let (dash, gap) = match style {
            Style::Solid => (22, 0),
            Style::Dashed => (7, 4),
            Style::Dotted => (2, 3),
        };
        let mut at = 2;
        while at < 24 {
            let end = (at + dash).min(24);
            area.draw(&PathElement::new(
                vec![(x + at * s, y), (x + end * s, y)],
                stroke,
            ))?;
            if gap == 0 {
                break;
            }
            at = end + gap;
        }
        area.draw(&Text::new(
            label.to_string(),
            (x + 28 * s, y - 7 * s),
            font(size),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::ticks;

    /// The ticks enclose the data, the first and last at the data bounds when those are on the
    /// step (the identification plot's 5.4..7.2 s ended at a 6.8 tick before issue 30).
    #[test]
    fn ticks_cover_the_data() {
        let t = ticks(5.4, 7.2, 0.0);
        assert_eq!((t.step, t.lo, t.hi), (0.2, 5.4, 7.2));
        assert_eq!(t.label(t.hi), "7.2");
        let t = ticks(5.3999, 7.1998, 0.0);
        assert!(t.lo <= 5.3999 && t.hi >= 7.1998 && t.hi - 7.1998 < t.step);
        let t = ticks(0.0, 1.8000000000000003, 0.0);
        assert_eq!((t.lo, t.hi), (0.0, 1.8));
        let t = ticks(-61.3, 66.2, 0.03);
        assert!(t.lo <= -61.3 && t.hi >= 66.2 && t.values.len() <= 11);
        assert_eq!(t.label(0.0), "0");
        // a drift of nanojoules: readable labels, no `-0`
        let t = ticks(-2.1e-9, 3.3e-9, 0.03);
        assert!(t.values.iter().all(|&v| !t.label(v).starts_with("-0")));
        assert_eq!(t.label(2e-9), "2e-9");
        // a flat curve at 0 still has an axis
        let t = ticks(0.0, 0.0, 0.03);
        assert!(t.lo < 0.0 && t.hi > 0.0);
        for v in &t.values {
            assert!(!t.label(*v).contains("e0"));
        }
    }
}
