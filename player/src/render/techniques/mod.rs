//! Techniques as modules: one folder per effect, one module per technique. A technique's module
//! holds its settings (its knobs as named fields, declared with their ranges, defaults, sweep
//! values and help), what it reads from the file ([`Needs`]), the passes it adds to the frame
//! ([`Technique::passes`]), the frame inputs it sets (flags, the ray-traced passes' constants),
//! its fallback while ray-traced pipelines compile, and its warnings.
//!
//! Each effect's `mod.rs` registers its techniques in one [`techniques!`] list, which makes the
//! effect's enum (one variant per technique, carrying its settings), its part of the
//! [`catalogue`] and the name mapping. The command line (`crate::cli`) and the benchmark's sweep
//! (`crate::sweep`) are generated from the catalogue; `docs/contributing.md` says how to add a
//! technique.

use std::fmt;
use std::sync::LazyLock;

use crate::scene::linespace::LsArrays;

pub mod knobs;

pub mod aa;
pub mod ao;
pub mod denoise;
pub mod direct;
pub mod gbuffer;
pub mod gi;
pub mod media;
pub mod reflections;
pub mod shadows;

pub use aa::Aa;
pub use ao::Ao;
pub use denoise::Denoise;
pub use direct::Direct;
pub use gbuffer::GBuffer;
pub use gi::Gi;
pub use knobs::{Knob, KnobRange, KnobRole, KnobValue, Knobs};
pub use media::Media;
pub use reflections::Reflections;
pub use shadows::Shadows;

use super::frame::FrameBuild;
use super::passes::denoise::Noisy;
use super::passes::rt_history::Accumulated;

/// What a technique does beyond its passes, each with the answer of a technique that does
/// nothing. Implemented by every technique module; reached through its effect's enum
/// ([`Techniques::get`]).
pub trait Technique: fmt::Debug + Send + Sync {
    /// The sections of a `.kiln` file it reads beyond the frame's own ([`Needs::FRAME`]).
    fn needs(&self) -> Needs {
        Needs::NONE
    }

    /// Whether it traces rays (through the BVH or the line space): such pipelines compile
    /// slowly, and a file without a BVH cannot run it.
    fn ray_traced(&self) -> bool {
        false
    }

    /// The technique of its effect (by catalogue name, at its defaults) that stands in while
    /// the ray-traced pipelines compile; `None`: it stands for itself. `shadow_maps`: whether
    /// the file has shadow maps.
    fn fallback(&self, _shadow_maps: bool) -> Option<&'static str> {
        self.ray_traced().then_some("none")
    }

    /// Adds its passes to the frame, each at its stage, and the shared prerequisites they read.
    fn passes<'a>(&'a self, _frame: &mut FrameBuild<'a>) {}

    /// The frame flags (`kiln_format::gpu::FrameFlags`) it raises; the direct-light pass is
    /// specialised for them.
    fn flags(&self) -> u32 {
        0
    }

    /// Sets its part of the ray-traced passes' constants and the lights' sizes.
    fn rays(&self, _scene: &RayScene, _inputs: &mut RayInputs) {}

    /// The target it makes that the reprojected accumulation carries across frames, for a
    /// scene of `lights` lights (the ray-traced techniques' one sample per pixel per frame).
    fn accumulated(&self, _lights: usize) -> Option<Accumulated> {
        None
    }

    /// The noisy signal it makes that a denoiser may filter (its one sample per pixel per frame
    /// of light the composition reads).
    fn noisy(&self) -> Option<Noisy> {
        None
    }

    /// Whether it dims the light reaching surfaces, and the surfaces seen, through the media.
    fn dims_surfaces(&self) -> bool {
        false
    }

    /// Whether it shows the previous frame's radiance (the first frame lacks it).
    fn reads_previous_frame(&self) -> bool {
        false
    }

    /// A shadows technique whose rays go through the line space: `Some(exact)` (exact triangle
    /// tests in every filled shaft, or only near the rays' ends), so that the emissive
    /// surfaces' shadow rays take the same way; `None` (the BVH) for every other.
    fn line_space_visibility(&self) -> Option<bool> {
        None
    }

    /// What happens to the stochastic passes' samples across frames (the anti-aliasing
    /// techniques say; the others keep no history).
    fn history(&self) -> History {
        History::None
    }

    /// Whether frames are jittered and resolved through a history (temporal anti-aliasing).
    fn temporal(&self) -> bool {
        false
    }

    /// Warnings for a file that lacks what it reads, named as the user chose it (`flag`:
    /// `--media toth`).
    fn warnings(&self, _flag: &str, _manifest: &kiln_format::Manifest, _warnings: &mut Vec<String>) {}
}

/// A technique as its module registers it: its catalogue entry and how it is built from knob
/// values.
pub trait Registered: Technique + Sized {
    /// Name (the command-line value).
    const NAME: &'static str;
    /// What it does (`--help`).
    const HELP: &'static str;
    /// Its knobs.
    const KNOBS: &'static [Knob] = &[];
    /// Whether its result improves with frames accumulated (a sweep varies the frame count).
    const STOCHASTIC: bool = false;

    /// The technique with `knobs`' values.
    fn new(knobs: &Knobs) -> Result<Self, String>;
}

/// What the stochastic passes' samples do across frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum History {
    /// Every frame shows its own samples.
    None,
    /// A running mean while the camera is still; any change of view restarts it.
    Still,
    /// A running mean carried along while the camera moves, at most this many frames long
    /// while it moves.
    Reprojected(u32),
}

/// What the ray-traced passes' constants are computed from.
#[derive(Debug, Clone, Copy)]
pub struct RayScene {
    /// The scene's bounding-box diagonal.
    pub diagonal: f32,
    /// Analytic lights the frame draws.
    pub lights_used: usize,
}

/// What the techniques set for the ray-traced passes: their constants (push constants) and the
/// analytic lights' sizes.
#[derive(Debug, Clone, Copy)]
pub struct RayInputs {
    /// The constants.
    pub rt: kiln_format::gpu::RtConstants,
    /// Sphere radius of point and spot lights in scene units.
    pub light_radius: f32,
    /// Angular diameter of directional lights in degrees.
    pub sun_degrees: f32,
}

impl RayInputs {
    /// What a frame without ray-traced techniques holds (read by no pass): AO radius 0.1 times
    /// the diagonal, no roughness limit, one ray per pixel.
    pub fn unset(scene: &RayScene) -> RayInputs {
        RayInputs {
            rt: kiln_format::gpu::RtConstants {
                ao_radius: (0.1 * scene.diagonal).max(1e-6),
                max_roughness: 1.0,
                reflection_step: 1,
                direct_visibility: 1,
                ..Default::default()
            },
            light_radius: 0.0,
            sun_degrees: 0.0,
        }
    }
}

/// Makes an effect's enum from its technique modules: `techniques! { ... }` in the effect's
/// `mod.rs`, one line per technique (`module => Type,`), which also declares the module. The
/// enum has one variant per technique, named as its type and carrying its settings; it lists
/// its techniques for the catalogue (in this order), names them and builds them from knobs.
macro_rules! techniques {
    (
        $(#[$doc:meta])*
        $enum:ident for $effect:ident, default $dmod:ident :: $dty:ident;
        $($module:ident => $ty:ident,)+
    ) => {
        $(pub mod $module;)+

        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum $enum {
            $(
                #[doc = concat!("`--", stringify!($module), "`: see [`", stringify!($module), "::", stringify!($ty), "`].")]
                $ty($module::$ty),
            )+
        }

        impl $enum {
            /// This effect's techniques as data, in catalogue order.
            pub fn catalogue() -> Vec<$crate::render::techniques::TechniqueInfo> {
                vec![$($crate::render::techniques::TechniqueInfo::of::<$module::$ty>(
                    $crate::render::techniques::Effect::$effect,
                ),)+]
            }

            /// The technique's behaviour.
            pub fn technique(&self) -> &dyn $crate::render::techniques::Technique {
                match self {
                    $($enum::$ty(t) => t,)+
                }
            }

            /// Its catalogue name.
            pub fn name(&self) -> &'static str {
                match self {
                    $($enum::$ty(_) => <$module::$ty as $crate::render::techniques::Registered>::NAME,)+
                }
            }

            /// The technique `name` built from `knobs`; `None` when no technique has that name.
            pub fn build(
                name: &str,
                knobs: &$crate::render::techniques::Knobs,
            ) -> Option<Result<$enum, String>> {
                use $crate::render::techniques::Registered;
                $(
                    if name == <$module::$ty as Registered>::NAME {
                        return Some(<$module::$ty as Registered>::new(knobs).map($enum::$ty));
                    }
                )+
                None
            }
        }

        impl Default for $enum {
            /// The default technique at its knobs' defaults.
            fn default() -> $enum {
                use $crate::render::techniques::{Knobs, Registered};
                let knobs = Knobs::defaults(String::new(), <$dmod::$dty as Registered>::KNOBS);
                $enum::$dty(<$dmod::$dty as Registered>::new(&knobs).expect("a technique builds at its defaults"))
            }
        }
    };
}
pub(crate) use techniques;

/// A technique without knobs: its unit struct and its registration (`NAME`, `HELP`); the module
/// still writes `impl Technique`.
macro_rules! plain_technique {
    ($(#[$doc:meta])* $ty:ident, $name:literal, $help:expr) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
        pub struct $ty;

        impl $crate::render::techniques::Registered for $ty {
            const NAME: &'static str = $name;
            const HELP: &'static str = $help;

            fn new(_: &$crate::render::techniques::Knobs) -> Result<$ty, String> {
                Ok($ty)
            }
        }
    };
}
pub(crate) use plain_technique;

/// One technique per effect: what a frame renders.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Techniques {
    /// How the G-buffer is made.
    pub gbuffer: GBuffer,
    /// Shadows.
    pub shadows: Shadows,
    /// Direct light of emissive surfaces.
    pub direct: Direct,
    /// Ambient occlusion.
    pub ao: Ao,
    /// Reflections.
    pub reflections: Reflections,
    /// Global illumination.
    pub gi: Gi,
    /// Participating media.
    pub media: Media,
    /// Accumulation / anti-aliasing.
    pub aa: Aa,
    /// Denoising of the ray-traced signals.
    pub denoise: Denoise,
}

/// The sections of a `.kiln` file the chosen passes read (geometry always).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Needs {
    /// Material textures.
    pub textures: bool,
    /// The split-sum BRDF table.
    pub brdf_lut: bool,
    /// Shadow maps.
    pub shadow_maps: bool,
    /// The BVH and its triangles, for ray queries.
    pub bvh: bool,
    /// Materials, per-triangle materials, texels and the emitter table as storage buffers
    /// (what passes that shade surfaces in compute read).
    pub scene_buffers: bool,
    /// Arrays of the voxel grid and line space ([`crate::scene::linespace::LsArrays`] bits).
    pub line_space: u32,
    /// The media table (from the manifest).
    pub media: bool,
    /// The light-visibility volumes (`MVIS` sections).
    pub media_volumes: bool,
    /// The irradiance probe volume (`PRBG`, `PRBS`, `PRBI`, `PRBV`).
    pub probes: bool,
    /// The irradiance probe volume where the file has one (the ray-traced reflections light
    /// their hits with it; without, with the sky).
    pub probes_if_present: bool,
    /// The texel buffer decoded to RGBA8 where the file stores block-compressed textures: four
    /// times the memory, no BC decoding in the shaders (the reference path tracer's, which
    /// reads five textures at every vertex of ToyCar).
    pub decoded_texels: bool,
}

impl Needs {
    /// Both sets together.
    pub fn union(self, o: Needs) -> Needs {
        Needs {
            textures: self.textures || o.textures,
            brdf_lut: self.brdf_lut || o.brdf_lut,
            shadow_maps: self.shadow_maps || o.shadow_maps,
            bvh: self.bvh || o.bvh,
            scene_buffers: self.scene_buffers || o.scene_buffers,
            line_space: self.line_space | o.line_space,
            media: self.media || o.media,
            media_volumes: self.media_volumes || o.media_volumes,
            probes: self.probes || o.probes,
            probes_if_present: self.probes_if_present || o.probes_if_present,
            decoded_texels: self.decoded_texels || o.decoded_texels,
        }
    }

    /// Whether the probe volume is read (required or where present).
    pub fn any_probes(self) -> bool {
        self.probes || self.probes_if_present
    }

    /// What `self` reads beyond `o`.
    pub fn minus(self, o: Needs) -> Needs {
        Needs {
            textures: self.textures && !o.textures,
            brdf_lut: self.brdf_lut && !o.brdf_lut,
            shadow_maps: self.shadow_maps && !o.shadow_maps,
            bvh: self.bvh && !o.bvh,
            scene_buffers: self.scene_buffers && !o.scene_buffers,
            line_space: self.line_space & !o.line_space,
            media: self.media && !o.media,
            media_volumes: self.media_volumes && !o.media_volumes,
            probes: self.probes && !o.probes,
            probes_if_present: self.probes_if_present && !o.any_probes(),
            decoded_texels: self.decoded_texels && !o.decoded_texels,
        }
    }

    /// Nothing.
    pub const NONE: Needs = Needs {
        textures: false,
        brdf_lut: false,
        shadow_maps: false,
        bvh: false,
        scene_buffers: false,
        line_space: 0,
        media: false,
        media_volumes: false,
        probes: false,
        probes_if_present: false,
        decoded_texels: false,
    };
    /// What ray queries through the BVH read.
    pub const RAYS: Needs = Needs { bvh: true, ..Needs::NONE };
    /// What the ray-traced passes and the path tracer read: the BVH and the surfaces it hits.
    pub const TRACED_SURFACES: Needs = Needs { bvh: true, scene_buffers: true, ..Needs::NONE };
    /// What the G-buffer and the direct-light pass always read.
    pub const FRAME: Needs = Needs { textures: true, brdf_lut: true, ..Needs::NONE };
}

/// A resolution as a fraction of the screen's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScreenFraction {
    /// The screen's.
    Full,
    /// Half on each axis.
    Half,
    /// A quarter on each axis (the seed's 200 × 150 at 800 × 600).
    Quarter,
}

impl ScreenFraction {
    /// Screen pixels per image pixel along each axis.
    pub fn divisor(self) -> u32 {
        match self {
            ScreenFraction::Full => 1,
            ScreenFraction::Half => 2,
            ScreenFraction::Quarter => 4,
        }
    }

    /// The fraction a resolution knob's option names (`full`, `half`, `quarter`).
    pub fn named(option: &str) -> ScreenFraction {
        match option {
            "full" => ScreenFraction::Full,
            "half" => ScreenFraction::Half,
            _ => ScreenFraction::Quarter,
        }
    }
}

impl Techniques {
    /// The technique chosen for `effect`.
    pub fn get(&self, effect: Effect) -> &dyn Technique {
        match effect {
            Effect::GBuffer => self.gbuffer.technique(),
            Effect::Shadows => self.shadows.technique(),
            Effect::Direct => self.direct.technique(),
            Effect::Ao => self.ao.technique(),
            Effect::Reflections => self.reflections.technique(),
            Effect::Gi => self.gi.technique(),
            Effect::Media => self.media.technique(),
            Effect::Aa => self.aa.technique(),
            Effect::Denoise => self.denoise.technique(),
        }
    }

    /// The technique each effect uses now, by catalogue name.
    pub fn name_of(&self, effect: Effect) -> &'static str {
        match effect {
            Effect::GBuffer => self.gbuffer.name(),
            Effect::Shadows => self.shadows.name(),
            Effect::Direct => self.direct.name(),
            Effect::Ao => self.ao.name(),
            Effect::Reflections => self.reflections.name(),
            Effect::Gi => self.gi.name(),
            Effect::Media => self.media.name(),
            Effect::Aa => self.aa.name(),
            Effect::Denoise => self.denoise.name(),
        }
    }

    /// Every effect's technique, in frame order.
    pub fn each(&self) -> impl Iterator<Item = &dyn Technique> {
        Effect::ALL.into_iter().map(|e| self.get(e))
    }

    /// The sections these techniques read.
    pub fn needs(&self) -> Needs {
        let mut n = self.each().fold(Needs::FRAME, |n, t| n.union(t.needs()));
        if self.ray_traced() {
            // Surfaces at hits, and for GI the emitter table (made with the scene buffers).
            n = n.union(Needs::TRACED_SURFACES);
        }
        if n.line_space & LsArrays::CELL_LISTS != 0 {
            // Exact tests near the shadow feelers' ends read the shaft's candidates, when the
            // file has them, instead of the whole cell's triangles.
            n.line_space |= LsArrays::CANDIDATES_IF_PRESENT;
        }
        n
    }

    /// The frame flags these techniques raise: all but `SHADOW_MAPS`, which also depends on
    /// the file. The direct pass is specialised for these.
    pub fn flags(&self) -> u32 {
        self.each().fold(0, |f, t| f | t.flags())
    }

    /// The ray-traced passes' constants and the lights' sizes for a scene.
    pub fn rays(&self, scene: &RayScene) -> RayInputs {
        let mut inputs = RayInputs::unset(scene);
        for t in self.each() {
            t.rays(scene, &mut inputs);
        }
        inputs
    }

    /// Whether a technique dims surfaces through the media.
    pub fn dims_surfaces(&self) -> bool {
        self.each().any(|t| t.dims_surfaces())
    }

    /// Whether surfaces are lit with the file's shadow maps (the shadows technique reads them).
    pub fn shadow_mapped_surfaces(&self) -> bool {
        self.shadows.technique().needs().shadow_maps
    }

    /// The longest history of the ray-traced passes' reprojected accumulation while the camera
    /// moves, when it runs (a ray-traced pass and a reprojecting history): the passes then
    /// write each frame's sample and the history pass blends it.
    pub fn reprojected_rays(&self) -> Option<u32> {
        match self.aa.technique().history() {
            History::Reprojected(frames) if self.ray_traced() => Some(frames),
            _ => None,
        }
    }

    /// Whether a pass shows the previous frame's radiance (the screen-space reflections and GI
    /// read the lit pyramid): the first frame lacks it, so the image depends on the frame count.
    pub fn reads_previous_frame(&self) -> bool {
        self.each().any(|t| t.reads_previous_frame())
    }

    /// The noisy signals the denoiser filters: none without a denoiser, else those of the
    /// ray-traced techniques that make one, in frame order.
    pub fn noisy(&self) -> Vec<Noisy> {
        if matches!(self.denoise, Denoise::Off(_)) {
            return Vec::new();
        }
        self.each().filter_map(|t| t.noisy()).collect()
    }

    /// Whether any ray-traced pass runs.
    pub fn ray_traced(&self) -> bool {
        self.each().any(|t| t.ray_traced())
    }

    /// Every ray-traced technique replaced by its effect's `none` (what the frame falls back to
    /// when the file has no BVH).
    pub fn without_rays(self) -> Techniques {
        let mut t = self;
        for e in Effect::ALL {
            if self.get(e).ray_traced() {
                t.set(e, "none", &[]).expect("every effect with a ray-traced technique has 'none'");
            }
        }
        t
    }

    /// What a session shows while the ray-traced passes' pipelines compile (`None`: no pass is
    /// ray traced, nothing to wait for): each technique's [`Technique::fallback`] (shadows from
    /// the file's shadow maps when it has them, `shadow_maps`, reflections by the split-sum
    /// ambient, AO off, GI by the sky's ambient); the other effects keep their techniques.
    pub fn fallback(&self, shadow_maps: bool) -> Option<Techniques> {
        if !self.ray_traced() {
            return None;
        }
        let mut t = *self;
        for e in Effect::ALL {
            if let Some(name) = self.get(e).fallback(shadow_maps) {
                t.set(e, name, &[]).expect("a fallback names a technique of its effect");
            }
        }
        Some(t)
    }

    /// The effects whose technique differs in `other`: (effect, this one's name, `other`'s).
    pub fn differences(&self, other: &Techniques) -> Vec<(Effect, &'static str, &'static str)> {
        Effect::ALL
            .into_iter()
            .filter(|&e| self.name_of(e) != other.name_of(e))
            .map(|e| (e, self.name_of(e), other.name_of(e)))
            .collect()
    }

    /// Warnings for what the file lacks that the chosen techniques read.
    pub fn warnings(&self, manifest: &kiln_format::Manifest) -> Vec<String> {
        let mut warnings = Vec::new();
        if !matches!(self.denoise, Denoise::Off(_)) && self.noisy().is_empty() {
            warnings.push(format!(
                "--denoise {}: no ray-traced signal to filter in this frame (it filters --gi rt|linespace and \
                 --direct ris|restir); it does nothing",
                self.denoise.name()
            ));
        }
        for e in Effect::ALL {
            let flag = format!("--{e} {}", self.name_of(e));
            self.get(e).warnings(&flag, manifest, &mut warnings);
        }
        warnings
    }

    /// The technique `name` for `effect` with `knobs` (name, value) set, the others at their
    /// defaults; errors name the effect, technique or knob and the valid values.
    pub fn set(&mut self, effect: Effect, name: &str, knobs: &[(&str, KnobValue)]) -> Result<(), String> {
        let info = techniques_of(effect).find(|t| t.name == name).ok_or_else(|| {
            let names: Vec<&str> = techniques_of(effect).map(|t| t.name).collect();
            format!("{effect}: no technique '{name}' (one of: {})", names.join(", "))
        })?;
        let mut values = Knobs::defaults(format!("{effect} {name}"), info.knobs);
        for (knob, value) in knobs {
            values.set(knob, *value)?;
        }
        fn built<T>(made: Option<Result<T, String>>) -> Result<T, String> {
            made.expect("every catalogue entry is registered by its effect's enum")
        }
        match effect {
            Effect::GBuffer => self.gbuffer = built(GBuffer::build(name, &values))?,
            Effect::Shadows => self.shadows = built(Shadows::build(name, &values))?,
            Effect::Direct => self.direct = built(Direct::build(name, &values))?,
            Effect::Ao => self.ao = built(Ao::build(name, &values))?,
            Effect::Reflections => self.reflections = built(Reflections::build(name, &values))?,
            Effect::Gi => self.gi = built(Gi::build(name, &values))?,
            Effect::Media => self.media = built(Media::build(name, &values))?,
            Effect::Aa => self.aa = built(Aa::build(name, &values))?,
            Effect::Denoise => self.denoise = built(Denoise::build(name, &values))?,
        }
        Ok(())
    }
}

/// An effect: something a frame shows, made by one of several techniques.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Effect {
    /// How surfaces are found per pixel.
    GBuffer,
    /// Shadows of analytic lights.
    Shadows,
    /// Direct light of emissive surfaces.
    Direct,
    /// Ambient occlusion.
    Ao,
    /// Specular reflections.
    Reflections,
    /// Indirect diffuse light.
    Gi,
    /// Participating media.
    Media,
    /// Accumulation and anti-aliasing.
    Aa,
    /// Denoising of the ray-traced signals.
    Denoise,
}

impl Effect {
    /// Every effect, in frame order.
    pub const ALL: [Effect; 9] = [
        Effect::GBuffer,
        Effect::Shadows,
        Effect::Direct,
        Effect::Ao,
        Effect::Reflections,
        Effect::Gi,
        Effect::Media,
        Effect::Aa,
        Effect::Denoise,
    ];

    /// The effect's name (also its command-line flag without `--`).
    pub fn name(self) -> &'static str {
        match self {
            Effect::GBuffer => "gbuffer",
            Effect::Shadows => "shadows",
            Effect::Direct => "direct",
            Effect::Ao => "ao",
            Effect::Reflections => "reflections",
            Effect::Gi => "gi",
            Effect::Media => "media",
            Effect::Aa => "aa",
            Effect::Denoise => "denoise",
        }
    }

    /// What it is, as `--help` heads its flags.
    pub fn title(self) -> &'static str {
        match self {
            Effect::GBuffer => "G-buffer",
            Effect::Shadows => "Shadows",
            Effect::Direct => "Direct light of emissive surfaces",
            Effect::Ao => "Ambient occlusion",
            Effect::Reflections => "Reflections",
            Effect::Gi => "Global illumination",
            Effect::Media => "Participating media",
            Effect::Aa => "Accumulation and anti-aliasing",
            Effect::Denoise => "Denoising of the ray-traced signals",
        }
    }

    /// Its techniques as data, in catalogue order.
    fn techniques(self) -> Vec<TechniqueInfo> {
        match self {
            Effect::GBuffer => GBuffer::catalogue(),
            Effect::Shadows => Shadows::catalogue(),
            Effect::Direct => Direct::catalogue(),
            Effect::Ao => Ao::catalogue(),
            Effect::Reflections => Reflections::catalogue(),
            Effect::Gi => Gi::catalogue(),
            Effect::Media => Media::catalogue(),
            Effect::Aa => Aa::catalogue(),
            Effect::Denoise => Denoise::catalogue(),
        }
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A technique of an effect, as data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TechniqueInfo {
    /// The effect.
    pub effect: Effect,
    /// Name (the command-line value).
    pub name: &'static str,
    /// What it does.
    pub help: &'static str,
    /// Its quality knobs.
    pub knobs: &'static [Knob],
    /// Whether its result improves with frames accumulated (a sweep varies the frame count).
    pub stochastic: bool,
}

impl TechniqueInfo {
    /// The entry of the technique `T` of `effect`.
    pub fn of<T: Registered>(effect: Effect) -> TechniqueInfo {
        TechniqueInfo { effect, name: T::NAME, help: T::HELP, knobs: T::KNOBS, stochastic: T::STOCHASTIC }
    }
}

static CATALOGUE: LazyLock<Vec<TechniqueInfo>> =
    LazyLock::new(|| Effect::ALL.into_iter().flat_map(Effect::techniques).collect());

/// Every technique of every effect with its knobs, effect by effect in frame order.
pub fn catalogue() -> &'static [TechniqueInfo] {
    &CATALOGUE
}

/// The techniques of one effect, in catalogue order.
pub fn techniques_of(effect: Effect) -> impl Iterator<Item = &'static TechniqueInfo> {
    catalogue().iter().filter(move |t| t.effect == effect)
}

/// The techniques (at their defaults) that read what `reads` says of their needs, as the
/// command line chooses them (`--shadows shadowmap, --media toth`): where the player says why a
/// section is not uploaded.
pub fn readers(reads: impl Fn(&Needs) -> bool) -> Vec<String> {
    catalogue()
        .iter()
        .filter(|info| {
            let mut t = Techniques::default();
            t.set(info.effect, info.name, &[]).is_ok() && reads(&t.get(info.effect).needs())
        })
        .map(|info| format!("--{} {}", info.effect, info.name))
        .collect()
}

#[cfg(test)]
mod tests;
