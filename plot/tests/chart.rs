//! The charts: the Pareto front against a brute-force definition, the SVG's structure read back
//! with an XML parser, the PNG decoded and compared with where the SVG put the points, and
//! degenerate input.

use kiln_plot::{Chart, ChartPoint, pareto_front, png, svg};
use proptest::prelude::*;

/// The definition, O(n²): i is on the front unless another point has x <= and y <= with one
/// strictly less. Points with a NaN are left out (documented: they are never on the front).
fn brute_front(pts: &[(f64, f64)]) -> Vec<usize> {
    let ok = |p: (f64, f64)| !p.0.is_nan() && !p.1.is_nan();
    let mut front: Vec<usize> = (0..pts.len())
        .filter(|&i| ok(pts[i]))
        .filter(|&i| {
            let p = pts[i];
            !pts.iter().any(|&q| ok(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect();
    front.sort_by(|&a, &b| pts[a].0.partial_cmp(&pts[b].0).unwrap().then(a.cmp(&b)));
    front
}

fn coord() -> impl Strategy<Value = f64> {
    // Few distinct values, so that ties and duplicates are common, and now and then a NaN or an
    // infinity.
    prop_oneof![
        20 => (0u8..6).prop_map(f64::from),
        3 => 0.0..10.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn front_matches_the_definition(pts in prop::collection::vec((coord(), coord()), 0..24)) {
        prop_assert_eq!(pareto_front(&pts), brute_front(&pts));
    }
}

fn point(label: &str, series: &str, x: f64, y: f64) -> ChartPoint {
    ChartPoint { label: label.into(), series: series.into(), x, y }
}

fn chart(points: Vec<ChartPoint>, noise_floor: Option<f64>) -> Chart {
    Chart {
        title: "shadows: test scene 1600x900, <GPU> & \"co\"".into(),
        subtitle: vec!["fixed: gbuffer raster, ao none".into()],
        x_label: "GPU ms".into(),
        y_label: "mean HDR-FLIP vs reference".into(),
        points,
        noise_floor,
    }
}

fn sample() -> Vec<ChartPoint> {
    vec![
        point("shadowmap", "raster", 0.5, 0.06),
        point("pcss", "raster", 1.5, 0.04),
        point("pcss slow", "raster", 3.0, 0.05),
        point("rt 1f", "rt", 1.0, 0.05),
        point("rt 16f", "rt", 16.0, 0.015),
        point("rt <64f> & more", "rt", 64.0, 0.011),
        point("rt 64f again", "rt", 80.0, 0.02),
    ]
}

/// All text content of the SVG's `<text>` elements.
fn texts(doc: &roxmltree::Document) -> Vec<String> {
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

fn polylines(doc: &roxmltree::Document) -> Vec<Vec<(f64, f64)>> {
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .map(|n| {
            n.attribute("points")
                .unwrap_or("")
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}

/// Shaded rectangles: neither opaque nor invisible, not white, wider than a marker.
fn bands(doc: &roxmltree::Document) -> usize {
    doc.descendants()
        .filter(|n| n.has_tag_name("rect"))
        .filter(|n| {
            let op: f64 = n.attribute("opacity").unwrap_or("1").parse().unwrap();
            let w: f64 = n.attribute("width").unwrap_or("0").parse().unwrap();
            let h: f64 = n.attribute("height").unwrap_or("0").parse().unwrap();
            op > 0.0 && op < 1.0 && n.attribute("fill") != Some("#FFFFFF") && w > 200.0 && h > 0.0
        })
        .count()
}

#[test]
fn svg_has_labels_title_front_and_band() {
    let c = chart(sample(), Some(0.008));
    let s = svg(&c).unwrap();
    let doc = roxmltree::Document::parse(&s).expect("the SVG is well-formed XML");
    let t = texts(&doc);
    for p in &c.points {
        assert!(t.contains(&p.label), "label {:?} missing from {t:?}", p.label);
    }
    assert!(t.contains(&c.title), "title missing");
    assert!(t.contains(&c.subtitle[0]), "subtitle missing");
    assert!(t.iter().any(|x| x == "reference noise floor"), "band's legend entry missing");
    assert_eq!(bands(&doc), 1, "one noise floor band");

    // The front: exactly one polyline of more than two vertices, a staircase of 2m vertices for m
    // front points (m - 1 drops and a last step to the right edge), x never decreasing and y
    // (downwards in SVG) never going up, alternately horizontal and vertical.
    let xy: Vec<(f64, f64)> = c.points.iter().map(|p| (p.x, p.y)).collect();
    let m = brute_front(&xy).len();
    assert_eq!(m, 5);
    let stairs: Vec<_> = polylines(&doc).into_iter().filter(|l| l.len() > 2).collect();
    assert_eq!(stairs.len(), 1, "one step line: {stairs:?}");
    let l = &stairs[0];
    assert_eq!(l.len(), 2 * m, "{l:?}");
    for (k, w) in l.windows(2).enumerate() {
        assert!(w[1].0 >= w[0].0 && w[1].1 >= w[0].1, "not a descending staircase: {l:?}");
        let horizontal = w[0].1 == w[1].1;
        let vertical = w[0].0 == w[1].0;
        assert!(if k % 2 == 0 { horizontal && !vertical } else { vertical && !horizontal }, "{l:?}");
    }

    // Without a noise floor: no band, no legend entry.
    let doc2 = svg(&chart(sample(), None)).unwrap();
    let doc2 = roxmltree::Document::parse(&doc2).unwrap();
    assert_eq!(bands(&doc2), 0);
    assert!(!texts(&doc2).iter().any(|x| x == "reference noise floor"));
}

fn decode(bytes: &[u8]) -> image::RgbImage {
    image::load_from_memory_with_format(bytes, image::ImageFormat::Png).expect("a PNG").to_rgb8()
}

#[test]
fn png_decodes_at_its_size_with_points_and_text() {
    // One series, so that every SVG <circle> is a point (or its legend entry).
    let pts: Vec<ChartPoint> =
        sample().into_iter().map(|p| ChartPoint { series: "one".into(), ..p }).collect();
    let c = chart(pts, Some(0.008));
    let img = decode(&png(&c, 1000, 700).unwrap());
    assert_eq!(img.dimensions(), (1000, 700));
    let bg = *img.get_pixel(999, 699);
    assert_eq!(bg, image::Rgb([255, 255, 255]), "the corner is background");

    // At 1000x700 the PNG's layout is the SVG's: where the SVG has a marker, the PNG has its
    // colour.
    let s = svg(&c).unwrap();
    let doc = roxmltree::Document::parse(&s).unwrap();
    let circles: Vec<(u32, u32, String)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("circle") && n.attribute("fill").is_some_and(|f| f != "none"))
        .map(|n| {
            (
                n.attribute("cx").unwrap().parse().unwrap(),
                n.attribute("cy").unwrap().parse().unwrap(),
                n.attribute("fill").unwrap().to_string(),
            )
        })
        .collect();
    assert_eq!(circles.len(), c.points.len() + 1, "one per point and the legend's: {circles:?}");
    for (x, y, fill) in &circles {
        let want = u32::from_str_radix(fill.trim_start_matches('#'), 16).unwrap();
        let want = [(want >> 16) as u8, (want >> 8) as u8, want as u8];
        let got = img.get_pixel(*x, *y).0;
        let d: i32 = (0..3).map(|i| (got[i] as i32 - want[i] as i32).abs()).sum();
        assert!(d < 30, "pixel at ({x}, {y}) is {got:?}, the marker is {want:?}");
    }

    // The title is drawn: dark pixels in its band at the top left.
    let dark = (0..500)
        .flat_map(|x| (10..45).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 100)
        .count();
    assert!(dark > 300, "only {dark} dark pixels where the title is");

    // Another size.
    let small = decode(&png(&c, 640, 480).unwrap());
    assert_eq!(small.dimensions(), (640, 480));
    assert!(png(&c, 20, 10).is_err(), "too small is an error, not a panic");
}

#[test]
fn degenerate_input_draws() {
    let cases: Vec<(&str, Vec<ChartPoint>)> = vec![
        ("none", vec![]),
        ("one", vec![point("only", "a", 2.0, 0.1)]),
        ("equal x", vec![point("a", "a", 2.0, 0.1), point("b", "b", 2.0, 0.2), point("c", "b", 2.0, 0.2)]),
        ("y zero", vec![point("a", "a", 1.0, 0.0), point("b", "a", 3.0, 0.0)]),
        ("huge span", vec![point("a", "a", 1e-6, 1e-9), point("b", "a", 1e6, 5.0)]),
        (
            "bad values",
            vec![
                point("nan", "a", f64::NAN, 0.1),
                point("inf", "a", 1.0, f64::INFINITY),
                point("neg", "a", -1.0, 0.1),
                point("good", "a", 1.0, 0.1),
            ],
        ),
    ];
    for (name, pts) in cases {
        for floor in [None, Some(0.05), Some(0.0), Some(f64::NAN)] {
            let c = chart(pts.clone(), floor);
            let s = svg(&c).unwrap_or_else(|e| panic!("{name}: {e}"));
            let doc = roxmltree::Document::parse(&s).unwrap_or_else(|e| panic!("{name}: {e}"));
            let t = texts(&doc);
            let img = decode(&png(&c, 1000, 700).unwrap_or_else(|e| panic!("{name}: {e}")));
            assert_eq!(img.dimensions(), (1000, 700));
            match name {
                "none" => assert!(t.iter().any(|x| x == "no points"), "{t:?}"),
                "bad values" => {
                    assert!(t.iter().any(|x| x.starts_with("left out 3 points")), "{t:?}");
                    assert!(t.contains(&"good".to_string()));
                }
                _ => {
                    for p in &c.points {
                        assert!(t.contains(&p.label), "{name}: {:?} missing", p.label);
                    }
                }
            }
            if floor.is_some_and(f64::is_nan) {
                assert!(t.iter().any(|x| x.starts_with("left out the noise floor")), "{t:?}");
            }
        }
    }
}
