//! Human-readable formatting helpers shared by commands.

/// Bytes as a short human-readable size (binary units).
pub fn size(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 { format!("{bytes} B") } else { format!("{v:.1} {}", UNITS[u]) }
}

/// Writes JSON to stdout, pretty-printed, with a final newline.
pub fn print_json(value: &impl serde::Serialize) {
    match serde_json::to_string_pretty(value) {
        Ok(s) => println!("{s}"),
        // Our report types contain only strings, numbers, bools and sequences.
        Err(e) => unreachable!("report serialisation failed: {e}"),
    }
}
