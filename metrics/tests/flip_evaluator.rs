//! kiln-metrics' FLIP against `flip_evaluator`, NVIDIA's own implementation (PyPI
//! `flip-evaluator`, the C++ `FLIP.h` behind a Python binding): the mean HDR-FLIP and LDR-FLIP
//! of synthetic image pairs must agree to [`TOLERANCE`].
//!
//! The pairs are built here, deterministically, to exercise the parts of FLIP: a smooth HDR
//! gradient with highlights against Monte Carlo-like noise (with fireflies), a blur of sharp
//! edges, an edge pattern shifted by a pixel, very dark content, a hue shift; sizes are
//! non-square and differ from pair to pair. They go to `metrics/tests/reference_flip.py` as
//! `.npy` files; the expected numbers come only from there.
//!
//! Needs a Python with `flip_evaluator` and `numpy`: the virtual environment `.venv-mitsuba` at
//! the workspace root (the one the Mitsuba comparison uses), or the interpreter
//! `KILN_MITSUBA_PYTHON` names. Without either the test says why and passes, unless
//! `KILN_REQUIRE_MITSUBA` is set (as `.ci/run` does), when it fails.

use std::path::PathBuf;
use std::process::Command;

use kiln_metrics::{RgbImage, hdr_flip, ldr_flip};
use kiln_test_support::{flip_python, require, workspace, write_npy};

/// Largest allowed difference of the mean FLIP from flip_evaluator's. kiln-bench needs 1e-3;
/// the port agrees to about 1e-6 (both work in f32 with the same filters and order of
/// summation), and 1e-3 let real bugs through: a blue-yellow CSF amplitude of 30 instead of 34.1
/// moved the means by at most 5e-4, zero padding at the left border by at most 1.4e-3.
const TOLERANCE: f64 = 1e-5;

/// xorshift64: deterministic noise in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// An image from a function of (u, v) in [0, 1)².
fn image(w: u32, h: u32, mut f: impl FnMut(f32, f32) -> [f32; 3]) -> Vec<f32> {
    let mut out = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            out.extend(f(x as f32 / w as f32, y as f32 / h as f32));
        }
    }
    out
}

/// A smooth, coloured HDR gradient with two bright highlights (up to about 60).
fn hdr_scene(u: f32, v: f32) -> [f32; 3] {
    let spot = |cu: f32, cv: f32, s: f32| (-((u - cu).powi(2) + (v - cv).powi(2)) / s).exp();
    let highlight = 60.0 * spot(0.7, 0.3, 0.002) + 8.0 * spot(0.2, 0.75, 0.01);
    [0.05 + 0.9 * u + highlight, 0.1 + 0.6 * v + 0.9 * highlight, 0.4 * (1.0 - u) * v + 0.7 * highlight]
}

/// Sharp-edged HDR content: coloured checkers with a bright bar.
fn edges(u: f32, v: f32, w: u32, h: u32) -> [f32; 3] {
    let (x, y) = ((u * w as f32) as u32, (v * h as f32) as u32);
    let checker = ((x / 8) + (y / 8)) % 2 == 0;
    let bar = (x / 3) % 7 == 0 && y > h / 3;
    let base = if checker { [0.8, 0.3, 0.1] } else { [0.05, 0.2, 0.6] };
    if bar { [12.0, 11.0, 9.0] } else { base }
}

/// A 3x3 box blur, edges clamped.
fn blur(w: u32, h: u32, src: &[f32]) -> Vec<f32> {
    let (w, h) = (w as i64, h as i64);
    let mut out = vec![0.0; src.len()];
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0.0;
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (xx, yy) = ((x + dx).clamp(0, w - 1), (y + dy).clamp(0, h - 1));
                        sum += src[((yy * w + xx) * 3 + c) as usize];
                    }
                }
                out[((y * w + x) * 3 + c) as usize] = sum / 9.0;
            }
        }
    }
    out
}

/// Monte Carlo-like noise: each pixel scaled by a random factor of mean about 1, with rare
/// fireflies.
fn noisy(src: &[f32], rng: &mut Rng, amount: f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(src.len());
    for p in src.chunks_exact(3) {
        let firefly = if rng.next() < 0.003 { 30.0 } else { 0.0 };
        let scale = 1.0 + amount * (2.0 * rng.next() - 1.0);
        out.extend(p.iter().map(|&v| v * scale + firefly * v.max(0.05)));
    }
    out
}

struct Pair {
    name: &'static str,
    hdr: bool,
    width: u32,
    height: u32,
    reference: Vec<f32>,
    test: Vec<f32>,
}

fn pairs() -> Vec<Pair> {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut pairs = Vec::new();
    let mut add = |name, hdr, width, height, reference, test| {
        pairs.push(Pair { name, hdr, width, height, reference, test })
    };

    let (w, h) = (160, 120);
    let r = image(w, h, hdr_scene);
    add("hdr noise", true, w, h, r.clone(), noisy(&r, &mut rng, 0.5));

    let (w, h) = (128, 96);
    let r = image(w, h, |u, v| edges(u, v, w, h));
    add("hdr blur", true, w, h, r.clone(), blur(w, h, &r));

    let (w, h) = (96, 64);
    let r = image(w, h, |u, v| edges(u, v, w, h));
    let shifted = image(w, h, |u, v| edges((u - 1.0 / w as f32).max(0.0), v, w, h));
    add("hdr shifted edges", true, w, h, r, shifted);

    let (w, h) = (120, 80);
    let r = image(w, h, |u, v| hdr_scene(u, v).map(|c| 1e-3 * c));
    add("hdr very dark", true, w, h, r.clone(), noisy(&r, &mut rng, 0.8));

    let (w, h) = (72, 136);
    let r = image(w, h, hdr_scene);
    let hue = image(w, h, |u, v| {
        let [r, g, b] = hdr_scene(u, v);
        [g, 0.9 * b + 0.1 * r, r]
    });
    add("hdr tall hue shift", true, w, h, r, hue);

    let (w, h) = (100, 70);
    let r = image(w, h, |u, v| hdr_scene(u, v).map(|c| (0.3 * c).min(1.0)));
    add("ldr noise", false, w, h, r.clone(), noisy(&r, &mut rng, 0.3).iter().map(|v| v.min(1.0)).collect());

    let (w, h) = (90, 110);
    let r = image(w, h, |u, v| edges(u, v, w, h).map(|c| c.min(1.0)));
    add("ldr blur", false, w, h, r.clone(), blur(w, h, &r));

    // Values above 1 in the test image: both implementations clamp LDR input to [0, 1].
    let (w, h) = (64, 48);
    let r = image(w, h, |u, v| [u, v, 0.5 * (u + v)]);
    add("ldr clamped", false, w, h, r.clone(), r.iter().map(|v| 1.6 * v).collect());
    pairs
}

#[test]
fn mean_flip_agrees_with_flip_evaluator() {
    let python = require!(flip_python());
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("kiln-metrics-flip");
    std::fs::create_dir_all(&dir).unwrap();
    let pairs = pairs();
    let mut args = Vec::new();
    for (i, p) in pairs.iter().enumerate() {
        let (r, t) = (dir.join(format!("{i}-reference.npy")), dir.join(format!("{i}-test.npy")));
        write_npy(&r, p.width, p.height, &p.reference);
        write_npy(&t, p.width, p.height, &p.test);
        args.extend([(if p.hdr { "HDR" } else { "LDR" }).into(), r.into_os_string(), t.into_os_string()]);
    }
    let script = workspace().join("metrics/tests/reference_flip.py");
    let out = Command::new(&python).arg(&script).args(&args).output().expect("running Python");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "reference_flip.py: {}\n{stdout}{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let expected: Vec<f64> = stdout.lines().map(|l| l.trim().parse().expect("a mean per line")).collect();
    assert_eq!(expected.len(), pairs.len(), "{stdout}");

    let mut failures = Vec::new();
    println!("{:<20} {:>9} {:>10} {:>10} {:>9}", "pair", "size", "flip-eval", "kiln", "diff");
    for (p, &want) in pairs.iter().zip(&expected) {
        let r = RgbImage { width: p.width, height: p.height, pixels: &p.reference };
        let t = RgbImage { width: p.width, height: p.height, pixels: &p.test };
        let got = if p.hdr { hdr_flip(r, t) } else { ldr_flip(r, t) }.unwrap();
        let diff = got - want;
        println!(
            "{:<20} {:>9} {want:>10.6} {got:>10.6} {diff:>9.1e}",
            p.name,
            format!("{}x{}", p.width, p.height)
        );
        // The pairs must be far from trivial for the comparison to mean something.
        assert!(want > 0.01, "{}: flip_evaluator's mean {want} is too small to test with", p.name);
        if !(diff.abs() <= TOLERANCE) {
            failures.push(format!("{}: kiln {got}, flip_evaluator {want}", p.name));
        }
    }
    assert!(failures.is_empty(), "mean FLIP differs by more than {TOLERANCE}:\n{}", failures.join("\n"));
}
