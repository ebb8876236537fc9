//! The view: where it starts (the file's camera, a `--camera` override, or a view of the scene
//! bounds), its matrices (reversed-Z, computed in f64), and the fly controls of the window.

use glam::{DMat4, DVec3, Vec3};
use kiln_format::manifest::Manifest;
use kiln_format::projection::{look_to_rh, orthographic_rh, perspective_infinite_reverse_rh, perspective_rh};

use crate::error::{Exit, PlayError, PlayResult};

/// A camera looking from `position` along `forward`: perspective, or orthographic when `ortho`
/// is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Up hint.
    pub up: DVec3,
    /// Vertical field of view, degrees.
    pub vfov_degrees: f64,
    /// Near plane distance.
    pub znear: f64,
    /// Far plane distance; 0 or infinite for an infinite far plane.
    pub zfar: f64,
    /// Orthographic: the half-height of the view rectangle (its half-width follows from the
    /// image's aspect ratio, as a perspective camera's horizontal field of view does).
    pub ortho: Option<f64>,
    /// Far plane of an orthographic camera without one: beyond the scene bounds.
    pub ortho_far: f64,
}

/// A `--camera` override: position, target and optionally the vertical field of view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraOverride {
    /// Eye.
    pub position: [f64; 3],
    /// Point looked at.
    pub target: [f64; 3],
    /// Vertical field of view, degrees.
    pub vfov_degrees: Option<f64>,
}

impl std::str::FromStr for CameraOverride {
    type Err = String;

    /// `px,py,pz,tx,ty,tz[,vfov]`.
    fn from_str(s: &str) -> Result<Self, String> {
        let v: Vec<f64> = s
            .split(',')
            .map(|t| t.trim().parse::<f64>().map_err(|_| format!("'{t}' is not a number")))
            .collect::<Result<_, _>>()?;
        if !(v.len() == 6 || v.len() == 7) {
            return Err(format!(
                "expected 6 or 7 comma-separated numbers (px,py,pz,tx,ty,tz[,vfov]), got {}",
                v.len()
            ));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err("every number must be finite".into());
        }
        let position = [v[0], v[1], v[2]];
        let target = [v[3], v[4], v[5]];
        if position == target {
            return Err("position and target must differ".into());
        }
        let vfov_degrees = v.get(6).copied();
        if let Some(f) = vfov_degrees
            && !(f > 0.0 && f < 180.0)
        {
            return Err(format!("vfov {f} must be in (0, 180) degrees"));
        }
        Ok(CameraOverride { position, target, vfov_degrees })
    }
}

/// A `--camera-path` file: poses (each as a `--camera` value, one per line; blank lines and
/// `#` comments skipped) that a run of N frames moves through at an even pace, frame i at
/// i / (N − 1) of the way, position, target and field of view interpolated linearly between
/// neighbouring poses.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraPath {
    poses: Vec<CameraOverride>,
}

impl CameraPath {
    /// Parses a path's text; errors name the line.
    pub fn parse(text: &str) -> Result<CameraPath, String> {
        let mut poses = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let pose: CameraOverride = line.parse().map_err(|e| format!("line {}: {e}", i + 1))?;
            if let Some(first) = poses.first().map(|p: &CameraOverride| p.vfov_degrees.is_some())
                && first != pose.vfov_degrees.is_some()
            {
                return Err(format!(
                    "line {}: give a field of view on every pose or on none (the first pose {})",
                    i + 1,
                    if first { "has one" } else { "has none" }
                ));
            }
            poses.push(pose);
        }
        if poses.is_empty() {
            return Err("no pose: write one `px,py,pz,tx,ty,tz[,vfov]` per line".into());
        }
        Ok(CameraPath { poses })
    }

    /// Reads and parses a path file.
    pub fn load(path: &std::path::Path) -> PlayResult<CameraPath> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| PlayError::new(Exit::Io, format!("--camera-path {}: {e}", path.display())))?;
        CameraPath::parse(&text)
            .map_err(|e| PlayError::new(Exit::Usage, format!("--camera-path {}: {e}", path.display())))
    }

    /// The pose of frame `i` of `frames`.
    pub fn at(&self, i: u32, frames: u32) -> CameraOverride {
        let last = self.poses.len() - 1;
        let s = if frames > 1 { i.min(frames - 1) as f64 / (frames - 1) as f64 * last as f64 } else { 0.0 };
        let k = (s.floor() as usize).min(last.saturating_sub(1));
        let (a, b) = (&self.poses[k], &self.poses[(k + 1).min(last)]);
        let t = s - k as f64;
        let mix = |x: [f64; 3], y: [f64; 3]| std::array::from_fn(|j| x[j] + (y[j] - x[j]) * t);
        let (position, target) = (mix(a.position, b.position), mix(a.target, b.target));
        // Equal positions and targets are refused per pose; a blend of two can still meet.
        let target = if position == target { a.target } else { target };
        CameraOverride {
            position,
            target,
            vfov_degrees: a.vfov_degrees.zip(b.vfov_degrees).map(|(x, y)| x + (y - x) * t),
        }
    }
}

fn d3(v: [f32; 3]) -> DVec3 {
    Vec3::from_array(v).as_dvec3()
}

impl Camera {
    /// The camera to start with: the override applied to the file's first camera (orthographic
    /// with half-extents `ortho` when the manifest says so), or to a view of the bounds from
    /// above and in front when the file has none. An override's field of view makes it
    /// perspective. The override is in world space: it is moved into the file's frame (its
    /// positions are relative to `manifest.origin`).
    pub fn initial(manifest: &Manifest, over: Option<CameraOverride>) -> PlayResult<Camera> {
        let (cameras, ortho, bounds) = (&manifest.cameras, manifest.orthographic(0), &manifest.bounds);
        let lo = d3(bounds.min);
        let hi = d3(bounds.max);
        let valid = lo.is_finite() && hi.is_finite() && lo.cmple(hi).all();
        let (centre, radius) =
            if valid { ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3)) } else { (DVec3::ZERO, 1.0) };
        let mut cam = match cameras.first() {
            Some(c) => Camera {
                position: d3(c.position),
                forward: (d3(c.target) - d3(c.position)).normalize_or(DVec3::NEG_Z),
                up: d3(c.up).normalize_or(DVec3::Y),
                vfov_degrees: c.vfov_degrees as f64,
                znear: c.znear as f64,
                zfar: c.zfar as f64,
                ortho: ortho.map(|(_, ymag)| ymag as f64),
                ortho_far: 0.0,
            },
            None => {
                let vfov = 45.0f64;
                let distance = radius / (vfov.to_radians() * 0.5).sin();
                let dir = DVec3::new(0.0, 0.35, 1.0).normalize();
                Camera {
                    position: centre + dir * distance,
                    forward: -dir,
                    up: DVec3::Y,
                    vfov_degrees: vfov,
                    znear: 0.0,
                    zfar: 0.0,
                    ortho: None,
                    ortho_far: 0.0,
                }
            }
        };
        if let Some(o) = over {
            let origin = DVec3::from_array(manifest.origin);
            cam.position = DVec3::from_array(o.position) - origin;
            cam.forward = (DVec3::from_array(o.target) - origin - cam.position).normalize();
            if let Some(f) = o.vfov_degrees {
                cam.vfov_degrees = f;
                cam.ortho = None;
            }
        }
        if !(cam.znear > 0.0) {
            // Reversed-Z float depth keeps precision over the whole range, so a small near plane
            // costs nothing: 1/10000 of the scene diagonal (as the compiler's default).
            cam.znear = (2.0 * radius) * 1e-4;
        }
        // Everything in the bounds lies within this distance along any view direction.
        cam.ortho_far = (cam.position - centre).length() + 2.0 * radius;
        let usable = cam.ortho.is_none_or(|h| h.is_finite() && h > 0.0)
            && cam.position.is_finite()
            && cam.forward.is_finite()
            && cam.vfov_degrees > 0.0
            && cam.vfov_degrees < 180.0;
        if !usable {
            return Err(PlayError::new(
                Exit::BadInput,
                "the camera is not finite or its field of view is outside (0, 180) degrees",
            ));
        }
        Ok(cam)
    }

    /// The image plane: unit right and up vectors, and the image's half height, at unit distance
    /// for a perspective camera (the tangent of half the vertical field of view), in scene units
    /// for an orthographic one (its half extent).
    pub fn image_axes(&self) -> (DVec3, DVec3, f64) {
        let right = self.forward.cross(self.up).normalize_or(DVec3::X);
        let up = right.cross(self.forward);
        (right, up, self.ortho.unwrap_or((self.vfov_degrees.to_radians() * 0.5).tan()))
    }

    /// The ray through image point (`nx`, `ny`) in [-1, 1]² (y up) of an image `aspect` wide per
    /// unit of height: from the eye, or parallel from the image plane (orthographic).
    pub fn pixel_ray(&self, nx: f64, ny: f64, aspect: f64) -> (DVec3, DVec3) {
        let (right, up, half) = self.image_axes();
        let offset = right * nx * half * aspect + up * ny * half;
        match self.ortho {
            None => (self.position, (self.forward + offset).normalize()),
            Some(_) => (self.position + offset, self.forward),
        }
    }

    /// World to view.
    pub fn view(&self) -> DMat4 {
        let up = if self.forward.cross(self.up).length_squared() < 1e-12 { DVec3::Z } else { self.up };
        look_to_rh(self.position, self.forward, up)
    }

    /// View to clip with reversed Z (near → 1, far → 0) and Vulkan's [0, 1] depth; clip y up (the
    /// viewport flips it).
    pub fn projection(&self, aspect: f64) -> DMat4 {
        if let Some(h) = self.ortho {
            let far =
                if self.zfar > self.znear && self.zfar.is_finite() { self.zfar } else { self.ortho_far };
            // Reversed Z: near and far swapped.
            return orthographic_rh(-h * aspect, h * aspect, -h, h, far, self.znear);
        }
        let fov = self.vfov_degrees.to_radians();
        if self.zfar > self.znear && self.zfar.is_finite() {
            perspective_rh(fov, aspect, self.zfar, self.znear)
        } else {
            perspective_infinite_reverse_rh(fov, aspect, self.znear)
        }
    }

    /// World to clip for an image of `width` × `height`.
    pub fn view_projection(&self, width: u32, height: u32) -> DMat4 {
        let aspect = width.max(1) as f64 / height.max(1) as f64;
        self.projection(aspect) * self.view()
    }

    /// World to clip and its inverse, as f32 column-major arrays.
    pub fn matrices(&self, width: u32, height: u32) -> ([f32; 16], [f32; 16]) {
        let vp = self.view_projection(width, height);
        (vp.as_mat4().to_cols_array(), vp.inverse().as_mat4().to_cols_array())
    }

    /// Turns the view by yaw (about world up) and pitch, in radians; pitch stops short of the poles.
    pub fn turn(&mut self, yaw: f64, pitch: f64) {
        let up = DVec3::Y;
        let current_pitch = self.forward.dot(up).clamp(-1.0, 1.0).asin();
        let new_pitch = (current_pitch + pitch).clamp(-1.5, 1.5);
        let flat = DVec3::new(self.forward.x, 0.0, self.forward.z).normalize_or(DVec3::NEG_Z);
        let (s, c) = (-yaw).sin_cos();
        let flat = DVec3::new(flat.x * c - flat.z * s, 0.0, flat.x * s + flat.z * c);
        self.forward = (flat * new_pitch.cos() + up * new_pitch.sin()).normalize();
        self.up = up;
    }

    /// Moves by `local` (x right, y up, z forward) scaled by `distance`.
    pub fn fly(&mut self, local: DVec3, distance: f64) {
        let right = self.forward.cross(DVec3::Y).normalize_or(DVec3::X);
        self.position += (right * local.x + DVec3::Y * local.y + self.forward * local.z) * distance;
    }
}

#[cfg(test)]
mod tests {
    use kiln_format::manifest::Bounds;

    use super::*;

    /// A `--camera` override is in world space; a file far from the origin stores positions
    /// relative to `manifest.origin`, so the override lands at world − origin.
    #[test]
    fn overrides_are_moved_into_the_files_frame() {
        let m = Manifest { bounds: bounds(), origin: [1.0e5, -3.0, 0.5], ..Default::default() };
        let cam = Camera::initial(&m, Some("100000,-3,5.5,100000,-3,0.5".parse().unwrap())).unwrap();
        assert_eq!(cam.position, DVec3::new(0.0, 0.0, 5.0));
        assert_eq!(cam.forward, DVec3::NEG_Z);
    }

    fn bounds() -> Bounds {
        Bounds { min: [-1.0, -1.0, -1.0], max: [1.0, 1.0, 1.0] }
    }

    #[test]
    fn camera_paths_interpolate_evenly_and_name_bad_lines() {
        let path =
            CameraPath::parse("# a dolly\n0,0,0, 0,0,-1, 40\n\n4,0,0, 4,0,-1, 60 # end\n8,2,0,8,2,-1,60")
                .unwrap();
        // 9 frames over 3 poses: frame 2 halfway to the second pose, frame 8 the last pose.
        let p = path.at(2, 9);
        assert_eq!(p.position, [2.0, 0.0, 0.0]);
        assert_eq!(p.target, [2.0, 0.0, -1.0]);
        assert_eq!(p.vfov_degrees, Some(50.0));
        assert_eq!(path.at(8, 9).position, [8.0, 2.0, 0.0]);
        assert_eq!(path.at(0, 9).position, [0.0; 3]);
        assert_eq!(path.at(0, 1).position, [0.0; 3]);
        let one = CameraPath::parse("1,2,3,0,0,0").unwrap();
        assert_eq!(one.at(5, 10).position, [1.0, 2.0, 3.0]);
        let e = CameraPath::parse("0,0,0,0,0,-1\n1,2").unwrap_err();
        assert!(e.starts_with("line 2:"), "{e}");
        let e = CameraPath::parse("0,0,0,0,0,-1,40\n1,0,0,0,0,-1").unwrap_err();
        assert!(e.contains("line 2") && e.contains("field of view"), "{e}");
        assert!(CameraPath::parse("# nothing\n").unwrap_err().contains("no pose"));
    }

    #[test]
    fn override_parses_and_rejects() {
        let o: CameraOverride = "1,2,3,0,0,0,60".parse().unwrap();
        assert_eq!(o.position, [1.0, 2.0, 3.0]);
        assert_eq!(o.vfov_degrees, Some(60.0));
        assert!("1,2,3".parse::<CameraOverride>().is_err());
        assert!("1,2,3,1,2,3".parse::<CameraOverride>().is_err());
        assert!("1,2,3,0,0,0,200".parse::<CameraOverride>().is_err());
        assert!("1,2,x,0,0,0".parse::<CameraOverride>().is_err());
    }

    #[test]
    fn reversed_depth_maps_near_to_one_and_far_towards_zero() {
        let cam = Camera::initial(
            &Manifest { bounds: bounds(), ..Default::default() },
            Some("0,0,5,0,0,0,60".parse().unwrap()),
        )
        .unwrap();
        let exact = cam.projection(1.0) * cam.view();
        let near = exact * glam::DVec4::new(0.0, 0.0, 5.0 - cam.znear, 1.0);
        assert!((near.z / near.w - 1.0).abs() < 1e-9);
        let far = exact * glam::DVec4::new(0.0, 0.0, -1000.0, 1.0);
        assert!(far.z / far.w > 0.0 && far.z / far.w < 1e-6);
        let (vp, inv) = cam.matrices(100, 100);
        let vp = glam::Mat4::from_cols_array(&vp);
        // The inverse recovers a world point from its clip position.
        let p = glam::Vec4::new(0.3, -0.2, 0.5, 1.0);
        let clip = vp * p;
        let back = glam::Mat4::from_cols_array(&inv) * (clip / clip.w);
        assert!((back.truncate() / back.w - p.truncate()).length() < 1e-4);
    }

    #[test]
    fn default_view_sees_the_bounds() {
        let cam = Camera::initial(&Manifest { bounds: bounds(), ..Default::default() }, None).unwrap();
        let (vp, _) = cam.matrices(64, 64);
        let vp = glam::Mat4::from_cols_array(&vp);
        for corner in [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], [1.0, -1.0, 1.0], [-1.0, 1.0, -1.0]] {
            let c = vp * glam::Vec3::from_array(corner).extend(1.0);
            let ndc = c.truncate() / c.w;
            assert!(c.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{corner:?} → {ndc}");
        }
    }

    #[test]
    fn turning_keeps_a_unit_forward_below_the_pole() {
        let mut cam = Camera::initial(&Manifest { bounds: bounds(), ..Default::default() }, None).unwrap();
        for _ in 0..100 {
            cam.turn(0.1, 0.1);
        }
        assert!((cam.forward.length() - 1.0).abs() < 1e-9);
        assert!(cam.forward.y < 1.0);
    }
}
