//! Rays with the per-ray constants of the watertight triangle test precomputed.

use glam::Vec3;

/// A ray `origin + t * direction` for `t` in `[tmin, tmax]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (need not be unit length; `t` is measured in its length).
    pub direction: Vec3,
    /// Start of the interval.
    pub tmin: f32,
    /// End of the interval.
    pub tmax: f32,
    /// Reciprocal direction (±inf for zero components).
    pub inv_direction: Vec3,
    /// Axis permutation of the watertight test: kz is the dominant axis.
    pub(crate) k: [usize; 3],
    /// Shear constants of the watertight test.
    pub(crate) shear: Vec3,
}

impl Ray {
    /// A ray; `direction` must be non-zero and finite.
    pub fn new(origin: Vec3, direction: Vec3, tmin: f32, tmax: f32) -> Ray {
        let a = direction.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding of the projected triangle independent of the direction's sign.
        if direction[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = direction[kz];
        Ray {
            origin,
            direction,
            tmin,
            tmax,
            inv_direction: direction.recip(),
            k: [kx, ky, kz],
            shear: Vec3::new(direction[kx] / dz, direction[ky] / dz, 1.0 / dz),
        }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }
}
