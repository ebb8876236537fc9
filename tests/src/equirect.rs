//! Equirectangular maps as the environment tests write and sum them, from FORMAT.md
//! ("Environment") and not from `kiln_format::environment` (the code the tests judge): direction
//! (x, y, z) at map coordinates (u, v) is (sin θ sin φ, cos θ, −sin θ cos φ) with φ = 2πu, θ = πv.

use kiln_compiler::ir::EnvironmentImage;

/// The unit direction at map coordinates (u, v).
pub fn direction(u: f64, v: f64) -> [f64; 3] {
    let (phi, theta) = (2.0 * std::f64::consts::PI * u, std::f64::consts::PI * v);
    [theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()]
}

/// Every texel of a `w` × `h` map, rows from the zenith: (x, y, the direction through its centre,
/// its exact solid angle).
pub fn texels(w: u32, h: u32) -> impl Iterator<Item = (u32, u32, [f64; 3], f64)> {
    (0..h).flat_map(move |y| {
        let (t0, t1) =
            (std::f64::consts::PI * y as f64 / h as f64, std::f64::consts::PI * (y + 1) as f64 / h as f64);
        let dw = (t0.cos() - t1.cos()) * 2.0 * std::f64::consts::PI / w as f64;
        (0..w).map(move |x| (x, y, direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64), dw))
    })
}

/// A `width` × `width / 2` environment of `f` at its texel centres, not rotated.
pub fn image(width: u32, f: impl Fn([f64; 3]) -> [f64; 3]) -> EnvironmentImage {
    let height = width / 2;
    let pixels = texels(width, height).map(|(_, _, d, _)| f(d).map(|c| c as f32)).collect();
    EnvironmentImage { name: "test".into(), width, height, pixels, rotation_degrees: 0.0 }
}
