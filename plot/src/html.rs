//! The web page: see [`index_html`].

use std::fmt::Write;

use crate::Page;

/// A self-contained HTML page of the charts: the title, the notes, and per section its heading,
/// its SVG chart (an `<img>`, with links to the SVG and the PNG) and its table, the rows on the
/// Pareto front highlighted. Inline CSS, no scripts, nothing from the network; all text is
/// HTML-escaped and the file paths are percent-encoded (they are relative URLs).
pub fn index_html(page: &Page) -> String {
    let mut h = String::new();
    let title = escape(&page.title);
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    h.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    let _ = writeln!(h, "<title>{title}</title>");
    h.push_str(CSS);
    let _ = writeln!(h, "</head>\n<body>\n<h1>{title}</h1>");
    for note in &page.notes {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(note));
    }
    for (n, s) in page.sections.iter().enumerate() {
        let heading = escape(&s.heading);
        let svg = escape(&url_path(&s.svg_file));
        let png = escape(&url_path(&s.png_file));
        let _ = writeln!(h, "<section id=\"s{n}\">\n<h2>{heading}</h2>");
        let _ = writeln!(
            h,
            "<img class=\"chart\" src=\"{svg}\" width=\"{}\" height=\"{}\" alt=\"chart: {heading}\">",
            crate::SVG_SIZE.0,
            crate::SVG_SIZE.1
        );
        let _ = writeln!(
            h,
            "<p class=\"files\"><a href=\"{svg}\">SVG</a> &middot; <a href=\"{png}\">PNG</a></p>"
        );
        let t = &s.table;
        if !t.headers.is_empty() || !t.rows.is_empty() {
            h.push_str("<table>\n<thead><tr>");
            for c in &t.headers {
                let _ = write!(h, "<th>{}</th>", escape(c));
            }
            h.push_str("</tr></thead>\n<tbody>\n");
            for (i, row) in t.rows.iter().enumerate() {
                let front = t.highlight.get(i).copied().unwrap_or(false);
                h.push_str(if front { "<tr class=\"front\">" } else { "<tr>" });
                for c in row {
                    let num = c.trim().parse::<f64>().is_ok();
                    let _ = write!(h, "<td{}>{}</td>", if num { " class=\"num\"" } else { "" }, escape(c));
                }
                h.push_str("</tr>\n");
            }
            h.push_str("</tbody>\n</table>\n");
            if t.highlight.iter().any(|&b| b) {
                h.push_str("<p class=\"key\"><span class=\"swatch\"></span> on the Pareto front</p>\n");
            }
        }
        h.push_str("</section>\n");
    }
    h.push_str("</body>\n</html>\n");
    h
}

const CSS: &str = "<style>
body { font-family: system-ui, sans-serif; margin: 24px; color: #1e1e1e; background: #fff; max-width: 1100px; }
h1 { font-size: 1.6em; margin: 0 0 8px; }
h2 { font-size: 1.25em; margin: 32px 0 8px; }
p.note { margin: 4px 0; color: #444; }
img.chart { display: block; max-width: 100%; height: auto; border: 1px solid #ddd; }
p.files { margin: 4px 0 12px; font-size: 0.9em; }
table { border-collapse: collapse; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: left; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.front td { background: #fff3c4; font-weight: 600; }
p.key { font-size: 0.85em; color: #444; }
span.swatch { display: inline-block; width: 1em; height: 0.8em; background: #fff3c4; border: 1px solid #ccc; }
</style>
";

/// Text for HTML content and attribute values.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A relative file path as a URL path: every byte but unreserved ones and `/` percent-encoded.
fn url_path(p: &str) -> String {
    let mut out = String::with_capacity(p.len());
    for b in p.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            out.push(b as char);
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn paths() {
        assert_eq!(super::url_path("a b/c#1.svg"), "a%20b/c%231.svg");
        assert_eq!(super::url_path("é"), "%C3%A9");
    }
}
