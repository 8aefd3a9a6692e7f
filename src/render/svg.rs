//! Pictures of answers as SVG, written by hand: a chart (axes in the units a person reads, a
//! title, a legend) of lines, markers, outlines, circles and heat maps. Text is in the viewer's
//! sans-serif font; colours are attributes, not `style`, so a page with
//! `Content-Security-Policy: default-src 'self'` can inline the picture.

use std::fmt::Write;

use super::number::format_number;
use super::table::with_unit;
use crate::model::text::prefixed;

/// Width and height of every picture (px): readable on a screen and in print.
pub const WIDTH: f64 = 800.0;
pub const HEIGHT: f64 = 500.0;
/// The plot area: left, top, right, bottom margins leave room for labels and the legend.
const LEFT: f64 = 80.0;
const TOP: f64 = 50.0;
const RIGHT: f64 = 230.0;
const BOTTOM: f64 = 60.0;
const LEGEND_ROWS: usize = 14;
const DASH: &str = r#" stroke-dasharray="6 4""#;

/// Colours of successive series (a palette distinguishable by most readers).
const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// viridis (0xRRGGBB): the colours of more series than [`PALETTE`] has, in their order (a
/// sweep's lines come in the order of the parameter that tells them apart), readable in grey
/// and by colour-blind readers.
const VIRIDIS: [u32; 5] = [0x440154, 0x3b528b, 0x21918c, 0x5ec962, 0xfde725];

/// The colours of heat maps, from blue (0) to red (1).
const HEAT: [u32; 5] = [0x313695, 0x74add1, 0xffffbf, 0xf46d43, 0xa50026];

/// The colour at `t` ∈ [0, 1] along `stops`, mixed linearly between the two it falls between.
fn ramp(stops: &[u32], t: f64) -> String {
    let position = t.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    let i = (position.floor() as usize).min(stops.len() - 2);
    let f = position - i as f64;
    let mix = |shift: u32| {
        let (a, b) = ((stops[i] >> shift) & 0xff, (stops[i + 1] >> shift) & 0xff);
        let (a, b) = (f64::from(a), f64::from(b));
        (a + f * (b - a)).round() as u8
    };
    format!("#{:02x}{:02x}{:02x}", mix(16), mix(8), mix(0))
}

/// How successive layers take their colours: lines of one group share one, along [`VIRIDIS`]
/// when the groups outnumber [`PALETTE`]; other layers go on past the groups met so far (a
/// fit's measured points take their curve's), dark grey past the lines along viridis.
struct Palette<'a> {
    /// Every group of lines, in the order the layers meet them.
    groups: Vec<&'a str>,
    sequential: bool,
    next: usize,
}

impl<'a> Palette<'a> {
    fn new(layers: &'a [Layer]) -> Palette<'a> {
        let mut groups = Vec::new();
        for layer in layers {
            if let Layer::Line { group, .. } = layer {
                if !groups.contains(&group.as_str()) {
                    groups.push(group.as_str());
                }
            }
        }
        Palette {
            sequential: groups.len() > PALETTE.len(),
            groups,
            next: 0,
        }
    }

    fn line(&self, i: usize) -> String {
        if self.sequential {
            let last = self.groups.len().saturating_sub(1).max(1);
            ramp(&VIRIDIS, i as f64 / last as f64)
        } else {
            PALETTE[i % PALETTE.len()].to_string()
        }
    }

    /// The colour of `layer`, the palette moved on past it.
    fn take(&mut self, layer: &Layer) -> String {
        match layer {
            Layer::Line { group, .. } => {
                let i = self.groups.iter().position(|g| g == group);
                let i = i.expect("every group was met in new()");
                self.next = self.next.max(i + 1);
                self.line(i)
            }
            // A heat map has its own colour bar.
            Layer::Heatmap { .. } => String::new(),
            _ => {
                self.next += 1;
                if self.sequential && self.next > self.groups.len() {
                    "#444444".to_string()
                } else {
                    self.line(self.next - 1)
                }
            }
        }
    }
}

/// An axis: the quantity it shows and its SI unit; its range follows the data.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub quantity: String,
    /// SI unit (`m`, `N`, `m/s`, `m^2`, `Pa`, or "" for a plain number).
    pub unit: String,
    /// A logarithmic scale (all values must be positive).
    pub log: bool,
}

impl Axis {
    pub fn new(quantity: &str, unit: &str) -> Axis {
        Axis {
            quantity: quantity.to_string(),
            unit: unit.to_string(),
            log: false,
        }
    }

    pub fn log(mut self) -> Axis {
        self.log = true;
        self
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Layer {
    /// A polyline through `points`; lines of one `group` share a colour (a curve at rest
    /// dashed beside the same curve rolling).
    Line {
        name: String,
        group: String,
        points: Vec<(f64, f64)>,
        dashed: bool,
    },
    /// A marker at each point: filled, or hollow.
    Markers {
        name: String,
        points: Vec<(f64, f64)>,
        hollow: bool,
    },
    /// A closed outline, filled lightly.
    Area {
        name: String,
        outline: Vec<(f64, f64)>,
    },
    /// A circle (drawn dashed).
    Circle {
        name: String,
        centre: (f64, f64),
        radius: f64,
    },
    /// Values on a grid, `values[j][i]` at (`x[i]`, `y[j]`), with a colour bar; drawn only
    /// inside the polygon `clip` when it has points (a pressure map inside its contact,
    /// whose edge cuts through the grid's cells).
    Heatmap {
        name: String,
        x: Vec<f64>,
        y: Vec<f64>,
        values: Vec<Vec<f64>>,
        unit: String,
        clip: Vec<(f64, f64)>,
    },
}

impl Layer {
    fn name(&self) -> &str {
        match self {
            Layer::Line { name, .. }
            | Layer::Markers { name, .. }
            | Layer::Area { name, .. }
            | Layer::Circle { name, .. }
            | Layer::Heatmap { name, .. } => name,
        }
    }

    /// The points that set the axes' ranges.
    fn extent(&self) -> Vec<(f64, f64)> {
        match self {
            Layer::Line { points, .. } | Layer::Markers { points, .. } => points.clone(),
            Layer::Area { outline, .. } => outline.clone(),
            Layer::Circle { centre, radius, .. } => vec![
                (centre.0 - radius, centre.1 - radius),
                (centre.0 + radius, centre.1 + radius),
            ],
            Layer::Heatmap { x, y, .. } => match (x.first(), x.last(), y.first(), y.last()) {
                (Some(&x0), Some(&x1), Some(&y0), Some(&y1)) => vec![(x0, y0), (x1, y1)],
                _ => Vec::new(),
            },
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    pub title: String,
    pub x: Axis,
    pub y: Axis,
    pub layers: Vec<Layer>,
    /// One unit on x as long as one on y (contact shapes).
    pub equal_aspect: bool,
    /// Lines of text under the legend (figures the picture has no axis for).
    pub notes: Vec<String>,
}

/// "Nice" tick values covering [lo, hi]: steps of 1, 2 or 5 × 10^k, about six of them.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = hi - lo;
    if span.is_nan() || span <= 0.0 || !span.is_finite() {
        return vec![lo];
    }
    let raw = span / 6.0;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| span / s <= 7.0)
        .unwrap_or(10.0 * magnitude);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

fn label(value: f64) -> String {
    if value.abs() < 1e-12 {
        return "0".to_string();
    }
    let text = format!("{}", (value * 1e6).round() / 1e6);
    if text.len() > 8 {
        format_number(value)
    } else {
        text
    }
}

/// The labels of an axis's ticks: short decimals, or, where those would not tell every tick
/// apart (ticks a millionth apart or less: a continuum μ at a slow speed read "0.000001"
/// twice), powers of ten with the digits the step needs ("1.2e-6").
fn labels(ticks: &[f64]) -> Vec<String> {
    let plain: Vec<String> = ticks.iter().map(|&t| label(t)).collect();
    if plain.windows(2).all(|w| w[0] != w[1]) {
        return plain;
    }
    let step = ticks
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    let power = |x: f64| (x.abs().log10() + 1e-9).floor();
    ticks
        .iter()
        .map(|&t| match t.abs() < step * 1e-9 {
            true => "0".to_string(),
            false => {
                let digits = (power(t) - power(step)).max(0.0) as usize;
                format!("{t:.digits$e}")
            }
        })
        .collect()
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A linear or logarithmic map from data (display units) to pixels.
struct Scale {
    lo: f64,
    hi: f64,
    from: f64,
    to: f64,
    log: bool,
}

impl Scale {
    /// The values to mark on the axis: powers of ten on a log scale, round steps else.
    fn ticks(&self) -> Vec<f64> {
        if !self.log {
            return ticks(self.lo, self.hi);
        }
        let (a, b) = (self.lo.log10().ceil(), self.hi.log10().floor());
        (a as i32..=b as i32).map(|k| 10f64.powi(k)).collect()
    }

    fn at(&self, value: f64) -> f64 {
        let (v, lo, hi) = if self.log {
            (value.max(1e-300).log10(), self.lo.log10(), self.hi.log10())
        } else {
            (value, self.lo, self.hi)
        };
        self.from + (v - lo) / (hi - lo) * (self.to - self.from)
    }
}

/// The range of `values`, padded a little (and never empty).
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let values = values.filter(|v| v.is_finite() && (!log || *v > 0.0));
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        return (lo / 1.2, hi * 1.2);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()) {
        let pad = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        return (lo - pad, hi + pad);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// Where a chart's data land on the page: each axis's scale, and the factor and prefixed unit
/// its values are shown in (nm for 1e-9 m).
struct Frame {
    sx: Scale,
    sy: Scale,
    factors: (f64, f64),
    units: (String, String),
}

impl Frame {
    /// The page position of the data point `(x, y)`.
    fn px(&self, &(x, y): &(f64, f64)) -> (f64, f64) {
        let (fx, fy) = self.factors;
        (self.sx.at(x * fx), self.sy.at(y * fy))
    }
}

/// A legend's entry: the layer's name, its colour and its mark (`line`, `dashed`,
/// `marker`, `hollow`, `area`).
type Entry<'a> = (&'a str, String, &'static str);

impl Chart {
    pub fn to_svg(&self) -> String {
        let frame = self.frame();
        let (sx, sy) = (&frame.sx, &frame.sy);
        let title = escape(&self.title);
        let mut svg = format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="13"><title>{title}</title><rect width="100%" height="100%" fill="#ffffff"/><text class="title" x="20" y="28" font-size="15" font-weight="bold">{title}</text>"##
        );
        self.write_axes(&mut svg, &frame);
        let (x, y, width, height) = (sx.from, sy.to, sx.to - sx.from, sy.from - sy.to);
        let _ = write!(
            svg,
            r#"<defs><clipPath id="plot"><rect x="{x}" y="{y}" width="{width}" height="{height}"/></clipPath></defs><g clip-path="url(#plot)">"#
        );
        let mut legend = Vec::new();
        let mut notes = self.notes.clone();
        let mut palette = Palette::new(&self.layers);
        for layer in &self.layers {
            let colour = palette.take(layer);
            legend.extend(write_layer(&mut svg, &frame, layer, colour, &mut notes));
        }
        svg.push_str("</g>");
        write_legend(&mut svg, &legend, &notes);
        svg.push_str("</svg>");
        svg
    }

    /// The axes' scales and units: ranges from the layers' extents, the plot a square
    /// when the chart keeps its aspect.
    fn frame(&self) -> Frame {
        let points: Vec<(f64, f64)> = self.layers.iter().flat_map(Layer::extent).collect();
        let largest =
            |f: fn(&(f64, f64)) -> f64| points.iter().map(f).map(f64::abs).fold(0.0, f64::max);
        let (x_factor, x_unit) = prefixed(&self.x.unit, largest(|p| p.0));
        let (y_factor, y_unit) = prefixed(&self.y.unit, largest(|p| p.1));
        let (mut x_lo, mut x_hi) = range(points.iter().map(|p| p.0 * x_factor), self.x.log);
        let (mut y_lo, mut y_hi) = range(points.iter().map(|p| p.1 * y_factor), self.y.log);
        let (mut left, mut right) = (LEFT, WIDTH - RIGHT);
        let (top, bottom) = (TOP, HEIGHT - BOTTOM);
        if self.equal_aspect {
            // Same data span per pixel on both axes: widen the narrower range.
            let per_px = ((x_hi - x_lo) / (right - left)).max((y_hi - y_lo) / (bottom - top));
            let (xc, yc) = ((x_lo + x_hi) / 2.0, (y_lo + y_hi) / 2.0);
            let width = per_px * (bottom - top);
            // A square plot, centred in the space left of the legend.
            let side = bottom - top;
            left += ((right - left) - side) / 2.0;
            right = left + side;
            (x_lo, x_hi) = (xc - width / 2.0, xc + width / 2.0);
            (y_lo, y_hi) = (yc - width / 2.0, yc + width / 2.0);
        }
        let scale = |(lo, hi), (from, to), log| Scale {
            lo,
            hi,
            from,
            to,
            log,
        };
        Frame {
            sx: scale((x_lo, x_hi), (left, right), self.x.log),
            sy: scale((y_lo, y_hi), (bottom, top), self.y.log),
            factors: (x_factor, y_factor),
            units: (x_unit, y_unit),
        }
    }

    fn write_axes(&self, svg: &mut String, frame: &Frame) {
        let (sx, sy) = (&frame.sx, &frame.sy);
        let (left, right, top, bottom) = (sx.from, sx.to, sy.to, sy.from);
        let name = |axis: &Axis, unit| escape(&with_unit(axis.quantity.replace('_', " "), unit));
        let _ = write!(
            svg,
            r##"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="#444444"/>"##,
            right - left,
            bottom - top
        );
        svg.push_str(r#"<g class="axis x">"#);
        let (tick, text) = (bottom + 5.0, bottom + 20.0);
        let ticks = sx.ticks();
        for (x, t) in ticks.iter().map(|&t| sx.at(t)).zip(labels(&ticks)) {
            let _ = write!(
                svg,
                r##"<line x1="{x:.1}" y1="{bottom}" x2="{x:.1}" y2="{tick:.1}" stroke="#444444"/><line x1="{x:.1}" y1="{top}" x2="{x:.1}" y2="{bottom}" stroke="#dddddd" stroke-width="0.5"/><text x="{x:.1}" y="{text:.1}" text-anchor="middle">{t}</text>"##
            );
        }
        let _ = write!(
            svg,
            r#"<text class="label" x="{:.1}" y="{:.1}" text-anchor="middle">{}</text></g>"#,
            (left + right) / 2.0,
            HEIGHT - 15.0,
            name(&self.x, &frame.units.0)
        );
        svg.push_str(r#"<g class="axis y">"#);
        let (tick, text) = (left - 5.0, left - 8.0);
        let ticks = sy.ticks();
        for (y, t) in ticks.iter().map(|&t| sy.at(t)).zip(labels(&ticks)) {
            let _ = write!(
                svg,
                r##"<line x1="{tick:.1}" y1="{y:.1}" x2="{left}" y2="{y:.1}" stroke="#444444"/><line x1="{left}" y1="{y:.1}" x2="{right}" y2="{y:.1}" stroke="#dddddd" stroke-width="0.5"/><text x="{text:.1}" y="{:.1}" text-anchor="end">{t}</text>"##,
                y + 4.0
            );
        }
        let (cx, cy) = (18.0, (top + bottom) / 2.0);
        let _ = write!(
            svg,
            r#"<text class="label" x="{cx}" y="{cy}" text-anchor="middle" transform="rotate(-90 {cx} {cy})">{}</text></g>"#,
            name(&self.y, &frame.units.1)
        );
    }
}

/// Draws one layer in colour `c`; returns its legend entry (a heat map has none: it adds to
/// `notes` when drawn coarser than the answer's grid).
fn write_layer<'a>(
    svg: &mut String,
    frame: &Frame,
    layer: &'a Layer,
    c: String,
    notes: &mut Vec<String>,
) -> Option<Entry<'a>> {
    let px = |p: &(f64, f64)| frame.px(p);
    let name = escape(layer.name());
    let mark = match layer {
        Layer::Line { points, dashed, .. } => {
            let dash = if *dashed { DASH } else { "" };
            let mark = if *dashed { "dashed" } else { "line" };
            let _ = write!(
                svg,
                r#"<path class="series" data-name="{name}" d="{}" fill="none" stroke="{c}" stroke-width="2"{dash}/>"#,
                path(points.iter().map(px), false)
            );
            // A line of one point (a one-point sweep) has no length: its point shows.
            if let [point] = points.as_slice() {
                let (x, y) = px(point);
                let _ = write!(
                    svg,
                    r#"<circle class="lone" cx="{x:.1}" cy="{y:.1}" r="4" fill="{c}"/>"#
                );
            }
            mark
        }
        Layer::Markers { points, hollow, .. } => {
            let fill = if *hollow { "#ffffff" } else { c.as_str() };
            let mark = if *hollow { "hollow" } else { "marker" };
            let _ = write!(svg, r#"<g class="series" data-name="{name}">"#);
            for (x, y) in points.iter().map(px) {
                let _ = write!(
                    svg,
                    r#"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="{fill}" stroke="{c}" stroke-width="1.5"/>"#
                );
            }
            svg.push_str("</g>");
            mark
        }
        Layer::Area { outline, .. } => {
            let _ = write!(
                svg,
                r#"<path class="series area" data-name="{name}" d="{}" fill="{c}" fill-opacity="0.25" stroke="{c}" stroke-width="2"/>"#,
                path(outline.iter().map(px), true)
            );
            "area"
        }
        Layer::Circle { centre, radius, .. } => {
            let (cx, cy) = px(centre);
            let r = (px(&(centre.0 + radius, centre.1)).0 - cx).abs();
            let _ = write!(
                svg,
                r#"<circle class="series" data-name="{name}" cx="{cx:.1}" cy="{cy:.1}" r="{r:.1}" fill="none" stroke="{c}" stroke-width="2"{DASH}/>"#
            );
            "dashed"
        }
        Layer::Heatmap {
            x,
            y,
            values,
            unit,
            clip,
            ..
        } => {
            let drawn = write_heatmap(svg, frame, (x, y, values), unit, clip);
            if drawn != (x.len(), y.len()) {
                let name = layer.name();
                notes.push(format!("{name} drawn on {} × {} cells", drawn.0, drawn.1));
                notes.push(format!("(the answer has {} × {})", x.len(), y.len()));
            }
            return None;
        }
    };
    Some((layer.name(), c, mark))
}

/// Draws a heatmap, only inside `clip` if it encloses anything, and its colour bar; returns
/// how many cells it drew along x and y.
fn write_heatmap(
    svg: &mut String,
    frame: &Frame,
    (x, y, values): (&[f64], &[f64], &[Vec<f64>]),
    unit: &str,
    clip: &[(f64, f64)],
) -> (usize, usize) {
    let finite = values.iter().flatten().copied().filter(|v| v.is_finite());
    let top_value = finite.fold(0.0, f64::max);
    if x.len() < 2 || y.len() < 2 || top_value <= 0.0 {
        return (x.len(), y.len());
    }
    let (factor, unit) = prefixed(unit, top_value);
    let (columns, rows, means) = coarsened((x, y, values), HEATMAP_CELLS);
    if clip.len() < 3 {
        svg.push_str(r#"<g class="heatmap">"#);
    } else {
        let _ = write!(
            svg,
            r#"<clipPath id="heatmap-clip"><path d="{}"/></clipPath><g class="heatmap" clip-path="url(#heatmap-clip)">"#,
            path(clip.iter().map(|p| frame.px(p)), true)
        );
    }
    for (&(y0, y1), row) in rows.iter().zip(&means) {
        for (&(x0, x1), &value) in columns.iter().zip(row) {
            if value <= 0.0 {
                continue;
            }
            let ((px0, py0), (px1, py1)) = (frame.px(&(x0, y1)), frame.px(&(x1, y0)));
            let _ = write!(
                svg,
                r#"<rect x="{px0:.1}" y="{py0:.1}" width="{:.2}" height="{:.2}" fill="{}"/>"#,
                (px1 - px0).abs() + 0.5,
                (py1 - py0).abs() + 0.5,
                ramp(&HEAT, value / top_value)
            );
        }
    }
    svg.push_str("</g>");
    // The colour bar, right of the plot under the legend.
    let (bx, by, height) = (WIDTH - RIGHT + 30.0, HEIGHT - BOTTOM - 180.0, 180.0);
    svg.push_str(r#"</g><g class="colourbar">"#);
    let step = height / 30.0;
    for t in (0..30).map(|k| f64::from(k) / 29.0) {
        let (y, colour) = (by + height * (1.0 - t) - step, ramp(&HEAT, t));
        let _ = write!(
            svg,
            r#"<rect x="{bx}" y="{y:.1}" width="16" height="{:.1}" fill="{colour}"/>"#,
            step + 0.5
        );
    }
    let (x, top) = (bx + 22.0, top_value * factor);
    for t in ticks(0.0, top) {
        let (y, text) = (by + height * (1.0 - t / top) + 4.0, label(t));
        let _ = write!(svg, r#"<text x="{x}" y="{y:.1}">{text}</text>"#);
    }
    let _ = write!(
        svg,
        r#"<text class="label" x="{bx}" y="{:.1}">pressure [{}]</text></g><g clip-path="url(#plot)">"#,
        by - 8.0,
        escape(&unit)
    );
    (columns.len(), rows.len())
}

/// The cells a heatmap draws at most along each axis (about 4 px each): a finer grid is drawn
/// in blocks, each the mean of its cells, as a 501 × 501 grid drew 12 MB of SVG cell by cell;
/// the answer's JSON and CSV carry every value.
pub const HEATMAP_CELLS: usize = 100;

/// Where a cell begins and ends along an axis.
type Span = (f64, f64);

/// At most `most` cells along each axis of `values[j][i]` at (x[i], y[j]): their extents and
/// the means of the fine cells they cover (one not positive, or not a number, counts as 0).
fn coarsened(
    (x, y, values): (&[f64], &[f64], &[Vec<f64>]),
    most: usize,
) -> (Vec<Span>, Vec<Span>, Vec<Vec<f64>>) {
    let columns = blocks(x, most);
    let rows = blocks(y, most);
    let value = |j: usize, i: usize| {
        let v = values.get(j).and_then(|row| row.get(i)).copied();
        v.filter(|v| *v > 0.0).unwrap_or(0.0)
    };
    let means = rows
        .iter()
        .map(|(_, js)| {
            columns
                .iter()
                .map(|(_, is)| {
                    let cells = js.clone().flat_map(|j| is.clone().map(move |i| (j, i)));
                    let sum: f64 = cells.map(|(j, i)| value(j, i)).sum();
                    sum / (js.len() * is.len()) as f64
                })
                .collect()
        })
        .collect();
    let extents = |cells: Vec<(Span, std::ops::Range<usize>)>| {
        cells.into_iter().map(|(extent, _)| extent).collect()
    };
    (extents(columns), extents(rows), means)
}

/// The points of axis `v` in at most `most` blocks of nearly equal size: each one's extent
/// (between midpoints, or the axis's ends) and its points' indices.
fn blocks(v: &[f64], most: usize) -> Vec<(Span, std::ops::Range<usize>)> {
    let count = v.len().min(most.max(1));
    let edge = |i: usize| match i {
        0 => v[0],
        i if i >= v.len() => v[v.len() - 1],
        i => (v[i - 1] + v[i]) / 2.0,
    };
    (0..count)
        .map(|k| {
            let (start, end) = (k * v.len() / count, (k + 1) * v.len() / count);
            ((edge(start), edge(end)), start..end)
        })
        .collect()
}

fn path(points: impl Iterator<Item = (f64, f64)>, closed: bool) -> String {
    let mut d = String::new();
    for (i, (x, y)) in points.enumerate() {
        let _ = write!(d, "{}{x:.2},{y:.2} ", if i == 0 { "M" } else { "L" });
    }
    if closed {
        d.push('Z');
    }
    d.trim_end().to_string()
}

/// Right of the plot, the legend (at most [`LEGEND_ROWS`] rows) and under it the notes (as
/// many as fit above the picture's foot), each cut by [`kept`].
fn write_legend(svg: &mut String, entries: &[Entry], notes: &[String]) {
    let x = WIDTH - RIGHT + 20.0;
    let entries: Vec<_> = entries.iter().filter(|e| !e.0.is_empty()).collect();
    let rows = kept(entries.len(), LEGEND_ROWS);
    let row_y = |i: usize| TOP + 10.0 + 22.0 * i as f64;
    svg.push_str(r#"<g class="legend">"#);
    for (i, (name, colour, mark)) in entries[..rows].iter().enumerate() {
        let y = row_y(i);
        let symbol = match *mark {
            "marker" | "hollow" => format!(
                r#"<circle cx="{}" cy="{y}" r="4" fill="{}" stroke="{colour}" stroke-width="1.5"/>"#,
                x + 12.0,
                if *mark == "hollow" { "#ffffff" } else { colour }
            ),
            "area" => format!(
                r#"<rect x="{x}" y="{}" width="24" height="10" fill="{colour}" fill-opacity="0.25" stroke="{colour}"/>"#,
                y - 5.0
            ),
            _ => format!(
                r#"<line x1="{x}" y1="{y}" x2="{}" y2="{y}" stroke="{colour}" stroke-width="2"{}/>"#,
                x + 24.0,
                if *mark == "dashed" { DASH } else { "" }
            ),
        };
        // Long names in a smaller type, to stay within the picture.
        let size = if name.chars().count() > 24 { 11 } else { 13 };
        let _ = write!(
            svg,
            r#"{symbol}<text class="entry" x="{}" y="{}" font-size="{size}">{}</text>"#,
            x + 32.0,
            y + 4.0,
            escape(name)
        );
    }
    let more = entries.len() - rows;
    if more > 0 {
        let y = row_y(rows) + 4.0;
        let _ = write!(
            svg,
            r#"<text class="entry" x="{x}" y="{y}">and {more} more</text>"#
        );
    }
    let mut y = row_y(rows + usize::from(more > 0)) + 10.0;
    svg.push_str(r#"</g><g class="notes">"#);
    let room = ((HEIGHT - 8.0 - y) / 18.0).floor().max(0.0) as usize + 1;
    let kept = kept(notes.len(), room);
    let more = (kept < notes.len()).then(|| format!("… {} more in the answer", notes.len() - kept));
    for note in notes[..kept].iter().chain(&more) {
        let _ = write!(
            svg,
            r#"<text x="{x}" y="{y}" font-size="11">{}</text>"#,
            escape(note)
        );
        y += 18.0;
    }
    svg.push_str("</g>");
}

/// How many of `count` rows to write in `room`: all if they fit, else one fewer, the last row
/// then saying how many more there are.
fn kept(count: usize, room: usize) -> usize {
    count.min(room.saturating_sub(usize::from(count > room)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chart of `layers` on plain axes.
    fn chart(layers: Vec<Layer>) -> Chart {
        Chart {
            title: "test".to_string(),
            x: Axis::new("x", "m"),
            y: Axis::new("y", ""),
            layers,
            equal_aspect: false,
            notes: Vec::new(),
        }
    }

    #[test]
    fn notes_beyond_the_picture_s_height_are_counted_not_drawn_off_it() {
        let chart = Chart {
            notes: (0..40).map(|i| format!("note {i}")).collect(),
            ..chart(vec![Layer::Line {
                name: "line".to_string(),
                group: "line".to_string(),
                points: vec![(0.0, 0.0), (1.0, 1.0)],
                dashed: false,
            }])
        };
        let svg = chart.to_svg();
        let notes = &svg[svg.find(r#"<g class="notes">"#).unwrap()..];
        let ys: Vec<f64> = notes
            .split(r#" y=""#)
            .skip(1)
            .map(|rest| rest[..rest.find('"').unwrap()].parse().unwrap())
            .collect();
        assert!(ys.iter().all(|&y| y <= HEIGHT - 8.0), "{ys:?}");
        let shown = ys.len() - 1;
        assert!(notes.contains(&format!("… {} more in the answer", 40 - shown)));
        assert!(notes.contains(&format!(">note {}<", shown - 1)));
    }

    #[test]
    fn past_the_palette_markers_take_their_lines_colour_and_the_rest_grey() {
        // Ten series as a fit draws them: each one's markers, then its curve; then one more
        // layer of markers that no line pairs with.
        let mut layers = Vec::new();
        for i in 0..10 {
            let name = format!("series {i}");
            let points = vec![(0.0, f64::from(i)), (1.0, f64::from(i) + 0.5)];
            layers.push(Layer::Markers {
                name: format!("{name}, measured"),
                points: points.clone(),
                hollow: false,
            });
            layers.push(Layer::Line {
                name: format!("{name}, fitted"),
                group: name,
                points,
                dashed: false,
            });
        }
        layers.push(Layer::Markers {
            name: "at rest".to_string(),
            points: vec![(0.5, 0.5)],
            hollow: false,
        });
        let svg = chart(layers).to_svg();
        let after = |name: &str, attribute: &str| {
            let at = svg.find(&format!(r#"data-name="{name}""#)).unwrap();
            let rest = &svg[at..];
            let start = rest.find(&format!(r#"{attribute}=""#)).unwrap() + attribute.len() + 2;
            rest[start..start + 7].to_string()
        };
        for i in 0..10 {
            let line = after(&format!("series {i}, fitted"), "stroke");
            assert_eq!(
                after(&format!("series {i}, measured"), "fill"),
                line,
                "series {i}"
            );
        }
        assert_eq!(after("series 0, fitted", "stroke"), "#440154");
        assert_eq!(after("series 9, fitted", "stroke"), "#fde725");
        assert_eq!(after("at rest", "fill"), "#444444");
    }

    #[test]
    fn a_heatmap_clip_of_fewer_than_three_points_clips_nothing() {
        let heatmap = |clip: Vec<(f64, f64)>| {
            Chart {
                y: Axis::new("y", "m"),
                equal_aspect: true,
                ..chart(vec![Layer::Heatmap {
                    name: "pressure".to_string(),
                    x: vec![0.0, 1.0],
                    y: vec![0.0, 1.0],
                    values: vec![vec![1.0, 2.0], vec![3.0, 4.0]],
                    unit: "Pa".to_string(),
                    clip,
                }])
            }
            .to_svg()
        };
        for clip in [vec![], vec![(0.5, 0.5)], vec![(0.0, 0.0), (1.0, 1.0)]] {
            let svg = heatmap(clip);
            assert!(svg.contains(r#"<g class="heatmap">"#) && !svg.contains("heatmap-clip"));
        }
        let svg = heatmap(vec![(0.0, 0.0), (1.0, 0.0), (0.5, 1.0)]);
        assert!(svg.contains(r#"clip-path="url(#heatmap-clip)""#));
    }

    #[test]
    fn a_fine_heatmap_is_drawn_as_blocks_that_cover_it_and_keep_its_total() {
        let x: Vec<f64> = (0..501).map(|i| f64::from(i) * 0.5).collect();
        let y: Vec<f64> = (0..37).map(|j| f64::from(j) * 2.0 - 30.0).collect();
        let value = |i: u32, j: u32| {
            if (i + j) % 7 == 0 {
                -1.0
            } else {
                f64::from(i * j)
            }
        };
        let values: Vec<Vec<f64>> = (0..37)
            .map(|j| (0..501).map(|i| value(i, j)).collect())
            .collect();
        let (columns, rows, means) = coarsened((&x, &y, &values), 100);
        assert_eq!((columns.len(), rows.len()), (100, 37), "coarse in x only");
        for (cells, axis) in [(&columns, &x), (&rows, &y)] {
            assert_eq!(cells[0].0, axis[0]);
            assert_eq!(cells[cells.len() - 1].1, axis[axis.len() - 1]);
            assert!(cells.windows(2).all(|w| w[0].1 == w[1].0), "no gaps");
        }
        // Each block is the mean of its cells, so blocks weighted by their cells' widths in
        // index space sum to the fine total (negative values count as no pressure).
        let fine: f64 = values.iter().flatten().map(|v| v.max(0.0)).sum();
        let blocks_x = blocks(&x, 100);
        let coarse: f64 = means
            .iter()
            .flat_map(|row| {
                row.iter()
                    .zip(&blocks_x)
                    .map(|(m, (_, is))| m * is.len() as f64)
            })
            .sum();
        assert!(
            (coarse / fine - 1.0).abs() < 1e-12,
            "{coarse} against {fine}"
        );
    }

    #[test]
    fn ticks_are_round_cover_the_range_and_are_labelled_apart() {
        assert_eq!(
            ticks(0.0, 1.0),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        let t = ticks(-5.6, 5.6);
        assert!(t.contains(&0.0) && t.len() >= 4 && t.len() <= 8, "{t:?}");
        // Their labels tell every tick apart.
        assert_eq!(labels(&[0.02, 0.022, 0.024]), ["0.02", "0.022", "0.024"]);
        let small = ticks(1.05e-6, 1.65e-6);
        let said = labels(&small);
        assert_eq!(said[..3], ["1.1e-6", "1.2e-6", "1.3e-6"]);
        assert!(said.windows(2).all(|w| w[0] != w[1]), "{said:?}");
        assert_eq!(labels(&[0.0, 2e-7, 4e-7]), ["0", "2e-7", "4e-7"]);
    }
}
