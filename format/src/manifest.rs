//! The manifest section: everything about a scene that is not bulk data, encoded with bincode 2
//! (standard configuration: little-endian, variable-length integers).
//!
//! Compatibility rule: a newer manifest version only appends top-level fields. A reader decodes
//! the fields it knows and ignores what follows them when the section's version is newer than its
//! own; for its own version, trailing bytes are an error.

use bincode::{Decode, Encode};
use serde::Serialize;

use crate::error::{ErrorKind, FormatError, Result};

/// Axis-aligned box, scene units.
#[derive(Debug, Clone, Copy, PartialEq, Default, Encode, Decode, Serialize)]
pub struct Bounds {
    /// Minimum corner.
    pub min: [f32; 3],
    /// Maximum corner.
    pub max: [f32; 3],
}

/// A file the compiler read, for depfiles, caches and provenance.
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct InputFile {
    /// Path as given to (or resolved by) the compiler.
    pub path: String,
    /// Length in bytes.
    pub bytes: u64,
    /// XXH3-128 of the contents, hex.
    pub hash: String,
}

/// A material's metadata (the shading parameters are in the `MATL` section).
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct MaterialInfo {
    /// Name in the source asset, or a generated one.
    pub name: String,
}

/// How texels are to be interpreted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Encode, Decode, Serialize)]
pub enum ColorSpace {
    /// sRGB-encoded colour (base colour, emissive).
    Srgb,
    /// Linear data (normals, metallic-roughness, occlusion).
    Linear,
}

/// Texture addressing per axis (glTF sampler wrap modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Encode, Decode, Serialize)]
pub enum Wrap {
    /// Repeat.
    Repeat,
    /// Mirrored repeat.
    MirroredRepeat,
    /// Clamp to edge.
    ClampToEdge,
}

/// Metadata of one `TEXL` section (same index).
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct TextureInfo {
    /// Source image name or URI.
    pub name: String,
    /// Width of mip 0 in texels.
    pub width: u32,
    /// Height of mip 0 in texels.
    pub height: u32,
    /// Number of mip levels (full chain down to 1×1).
    pub mip_levels: u32,
    /// Colour space of the texels.
    pub color_space: ColorSpace,
    /// Wrap mode along u.
    pub wrap_u: Wrap,
    /// Wrap mode along v.
    pub wrap_v: Wrap,
    /// Nearest (false) or linear (true) magnification.
    pub mag_linear: bool,
}

/// The kind of an analytic light, with its kind-specific parameters.
#[derive(Debug, Clone, Copy, PartialEq, Encode, Decode, Serialize)]
pub enum LightKind {
    /// Point light; intensity in W/sr.
    Point,
    /// Spot light; intensity in W/sr on the axis; cone half-angles in radians.
    Spot {
        /// Full intensity inside this half-angle.
        inner_cone: f32,
        /// Zero intensity outside this half-angle.
        outer_cone: f32,
    },
    /// Directional light; intensity is irradiance in W/m² on a surface facing it.
    Directional,
    /// One-sided rectangle centred at `position`; intensity is radiance in W/(sr·m²).
    Rect {
        /// Extent along `right`.
        width: f32,
        /// Extent along `direction × right`.
        height: f32,
    },
}

/// An analytic light.
#[derive(Debug, Clone, PartialEq, Encode, Decode, Serialize)]
pub struct Light {
    /// Name (from the asset or the sidecar).
    pub name: String,
    /// Kind and kind-specific parameters.
    pub kind: LightKind,
    /// Position (point, spot, rect centre); unused for directional.
    pub position: [f32; 3],
    /// Unit direction the light travels (directional, spot) or faces (rect).
    pub direction: [f32; 3],
    /// Unit vector along a rect light's width; zero for other kinds.
    pub right: [f32; 3],
    /// Linear RGB colour.
    pub color: [f32; 3],
    /// Scalar intensity in the kind's unit (see [`LightKind`]).
    pub intensity: f32,
    /// Distance beyond which the light is cut off (0 = unlimited).
    pub range: f32,
    /// Whether it casts shadows.
    pub casts_shadows: bool,
}

/// A perspective camera.
#[derive(Debug, Clone, PartialEq, Encode, Decode, Serialize)]
pub struct Camera {
    /// Name.
    pub name: String,
    /// Eye position.
    pub position: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Up vector (not necessarily orthogonal to the view direction).
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub vfov_degrees: f32,
    /// Near plane distance.
    pub znear: f32,
    /// Far plane distance (0 = infinite).
    pub zfar: f32,
}

/// Constant sky radiance seen by rays that leave the scene.
#[derive(Debug, Clone, Copy, PartialEq, Default, Encode, Decode, Serialize)]
pub struct Sky {
    /// Linear RGB radiance, W/(sr·m²).
    pub radiance: [f32; 3],
}

/// A homogeneous participating medium filling a box.
#[derive(Debug, Clone, Copy, PartialEq, Encode, Decode, Serialize)]
pub struct Medium {
    /// Region the medium fills.
    pub bounds: Bounds,
    /// Absorption coefficient per scene unit, RGB.
    pub sigma_a: [f32; 3],
    /// Scattering coefficient per scene unit, RGB.
    pub sigma_s: [f32; 3],
    /// Henyey–Greenstein anisotropy in (-1, 1).
    pub g: f32,
}

/// How a shadow map projects the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Encode, Decode, Serialize)]
pub enum ShadowProjection {
    /// Orthographic along the light direction (directional lights): one N × N map.
    Orthographic,
    /// Perspective from the light position (spot lights): one N × N map.
    Perspective,
    /// Cube map around the light position (point and rect lights): six N × N faces in Vulkan
    /// order (+X −X +Y −Y +Z −Z) and orientation.
    Cube,
}

/// Metadata of one `SHDW` section (same index).
#[derive(Debug, Clone, PartialEq, Encode, Decode, Serialize)]
pub struct ShadowMapInfo {
    /// The light it belongs to (index into `lights`).
    pub light: u32,
    /// Projection.
    pub projection: ShadowProjection,
    /// Texels per side.
    pub resolution: u32,
    /// World to clip space (Vulkan: x, y in [−1, 1], y up, z in [0, 1]), column-major; identity
    /// for cube maps, which are sampled by direction.
    pub view_proj: [f32; 16],
    /// Ray origin: the light position (perspective, cube) or the centre of the near plane
    /// (orthographic).
    pub origin: [f32; 3],
    /// View axis (orthographic, perspective).
    pub direction: [f32; 3],
    /// Near distance.
    pub near: f32,
    /// Farthest distance to the scene bounds.
    pub far: f32,
    /// Texel footprint: world size (orthographic) or angle in radians (perspective, cube).
    pub texel: f32,
}

impl ShadowMapInfo {
    /// Depths its `SHDW` section holds: one face of `resolution`², six for a cube map.
    pub fn depth_count(&self) -> u64 {
        let faces = if self.projection == ShadowProjection::Cube { 6 } else { 1 };
        faces * self.resolution as u64 * self.resolution as u64
    }
}

/// Metadata of the `BRDF` section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct BrdfLutInfo {
    /// Texels per side.
    pub resolution: u32,
    /// Evaluations of the integrand per texel.
    pub samples: u32,
}

/// Metadata of the `MVIS` sections: the light-visibility volume of one medium.
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct MediaVisibilityInfo {
    /// The medium (index into `media`) whose box the volume covers.
    pub medium: u32,
    /// Cells along x, y, z (cubic cells over the medium's box).
    pub dims: [u32; 3],
    /// Shadow rays per cell and light.
    pub samples: u32,
    /// The lights with a volume, in `MVIS` index order; [`MediaVisibilityInfo::SKY`]'s entries
    /// (format 1.10) name the sky's three grids.
    pub lights: Vec<u32>,
}

impl MediaVisibilityInfo {
    /// The entries of `lights` that name the sky's grids of red, green and blue (format 1.10):
    /// per cell, the sky's light reaching it through the geometry and the medium, relative to
    /// the sky's whole (FORMAT.md, "MVIS").
    pub const SKY: [u32; 3] = [u32::MAX - 2, u32::MAX - 1, u32::MAX];

    /// The entry of `lights` (and index of `MVIS`) of the sky's red grid: where the three sky
    /// entries stand as FORMAT.md requires, consecutive, red first. (The reader refuses a file
    /// with a sky entry anywhere else.)
    pub fn sky_index(&self) -> Option<usize> {
        self.lights.windows(3).position(|w| w == Self::SKY)
    }

    /// Cells of each light's `MVIS` section.
    pub fn cells(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }
}

/// A bake stage the compiler did not run, and why.
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct SkippedStage {
    /// Stage name as in `kiln plan`.
    pub stage: String,
    /// Why it was skipped.
    pub reason: String,
}

/// A bake setting, for provenance and `inspect`.
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode, Serialize)]
pub struct Setting {
    /// Name, as the command-line flag without dashes.
    pub key: String,
    /// Value as text.
    pub value: String,
}

/// The scene manifest.
#[derive(Debug, Clone, PartialEq, Default, Encode, Decode, Serialize)]
pub struct Manifest {
    /// Program and version that wrote the file, e.g. `kiln 0.1.0`.
    pub generator: String,
    /// Name of the scene (the input file's stem).
    pub scene_name: String,
    /// Every file read to produce this one.
    pub inputs: Vec<InputFile>,
    /// Bake settings in effect.
    pub settings: Vec<Setting>,
    /// Bounds of all triangles.
    pub bounds: Bounds,
    /// One per `MATL` element.
    pub materials: Vec<MaterialInfo>,
    /// One per `TEXL` section.
    pub textures: Vec<TextureInfo>,
    /// Analytic lights.
    pub lights: Vec<Light>,
    /// Cameras; the first is the default view.
    pub cameras: Vec<Camera>,
    /// Constant sky.
    pub sky: Sky,
    /// Participating media.
    pub media: Vec<Medium>,
    /// Stages not run, with reasons.
    pub skipped: Vec<SkippedStage>,
    /// Triangles dropped as degenerate during import.
    pub degenerate_triangles: u64,
    /// The BRDF lookup table, when baked.
    pub brdf_lut: Option<BrdfLutInfo>,
    /// One per `SHDW` section.
    pub shadow_maps: Vec<ShadowMapInfo>,
    /// The light-visibility volume, when baked.
    pub media_visibility: Option<MediaVisibilityInfo>,
    /// Manifest version 2: the cameras that are orthographic (the others are perspective).
    pub orthographic: Vec<OrthographicCamera>,
    /// Manifest version 3: where every position of the file is measured from, in world space
    /// (world = stored + origin). Zero unless the scene lies far from the world's origin for its
    /// size: single precision around the origin keeps such a scene's detail (FORMAT.md).
    pub origin: [f64; 3],
}

/// An orthographic camera (glTF `camera.orthographic`), manifest version 2: the camera
/// `cameras[camera]` projects along its view direction onto a rectangle of half-width `xmag` and
/// half-height `ymag` (scene units). Its `vfov_degrees` holds the field of view under which a
/// perspective camera at its position sees the same height at its target, for readers of
/// manifest version 1.
#[derive(Debug, Clone, Copy, PartialEq, Encode, Decode, Serialize)]
pub struct OrthographicCamera {
    /// Index into `cameras`.
    pub camera: u32,
    /// Half-width of the view rectangle.
    pub xmag: f32,
    /// Half-height of the view rectangle.
    pub ymag: f32,
}

impl Manifest {
    /// The orthographic extents `(xmag, ymag)` of camera `i`, or `None` when it is perspective.
    pub fn orthographic(&self, i: usize) -> Option<(f32, f32)> {
        self.orthographic.iter().find(|o| o.camera as usize == i).map(|o| (o.xmag, o.ymag))
    }
}

/// Manifest version this crate reads and writes (equals the `MANI` kind's version).
pub const MANIFEST_VERSION: u16 = 3;

impl Manifest {
    /// Encodes with bincode's standard configuration.
    pub fn encode(&self) -> Vec<u8> {
        // Encoding into a Vec cannot fail for these types (no maps with fallible keys, no limits).
        bincode::encode_to_vec(self, bincode::config::standard())
            .unwrap_or_else(|e| unreachable!("manifest encoding failed: {e}"))
    }

    /// Decodes a manifest section of version `version`. Allocation is bounded by bincode's
    /// limit, set to the smallest power of two at least four times the section length, so that
    /// no length read from the file can claim more memory than the file could describe.
    pub fn decode(bytes: &[u8], version: u16) -> Result<Manifest> {
        // Version 1 ends before `orthographic`, version 2 before `origin`: read them as version
        // 3 with the list empty (a zero length, one byte) and the origin zero (24 zero bytes).
        let old;
        let bytes = match version {
            0 | 1 => {
                old = [bytes, &[0u8; 25]].concat();
                &old[..]
            }
            2 => {
                old = [bytes, &[0u8; 24]].concat();
                &old[..]
            }
            _ => bytes,
        };
        let (manifest, used) = decode_limited(bytes)?;
        if used != bytes.len() && version <= MANIFEST_VERSION {
            return Err(FormatError::new(ErrorKind::Manifest(format!(
                "{} trailing bytes after the manifest",
                bytes.len() - used
            ))));
        }
        Ok(manifest)
    }
}

fn decode_limited(bytes: &[u8]) -> Result<(Manifest, usize)> {
    macro_rules! with_limit {
        ($($log2:literal)*) => {{
            let need = (bytes.len().max(256) as u64).saturating_mul(4);
            $(
                if need <= (1u64 << $log2) {
                    let cfg = bincode::config::standard().with_limit::<{ 1usize << $log2 }>();
                    return bincode::decode_from_slice(bytes, cfg).map_err(manifest_error);
                }
            )*
            Err(FormatError::new(ErrorKind::Manifest(format!(
                "manifest section of {} bytes is larger than the 1 GiB a manifest may have",
                bytes.len()
            ))))
        }};
    }
    with_limit!(10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30)
}

fn manifest_error(e: bincode::error::DecodeError) -> FormatError {
    use bincode::error::DecodeError as D;
    let msg = match e {
        D::UnexpectedEnd { additional } => {
            format!("it ends {additional} bytes early")
        }
        D::LimitExceeded => "a length in it is larger than the section could hold".to_string(),
        other => other.to_string(),
    };
    FormatError::new(ErrorKind::Manifest(msg))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn enc<T: Encode>(v: &T) -> Vec<u8> {
        bincode::encode_to_vec(v, bincode::config::standard()).unwrap()
    }

    /// A version-1 manifest is a version-3 one without its trailing `orthographic` list and
    /// `origin`, a version-2 one without `origin`: they read with the list empty and the origin
    /// zero; version 3 keeps both.
    #[test]
    fn older_manifests_read_with_no_orthographic_cameras_and_a_zero_origin() {
        let mut m = Manifest { scene_name: "s".into(), ..Default::default() };
        let v3 = m.encode();
        // The origin is the last 24 bytes (three f64 zeros), the empty list the byte before them.
        assert_eq!(v3[v3.len() - 25..], [0u8; 25]);
        let v2 = &v3[..v3.len() - 24];
        let v1 = &v3[..v3.len() - 25];
        assert_eq!(Manifest::decode(v1, 1).unwrap(), m);
        assert_eq!(Manifest::decode(v2, 2).unwrap(), m);
        assert!(Manifest::decode(v1, 2).is_err(), "version 2 requires the list");
        assert!(Manifest::decode(v2, 3).is_err(), "version 3 requires the origin");
        m.orthographic.push(OrthographicCamera { camera: 0, xmag: 2.0, ymag: 1.5 });
        m.origin = [1.0e5, -2.5, 0.0];
        let v3 = m.encode();
        let tail: Vec<u8> = [
            &[1u8, 0, 0, 0, 0, 0x40, 0, 0, 0xc0, 0x3f][..],
            &1.0e5f64.to_le_bytes(),
            &(-2.5f64).to_le_bytes(),
            &[0; 8],
        ]
        .concat();
        assert_eq!(&v3[v1.len()..], &tail[..]);
        assert_eq!(Manifest::decode(&v3, 3).unwrap(), m);
    }

    /// FORMAT.md's bincode table and its examples.
    #[test]
    fn bincode_rules_match_format_md() {
        let lut = |resolution| Some(BrdfLutInfo { resolution, samples: 144 });
        assert_eq!(enc(&lut(128)), [1, 0x80, 0x90]);
        assert_eq!(enc(&lut(256)), [1, 0xFB, 0x00, 0x01, 0x90]);
        assert_eq!(enc(&None::<BrdfLutInfo>), [0]);
        assert_eq!(enc(&70_000u32), [0xFC, 0x70, 0x11, 0x01, 0x00]);
        assert_eq!(enc(&(1u64 << 40)), [0xFD, 0, 0, 0, 0, 0, 1, 0, 0]);
        assert_eq!(enc(&1.0f32), 1.0f32.to_le_bytes());
        assert_eq!(enc(&true), [1]);
        assert_eq!(enc(&"ab".to_string()), [2, b'a', b'b']);
        assert_eq!(enc(&vec![7u32, 300]), [2, 7, 0xFB, 0x2C, 0x01]);
        assert_eq!(enc(&[1u32, 2, 3]), [1, 2, 3]);
        assert_eq!(enc(&LightKind::Spot { inner_cone: 0.0, outer_cone: 1.0 })[..1], [1]);
        assert_eq!(enc(&LightKind::Spot { inner_cone: 0.0, outer_cone: 1.0 }).len(), 9);
        assert_eq!(enc(&ShadowProjection::Cube), [2]);
        // A longer varint than needed is accepted; a tag wider than the type is refused.
        let cfg = bincode::config::standard();
        assert_eq!(bincode::decode_from_slice::<u32, _>(&[0xFB, 5, 0], cfg).unwrap().0, 5);
        assert!(bincode::decode_from_slice::<u32, _>(&[0xFD, 5, 0, 0, 0, 0, 0, 0, 0], cfg).is_err());
        assert!(bincode::decode_from_slice::<bool, _>(&[2], cfg).is_err());
        assert!(bincode::decode_from_slice::<Option<u32>, _>(&[2, 0], cfg).is_err());
        assert!(bincode::decode_from_slice::<ShadowProjection, _>(&[3], cfg).is_err());
    }
}
