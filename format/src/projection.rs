//! View and projection matrices shared by the compiler (shadow maps) and the player (camera),
//! in f64 so that far-from-origin scenes keep their precision until the final cast. Conventions:
//! right-handed view space (x right, y up, −z forward), clip z in [0, 1] (Vulkan), clip y up.

use glam::{DMat4, DVec3, DVec4};

/// View matrix looking from `eye` along `dir`.
pub fn look_to_rh(eye: DVec3, dir: DVec3, up: DVec3) -> DMat4 {
    let f = dir.normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    DMat4::from_cols(
        DVec4::new(s.x, u.x, -f.x, 0.0),
        DVec4::new(s.y, u.y, -f.y, 0.0),
        DVec4::new(s.z, u.z, -f.z, 0.0),
        DVec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// Orthographic projection of view-space [l, r] × [b, t] × [−near, −far] to x, y in [−1, 1] and
/// z in [0, 1].
pub fn orthographic_rh(l: f64, r: f64, b: f64, t: f64, near: f64, far: f64) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(2.0 / (r - l), 0.0, 0.0, 0.0),
        DVec4::new(0.0, 2.0 / (t - b), 0.0, 0.0),
        DVec4::new(0.0, 0.0, -1.0 / (far - near), 0.0),
        DVec4::new(-(r + l) / (r - l), -(t + b) / (t - b), -near / (far - near), 1.0),
    )
}

/// Perspective projection with vertical field of view `fov` (radians): depth `near` maps to 0
/// and `far` to 1. Swapping the two gives reversed Z.
pub fn perspective_rh(fov: f64, aspect: f64, near: f64, far: f64) -> DMat4 {
    let f = 1.0 / (fov * 0.5).tan();
    DMat4::from_cols(
        DVec4::new(f / aspect, 0.0, 0.0, 0.0),
        DVec4::new(0.0, f, 0.0, 0.0),
        DVec4::new(0.0, 0.0, far / (near - far), -1.0),
        DVec4::new(0.0, 0.0, near * far / (near - far), 0.0),
    )
}

/// Reversed-Z perspective with an infinite far plane: depth 1 at `near`, tending to 0 at
/// infinity (the precision of float depth then spreads evenly over distance).
pub fn perspective_infinite_reverse_rh(fov: f64, aspect: f64, near: f64) -> DMat4 {
    let f = 1.0 / (fov * 0.5).tan();
    DMat4::from_cols(
        DVec4::new(f / aspect, 0.0, 0.0, 0.0),
        DVec4::new(0.0, f, 0.0, 0.0),
        DVec4::new(0.0, 0.0, 0.0, -1.0),
        DVec4::new(0.0, 0.0, near, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ndc(m: DMat4, p: DVec3) -> DVec3 {
        let c = m * p.extend(1.0);
        c.truncate() / c.w
    }

    #[test]
    fn perspective_maps_near_and_far() {
        let m = perspective_rh(1.0, 1.5, 0.1, 100.0);
        assert!((ndc(m, DVec3::new(0.0, 0.0, -0.1)).z).abs() < 1e-12);
        assert!((ndc(m, DVec3::new(0.0, 0.0, -100.0)).z - 1.0).abs() < 1e-12);
        let r = perspective_infinite_reverse_rh(1.0, 1.5, 0.1);
        assert!((ndc(r, DVec3::new(0.0, 0.0, -0.1)).z - 1.0).abs() < 1e-12);
        assert!(ndc(r, DVec3::new(0.0, 0.0, -1e9)).z < 1e-9);
    }

    #[test]
    fn look_to_puts_the_target_on_the_axis() {
        let v = look_to_rh(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.0, 0.0, -1.0), DVec3::Y);
        let p = v * DVec4::new(1.0, 2.0, -7.0, 1.0);
        assert!((p.truncate() - DVec3::new(0.0, 0.0, -10.0)).length() < 1e-12);
    }

    #[test]
    fn orthographic_maps_the_box() {
        let m = orthographic_rh(-2.0, 2.0, -1.0, 1.0, 0.0, 10.0);
        assert!((ndc(m, DVec3::new(2.0, 1.0, -10.0)) - DVec3::new(1.0, 1.0, 1.0)).length() < 1e-12);
    }
}
