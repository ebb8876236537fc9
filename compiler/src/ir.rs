//! The scene IR: what every importer produces and every bake stage reads. Plain data, world
//! space, no loader types.

use std::path::PathBuf;

use kiln_format::manifest::{Camera, ColorSpace, Light, Medium, OrthographicCamera, Sky, Wrap};
use kiln_format::sections::{GpuMaterial, Vertex};

/// A white vertex colour, unorm16.
pub const WHITE: [u16; 4] = [u16::MAX; 4];

/// A material: shading parameters as stored, plus its name.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name in the asset (or generated).
    pub name: String,
    /// Shading parameters; texture slots index [`Scene::textures`].
    pub gpu: GpuMaterial,
}

/// What a texture is sampled for; decides its colour space and its placeholder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TextureRole {
    /// sRGB colour (base colour, emissive).
    Color,
    /// Linear data (metallic-roughness, occlusion).
    Data,
    /// Tangent-space normal map (linear; placeholder is the flat normal).
    Normal,
}

impl TextureRole {
    /// Colour space of textures in this role.
    pub fn color_space(self) -> ColorSpace {
        match self {
            TextureRole::Color => ColorSpace::Srgb,
            TextureRole::Data | TextureRole::Normal => ColorSpace::Linear,
        }
    }

    /// The texel that stands in for an image that could not be read: neutral for the role.
    pub fn placeholder(self) -> [u8; 4] {
        match self {
            TextureRole::Color | TextureRole::Data => [255, 255, 255, 255],
            TextureRole::Normal => [128, 128, 255, 255],
        }
    }
}

/// A decoded texture (mip 0 only; the texture bake builds the chain).
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// Image name or URI, for messages and the manifest.
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// RGBA8 texels, rows top to bottom.
    pub rgba: Vec<u8>,
    /// Role (colour space).
    pub role: TextureRole,
    /// Wrap along u.
    pub wrap_u: Wrap,
    /// Wrap along v.
    pub wrap_v: Wrap,
    /// Linear magnification.
    pub mag_linear: bool,
}

/// What a warning is about, so that a build can choose which ones fail it (`--strict` fails on
/// data loss only; `-W CLASS=error|warn|ignore` sets any class).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WarningClass {
    /// The file is not what the asset says: something was dropped or changed (an unsupported
    /// extension, a skipped primitive, an unreadable image, degenerate triangles, a material
    /// mapping that loses a term).
    DataLoss,
    /// The asset lacks what rendering needs and kiln made it up or found nothing (no camera,
    /// nothing that lights the scene): a sidecar supplies it.
    MissingSetup,
    /// The file is what the asset says but costs more than it needs to (instances flattened
    /// into copies of their triangles).
    Performance,
}

impl WarningClass {
    /// Every class.
    pub const ALL: [WarningClass; 3] =
        [WarningClass::DataLoss, WarningClass::MissingSetup, WarningClass::Performance];

    /// The class's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            WarningClass::DataLoss => "data-loss",
            WarningClass::MissingSetup => "missing-setup",
            WarningClass::Performance => "performance",
        }
    }
}

/// A non-fatal problem found while importing, with the object it concerns.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// What kind of problem.
    pub class: WarningClass,
    /// The message, naming file and object.
    pub message: String,
}

/// An imported scene.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// Scene name (the input's file stem).
    pub name: String,
    /// Where positions are measured from (world = stored + origin): zero unless the scene lies
    /// far from the world's origin for its size (`import::geometry::rebase_origin`). Vertices,
    /// lights, cameras and media are all stored relative to it.
    pub origin: [f64; 3],
    /// Vertices, relative to `origin`.
    pub vertices: Vec<Vertex>,
    /// Texture coordinate per vertex.
    pub uvs: Vec<[f32; 2]>,
    /// Vertex colour per vertex (unorm16 linear RGBA), or empty when every vertex is white.
    pub colors: Vec<[u16; 4]>,
    /// Triangles (vertex index triples), front faces counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Material of each triangle.
    pub triangle_materials: Vec<u32>,
    /// Materials.
    pub materials: Vec<Material>,
    /// Textures referenced by materials.
    pub textures: Vec<Texture>,
    /// Analytic lights.
    pub lights: Vec<Light>,
    /// Cameras, default first.
    pub cameras: Vec<Camera>,
    /// Which of `cameras` are orthographic, with their extents (indices into `cameras`).
    pub orthographic: Vec<OrthographicCamera>,
    /// Sky: constant radiance (with an environment, its mean radiance).
    pub sky: Sky,
    /// The environment's light in every direction, when one was given (`[sky] image`/`model`,
    /// `--environment`, the glTF's `EXT_lights_image_based`): baked by the `environment` stage.
    pub environment: Option<EnvironmentImage>,
    /// The name of `environment` while it is the one the asset gave (glTF
    /// `EXT_lights_image_based`), for the warning when a sidecar's or the command line's sky
    /// replaces it (`import::environment::replace_asset_environment`).
    pub asset_environment: Option<String>,
    /// Participating media.
    pub media: Vec<Medium>,
    /// Every file read (asset, buffers, images, sidecar), in reading order.
    pub inputs: Vec<PathBuf>,
    /// Warnings.
    pub warnings: Vec<Warning>,
    /// Degenerate triangles dropped.
    pub degenerate_triangles: u64,
}

/// An environment as the import left it: linear RGB radiance in an equirectangular map (the
/// mapping of `kiln_format::environment`, row 0 the zenith), intensity applied.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EnvironmentImage {
    /// Where it came from (a path or the model), for messages and the report.
    pub name: String,
    /// Width in pixels (twice the height).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Radiance per pixel, rows top (zenith) to bottom.
    pub pixels: Vec<[f32; 3]>,
    /// Rotation about +y, degrees, applied when the bake resamples it.
    pub rotation_degrees: f32,
}

impl Scene {
    /// Whether anything lights the scene: an analytic light, an emissive material, the constant
    /// sky or an environment that is not black.
    pub fn lit(&self) -> bool {
        !self.lights.is_empty()
            || self.materials.iter().any(|m| m.gpu.emission.iter().any(|&e| e > 0.0))
            || self.sky.radiance.iter().any(|&r| r > 0.0)
            || self.environment.as_ref().is_some_and(|e| e.pixels.iter().flatten().any(|&c| c > 0.0))
    }

    /// Whether a sky lights the scene: an environment, or a constant sky of non-zero radiance (what
    /// the media's sky grids are baked for).
    pub fn sky_lights(&self) -> bool {
        self.environment.is_some() || kiln_format::gpu::luminance(self.sky.radiance) > 0.0
    }

    /// Records a warning of data loss (what most import warnings are).
    pub fn warn(&mut self, message: impl Into<String>) {
        self.warn_as(WarningClass::DataLoss, message);
    }

    /// Records a warning of class `class`.
    pub fn warn_as(&mut self, class: WarningClass, message: impl Into<String>) {
        self.warnings.push(Warning { class, message: message.into() });
    }

    /// Records the colours of the vertices from `first` on (`None`: white), keeping
    /// [`Scene::colors`] empty while every vertex is white and one per vertex once one is not.
    pub fn set_colors(&mut self, first: usize, colors: Option<Vec<[u16; 4]>>) {
        let count = self.vertices.len() - first;
        match colors {
            Some(c) if c.iter().any(|&c| c != WHITE) => {
                debug_assert_eq!(c.len(), count);
                self.colors.resize(first, WHITE);
                self.colors.extend(c);
            }
            _ if !self.colors.is_empty() => self.colors.resize(first + count, WHITE),
            _ => {}
        }
    }

    /// Whether some material samples a texture.
    pub fn uses_textures(&self) -> bool {
        self.materials
            .iter()
            .any(|m| m.gpu.textures().iter().any(|&t| t != kiln_format::sections::NO_TEXTURE))
    }
}
