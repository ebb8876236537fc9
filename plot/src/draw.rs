//! Drawing a [`Chart`] with plotters, the same code for the SVG and the bitmap backend.

use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::axis::Axis;
use crate::{Chart, ChartPoint, MIN_SIZE, PlotError, SVG_SIZE, pareto_front};

/// DejaVu Sans 2.37 (Bitstream Vera licence, see `plot/fonts/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

/// The font family the chart's text asks for: the embedded font is registered under it for the
/// bitmap backend, and SVG viewers use their own sans-serif.
const FAMILY: &str = "sans-serif";

/// Registers the embedded font with plotters once (text layout needs it for SVG too).
fn font() -> Result<(), PlotError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        let normal = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok();
        normal && plotters::style::register_font(FAMILY, FontStyle::Bold, FONT).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Series colours (Okabe-Ito, readable by the colour-blind, yellow left out: it vanishes on
/// white), then Tableau's.
const PALETTE: [RGBColor; 10] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
    RGBColor(140, 86, 75),
    RGBColor(188, 189, 34),
    RGBColor(127, 127, 127),
];
/// The Pareto front's step line.
const FRONT: RGBColor = RGBColor(60, 60, 60);
/// The noise floor band (drawn at [`BAND_OPACITY`]).
pub(crate) const BAND: RGBColor = RGBColor(150, 150, 150);
const BAND_OPACITY: f64 = 0.3;
const TEXT: RGBColor = RGBColor(30, 30, 30);
const SUBTLE: RGBColor = RGBColor(90, 90, 90);

pub(crate) fn svg(chart: &Chart) -> Result<String, PlotError> {
    font()?;
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, SVG_SIZE).into_drawing_area();
        draw(&root, chart, 1.0)?;
        root.present().map_err(draw_error)?;
    }
    Ok(out)
}

pub(crate) fn png(chart: &Chart, width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    if width < MIN_SIZE.0 || height < MIN_SIZE.1 || width > 1 << 14 || height > 1 << 14 {
        return Err(PlotError::TooSmall { width, height, min_width: MIN_SIZE.0, min_height: MIN_SIZE.1 });
    }
    font()?;
    let mut rgb = vec![255u8; width as usize * height as usize * 3];
    {
        let font = ab_glyph::FontRef::try_from_slice(FONT).map_err(|_| PlotError::Font)?;
        let backend = crate::crisp::Crisp::new(BitMapBackend::with_buffer(&mut rgb, (width, height)), font);
        let root = backend.into_drawing_area();
        let scale = (width as f64 / SVG_SIZE.0 as f64).min(height as f64 / SVG_SIZE.1 as f64).clamp(0.5, 4.0);
        draw(&root, chart, scale)?;
        root.present().map_err(draw_error)?;
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &rgb,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| PlotError::Encode(e.to_string()))?;
    Ok(bytes)
}

fn draw_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// What is drawn, after leaving out what cannot be.
struct Prepared<'a> {
    points: Vec<&'a ChartPoint>,
    /// Subtitle lines about what was left out.
    notes: Vec<String>,
    floor: Option<f64>,
    /// Series names in order of first appearance.
    series: Vec<&'a str>,
    /// Indices into `points`, by x.
    front: Vec<usize>,
    x: Axis,
    y: Axis,
}

fn prepare(chart: &Chart) -> Prepared<'_> {
    let (points, skipped): (Vec<&ChartPoint>, Vec<&ChartPoint>) =
        chart.points.iter().partition(|p| p.x.is_finite() && p.x > 0.0 && p.y.is_finite() && p.y >= 0.0);
    let mut notes = Vec::new();
    if !skipped.is_empty() {
        let mut names: Vec<String> =
            skipped.iter().take(4).map(|p| format!("{} ({}, {})", p.label, p.x, p.y)).collect();
        if skipped.len() > 4 {
            names.push("...".into());
        }
        notes.push(format!(
            "left out {} point{} with a non-finite or out-of-range value: {}",
            skipped.len(),
            if skipped.len() == 1 { "" } else { "s" },
            names.join(", ")
        ));
    }
    let floor = match chart.noise_floor {
        Some(f) if f.is_finite() && f >= 0.0 => Some(f),
        Some(f) => {
            notes.push(format!("left out the noise floor {f}: not finite or negative"));
            None
        }
        None => None,
    };
    let mut series: Vec<&str> = Vec::new();
    for p in &points {
        if !series.contains(&p.series.as_str()) {
            series.push(&p.series);
        }
    }
    let xy: Vec<(f64, f64)> = points.iter().map(|p| (p.x, p.y)).collect();
    let front = pareto_front(&xy);

    let (x, y) = if points.is_empty() {
        (Axis::linear(0.0, 1.0), Axis::linear(0.0, floor.map_or(1.0, |f| f * 2.0).max(f64::MIN_POSITIVE)))
    } else {
        let (xmin, xmax) = min_max(xy.iter().map(|p| p.0));
        let (ymin, ymax) = min_max(xy.iter().map(|p| p.1));
        let x = if xmax / xmin > 20.0 {
            // Room on both sides for markers and labels: a twelfth of the span each side.
            let m = (xmax / xmin).powf(1.0 / 12.0);
            Axis::log(xmin / m, xmax * m)
        } else if xmax > xmin {
            let pad = (xmax - xmin) / 12.0;
            Axis::linear((xmin - pad).max(0.0), xmax + pad)
        } else {
            Axis::linear(xmin * 0.8, xmin * 1.2)
        };
        let y = if ymin > 0.0 && ymax / ymin > 100.0 {
            let lo = floor.filter(|f| *f > 0.0).map_or(ymin, |f| f.min(ymin));
            let m = (ymax / lo).powf(1.0 / 10.0);
            Axis::log(lo / m, ymax * m * m)
        } else {
            let top = ymax.max(floor.unwrap_or(0.0));
            // Room above the highest point for its label and for the legend (a row per series,
            // the front and the band, about 4% of the plot's height each), so that the legend
            // covers no point.
            let rows = series.len() + 1 + usize::from(floor.is_some());
            let free = (0.08 + 0.04 * rows as f64).min(0.6);
            Axis::linear(0.0, if top > 0.0 { top / (1.0 - free) } else { 1.0 })
        };
        (x, y)
    };
    Prepared { points, notes, floor, series, front, x, y }
}

fn min_max(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)))
}

fn style(size: f64, color: RGBColor) -> TextStyle<'static> {
    let mut st = TextStyle::from((FAMILY, size).into_font());
    st.color = color.to_backend_color();
    st
}

/// The text style at the largest size up to `size` (and down to 60% of it) at which `text` fits
/// into `width` pixels, so that long titles shrink instead of running off the picture.
fn fitting<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    width: f64,
    color: RGBColor,
) -> TextStyle<'static> {
    let mut s = size;
    while s > size * 0.6 {
        match area.estimate_text_size(text, &style(s, color)) {
            Ok((w, _)) if (w as f64) > width => s *= 0.93,
            _ => break,
        }
    }
    style(s, color)
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart, s: f64) -> Result<(), PlotError>
where
    DB::ErrorType: 'static,
{
    let p = prepare(chart);
    root.fill(&WHITE).map_err(draw_error)?;
    let (width, _) = root.dim_in_pixel();
    let margin = 16.0 * s;
    let usable = width as f64 - 2.0 * margin;

    // The title and subtitle lines.
    let mut y = margin;
    let title_size = 24.0 * s;
    let title = fitting(root, &chart.title, title_size, usable, TEXT);
    root.draw_text(&chart.title, &title, (margin as i32, y as i32)).map_err(draw_error)?;
    y += title_size * 1.15;
    let sub_size = 15.0 * s;
    for line in chart.subtitle.iter().chain(&p.notes) {
        let st = fitting(root, line, sub_size, usable, SUBTLE);
        root.draw_text(line, &st, (margin as i32, y as i32)).map_err(draw_error)?;
        y += sub_size * 1.3;
    }
    let body = root.split_vertically((y + 6.0 * s) as i32).1;

    let mut cc = ChartBuilder::on(&body)
        .margin_left((margin * 0.5) as i32)
        .margin_right(margin as i32)
        .margin_bottom((margin * 0.5) as i32)
        .margin_top((6.0 * s) as i32)
        .x_label_area_size((52.0 * s) as i32)
        .y_label_area_size((78.0 * s) as i32)
        .build_cartesian_2d(p.x, p.y)
        .map_err(draw_error)?;
    let x_desc = format!("{}{}", chart.x_label, if p.x.log { " (log scale)" } else { "" });
    let y_desc = format!("{}{}", chart.y_label, if p.y.log { " (log scale)" } else { "" });
    cc.configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(10)
        .y_labels(8)
        .label_style(style(14.0 * s, TEXT))
        .axis_desc_style(style(16.0 * s, TEXT))
        .bold_line_style(RGBColor(215, 215, 215))
        .light_line_style(RGBColor(240, 240, 240))
        .axis_style(RGBColor(80, 80, 80))
        .draw()
        .map_err(draw_error)?;

    let line_w = (1.5 * s).round().max(1.0) as u32;
    // The noise floor band, under everything else.
    if let Some(floor) = p.floor {
        let band = BAND.mix(BAND_OPACITY).filled();
        let top = floor.min(p.y.hi);
        cc.draw_series(std::iter::once(Rectangle::new([(p.x.lo, p.y.lo), (p.x.hi, top)], band)))
            .map_err(draw_error)?
            .label("reference noise floor")
            .legend(move |(x, y)| Rectangle::new([(x - 9, y - 6), (x + 9, y + 6)], band));
    }

    // The Pareto front as a step line: for a budget x, the least error within it, continued to
    // the right edge.
    let steps = front_steps(&p);
    if !steps.is_empty() {
        let front_style = FRONT.mix(0.75).stroke_width((2.0 * s).round().max(1.0) as u32);
        cc.draw_series(LineSeries::new(steps.iter().copied(), front_style))
            .map_err(draw_error)?
            .label("Pareto front")
            .legend(move |(x, y)| PathElement::new([(x - 10, y), (x + 10, y)], front_style));
    }

    // The points, a series at a time.
    let r = (5.0 * s).round().max(2.0) as i32;
    for (k, name) in p.series.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let marker = Marker::ALL[(k / PALETTE.len() + k) % Marker::ALL.len()];
        let pts: Vec<(f64, f64)> =
            p.points.iter().filter(|q| q.series == *name).map(|q| (q.x, q.y)).collect();
        cc.draw_series(pts.iter().map(|&c| EmptyElement::at(c) + marker.element(r, color, line_w)))
            .map_err(draw_error)?
            .label(*name)
            .legend(move |c| EmptyElement::at(c) + marker.element(r, color, line_w));
    }

    // Where the legend goes: the upper corner with fewer points under it.
    let legend_size = (14.0 * s, p.series.len() + usize::from(p.floor.is_some()) + 1);
    let legend_w = std::iter::once("reference noise floor")
        .chain(p.series.iter().copied())
        .filter_map(|t| body.estimate_text_size(t, &style(legend_size.0, TEXT)).ok())
        .map(|(w, _)| w as f64)
        .fold(0.0, f64::max)
        + 50.0 * s;
    let legend_h = legend_size.1 as f64 * (legend_size.0 * 1.45) + 16.0 * s;
    let (px, py) = cc.plotting_area().get_pixel_range();
    let in_box = |x0: f64, x1: f64| {
        p.points
            .iter()
            .filter(|q| {
                let c = cc.backend_coord(&(q.x, q.y));
                (c.0 as f64) >= x0 && (c.0 as f64) <= x1 && (c.1 as f64) <= py.start as f64 + legend_h + 10.0
            })
            .count()
    };
    let right = in_box(px.end as f64 - legend_w - 10.0, px.end as f64);
    let left = in_box(px.start as f64, px.start as f64 + legend_w + 10.0);
    let (legend_pos, legend_box) = if left < right {
        (
            SeriesLabelPosition::UpperLeft,
            Rect::new(px.start as f64, py.start as f64, legend_w + 10.0, legend_h + 10.0),
        )
    } else {
        (
            SeriesLabelPosition::UpperRight,
            Rect::new(px.end as f64 - legend_w - 10.0, py.start as f64, legend_w + 10.0, legend_h + 10.0),
        )
    };

    // The labels, each where it overlaps the least with markers, other labels and the legend.
    let label_style = style(13.0 * s, TEXT);
    let centres: Vec<(i32, i32)> = p.points.iter().map(|q| cc.backend_coord(&(q.x, q.y))).collect();
    let mut taken: Vec<Rect> = centres
        .iter()
        .map(|c| {
            Rect::new((c.0 - r - 1) as f64, (c.1 - r - 1) as f64, (2 * r + 2) as f64, (2 * r + 2) as f64)
        })
        .collect();
    taken.push(legend_box);
    // The front's step line: horizontal and vertical segments, a few pixels thick.
    for seg in steps.windows(2) {
        let (a, b) = (cc.backend_coord(&seg[0]), cc.backend_coord(&seg[1]));
        let (x0, x1) = (a.0.min(b.0) as f64 - 2.0, a.0.max(b.0) as f64 + 2.0);
        let (y0, y1) = (a.1.min(b.1) as f64 - 2.0, a.1.max(b.1) as f64 + 2.0);
        taken.push(Rect::new(x0, y0, x1 - x0, y1 - y0));
    }
    let area =
        Rect::new(px.start as f64, py.start as f64, (px.end - px.start) as f64, (py.end - py.start) as f64);
    // Place labels left to right, the front's first (they matter most).
    let mut order: Vec<usize> = (0..p.points.len()).collect();
    order.sort_by(|&a, &b| {
        let fa = !p.front.contains(&a);
        let fb = !p.front.contains(&b);
        fa.cmp(&fb).then(p.points[a].x.total_cmp(&p.points[b].x))
    });
    for i in order {
        let q = p.points[i];
        if q.label.is_empty() {
            continue;
        }
        let (w, h) =
            body.estimate_text_size(&q.label, &label_style).unwrap_or((q.label.len() as u32 * 7, 13));
        let (w, h) = (w as f64, h as f64);
        let c = (centres[i].0 as f64, centres[i].1 as f64);
        let g = r as f64 + 3.0 * s;
        let candidates = [
            (g, -h / 2.0),
            (g, -h - 2.0),
            (g, 2.0),
            (-g - w, -h / 2.0),
            (-g - w, -h - 2.0),
            (-g - w, 2.0),
            (-w / 2.0, -h - g),
            (-w / 2.0, g),
            (g, -2.0 * h - 2.0),
            (g, h + 2.0),
            (-g - w, -2.0 * h - 2.0),
            (-g - w, h + 2.0),
        ];
        let mut best = (f64::INFINITY, candidates[0]);
        for (n, d) in candidates.iter().enumerate() {
            let rect = Rect::new(c.0 + d.0, c.1 + d.1, w, h);
            let overlap: f64 = taken.iter().map(|t| t.overlap(&rect)).sum();
            let outside = w * h - area.overlap(&rect);
            let score = overlap + 4.0 * outside + n as f64 * 0.01;
            if score < best.0 {
                best = (score, *d);
            }
        }
        let d = best.1;
        taken.push(Rect::new(c.0 + d.0, c.1 + d.1, w, h));
        let st = label_style.pos(Pos::new(HPos::Left, VPos::Top));
        cc.plotting_area()
            .draw(&(EmptyElement::at((q.x, q.y)) + Text::new(q.label.clone(), (d.0 as i32, d.1 as i32), st)))
            .map_err(draw_error)?;
    }

    if p.points.is_empty() {
        let st = style(28.0 * s, SUBTLE).pos(Pos::new(HPos::Center, VPos::Center));
        let c = ((px.start + px.end) / 2, (py.start + py.end) / 2);
        body.draw_text("no points", &st, (c.0 - body.get_base_pixel().0, c.1 - body.get_base_pixel().1))
            .map_err(draw_error)?;
    }

    if !p.series.is_empty() || p.floor.is_some() {
        cc.configure_series_labels()
            .position(legend_pos)
            .margin((8.0 * s) as i32)
            .legend_area_size((24.0 * s) as i32)
            .label_font(style(legend_size.0, TEXT))
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(170, 170, 170))
            .draw()
            .map_err(draw_error)?;
    }
    Ok(())
}

/// The Pareto front as a step line: for a budget x, the least error within it, continued to the
/// right edge. Empty without points.
fn front_steps(p: &Prepared) -> Vec<(f64, f64)> {
    let mut steps = Vec::new();
    for (k, &i) in p.front.iter().enumerate() {
        let pt = p.points[i];
        if k > 0 {
            steps.push((pt.x, p.points[p.front[k - 1]].y));
        }
        steps.push((pt.x, pt.y));
    }
    // Duplicated front points make zero-length steps: leave them out.
    steps.dedup();
    if let Some(&last) = steps.last() {
        steps.push((p.x.hi, last.1));
    }
    steps
}

/// An axis-aligned rectangle in pixels.
#[derive(Debug, Clone, Copy)]
struct Rect {
    x: f64,
    y: f64,
    w: f64,
    h: f64,
}

impl Rect {
    fn new(x: f64, y: f64, w: f64, h: f64) -> Rect {
        Rect { x, y, w, h }
    }

    fn overlap(&self, o: &Rect) -> f64 {
        let w = (self.x + self.w).min(o.x + o.w) - self.x.max(o.x);
        let h = (self.y + self.h).min(o.y + o.h) - self.y.max(o.y);
        w.max(0.0) * h.max(0.0)
    }
}

/// The marker shapes, one per series (cycling after the colours do).
#[derive(Debug, Clone, Copy)]
enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
    Ring,
    Cross,
}

impl Marker {
    const ALL: [Marker; 6] =
        [Marker::Circle, Marker::Square, Marker::Triangle, Marker::Diamond, Marker::Ring, Marker::Cross];

    /// The marker as a polygon or circle around (0, 0), `r` pixels in radius.
    fn element(self, r: i32, color: RGBColor, line: u32) -> MarkerElement {
        MarkerElement { marker: self, r, color, line }
    }
}

/// A drawn [`Marker`].
struct MarkerElement {
    marker: Marker,
    r: i32,
    color: RGBColor,
    line: u32,
}

impl<'a> PointCollection<'a, (i32, i32)> for &'a MarkerElement {
    type Point = &'a (i32, i32);
    type IntoIter = std::iter::Once<&'a (i32, i32)>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&(0, 0))
    }
}

impl<DB: DrawingBackend> Drawable<DB> for MarkerElement {
    fn draw<I: Iterator<Item = (i32, i32)>>(
        &self,
        mut pos: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), plotters_backend::DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = pos.next() else { return Ok(()) };
        let r = self.r;
        let fill = self.color.filled();
        let stroke = self.color.stroke_width(self.line);
        let ring = WHITE.stroke_width(1);
        match self.marker {
            Marker::Circle => {
                backend.draw_circle((x, y), r as u32, &fill, true)?;
                backend.draw_circle((x, y), r as u32, &ring, false)
            }
            Marker::Ring => {
                backend.draw_circle((x, y), r as u32, &WHITE.filled(), true)?;
                backend.draw_circle((x, y), r as u32, &stroke, false)
            }
            Marker::Square => {
                let a = r * 9 / 10;
                backend.draw_rect((x - a, y - a), (x + a, y + a), &fill, true)
            }
            Marker::Triangle => {
                let h = r + r / 4;
                backend.fill_polygon(vec![(x, y - h), (x + h, y + h * 3 / 4), (x - h, y + h * 3 / 4)], &fill)
            }
            Marker::Diamond => {
                let h = r + r / 4;
                backend.fill_polygon(vec![(x, y - h), (x + h, y), (x, y + h), (x - h, y)], &fill)
            }
            Marker::Cross => {
                backend.draw_line((x - r, y - r), (x + r, y + r), &stroke)?;
                backend.draw_line((x - r, y + r), (x + r, y - r), &stroke)
            }
        }
    }
}
