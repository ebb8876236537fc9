//! The pictures of `kiln-bench`: charts of GPU time against error, and a small web page of them.
//!
//! `kiln-bench` renders each rendering technique of a scene at several quality settings and
//! measures every run as a point: its GPU time (x, milliseconds) and its error against a
//! path-traced reference (y, mean HDR-FLIP). This crate draws those points:
//!
//! - [`svg`] and [`png`] draw a [`Chart`]: every point with its label, one colour and marker per
//!   series (technique) with a legend, the [Pareto front](pareto_front) as a step line (for a
//!   GPU budget x, the least error any measured setting reaches within it), and the reference's
//!   own noise as a shaded band at the bottom. Both go through `plotters`; PNG text is drawn with
//!   an embedded font (DejaVu Sans, see `plot/fonts/`), so no system font or fontconfig is needed.
//! - [`index_html`] writes a self-contained page (inline CSS, no scripts, nothing fetched over the
//!   network) that shows each section's SVG chart and its table of measurements.
//!
//! # Axes
//!
//! The x axis is logarithmic when the largest x is more than 20 times the smallest, linear
//! otherwise. The y axis is linear from 0, unless every y is above 0 and the largest is more than
//! 100 times the smallest: then it is logarithmic too (a linear axis would squash the good
//! settings against 0), and the noise floor band starts at the axis bottom.
//!
//! # Degenerate input
//!
//! Nothing here panics on odd data. Points with a non-finite coordinate, an `x <= 0` or a
//! `y < 0` are left out of the chart and a subtitle line says how many and which; a non-finite or
//! negative noise floor is left out the same way. A chart without (drawable) points says
//! "no points". One point, equal x values and `y = 0` get a sensible range around them.

#![deny(missing_docs)]

mod axis;
mod crisp;
mod draw;
mod html;

pub use html::index_html;

/// One chart: the points of one comparison (e.g. the shadow techniques of one scene).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Chart {
    /// The title, e.g. "shadows: pica_pica 1600x900, H100".
    pub title: String,
    /// Lines under the title, e.g. "fixed: gbuffer raster, ao none, reflections none".
    pub subtitle: Vec<String>,
    /// The x axis' caption, e.g. "GPU ms (frames x ms per frame)".
    pub x_label: String,
    /// The y axis' caption, e.g. "mean HDR-FLIP vs reference".
    pub y_label: String,
    /// The measurements.
    pub points: Vec<ChartPoint>,
    /// The reference's own error: drawn as a shaded band from the axis bottom up to this y,
    /// labelled "reference noise floor".
    pub noise_floor: Option<f64>,
}

/// One measurement in a [`Chart`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChartPoint {
    /// A short label drawn next to the point, e.g. "rt 16f" or "shadowmap".
    pub label: String,
    /// The technique: one colour and marker per series, and a legend entry.
    pub series: String,
    /// GPU time; must be finite and above 0 to be drawn.
    pub x: f64,
    /// Error; must be finite and at least 0 to be drawn.
    pub y: f64,
}

/// Why a chart could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The requested picture is too small to hold a chart.
    #[error("a chart needs at least {min_width}x{min_height} pixels, not {width}x{height}")]
    TooSmall {
        /// The requested width.
        width: u32,
        /// The requested height.
        height: u32,
        /// The smallest width drawn.
        min_width: u32,
        /// The smallest height drawn.
        min_height: u32,
    },
    /// The embedded font could not be loaded.
    #[error("the embedded font does not load")]
    Font,
    /// Drawing failed in `plotters`.
    #[error("drawing the chart failed: {0}")]
    Draw(String),
    /// Encoding the PNG failed.
    #[error("encoding the PNG failed: {0}")]
    Encode(String),
}

/// The smallest picture [`png`] draws: below it there is no room for axes and labels.
pub const MIN_SIZE: (u32, u32) = (240, 180);

/// The size of the [`svg`] canvas (an SVG scales; this sets the proportions and text size).
pub const SVG_SIZE: (u32, u32) = (1000, 700);

/// Indices of the Pareto-optimal points, sorted by x (ties, which are duplicates, by index).
///
/// A point is Pareto-optimal when no other point has `x <=` and `y <=` with one of the two
/// strictly less: so duplicates of an optimal point are all optimal. Points with a NaN
/// coordinate are ignored: they are never on the front and dominate nothing. Infinities compare
/// as usual.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> =
        (0..points.len()).filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan()).collect();
    // Lexicographic by (x, y): every point that dominates p comes before p's group of duplicates.
    order.sort_by(|&a, &b| {
        let (pa, pb) = (points[a], points[b]);
        pa.0.total_cmp(&pb.0).then(pa.1.total_cmp(&pb.1)).then(a.cmp(&b))
    });
    let mut front = Vec::new();
    // The least y among the points strictly before the current group of duplicates.
    let mut best = f64::INFINITY;
    let mut i = 0;
    while i < order.len() {
        let p = points[order[i]];
        let mut j = i;
        while j < order.len() && points[order[j]] == p {
            j += 1;
        }
        // p is dominated exactly when an earlier (so x <=, and not equal) point has y <= p.y.
        // (`best` is infinite before the first group, and p.y may be infinite too.)
        if i == 0 || p.1 < best {
            front.extend_from_slice(&order[i..j]);
        }
        best = best.min(p.1);
        i = j;
    }
    front
}

/// The chart as an SVG document ([`SVG_SIZE`] user units; text as `<text>` elements in the
/// viewer's sans-serif font).
pub fn svg(chart: &Chart) -> Result<String, PlotError> {
    draw::svg(chart)
}

/// The chart as encoded PNG bytes of `width` x `height` pixels (1000x700 reads well), its text
/// drawn with the embedded DejaVu Sans. Smaller than [`MIN_SIZE`] is an error.
pub fn png(chart: &Chart, width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    draw::png(chart, width, height)
}

/// A web page of charts: see [`index_html`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Page {
    /// The page's title and top heading.
    pub title: String,
    /// Paragraphs under the title (machine, versions, how to read the charts).
    pub notes: Vec<String>,
    /// One chart and table each.
    pub sections: Vec<Section>,
}

/// One chart of a [`Page`], with its table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Section {
    /// The section's heading.
    pub heading: String,
    /// The SVG chart's path, relative to the page (it is shown with `<img>`).
    pub svg_file: String,
    /// The PNG chart's path, relative to the page (linked).
    pub png_file: String,
    /// The measurements.
    pub table: Table,
}

/// A table of a [`Section`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// Column headings.
    pub headers: Vec<String>,
    /// Cells, row by row.
    pub rows: Vec<Vec<String>>,
    /// One per row: whether it is on the Pareto front (the row is highlighted). Missing entries
    /// count as false.
    pub highlight: Vec<bool>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_of_a_small_set() {
        let pts = [(1.0, 5.0), (2.0, 3.0), (2.0, 4.0), (3.0, 3.0), (4.0, 1.0), (1.0, 5.0), (0.5, 9.0)];
        assert_eq!(pareto_front(&pts), vec![6, 0, 5, 1, 4]);
        assert_eq!(pareto_front(&[]), Vec::<usize>::new());
        assert_eq!(pareto_front(&[(f64::NAN, 1.0), (1.0, 1.0)]), vec![1]);
    }
}
