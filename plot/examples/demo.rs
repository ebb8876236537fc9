//! Writes an example page from made-up points to /tmp/kiln-plot-demo/ (index.html, chart.svg,
//! chart.png), to look at: `cargo run -p kiln-plot --example demo`.

use kiln_plot::{Chart, ChartPoint, Page, Section, Table, index_html, pareto_front, png, svg};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let made_up = [
        ("shadowmap", "shadowmap", 0.42, 0.061),
        ("shadowmap 4k", "shadowmap", 0.95, 0.048),
        ("pcss", "pcss", 1.3, 0.040),
        ("pcss 32 taps", "pcss", 2.6, 0.036),
        ("rt 1f", "rt", 0.8, 0.052),
        ("rt 4f", "rt", 3.1, 0.027),
        ("rt 16f", "rt", 12.4, 0.016),
        ("rt 64f", "rt", 49.8, 0.0112),
        ("rt 256f", "rt", 198.0, 0.0101),
        ("rt 8spp 16f", "rt", 60.0, 0.0125),
    ];
    let points: Vec<ChartPoint> = made_up
        .iter()
        .map(|&(label, series, x, y)| ChartPoint { label: label.into(), series: series.into(), x, y })
        .collect();
    let chart = Chart {
        title: "shadows: pica_pica 1600x900, H100 (made-up numbers)".into(),
        subtitle: vec!["fixed: gbuffer raster, ao none, reflections none, aa accumulate".into()],
        x_label: "GPU ms (frames x ms per frame)".into(),
        y_label: "mean HDR-FLIP vs reference".into(),
        points,
        noise_floor: Some(0.0085),
    };
    let dir = std::path::Path::new("/tmp/kiln-plot-demo");
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("chart.svg"), svg(&chart)?)?;
    std::fs::write(dir.join("chart.png"), png(&chart, 1000, 700)?)?;

    let xy: Vec<(f64, f64)> = chart.points.iter().map(|p| (p.x, p.y)).collect();
    let front = pareto_front(&xy);
    let table = Table {
        headers: vec!["technique".into(), "setting".into(), "GPU ms".into(), "mean HDR-FLIP".into()],
        rows: chart
            .points
            .iter()
            .map(|p| vec![p.series.clone(), p.label.clone(), format!("{:.2}", p.x), format!("{:.4}", p.y)])
            .collect(),
        highlight: (0..chart.points.len()).map(|i| front.contains(&i)).collect(),
    };
    let page = Page {
        title: "kiln-bench: made-up example".into(),
        notes: vec![
            "Every number here is invented; the page shows what kiln-bench's report looks like.".into(),
        ],
        sections: vec![Section {
            heading: chart.title.clone(),
            svg_file: "chart.svg".into(),
            png_file: "chart.png".into(),
            table,
        }],
    };
    std::fs::write(dir.join("index.html"), index_html(&page))?;
    println!("wrote {}", dir.display());
    Ok(())
}
