//! The web page: escaping, and the page as a browser shows it (headless Chromium takes a
//! screenshot; without Chromium the test says so and passes, unless `KILN_REQUIRE_CHROMIUM` is
//! set, as `.ci/run` sets it).

use kiln_plot::{Chart, ChartPoint, Page, Section, Table, index_html, png, svg};
use kiln_test_support::{chromium, require, screenshot};

const HOSTILE: &str = "<script>alert('x')</script> & \"quoted\" <b>";

fn page(heading: &str, cell: &str) -> Page {
    Page {
        title: format!("bench {heading}"),
        notes: vec![format!("note {cell}")],
        sections: vec![
            Section {
                heading: heading.into(),
                svg_file: "first.svg".into(),
                png_file: "first.png".into(),
                table: Table {
                    headers: vec!["technique".into(), cell.into()],
                    rows: vec![vec!["rt".into(), cell.into()], vec!["raster".into(), "0.5".into()]],
                    highlight: vec![true, false],
                },
            },
            Section {
                heading: "second".into(),
                svg_file: "second.svg".into(),
                png_file: "second.png".into(),
                table: Table::default(),
            },
        ],
    }
}

#[test]
fn text_is_escaped() {
    let h = index_html(&page(HOSTILE, HOSTILE));
    assert!(!h.contains("<script"), "{h}");
    assert!(!h.contains("<b>"), "{h}");
    assert!(!h.contains("\"quoted\""), "{h}");
    assert!(!h.contains("'x'"), "{h}");
    assert!(
        h.contains("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;quoted&quot; &lt;b&gt;"),
        "{h}"
    );
    // Every occurrence is escaped: title, heading, alt text, note, header and cell.
    assert_eq!(h.matches("&lt;script&gt;").count(), 7, "{h}");
    // The charts and the highlight are there.
    assert!(h.contains("<img class=\"chart\" src=\"first.svg\""), "{h}");
    assert!(h.contains("<img class=\"chart\" src=\"second.svg\""), "{h}");
    assert!(h.contains("href=\"first.png\""), "{h}");
    assert_eq!(h.matches("<tr class=\"front\">").count(), 1, "{h}");
    assert!(!h.contains("http"), "nothing from the network: {h}");
}

#[test]
fn browser_shows_the_charts() {
    let chromium = require!(chromium());
    let dir = tempfile::tempdir().unwrap();
    let chart = Chart {
        title: "shadows: browser test".into(),
        subtitle: vec!["fixed: nothing".into()],
        x_label: "GPU ms".into(),
        y_label: "mean HDR-FLIP".into(),
        points: vec![
            ChartPoint { label: "a".into(), series: "s".into(), x: 1.0, y: 0.05 },
            ChartPoint { label: "b".into(), series: "t".into(), x: 4.0, y: 0.02 },
        ],
        noise_floor: Some(0.01),
    };
    for name in ["first", "second"] {
        std::fs::write(dir.path().join(format!("{name}.svg")), svg(&chart).unwrap()).unwrap();
        std::fs::write(dir.path().join(format!("{name}.png")), png(&chart, 1000, 700).unwrap()).unwrap();
    }
    let html = dir.path().join("index.html");
    std::fs::write(&html, index_html(&page("first chart", "0.25"))).unwrap();
    let profile = dir.path().join("profile");

    let with = screenshot(&chromium, &html, &profile);
    assert_eq!(with.dimensions(), (1200, 1600), "the screenshot has the window's size");
    std::fs::remove_file(dir.path().join("first.svg")).unwrap();
    let without = screenshot(&chromium, &html, &profile);
    assert_eq!(without.dimensions(), (1200, 1600));

    // The first chart is 1000x700 below the title, the note and the first heading (together well
    // under 250 pixels): rows 250..750, columns 60..960 lie inside it.
    let region = || (60..960).flat_map(|x| (250..750).map(move |y| (x, y)));
    let first = *with.get_pixel(60, 250);
    let varied = region().filter(|&(x, y)| *with.get_pixel(x, y) != first).count();
    let differ = region().filter(|&(x, y)| with.get_pixel(x, y) != without.get_pixel(x, y)).count();
    let total = region().count();
    assert!(varied * 100 > total, "the chart region is (nearly) uniform: {varied} of {total} pixels vary");
    assert!(differ * 100 > total, "the SVG makes no difference: {differ} of {total} pixels differ");
    // And only the chart's SVG was missing: the page above it is the same.
    let above = (0..1200).flat_map(|x| (0..60).map(move |y| (x, y)));
    assert!(above.clone().all(|(x, y)| with.get_pixel(x, y) == without.get_pixel(x, y)));
    // Something (the title) is drawn above.
    assert!(above.filter(|&(x, y)| with.get_pixel(x, y).0[0] < 128).count() > 100, "no title");
}
