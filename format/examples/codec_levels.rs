//! Measures zstd on every section of a `.kiln` file at several levels: stored bytes and
//! compression / decompression time per section kind. Used to pick `codec::ZSTD_LEVEL` and
//! what `--codec auto` compresses (docs/testing.md "zstd level and default kinds").
//!
//! `cargo run --release -p kiln-format --example codec_levels -- FILE.kiln [LEVEL...]`

use std::collections::BTreeMap;
use std::time::Instant;

use kiln_format::{Checksums, KilnFile};

/// Per level: stored bytes, seconds compressing, seconds decompressing.
type PerLevel = Vec<(u64, f64, f64)>;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: codec_levels FILE.kiln [LEVEL...]");
        std::process::exit(2);
    };
    let levels: Vec<i32> = if args.len() > 1 {
        args[1..].iter().map(|l| l.parse().expect("a level is an integer")).collect()
    } else {
        vec![1, 3, 9, 19]
    };
    let file = KilnFile::open(std::path::Path::new(path), Checksums::Eager).expect("a valid file");
    // kind -> (raw bytes, per level: (stored bytes, compress s, decompress s))
    let mut by_kind: BTreeMap<String, (u64, PerLevel)> = BTreeMap::new();
    for s in file.sections() {
        let raw = file.section_bytes(s).expect("readable section");
        let e = by_kind.entry(s.entry.kind.name()).or_insert_with(|| (0, vec![(0, 0.0, 0.0); levels.len()]));
        e.0 += raw.len() as u64;
        for (i, &level) in levels.iter().enumerate() {
            let t = Instant::now();
            let frame = zstd::bulk::compress(&raw, level).expect("compress");
            let c = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let back = zstd::bulk::decompress(&frame, raw.len()).expect("decompress");
            let d = t.elapsed().as_secs_f64();
            assert_eq!(&back[..], &raw[..]);
            e.1[i].0 += (frame.len() as u64).min(raw.len() as u64);
            e.1[i].1 += c;
            e.1[i].2 += d;
        }
    }
    print!("{:<6} {:>12}", "kind", "raw");
    for l in &levels {
        print!(" {:>12} {:>8} {:>8}", format!("L{l} bytes"), "comp s", "dec s");
    }
    println!();
    let mut total = (0u64, vec![(0u64, 0.0f64, 0.0f64); levels.len()]);
    for (kind, (raw, per)) in &by_kind {
        print!("{kind:<6} {raw:>12}");
        for (i, (b, c, d)) in per.iter().enumerate() {
            print!(" {b:>12} {c:>8.3} {d:>8.3}");
            total.1[i].0 += b;
            total.1[i].1 += c;
            total.1[i].2 += d;
        }
        total.0 += raw;
        println!();
    }
    print!("{:<6} {:>12}", "total", total.0);
    for (b, c, d) in &total.1 {
        print!(" {b:>12} {c:>8.3} {d:>8.3}");
    }
    println!();
}
