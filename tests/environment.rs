//! The environment bake against closed forms and brute force: the map's direction mapping and
//! rotation, a constant environment baked to the constant, the irradiance harmonics of a linear
//! environment (exact in band 1), the prefiltered levels against the GGX lobe integral summed over
//! the map, the sampling table's density (integral, χ² against the map's luminance), importance
//! sampling of a small sun against uniform sampling, Preetham's sky against the published
//! formula, and bad environment images refused or warned.
//!
//! Every expected value is computed with this file's own arithmetic from FORMAT.md
//! ("Environment"): the mapping, the shared-exponent decoding, the cells' layout and the alias
//! draw are written out here, not taken from `kiln_format::environment`.

use glam::Vec3;
use kiln_compiler::ir::{EnvironmentImage, Scene};
use kiln_compiler::settings::Settings;
use kiln_format::sections;
use kiln_format::{Checksums, KilnFile};
use kiln_tests::equirect::{direction, image, texels};
use kiln_tests::{compile, scene_of};

use std::f64::consts::PI;

/// Settings for a quick compile: no line space, no probes.
fn settings(res: u32) -> Settings {
    Settings {
        shaft_variants: Some(0),
        probes: kiln_compiler::settings::Probes::Off,
        environment_res: res,
        ..Default::default()
    }
}

/// E5B9G9R9 as the Vulkan specification decodes it.
fn rgb9e5(t: u32) -> [f64; 3] {
    let scale = 2f64.powi((t >> 27) as i32 - 24);
    [(t & 511) as f64 * scale, ((t >> 9) & 511) as f64 * scale, ((t >> 18) & 511) as f64 * scale]
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A floor quad lit only by `env`.
fn scene(env: EnvironmentImage) -> Scene {
    let mut s = scene_of(&[
        [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(-1.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0)],
        [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(1.0, 0.0, -1.0)],
    ]);
    s.environment = Some(env);
    s
}

/// The baked environment as FORMAT.md lays it out.
struct Baked {
    map: [u32; 2],
    filtered: [u32; 4],
    table: [u32; 2],
    sh: Vec<[f64; 3]>,
    texels: Vec<u32>,
    levels: Vec<u32>,
    /// (keep, alias, density, alias density) per cell.
    cells: Vec<(f32, u32, f32, f32)>,
    sky: [f32; 3],
}

fn words(b: &[u8]) -> Vec<u32> {
    b.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect()
}

fn bake(env: EnvironmentImage, res: u32) -> Baked {
    let bytes = compile(scene(env), settings(res));
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let read = |k| file.section_bytes(file.find(k, 0).expect("section present")).unwrap().into_owned();
    let h = words(&read(sections::ENVIRONMENT_HEADER));
    assert_eq!(h.len(), 48, "the header is 192 bytes");
    let sh = (0..9).map(|k| std::array::from_fn(|c| f32::from_bits(h[12 + 4 * k + c]) as f64)).collect();
    let cells = words(&read(sections::ENVIRONMENT_TABLE))
        .chunks_exact(4)
        .map(|c| (f32::from_bits(c[0]), c[1], f32::from_bits(c[2]), f32::from_bits(c[3])))
        .collect();
    Baked {
        map: [h[0], h[1]],
        filtered: [h[4], h[5], h[6], h[7]],
        table: [h[8], h[9]],
        sh,
        texels: words(&read(sections::ENVIRONMENT_MAP)),
        levels: words(&read(sections::ENVIRONMENT_FILTERED)),
        cells,
        sky: file.manifest().unwrap().sky.radiance,
    }
}

impl Baked {
    /// The map texel holding direction (u, v).
    fn texel(&self, u: f64, v: f64) -> [f64; 3] {
        let [w, h] = self.map;
        let x = ((u * w as f64) as u32).min(w - 1);
        let y = ((v * h as f64) as u32).min(h - 1);
        rgb9e5(self.texels[(y * w + x) as usize])
    }

    /// Prefiltered level `i`: width, height and texels (FORMAT.md: max(w0 >> i, 2) wide).
    fn level(&self, i: u32) -> (u32, u32, &[u32]) {
        let ext = |l: u32| ((self.filtered[0] >> l).max(2), (self.filtered[0] >> l).max(2) / 2);
        let first: u32 = (0..i).map(|l| ext(l).0 * ext(l).1).sum();
        let (w, h) = ext(i);
        (w, h, &self.levels[first as usize..(first + w * h) as usize])
    }

    /// Irradiance over π at unit normal n from the nine coefficients (real SH, bands 0–2).
    fn irradiance(&self, n: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = n;
        let basis = [
            0.282_094_8,
            0.488_602_5 * y,
            0.488_602_5 * z,
            0.488_602_5 * x,
            1.092_548_4 * x * y,
            1.092_548_4 * y * z,
            0.315_391_57 * (3.0 * z * z - 1.0),
            1.092_548_4 * x * z,
            0.546_274_2 * (x * x - y * y),
        ];
        std::array::from_fn(|c| self.sh.iter().zip(basis).map(|(k, b)| k[c] * b).sum())
    }

    /// Solid-angle density of direction d: its cell's density over sin θ.
    fn pdf(&self, d: [f64; 3]) -> f64 {
        let [w, h] = self.table;
        let u = d[0].atan2(-d[2]) / (2.0 * PI);
        let u = u - u.floor();
        let v = d[1].clamp(-1.0, 1.0).acos() / PI;
        let x = ((u * w as f64) as u32).min(w - 1);
        let y = ((v * h as f64) as u32).min(h - 1);
        let s = (1.0 - d[1] * d[1]).max(0.0).sqrt();
        if s > 0.0 { self.cells[(y * w + x) as usize].2 as f64 / s } else { 0.0 }
    }

    /// A direction drawn from the table by Walker's method with uniforms (a, b, c), and its
    /// density.
    fn draw(&self, a: f64, b: f64, c: f64) -> ([f64; 3], f64) {
        let [w, h] = self.table;
        let n = (w * h) as f64;
        let mut cell = ((a * n) as u32).min(w * h - 1);
        let e = self.cells[cell as usize];
        let mut density = e.2;
        if a * n - cell as f64 >= e.0 as f64 {
            cell = e.1;
            density = e.3;
        }
        let (u, v) = (((cell % w) as f64 + b) / w as f64, ((cell / w) as f64 + c) / h as f64);
        let s = (PI * v).sin();
        (direction(u, v), if s > 0.0 { density as f64 / s } else { 0.0 })
    }
}

/// xorshift64*: a small, seeded generator for the Monte Carlo checks.
struct Rng(u64);

impl Rng {
    fn f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn a_constant_environment_bakes_to_the_constant_to_the_last_bit() {
    // 0.75 = 384 · 2⁻⁹ is exact in E5B9G9R9: every texel of the map and of every level decodes
    // to it exactly; the harmonics give it at any normal to quadrature accuracy.
    let b = bake(image(64, |_| [0.75; 3]), 64);
    assert_eq!(b.map, [64, 32]);
    for (i, &t) in b.texels.iter().chain(&b.levels).enumerate() {
        assert_eq!(rgb9e5(t), [0.75; 3], "texel {i}");
    }
    for n in [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.6, 0.0, -0.8]] {
        for c in b.irradiance(n) {
            assert!((c - 0.75).abs() < 1e-4, "irradiance / pi at {n:?}: {c}");
        }
    }
    assert!(b.sky.iter().all(|&s| (s - 0.75).abs() < 1e-6), "the manifest's sky is the mean: {:?}", b.sky);
}

#[test]
fn the_map_follows_the_mapping_and_the_rotation() {
    // Each colour channel a different function of the direction: a flipped latitude, a mirrored
    // or shifted longitude each change some texel by far more than the encoding's 0.2 %.
    let f = |d: [f64; 3]| [1.0 + d[1], 1.0 + d[0], 1.0 - d[2]];
    let b = bake(image(128, f), 128);
    let [w, h] = b.map;
    for (x, y) in [(0, 0), (5, 3), (31, 20), (64, 32), (100, 60), (127, 63)] {
        let d = direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
        let got = rgb9e5(b.texels[(y * w + x) as usize]);
        // E5B9G9R9 shares one exponent: each channel within 1/256 of the largest.
        let top = f(d).into_iter().fold(0.0, f64::max);
        for c in 0..3 {
            assert!(
                (got[c] - f(d)[c]).abs() < 4e-3 * top,
                "texel ({x}, {y}) channel {c}: {got:?} vs {:?}",
                f(d)
            );
        }
    }
    // Rotated by 90° about +y (right-hand rule: what lay along −z now lies along −x): the texel
    // at u sees the source at u + 1/4.
    let mut env = image(128, f);
    env.rotation_degrees = 90.0;
    let r = bake(env, 128);
    for (x, y) in [(10, 10), (70, 40), (120, 5)] {
        let d = direction((x as f64 + 0.5) / w as f64 + 0.25, (y as f64 + 0.5) / h as f64);
        let got = rgb9e5(r.texels[(y * w + x) as usize]);
        let top = f(d).into_iter().fold(0.0, f64::max);
        for c in 0..3 {
            assert!((got[c] - f(d)[c]).abs() < 4e-3 * top, "rotated texel ({x}, {y}): {got:?} vs {:?}", f(d));
        }
    }
}

#[test]
fn the_harmonics_of_a_linear_environment_are_exact() {
    // L(d) = a + b·d: E(n)/π = a + (2/3) b·n in closed form (band 1 carries it all).
    let (a, bv) = (0.5, [0.2, 0.4, -0.1]);
    let b = bake(image(128, |d| [a + dot(bv, d), a + 0.5 * dot(bv, d), a]), 128);
    for n in [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.6, 0.8], [-0.48, 0.6, -0.64]] {
        let want = [a + 2.0 / 3.0 * dot(bv, n), a + 1.0 / 3.0 * dot(bv, n), a];
        let got = b.irradiance(n);
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() < 2e-3, "E/pi at {n:?}: {got:?} vs {want:?}");
        }
    }
}

#[test]
fn the_prefiltered_levels_are_the_ggx_lobe_integral() {
    // A bright lobe around `axis` over a dim floor: each level's texel against
    // ∫ L(l) D(h) (n·l)⁺ dl / ∫ D(h) (n·l)⁺ dl summed over every texel of the baked map.
    let axis = {
        let v = [0.3, 0.8, -0.52];
        let n = dot(v, v).sqrt();
        v.map(|c| c / n)
    };
    let b = bake(image(256, |d| [0.1 + 5.0 * dot(d, axis).max(0.0).powi(8); 3]), 256);
    let [w, h] = b.map;
    let texels: Vec<([f64; 3], f64, f64)> =
        texels(w, h).map(|(x, y, d, dw)| (d, rgb9e5(b.texels[(y * w + x) as usize])[0], dw)).collect();
    assert_eq!(b.filtered[2], 6, "six levels");
    let mut worst: f64 = 0.0;
    for i in 1..b.filtered[2] {
        let alpha = (i as f64 / (b.filtered[2] - 1) as f64).powi(2);
        let a2 = alpha * alpha;
        let (lw, lh, level) = b.level(i);
        for (x, y) in [(lw / 4, lh / 4), (lw / 2, lh / 2 - 1), (3 * lw / 4, lh / 3), (lw / 8, lh - 1)] {
            let n = direction((x as f64 + 0.5) / lw as f64, (y as f64 + 0.5) / lh as f64);
            let (mut num, mut den) = (0.0, 0.0);
            for &(l, radiance, dw) in &texels {
                let nl = dot(n, l);
                if nl <= 0.0 {
                    continue;
                }
                let hv = [n[0] + l[0], n[1] + l[1], n[2] + l[2]];
                let nh = dot(n, hv) / dot(hv, hv).sqrt();
                let d = a2 / (PI * ((a2 - 1.0) * nh * nh + 1.0).powi(2));
                num += radiance * d * nl * dw;
                den += d * nl * dw;
            }
            let want = num / den;
            let got = rgb9e5(level[(y * lw + x) as usize])[0];
            let err = (got - want).abs() / want;
            worst = worst.max(err);
            assert!(err < 0.05, "level {i} texel ({x}, {y}): {got} vs the lobe integral {want}");
        }
    }
    eprintln!("worst relative error of the prefiltered texels: {worst:.4}");
}

#[test]
fn the_sampling_table_is_a_density_in_proportion_to_the_light() {
    // A map of varied brightness: a sky gradient, a bright patch and a black lower half.
    let f = |d: [f64; 3]| {
        if d[1] < 0.0 {
            [0.0; 3]
        } else {
            let patch = if dot(d, [0.0, 0.6, 0.8]) > 0.9 { 20.0 } else { 0.0 };
            [0.2 + d[1] + patch, 0.3 + patch, 0.5 + 0.5 * d[0].abs()]
        }
    };
    let b = bake(image(256, f), 256);
    // The density integrates to 1 over the sphere (a Fibonacci lattice, independent of the cells).
    let n = 400_000;
    let mut integral = 0.0;
    for i in 0..n {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - y * y).sqrt();
        let phi = i as f64 * PI * (3.0 - 5f64.sqrt());
        integral += b.pdf([r * phi.cos(), y, r * phi.sin()]) * 4.0 * PI / n as f64;
    }
    assert!((integral - 1.0).abs() < 0.01, "the density integrates to {integral}");
    // χ² of drawn directions in 16 x 8 bins against the map's luminance times solid angle.
    let (bw, bh) = (16usize, 8usize);
    let [w, h] = b.map;
    let mut expected = vec![0.0; bw * bh];
    for (x, y, _, dw) in texels(w, h) {
        let bin = (y as usize * bh / h as usize) * bw + x as usize * bw / w as usize;
        expected[bin] += luminance(rgb9e5(b.texels[(y * w + x) as usize])) * dw;
    }
    let total: f64 = expected.iter().sum();
    let draws = 200_000;
    let mut observed = vec![0u32; bw * bh];
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..draws {
        let (d, pdf) = b.draw(rng.f64(), rng.f64(), rng.f64());
        assert!(pdf > 0.0, "a drawn direction has a density");
        let u = d[0].atan2(-d[2]) / (2.0 * PI);
        let u = u - u.floor();
        let v = d[1].clamp(-1.0, 1.0).acos() / PI;
        let bin = ((v * bh as f64) as usize).min(bh - 1) * bw + ((u * bw as f64) as usize).min(bw - 1);
        observed[bin] += 1;
    }
    let mut chi2 = 0.0;
    let mut dof = 0;
    for (o, e) in observed.iter().zip(&expected) {
        let e = e / total * draws as f64;
        if e > 5.0 {
            chi2 += (*o as f64 - e).powi(2) / e;
            dof += 1;
        } else {
            assert!(*o as f64 <= 5.0 + 5.0 * e, "a bin of expectation {e} drew {o}");
        }
    }
    // The 99.9th percentile of χ² with k degrees of freedom is below k + 4.5 √(2k) + 10.
    let bound = dof as f64 + 4.5 * (2.0 * dof as f64).sqrt() + 10.0;
    assert!(chi2 < bound, "chi2 {chi2:.1} over {dof} bins (bound {bound:.1})");
}

#[test]
fn importance_sampling_a_small_sun_beats_uniform_sampling_fourfold() {
    // A dim sky with a sun disc of 1.5° radius 40° up: the irradiance on a horizontal surface by
    // 64 directions drawn from the table against 64 drawn uniformly over the sphere.
    let sun = direction(0.3, (90.0f64 - 40.0).to_radians() / PI);
    let cos_r = 1.5f64.to_radians().cos();
    let b = bake(image(2048, |d| if dot(d, sun) > cos_r { [3000.0; 3] } else { [0.05; 3] }), 2048);
    let up = [0.0, 1.0, 0.0];
    let [w, h] = b.map;
    // The exact irradiance of the baked map (every texel, its solid angle).
    let exact: f64 = texels(w, h)
        .map(|(x, y, d, dw)| {
            b.texel((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64)[1] * dot(d, up).max(0.0) * dw
        })
        .sum();
    let radiance = |d: [f64; 3]| {
        let u = d[0].atan2(-d[2]) / (2.0 * PI);
        b.texel(u - u.floor(), d[1].clamp(-1.0, 1.0).acos() / PI)[1]
    };
    let mut rng = Rng(7);
    let (trials, spp) = (2000, 64);
    let (mut mse_table, mut mse_uniform) = (0.0, 0.0);
    for _ in 0..trials {
        let (mut table, mut uniform) = (0.0, 0.0);
        for _ in 0..spp {
            let (d, pdf) = b.draw(rng.f64(), rng.f64(), rng.f64());
            if pdf > 0.0 {
                table += radiance(d) * dot(d, up).max(0.0) / pdf;
            }
            let y = 1.0 - 2.0 * rng.f64();
            let phi = 2.0 * PI * rng.f64();
            let r = (1.0 - y * y).max(0.0).sqrt();
            let d = [r * phi.cos(), y, r * phi.sin()];
            uniform += radiance(d) * dot(d, up).max(0.0) * 4.0 * PI;
        }
        mse_table += ((table / spp as f64 - exact) / exact).powi(2) / trials as f64;
        mse_uniform += ((uniform / spp as f64 - exact) / exact).powi(2) / trials as f64;
    }
    eprintln!(
        "relMSE at {spp} spp: table {mse_table:.3e}, uniform {mse_uniform:.3e} (ratio {:.4})",
        mse_table / mse_uniform
    );
    assert!(mse_table <= 0.25 * mse_uniform, "table {mse_table} vs uniform {mse_uniform}");
}

/// Preetham, Shirley and Smits (1999), appendix: the Perez function and the zenith values, with
/// the paper's coefficients, in kcd/m² and CIE xy; then CIE XYZ to linear Rec. 709.
fn preetham(d: [f64; 3], sun: [f64; 3], t: f64) -> [f64; 3] {
    let theta_s = sun[1].acos();
    let gamma = dot(d, sun).clamp(-1.0, 1.0).acos();
    let cos_t = d[1].max(0.01);
    let perez = |c: [f64; 5], cos_theta: f64, g: f64| {
        (1.0 + c[0] * (c[1] / cos_theta).exp()) * (1.0 + c[2] * (c[3] * g).exp() + c[4] * g.cos().powi(2))
    };
    let cy = [
        0.1787 * t - 1.4630,
        -0.3554 * t + 0.4275,
        -0.0227 * t + 5.3251,
        0.1206 * t - 2.5771,
        -0.0670 * t + 0.3703,
    ];
    let cx = [
        -0.0193 * t - 0.2592,
        -0.0665 * t + 0.0008,
        -0.0004 * t + 0.2125,
        -0.0641 * t - 0.8989,
        -0.0033 * t + 0.0452,
    ];
    let cyy = [
        -0.0167 * t - 0.2608,
        -0.0950 * t + 0.0092,
        -0.0079 * t + 0.2102,
        -0.0441 * t - 1.6537,
        -0.0109 * t + 0.0529,
    ];
    let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
    let yz = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
    let (t2, s) = (t * t, theta_s);
    let xz = t2 * (0.00166 * s.powi(3) - 0.00375 * s * s + 0.00209 * s)
        + t * (-0.02903 * s.powi(3) + 0.06377 * s * s - 0.03202 * s + 0.00394)
        + (0.11693 * s.powi(3) - 0.21196 * s * s + 0.06052 * s + 0.25886);
    let yzc = t2 * (0.00275 * s.powi(3) - 0.00610 * s * s + 0.00317 * s)
        + t * (-0.04214 * s.powi(3) + 0.08970 * s * s - 0.04153 * s + 0.00516)
        + (0.15346 * s.powi(3) - 0.26756 * s * s + 0.06670 * s + 0.26688);
    let lum = yz * perez(cy, cos_t, gamma) / perez(cy, 1.0, theta_s);
    let x = xz * perez(cx, cos_t, gamma) / perez(cx, 1.0, theta_s);
    let y = yzc * perez(cyy, cos_t, gamma) / perez(cyy, 1.0, theta_s);
    let (cx_, cz_) = (x * lum / y, (1.0 - x - y) * lum / y);
    [
        (3.2406 * cx_ - 1.5372 * lum - 0.4986 * cz_).max(0.0),
        (-0.9689 * cx_ + 1.8758 * lum + 0.0415 * cz_).max(0.0),
        (0.0557 * cx_ - 0.2040 * lum + 1.0570 * cz_).max(0.0),
    ]
}

#[test]
fn the_preetham_sky_follows_the_published_model() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("sky.toml");
    std::fs::write(
        &cfg,
        "[sky]\nmodel = \"preetham\"\nsun_direction = [0.0, 0.5, -0.8660254]\nturbidity = 4.0\n",
    )
    .unwrap();
    let sidecar = kiln_compiler::import::sidecar::Sidecar::load(&cfg, &mut Vec::new()).unwrap();
    let mut s = scene(image(8, |_| [0.0; 3]));
    s.environment = None;
    sidecar.apply(&mut s, "sky.toml").unwrap();
    let sun =
        s.lights.iter().find(|l| l.kind == kiln_format::manifest::LightKind::Directional).expect("the sun");
    let sd = [0.0, 0.5, -0.866_025_4];
    assert!(
        (0..3).all(|i| (sun.direction[i] as f64 + sd[i]).abs() < 1e-6),
        "the sun shines along -sun_direction"
    );
    let bytes = compile(s, settings(1024));
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let h = words(&file.section_bytes(file.find(sections::ENVIRONMENT_HEADER, 0).unwrap()).unwrap());
    let map = words(&file.section_bytes(file.find(sections::ENVIRONMENT_MAP, 0).unwrap()).unwrap());
    let (w, hh) = (h[0], h[1]);
    // Texel centres in the upper hemisphere: the zenith, near the sun, the horizon opposite.
    for (x, y) in
        [(512, 0), (w / 2, hh / 6), (w / 2 + 3, hh / 6 + 2), (0, hh / 2 - 2), (w / 4, hh / 4), (700, 100)]
    {
        let d = direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / hh as f64);
        let want = preetham(d, sd, 4.0);
        let got = rgb9e5(map[(y * w + x) as usize]);
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 0.01 * want[c] + 1e-3,
                "({x}, {y}) {d:?}: {got:?} vs {want:?}"
            );
        }
    }
}

#[test]
fn bad_environment_images_are_refused_or_warned() {
    use kiln_compiler::import::environment::{EnvironmentSpec, Placement, apply};
    let dir = tempfile::tempdir().unwrap();
    let try_image = |name: &str, img: image::DynamicImage| {
        let path = dir.path().join(name);
        img.save(&path).unwrap();
        let mut s = scene(image(8, |_| [0.0; 3]));
        s.environment = None;
        let r =
            apply(&mut s, &EnvironmentSpec::Image { path, extract_sun: true }, Placement::default(), "test");
        (r.map_err(|e| e.to_string()), s)
    };
    let (r, _) = try_image("ldr.png", image::DynamicImage::new_rgb8(64, 32));
    let e = r.unwrap_err();
    assert!(e.contains(".hdr") && e.contains("OpenEXR"), "{e}");
    let (r, _) = try_image("tiny.exr", image::DynamicImage::new_rgb32f(1, 1));
    let e = r.unwrap_err();
    assert!(e.contains("1 x 1") && e.contains("twice as wide"), "{e}");
    // A Radiance header claiming 60,000 x 30,000 pixels (7.2 GB of floats) is refused from its
    // header, before anything is decoded, saying which limit to raise.
    let huge = dir.path().join("huge.hdr");
    std::fs::write(&huge, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 60000\n\x02\x02\xea\x60")
        .unwrap();
    let mut s = scene(image(8, |_| [0.0; 3]));
    let e = apply(
        &mut s,
        &EnvironmentSpec::Image { path: huge, extract_sun: true },
        Placement::default(),
        "test",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("60000 x 30000") && e.contains("--max-image-side"), "{e}");
    let mut nan = image::Rgb32FImage::from_pixel(16, 8, image::Rgb([1.0, 2.0, 3.0]));
    nan.put_pixel(3, 3, image::Rgb([f32::NAN, 1.0, f32::INFINITY]));
    let (r, s) = try_image("nan.exr", nan.into());
    r.unwrap();
    assert!(s.warnings.iter().any(|w| w.message.contains("2 pixel channels")), "{:?}", s.warnings);
    let env = s.environment.unwrap();
    assert_eq!(env.pixels[3 * 16 + 3], [0.0, 1.0, 0.0]);
    assert_eq!(env.pixels[0], [1.0, 2.0, 3.0]);
}

#[test]
fn a_sun_in_an_image_becomes_a_directional_light_of_its_irradiance() {
    use kiln_compiler::import::environment::{EnvironmentSpec, Placement, apply};
    // A 512 x 256 sky of radiance 0.4 with a sun of radiance 5000 and 1° radius, 30° up.
    let (w, h) = (512u32, 256u32);
    let sun = direction(0.15, 60.0 / 180.0);
    let cos_r = 1f64.to_radians().cos();
    let mut img = image::Rgb32FImage::new(w, h);
    let mut excess = 0.0;
    for (x, y, d, dw) in texels(w, h) {
        let on = dot(d, sun) > cos_r;
        if on {
            excess += (5000.0 - 0.4) * dw;
        }
        img.put_pixel(x, y, image::Rgb([if on { 5000.0 } else { 0.4 }; 3]));
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sun.exr");
    image::DynamicImage::from(img).save(&path).unwrap();
    for (rotation, extract) in [(0.0f32, true), (90.0, true), (0.0, false)] {
        let mut s = scene(image(8, |_| [0.0; 3]));
        s.environment = None;
        let spec = EnvironmentSpec::Image { path: path.clone(), extract_sun: extract };
        apply(&mut s, &spec, Placement { intensity: 2.0, rotation_degrees: rotation }, "test").unwrap();
        let env = s.environment.as_ref().unwrap();
        let brightest = env.pixels.iter().map(|p| p[1]).fold(0.0f32, f32::max);
        let suns: Vec<_> =
            s.lights.iter().filter(|l| l.kind == kiln_format::manifest::LightKind::Directional).collect();
        if !extract {
            assert!(suns.is_empty() && brightest == 10000.0, "the sun stays in the map when asked");
            continue;
        }
        let [l] = suns[..] else { panic!("one sun light: {:?}", s.lights) };
        // Turned by the right-hand rule about +y, as the bake turns the map.
        let (sn, cs) = (rotation as f64).to_radians().sin_cos();
        let want = [sun[0] * cs + sun[2] * sn, sun[1], -sun[0] * sn + sun[2] * cs];
        let got = l.direction.map(|c| -c as f64);
        assert!(
            dot(got, want) > 0.5f64.to_radians().cos(),
            "rotation {rotation}: the sun at {got:?}, want {want:?}"
        );
        let irradiance = l.intensity as f64 * luminance(l.color.map(|c| c as f64));
        assert!(
            (irradiance - 2.0 * excess).abs() < 0.01 * 2.0 * excess,
            "irradiance {irradiance} vs {}",
            2.0 * excess
        );
        assert!(brightest <= 0.8 + 1e-4, "the map keeps the sky only: brightest {brightest}");
    }
}
