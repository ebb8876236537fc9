//! Time of `hdr_flip` on render-sized image pairs: a smooth HDR image with highlights against a
//! noisy copy of it (the kind of pair kiln-bench compares).

use criterion::{Criterion, criterion_group, criterion_main};
use kiln_metrics::{RgbImage, hdr_flip};

/// A deterministic HDR "render" and a noisy version: xorshift noise, no dependencies.
fn pair(w: u32, h: u32) -> (Vec<f32>, Vec<f32>) {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut reference = Vec::with_capacity((w * h * 3) as usize);
    let mut test = Vec::with_capacity(reference.capacity());
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
            let highlight = 40.0 * (-((u - 0.7).powi(2) + (v - 0.3).powi(2)) * 200.0).exp();
            let base = [0.05 + 0.8 * u, 0.1 + 0.5 * v, 0.3 * (1.0 - u)];
            for c in base {
                let r = c + highlight;
                reference.push(r);
                test.push(r * (0.6 + 0.8 * rand()));
            }
        }
    }
    (reference, test)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("hdr_flip");
    group.sample_size(10);
    for (w, h) in [(1600, 900), (800, 600)] {
        let (r, t) = pair(w, h);
        group.bench_function(format!("{w}x{h}"), |b| {
            b.iter(|| {
                hdr_flip(
                    RgbImage { width: w, height: h, pixels: &r },
                    RgbImage { width: w, height: h, pixels: &t },
                )
                .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
