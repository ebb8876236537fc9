//! Techniques as values: one enum per effect, each variant carrying its quality knobs. A
//! technique knows the passes it runs ([`super::passes`]) and the `.kiln` sections they read
//! ([`Needs`]); the player uploads exactly the union of those sections.
//!
//! [`catalogue`] lists every technique of every effect with its knobs as data, so that a
//! benchmark can sweep them without knowing any by name, and [`Techniques::set`] builds a
//! technique from such a description (the command line goes through the same door).

use std::fmt;

use crate::scene::linespace::LsArrays;

/// Resolution of the ray-traced reflections.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReflectionRes {
    /// One ray per pixel.
    Full,
    /// One ray per 2 × 2 pixels, upsampled with normal- and plane-aware weights.
    Half,
}

/// How the G-buffer is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GBuffer {
    /// Rasterised with every material evaluated per fragment (five targets).
    #[default]
    Raster,
    /// A visibility buffer (the triangle under each pixel) rasterised, the materials evaluated in
    /// compute: far cheaper where raster throughput is small next to compute (datacenter GPUs).
    Visibility,
}

/// Shadows of the analytic lights.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Shadows {
    /// Every light unshadowed.
    None,
    /// The compiler's baked shadow maps (PCF; PCSS for rect lights).
    #[default]
    ShadowMap,
    /// One ray per light per pixel per frame towards a point sampled on the light.
    Rt {
        /// Sphere radius of point and spot lights in scene units (0: hard shadows).
        light_radius: f32,
        /// Angular diameter of directional lights in degrees (0: hard).
        sun_degrees: f32,
    },
    /// The same estimator with its rays through the binary line space (seed 004's shadow
    /// feelers).
    LineSpace {
        /// As for [`Shadows::Rt`].
        light_radius: f32,
        /// As for [`Shadows::Rt`].
        sun_degrees: f32,
        /// How a filled shaft is decided.
        test: LsShadowTest,
    },
}

impl Shadows {
    /// The light sizes of a traced technique (point/spot radius, sun degrees); `None` for the
    /// others.
    pub fn traced(&self) -> Option<(f32, f32)> {
        match *self {
            Shadows::Rt { light_radius, sun_degrees }
            | Shadows::LineSpace { light_radius, sun_degrees, .. } => Some((light_radius, sun_degrees)),
            _ => None,
        }
    }
}

/// How line-space shadow feelers decide a filled shaft.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LsShadowTest {
    /// Exact triangle tests in the cells holding the ray's ends, a filled shaft elsewhere counts
    /// as occluded: conservative (never a missed occluder), the cheapest.
    Ends,
    /// Exact triangle tests wherever the shaft is filled: the exact answer, the bits skipping
    /// empty shafts.
    Filled,
}

/// Ambient occlusion.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Ao {
    /// None (the material's occlusion texture still applies).
    #[default]
    None,
    /// One cosine-weighted ray per pixel per frame; a hit at t weighs (t/R)².
    Rt {
        /// Ray length R in scene units; `None`: `reach` times the scene's bounding-box diagonal.
        radius: Option<f32>,
        /// R as a fraction of the scene's bounding-box diagonal (when `radius` is `None`); large
        /// values (≥ 10) make every hit occlude fully: the sky's visibility.
        reach: f32,
    },
    /// Scalable ambient obscurance as the seed modifies it (seed 000 §2.3): spiral samples of
    /// a camera-space depth pyramid and the G-buffer normals, blurred with depth weights.
    Sao {
        /// World radius r in scene units; `None`: `reach` times the scene's diagonal.
        radius: Option<f32>,
        /// r as a fraction of the scene's bounding-box diagonal (when `radius` is `None`).
        reach: f32,
        /// Samples per AO pixel (the seed's N = 16).
        samples: u32,
        /// Turns of the sample spiral (τ).
        turns: f32,
        /// Full or half resolution (the seed's default: half).
        resolution: ScreenFraction,
    },
    /// Ground-truth AO (Jimenez et al. 2016): horizons searched along screen-space slices, the
    /// cosine-weighted visibility between them integrated with the projected normal.
    Gtao {
        /// World radius R in scene units; `None`: `reach` times the scene's diagonal.
        radius: Option<f32>,
        /// R as a fraction of the scene's bounding-box diagonal (when `radius` is `None`).
        reach: f32,
        /// Slices (screen directions) per pixel.
        slices: u32,
        /// Samples along each side of a slice.
        steps: u32,
    },
}

impl Ao {
    /// The radius in scene units for a scene of bounding-box diagonal `diagonal` (the ray
    /// length of `Rt`, the world radius of the screen-space techniques); without AO, 0.1 times
    /// the diagonal (what the ray-traced passes' constants then hold, unread).
    pub fn world_radius(&self, diagonal: f32) -> f32 {
        match *self {
            Ao::Rt { radius, reach } | Ao::Sao { radius, reach, .. } | Ao::Gtao { radius, reach, .. } => {
                radius.unwrap_or(reach * diagonal)
            }
            Ao::None => 0.1 * diagonal,
        }
    }
}

/// Specular reflections beyond the split-sum ambient.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Reflections {
    /// The split-sum ambient only.
    #[default]
    None,
    /// One GGX visible-normal sample per pixel (or per 2 × 2) per frame, shaded at the hit.
    Rt {
        /// Full or half resolution.
        resolution: ReflectionRes,
        /// Surfaces rougher than this keep the split-sum ambient.
        max_roughness: f32,
    },
    /// Screen-space reflections (seed 000 §3.9, traced hierarchically after McGuire & Mara 2014
    /// and AMD's FidelityFX SSSR): the mirror direction marched through a closest-depth (Hi-Z)
    /// pyramid, a hit accepted at the coarsest level the roughness's cone covers, showing the
    /// previous frame's lit radiance; the split-sum ambient where the ray misses or leaves the
    /// screen (`passes/ssr.rs`).
    Ssr {
        /// The most iterations of the hierarchical march per pixel.
        steps: u32,
        /// Surfaces rougher than this keep the split-sum ambient.
        max_roughness: f32,
    },
}

/// Indirect diffuse light: what replaces the sky's diffuse ambient.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Gi {
    /// None: the constant sky, darkened by AO where it runs.
    #[default]
    None,
    /// Path traced from the G-buffer through the CWBVH: one cosine-weighted path per pixel per
    /// frame, next-event estimation at its hits (`shaders/rt/gi.glsl`).
    Rt {
        /// Scattering events after the primary surface whose light counts (1: the sky, and
        /// what the first surface hit emits and receives directly), 1..=8.
        bounces: u32,
    },
    /// The same estimator with its rays through the line space (seed 004).
    LineSpace {
        /// As for [`Gi::Rt`].
        bounces: u32,
        /// What answers the bounce rays.
        structure: GiStructure,
    },
    /// Screen-space diffuse GI (seed 000): the previous frame's lit radiance gathered on
    /// spirals over a MIP hierarchy of depth, normals and light, joint-bilaterally upsampled;
    /// added to the sky's ambient.
    Ssgi {
        /// Spiral samples per pixel and level (the seed's 128).
        samples: u32,
        /// The finest level gathered: full, half (the seed's default, ~540p at 1080p) or quarter.
        resolution: ScreenFraction,
        /// Sample radius R in pixels of each level (the seed's 40).
        radius: u32,
        /// The depth and normal pyramids reduced by the seed's voting filter (else nearest).
        voting: bool,
        /// The seed's distance fall-off in place of visibility.
        falloff: bool,
        /// The most frames the running mean averages while the camera is still.
        frames: u32,
        /// One spiral rotation per 8 × 8 block of texels instead of per texel.
        tiled: bool,
    },
}

/// What answers the bounce rays of `--gi linespace` (shadow rays: the binary line space).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GiStructure {
    /// The shaft's PNMT record: an approximate hit without triangle tests.
    Pnmt,
    /// The candidate lists: the exact hit.
    Candidates,
    /// The record's pre-illuminated radiance: one lookup, no shading, one bounce.
    Preillum,
}

impl Gi {
    /// The bounce count of a path-traced technique.
    pub fn bounces(&self) -> Option<u32> {
        match *self {
            Gi::Rt { bounces } | Gi::LineSpace { bounces, .. } => Some(bounces),
            Gi::None | Gi::Ssgi { .. } => None,
        }
    }
}

/// Participating media.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Media {
    /// None.
    #[default]
    None,
    /// Single scattering by marching each pixel's view ray through the media in world space:
    /// light visibility from the baked volume (trilinear), transmittance analytic
    /// (`shaders/media/march.comp`).
    March {
        /// Steps through each medium the ray crosses.
        steps: u32,
    },
    /// Mitchell's god rays (seed 002): a radial blur of an occlusion image towards each light's
    /// screen position (`shaders/mitchell/`). Image space: no shafts from a light behind the
    /// camera.
    Mitchell {
        /// Samples towards the light (the seed's n).
        samples: u32,
        /// Resolution of the occlusion image.
        resolution: ScreenFraction,
        /// The gain of a march that sees the emitter at every sample (the seed's exposure × n).
        exposure: f32,
    },
    /// Sousa's sun shafts (seed 002): three chained radial blurs of the depth map with steps
    /// TAPS⁻¹, TAPS⁻², TAPS⁻³ (`shaders/sousa/`). Image space, as Mitchell.
    Sousa {
        /// Samples per pass (TAPS).
        taps: u32,
        /// Resolution of the depth map and the first two passes.
        resolution: ScreenFraction,
        /// The factor on each pass's sum at 6 taps (scaled by 6/TAPS for other counts).
        brightness: f32,
    },
    /// Tóth & Umenhoffer's ray march through the baked shadow maps (seed 002, errata fixed),
    /// interleaved over block × block pixels and blurred back together (`shaders/toth/`).
    Toth {
        /// Samples along the view ray's part inside the media, over a block.
        samples: u32,
        /// Side of the interleaving block in pixels.
        block: u32,
        /// Phase function.
        phase: Phase,
    },
}

impl Media {
    /// Whether this technique dims the light reaching surfaces through the media and the
    /// surfaces seen through them (the world-space ones; the image-space blurs only add light,
    /// as in the seed).
    pub fn dims_surfaces(&self) -> bool {
        matches!(self, Media::March { .. } | Media::Toth { .. })
    }
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
}

/// The phase function of `--media toth`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Henyey–Greenstein with the medium's g.
    Medium,
    /// Rayleigh.
    Rayleigh,
}

/// What happens to the stochastic passes' samples across frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Aa {
    /// Every frame shows its own samples.
    None,
    /// A running mean while the camera is still; any change of view, projection or size
    /// restarts it.
    #[default]
    Accumulate,
    /// The running mean of the ray-traced passes carried along while the camera moves: each
    /// pixel's history read where its surface point was last frame, restarted only where that
    /// point was hidden (`passes/rt_history.rs`).
    Reproject {
        /// The longest history while the camera moves (a still camera's is unbounded).
        frames: u32,
    },
    /// Temporal anti-aliasing (seed 000, after Karis 2014): the projection jittered by a
    /// Halton (2, 3) sub-pixel offset each frame, the frame blended into a history reprojected
    /// from the previous frame's camera, the history clamped to the current frame's
    /// neighbourhood in YCoCg (`shaders/taa/`). The ray-traced passes' running mean is
    /// reprojected as with [`Aa::Reproject`], capped at the same length.
    Taa {
        /// The longest history in frames: a pixel's new sample weighs 1/min(n + 1, frames)
        /// after n frames of history.
        frames: u32,
        /// Blend with Karis's luminance weights c / (1 + luma) (the seed's; damps fireflies,
        /// darkens high-contrast edges) instead of linearly.
        luma_weights: bool,
    },
}

impl Aa {
    /// Whether frames are jittered and resolved through a history.
    pub fn temporal(&self) -> bool {
        matches!(self, Aa::Taa { .. })
    }

    /// Whether the stochastic passes keep a running mean while the camera is still.
    pub fn accumulates(&self) -> bool {
        !matches!(self, Aa::None)
    }

    /// The longest history of the ray-traced passes while the camera moves, when it is
    /// reprojected (`None`: it restarts at every move, or there is none).
    pub fn reprojected(&self) -> Option<u32> {
        match *self {
            Aa::Reproject { frames } | Aa::Taa { frames, .. } => Some(frames),
            Aa::None | Aa::Accumulate => None,
        }
    }
}

/// One technique per effect: what a frame renders.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Techniques {
    /// How the G-buffer is made.
    pub gbuffer: GBuffer,
    /// Shadows.
    pub shadows: Shadows,
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
        }
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
        }
    }

    /// What ray queries through the BVH read.
    pub const RAYS: Needs = Needs {
        textures: false,
        brdf_lut: false,
        shadow_maps: false,
        bvh: true,
        scene_buffers: false,
        line_space: 0,
        media: false,
        media_volumes: false,
    };
    /// What the ray-traced passes and the path tracer read: the BVH and the surfaces it hits.
    pub const TRACED_SURFACES: Needs = Needs {
        textures: false,
        brdf_lut: false,
        shadow_maps: false,
        bvh: true,
        scene_buffers: true,
        line_space: 0,
        media: false,
        media_volumes: false,
    };
    /// What the G-buffer and the direct-light pass always read.
    pub const FRAME: Needs = Needs {
        textures: true,
        brdf_lut: true,
        shadow_maps: false,
        bvh: false,
        scene_buffers: false,
        line_space: 0,
        media: false,
        media_volumes: false,
    };
}

/// A knob's value as a whole number, or an error naming it.
fn whole(effect: Effect, technique: &str, knob: &str, value: KnobValue) -> Result<u32, String> {
    let v = value.number();
    if v.fract() != 0.0 {
        return Err(format!("{effect} {technique}: {knob} must be a whole number, not {v}"));
    }
    Ok(v as u32)
}

/// The screen fraction of a `media-res` choice.
fn fraction(value: KnobValue) -> ScreenFraction {
    match value {
        KnobValue::Choice(0) => ScreenFraction::Full,
        KnobValue::Choice(1) => ScreenFraction::Half,
        _ => ScreenFraction::Quarter,
    }
}

impl Techniques {
    /// The sections these techniques read.
    pub fn needs(&self) -> Needs {
        let mut n = Needs::FRAME;
        if self.gbuffer == GBuffer::Visibility {
            n.scene_buffers = true;
        }
        match self.shadows {
            Shadows::ShadowMap => n.shadow_maps = true,
            Shadows::Rt { .. } => n = n.union(Needs::TRACED_SURFACES),
            Shadows::LineSpace { .. } => {
                n = n.union(Needs::TRACED_SURFACES);
                n.line_space |= LsArrays::BINARY_QUERY;
            }
            Shadows::None => {}
        }
        if self.ray_traced() {
            // Surfaces at hits, and for GI the emitter table (made with the scene buffers).
            n = n.union(Needs::TRACED_SURFACES);
        }
        if let Gi::LineSpace { structure, .. } = self.gi {
            n.line_space |= match structure {
                GiStructure::Pnmt => LsArrays::PNMT_QUERY | LsArrays::BINARY_QUERY,
                GiStructure::Candidates => LsArrays::CANDIDATE_QUERY | LsArrays::BINARY_QUERY,
                GiStructure::Preillum => LsArrays::PNMT_QUERY | LsArrays::PREILLUM,
            };
        }
        match self.media {
            Media::None => {}
            Media::March { .. } => {
                n.media = true;
                n.media_volumes = true;
            }
            Media::Mitchell { .. } | Media::Sousa { .. } => n.media = true,
            Media::Toth { .. } => {
                n.media = true;
                n.shadow_maps = true;
            }
        }
        if n.line_space & LsArrays::CELL_LISTS != 0 {
            // Exact tests near the shadow feelers' ends read the shaft's candidates, when the
            // file has them, instead of the whole cell's triangles.
            n.line_space |= LsArrays::CANDIDATES_IF_PRESENT;
        }
        n
    }

    /// The longest history of the ray-traced passes' reprojected accumulation while the camera
    /// moves, when it runs (a ray-traced pass and `--aa reproject` or `taa`): the passes then
    /// write each frame's sample and the history pass blends it.
    pub fn reprojected_rays(&self) -> Option<u32> {
        self.aa.reprojected().filter(|_| self.ray_traced())
    }

    /// Whether a pass shows the previous frame's radiance (the screen-space reflections and GI
    /// read the lit pyramid): the first frame lacks it, so the image depends on the frame count.
    pub fn reads_previous_frame(&self) -> bool {
        matches!(self.reflections, Reflections::Ssr { .. }) || matches!(self.gi, Gi::Ssgi { .. })
    }

    /// Whether any ray-traced pass runs.
    pub fn ray_traced(&self) -> bool {
        self.shadows.traced().is_some()
            || matches!(self.ao, Ao::Rt { .. })
            || matches!(self.reflections, Reflections::Rt { .. })
            || self.gi.bounces().is_some()
    }

    /// Every ray-traced technique replaced by its effect's default or off (what the frame
    /// falls back to when the file has no BVH).
    pub fn without_rays(self) -> Techniques {
        Techniques {
            shadows: if self.shadows.traced().is_some() { Shadows::None } else { self.shadows },
            ao: if matches!(self.ao, Ao::Rt { .. }) { Ao::None } else { self.ao },
            reflections: if matches!(self.reflections, Reflections::Rt { .. }) {
                Reflections::None
            } else {
                self.reflections
            },
            gi: Gi::None,
            ..self
        }
    }

    /// What a session shows while the ray-traced passes' pipelines compile (`None`: no pass is
    /// ray traced, nothing to wait for). Each ray-traced technique is replaced by what keeps its
    /// effect from baked data without rays: shadows from the file's shadow maps (when it has
    /// them, `shadow_maps`; else unshadowed), reflections by the split-sum ambient, AO off (the
    /// materials' occlusion textures still apply), GI by the sky's ambient. The other effects
    /// keep their techniques.
    pub fn fallback(&self, shadow_maps: bool) -> Option<Techniques> {
        if !self.ray_traced() {
            return None;
        }
        let shadows = match self.shadows {
            Shadows::Rt { .. } | Shadows::LineSpace { .. } if shadow_maps => Shadows::ShadowMap,
            Shadows::Rt { .. } | Shadows::LineSpace { .. } => Shadows::None,
            s => s,
        };
        Some(Techniques {
            shadows,
            ao: if matches!(self.ao, Ao::Rt { .. }) { Ao::None } else { self.ao },
            reflections: if matches!(self.reflections, Reflections::Rt { .. }) {
                Reflections::None
            } else {
                self.reflections
            },
            gi: if self.gi.bounces().is_some() { Gi::None } else { self.gi },
            ..*self
        })
    }

    /// The effects whose technique differs in `other`: (effect, this one's name, `other`'s).
    pub fn differences(&self, other: &Techniques) -> Vec<(Effect, &'static str, &'static str)> {
        Effect::ALL
            .into_iter()
            .filter(|&e| self.name_of(e) != other.name_of(e))
            .map(|e| (e, self.name_of(e), other.name_of(e)))
            .collect()
    }

    /// The technique `name` for `effect` with `knobs` (name, value) set, the others at their
    /// defaults; errors name the effect, technique or knob and the valid values.
    pub fn set(&mut self, effect: Effect, name: &str, knobs: &[(&str, KnobValue)]) -> Result<(), String> {
        let info = catalogue().iter().find(|t| t.effect == effect && t.name == name).ok_or_else(|| {
            let names: Vec<&str> = techniques_of(effect).map(|t| t.name).collect();
            format!("{effect}: no technique '{name}' (one of: {})", names.join(", "))
        })?;
        let mut values: Vec<KnobValue> = info.knobs.iter().map(|k| k.default).collect();
        for (knob, value) in knobs {
            let at = info.knobs.iter().position(|k| k.name == *knob).ok_or_else(|| {
                let names: Vec<&str> = info.knobs.iter().map(|k| k.name).collect();
                format!(
                    "{effect} {name}: no knob '{knob}' ({})",
                    if names.is_empty() {
                        "it has none".into()
                    } else {
                        format!("it has {}", names.join(", "))
                    }
                )
            })?;
            info.knobs[at].check(*value).map_err(|e| format!("{effect} {name}: {e}"))?;
            values[at] = *value;
        }
        let v = |i: usize| values[i];
        match (effect, name) {
            (Effect::GBuffer, "raster") => self.gbuffer = GBuffer::Raster,
            (Effect::GBuffer, "visibility") => self.gbuffer = GBuffer::Visibility,
            (Effect::Shadows, "none") => self.shadows = Shadows::None,
            (Effect::Shadows, "shadowmap") => self.shadows = Shadows::ShadowMap,
            (Effect::Shadows, "rt") => {
                self.shadows = Shadows::Rt { light_radius: v(0).number(), sun_degrees: v(1).number() }
            }
            (Effect::Shadows, "linespace") => {
                self.shadows = Shadows::LineSpace {
                    light_radius: v(0).number(),
                    sun_degrees: v(1).number(),
                    test: if v(2) == KnobValue::Choice(1) {
                        LsShadowTest::Filled
                    } else {
                        LsShadowTest::Ends
                    },
                }
            }
            (Effect::Ao, "none") => self.ao = Ao::None,
            (Effect::Ao, "rt" | "sao" | "gtao") => {
                let r = v(0).number();
                let (radius, reach) = ((r > 0.0).then_some(r), v(1).number());
                self.ao = match name {
                    "rt" => Ao::Rt { radius, reach },
                    "sao" => Ao::Sao {
                        radius,
                        reach,
                        samples: whole(effect, name, "ao-samples", v(2))?,
                        turns: v(3).number(),
                        resolution: fraction(v(4)),
                    },
                    _ => Ao::Gtao {
                        radius,
                        reach,
                        slices: whole(effect, name, "ao-slices", v(2))?,
                        steps: whole(effect, name, "ao-steps", v(3))?,
                    },
                };
            }
            (Effect::Reflections, "none") => self.reflections = Reflections::None,
            (Effect::Reflections, "rt") => {
                self.reflections = Reflections::Rt {
                    resolution: if v(0) == KnobValue::Choice(1) {
                        ReflectionRes::Half
                    } else {
                        ReflectionRes::Full
                    },
                    max_roughness: v(1).number(),
                }
            }
            (Effect::Reflections, "ssr") => {
                self.reflections = Reflections::Ssr {
                    steps: whole(effect, name, "ssr-steps", v(0))?,
                    max_roughness: v(1).number(),
                }
            }
            (Effect::Gi, "none") => self.gi = Gi::None,
            (Effect::Gi, "rt" | "linespace") => {
                let bounces = whole(effect, name, "gi-bounces", v(0))?;
                self.gi = if name == "rt" {
                    Gi::Rt { bounces }
                } else {
                    let structure = match v(1) {
                        KnobValue::Choice(1) => GiStructure::Candidates,
                        KnobValue::Choice(2) => GiStructure::Preillum,
                        _ => GiStructure::Pnmt,
                    };
                    Gi::LineSpace { bounces, structure }
                };
            }
            (Effect::Gi, "ssgi") => {
                self.gi = Gi::Ssgi {
                    samples: whole(effect, name, "ssgi-samples", v(0))?,
                    resolution: fraction(v(1)),
                    radius: whole(effect, name, "ssgi-radius", v(2))?,
                    voting: v(3) == KnobValue::Choice(1),
                    falloff: v(4) == KnobValue::Choice(1),
                    frames: whole(effect, name, "ssgi-frames", v(5))?,
                    tiled: v(6) == KnobValue::Choice(1),
                };
            }
            (Effect::Media, "none") => self.media = Media::None,
            (Effect::Media, "march") => {
                self.media = Media::March { steps: whole(effect, name, "media-steps", v(0))? };
            }
            (Effect::Media, "mitchell") => {
                self.media = Media::Mitchell {
                    samples: whole(effect, name, "media-samples", v(0))?,
                    resolution: fraction(v(1)),
                    exposure: v(2).number(),
                };
            }
            (Effect::Media, "sousa") => {
                self.media = Media::Sousa {
                    taps: whole(effect, name, "media-taps", v(0))?,
                    resolution: fraction(v(1)),
                    brightness: v(2).number(),
                };
            }
            (Effect::Media, "toth") => {
                let samples = whole(effect, name, "media-samples", v(0))?;
                let block = whole(effect, name, "media-block", v(1))?;
                if block * block > samples {
                    return Err(format!(
                        "{effect} {name}: media-block {block} splits the samples over {} pixels: give at least \
                         that many media-samples (there are {samples}), or a smaller block",
                        block * block
                    ));
                }
                let phase = if v(2) == KnobValue::Choice(1) { Phase::Rayleigh } else { Phase::Medium };
                self.media = Media::Toth { samples, block, phase };
            }
            (Effect::Aa, "none") => self.aa = Aa::None,
            (Effect::Aa, "accumulate") => self.aa = Aa::Accumulate,
            (Effect::Aa, "reproject") => {
                self.aa = Aa::Reproject { frames: whole(effect, name, "history-frames", v(0))? }
            }
            (Effect::Aa, "taa") => {
                self.aa = Aa::Taa {
                    frames: whole(effect, name, "taa-frames", v(0))?,
                    luma_weights: v(1) == KnobValue::Choice(0),
                }
            }
            _ => unreachable!("every catalogue entry is matched above (checked by a test)"),
        }
        Ok(())
    }

    /// The technique each effect uses now, by catalogue name.
    pub fn name_of(&self, effect: Effect) -> &'static str {
        match effect {
            Effect::GBuffer => match self.gbuffer {
                GBuffer::Raster => "raster",
                GBuffer::Visibility => "visibility",
            },
            Effect::Shadows => match self.shadows {
                Shadows::None => "none",
                Shadows::ShadowMap => "shadowmap",
                Shadows::Rt { .. } => "rt",
                Shadows::LineSpace { .. } => "linespace",
            },
            Effect::Ao => match self.ao {
                Ao::None => "none",
                Ao::Rt { .. } => "rt",
                Ao::Sao { .. } => "sao",
                Ao::Gtao { .. } => "gtao",
            },
            Effect::Reflections => match self.reflections {
                Reflections::None => "none",
                Reflections::Rt { .. } => "rt",
                Reflections::Ssr { .. } => "ssr",
            },
            Effect::Gi => match self.gi {
                Gi::None => "none",
                Gi::Rt { .. } => "rt",
                Gi::LineSpace { .. } => "linespace",
                Gi::Ssgi { .. } => "ssgi",
            },
            Effect::Media => match self.media {
                Media::None => "none",
                Media::March { .. } => "march",
                Media::Mitchell { .. } => "mitchell",
                Media::Sousa { .. } => "sousa",
                Media::Toth { .. } => "toth",
            },
            Effect::Aa => match self.aa {
                Aa::None => "none",
                Aa::Accumulate => "accumulate",
                Aa::Reproject { .. } => "reproject",
                Aa::Taa { .. } => "taa",
            },
        }
    }
}

/// An effect: something a frame shows, made by one of several techniques.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Effect {
    /// How surfaces are found per pixel.
    GBuffer,
    /// Shadows of analytic lights.
    Shadows,
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
}

impl Effect {
    /// Every effect, in frame order.
    pub const ALL: [Effect; 7] = [
        Effect::GBuffer,
        Effect::Shadows,
        Effect::Ao,
        Effect::Reflections,
        Effect::Gi,
        Effect::Media,
        Effect::Aa,
    ];

    /// The effect's name (also its command-line flag without `--`).
    pub fn name(self) -> &'static str {
        match self {
            Effect::GBuffer => "gbuffer",
            Effect::Shadows => "shadows",
            Effect::Ao => "ao",
            Effect::Reflections => "reflections",
            Effect::Gi => "gi",
            Effect::Media => "media",
            Effect::Aa => "aa",
        }
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A knob's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KnobValue {
    /// A number.
    Number(f32),
    /// The index of one of a choice knob's options.
    Choice(usize),
}

impl KnobValue {
    fn number(self) -> f32 {
        match self {
            KnobValue::Number(v) => v,
            KnobValue::Choice(i) => i as f32,
        }
    }
}

/// The values a knob takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KnobRange {
    /// A number in `min..=max` (`max` may be infinite); `sweep` lists the values worth
    /// measuring.
    Number {
        /// Smallest value.
        min: f32,
        /// Largest value.
        max: f32,
        /// Values a sweep should measure.
        sweep: &'static [f32],
    },
    /// One of the named options.
    Choice(&'static [&'static str]),
}

/// A quality knob of a technique.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knob {
    /// Name (also the command-line flag without `--`).
    pub name: &'static str,
    /// What it does.
    pub help: &'static str,
    /// Valid values.
    pub range: KnobRange,
    /// The default.
    pub default: KnobValue,
    /// Whether it trades time for error, or changes what is rendered.
    pub role: KnobRole,
}

/// What a knob does, for a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnobRole {
    /// Trades time for error: a sweep measures its values.
    Quality,
    /// Changes the scene the technique renders (a light's size): a sweep holds it at its
    /// default, which is what the reference path tracer renders (point, spot and directional
    /// lights without extent).
    Scene,
}

impl Knob {
    /// Whether `value` is valid for this knob.
    pub fn check(&self, value: KnobValue) -> Result<(), String> {
        match (self.range, value) {
            (KnobRange::Number { min, max, .. }, KnobValue::Number(v)) => {
                if v.is_finite() && v >= min && v <= max {
                    Ok(())
                } else {
                    Err(format!("{} must be a number in {min}..={max}, not {v}", self.name))
                }
            }
            (KnobRange::Choice(options), KnobValue::Choice(i)) if i < options.len() => Ok(()),
            (KnobRange::Choice(options), _) => {
                Err(format!("{} must be one of {}", self.name, options.join(", ")))
            }
            (KnobRange::Number { .. }, KnobValue::Choice(_)) => Err(format!("{} takes a number", self.name)),
        }
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

const fn number(
    name: &'static str,
    help: &'static str,
    min: f32,
    max: f32,
    default: f32,
    sweep: &'static [f32],
) -> Knob {
    Knob {
        name,
        help,
        range: KnobRange::Number { min, max, sweep },
        default: KnobValue::Number(default),
        role: KnobRole::Quality,
    }
}

/// A knob that sizes the lights.
const fn light_size(knob: Knob) -> Knob {
    Knob { role: KnobRole::Scene, ..knob }
}

/// The upper end of an open range.
const UNBOUNDED: f32 = f32::INFINITY;

/// The AO radius in scene units, for every AO technique.
const AO_RADIUS: Knob = number(
    "ao-radius",
    "AO radius in scene units (rt: the ray length; sao, gtao: the world radius of the samples); \
     0: --ao-reach times the scene's diagonal",
    0.0,
    UNBOUNDED,
    0.0,
    &[0.0],
);

/// The AO radius as a fraction of the scene's diagonal, with a technique's default and sweep.
const fn ao_reach(default: f32, sweep: &'static [f32]) -> Knob {
    number(
        "ao-reach",
        "AO radius as a fraction of the scene's bounding-box diagonal, when --ao-radius is 0 (rt: \
         0.1, ≥ 10 makes every hit occlude fully, the sky's true visibility; sao, gtao: 0.05, about \
         the seed's 1.8 m in Sponza's 40 m)",
        1e-4,
        UNBOUNDED,
        default,
        sweep,
    )
}

/// Bounces of the path-traced GI techniques.
const GI_BOUNCES: Knob = number(
    "gi-bounces",
    "bounces of indirect light after the visible surface (1: the sky, emissive surfaces and \
     the light the first surface hit receives directly; each more adds one bounce)",
    1.0,
    8.0,
    1.0,
    &[1.0, 2.0],
);

/// The sphere radius of point and spot lights, for the traced shadow techniques.
const LIGHT_RADIUS: Knob = light_size(number(
    "light-radius",
    "sphere radius of point and spot lights in scene units (0: hard shadows)",
    0.0,
    UNBOUNDED,
    0.0,
    &[0.0, 0.1, 1.0],
));

/// The angular diameter of directional lights, for the traced shadow techniques.
const SUN_ANGLE: Knob = light_size(number(
    "sun-angle",
    "angular diameter of directional lights in degrees (the sun: 0.53)",
    0.0,
    179.99,
    0.0,
    &[0.0, 0.53, 2.0],
));

/// Samples along the way of the media techniques that take a fixed count (Mitchell, Tóth).
const MEDIA_SAMPLES: Knob = number(
    "media-samples",
    "samples per pixel: mitchell, towards the light; toth, along the view ray (over an \
     interleaving block)",
    1.0,
    1024.0,
    60.0,
    &[18.0, 60.0, 100.0],
);

/// Resolution of the image-space god rays' first image.
const MEDIA_RES: Knob = Knob {
    name: "media-res",
    help: "resolution of mitchell's occlusion image and sousa's depth map and first two blurs: \
           full, half or quarter of the screen's on each axis (read bilinearly: smoother shafts)",
    range: KnobRange::Choice(&["full", "half", "quarter"]),
    default: KnobValue::Choice(2),
    role: KnobRole::Quality,
};

/// The image-space techniques' artistic brightness: a sweep holds it at its default.
const fn artistic(knob: Knob) -> Knob {
    Knob { role: KnobRole::Scene, ..knob }
}

static CATALOGUE: [TechniqueInfo; 26] = [
    TechniqueInfo {
        effect: Effect::GBuffer,
        name: "raster",
        help: "rasterise every material attribute (five targets)",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::GBuffer,
        name: "visibility",
        help: "rasterise a visibility buffer (triangle per pixel), evaluate materials in compute: \
               faster on GPUs with little raster hardware (e.g. NVIDIA H100/H200)",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Shadows,
        name: "none",
        help: "no shadows",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Shadows,
        name: "shadowmap",
        help: "the compiler's baked shadow maps (PCF; PCSS for rect lights)",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Shadows,
        name: "rt",
        help: "ray-traced soft shadows: one ray per light per pixel per frame, averaged while the \
               camera is still (see --light-radius, --sun-angle)",
        knobs: &[LIGHT_RADIUS, SUN_ANGLE],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Shadows,
        name: "linespace",
        help: "the ray-traced estimator with its shadow feelers through the binary line space \
               (seed 004; needs a file compiled with line space, see --ls-shadow-test)",
        knobs: &[
            LIGHT_RADIUS,
            SUN_ANGLE,
            Knob {
                name: "ls-shadow-test",
                help: "ends: exact triangle tests in the cells holding the ray's ends, a filled shaft \
                       elsewhere occludes (conservative, cheapest); filled: exact tests wherever the \
                       shaft is filled (exact)",
                range: KnobRange::Choice(&["ends", "filled"]),
                default: KnobValue::Choice(0),
                role: KnobRole::Quality,
            },
        ],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Ao,
        name: "none",
        help: "no ambient occlusion (the material's occlusion texture still applies)",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Ao,
        name: "rt",
        help: "ray-traced: one cosine-weighted ray per pixel per frame within --ao-radius (or --ao-reach)",
        knobs: &[AO_RADIUS, ao_reach(0.1, &[0.03, 0.1, 0.3, 100.0])],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Ao,
        name: "sao",
        help: "scalable ambient obscurance as seed 000 modifies it: --ao-samples spiral samples of a \
               camera-space depth pyramid and the G-buffer normals within --ao-radius (or \
               --ao-reach), at --ao-res, blurred with depth weights; screen space (what the screen \
               does not show does not occlude)",
        knobs: &[
            AO_RADIUS,
            ao_reach(0.05, &[0.05]),
            number(
                "ao-samples",
                "samples per AO pixel on the spiral (the seed's N)",
                1.0,
                64.0,
                16.0,
                &[8.0, 16.0, 32.0],
            ),
            number(
                "ao-turns",
                "turns of the sample spiral (τ; 7: McGuire et al.'s prime for few samples)",
                0.0,
                UNBOUNDED,
                7.0,
                &[],
            ),
            Knob {
                name: "ao-res",
                help: "resolution of sao's samples: full, or half on each axis (the seed's default), \
                       upsampled by the depth-aware blur",
                range: KnobRange::Choice(&["full", "half"]),
                default: KnobValue::Choice(1),
                role: KnobRole::Quality,
            },
        ],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Ao,
        name: "gtao",
        help: "ground-truth AO (Jimenez et al. 2016): per pixel, --ao-slices screen directions, each \
               side's horizon found by --ao-steps samples of the depth pyramid within --ao-radius \
               (or --ao-reach), the cosine-weighted visibility between the horizons integrated with \
               the projected normal; blurred with depth weights; screen space",
        knobs: &[
            AO_RADIUS,
            ao_reach(0.05, &[0.05]),
            number(
                "ao-slices",
                "screen directions per pixel (XeGTAO High: 3)",
                1.0,
                32.0,
                3.0,
                &[2.0, 3.0, 9.0],
            ),
            number(
                "ao-steps",
                "samples along each side of a slice (XeGTAO High: 3)",
                1.0,
                64.0,
                3.0,
                &[2.0, 3.0, 8.0],
            ),
        ],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Reflections,
        name: "none",
        help: "split-sum ambient specular only",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Reflections,
        name: "rt",
        help: "ray-traced glossy reflections (GGX visible-normal samples, one per pixel per frame \
               at --reflection-res)",
        knobs: &[
            Knob {
                name: "reflection-res",
                help: "full: one ray per pixel; half: one per 2 × 2 pixels, upsampled with edge-aware weights",
                range: KnobRange::Choice(&["full", "half"]),
                default: KnobValue::Choice(0),
                role: KnobRole::Quality,
            },
            number(
                "reflection-max-roughness",
                "surfaces rougher than this keep the split-sum ambient",
                0.0,
                UNBOUNDED,
                1.0,
                &[0.4, 1.0],
            ),
        ],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Reflections,
        name: "ssr",
        help: "screen-space reflections (seed 000, traced hierarchically after McGuire & Mara 2014 and \
               AMD's SSSR): the mirror direction marched through a closest-depth pyramid, showing \
               the previous frame's lit radiance at the hit; rougher surfaces accept coarser hits; \
               the split-sum ambient where the ray misses or leaves the screen (faded near its \
               edges) and above --ssr-max-roughness; see --ssr-steps",
        knobs: &[
            number(
                "ssr-steps",
                "most iterations of the hierarchical march per pixel: each skips a cell of empty space \
                 (a level up) or refines a potential hit (a level down); 48 crosses a 1080p screen \
                 with room to refine, fewer lose distant hits",
                1.0,
                1024.0,
                48.0,
                &[16.0, 32.0, 48.0, 96.0],
            ),
            number(
                "ssr-max-roughness",
                "surfaces rougher than this keep the split-sum ambient (faded over the last fifth): \
                 above about 0.6 the cone covers much of the screen, where one ray says little",
                0.0,
                1.0,
                0.6,
                &[0.3, 0.6],
            ),
        ],
        // Not noisy, but it shows the previous frame's radiance: none in the first frame.
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Gi,
        name: "none",
        help: "no indirect diffuse light: the sky lights every surface unoccluded (times AO where it runs)",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Gi,
        name: "rt",
        help: "path-traced diffuse GI from the G-buffer through the BVH: one cosine-weighted path per \
               pixel per frame, next-event estimation to lights and emissive surfaces at its hits, \
               averaged while the camera is still; replaces the sky's diffuse ambient and its AO \
               (see --gi-bounces)",
        knobs: &[GI_BOUNCES],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Gi,
        name: "linespace",
        help: "the path-traced GI estimator with its rays through the line space (seed 004): bounce \
               rays through --gi-structure, shadow rays through the binary line space; specular \
               bounces and emissive hits through the BVH (needs a file compiled with line space)",
        knobs: &[
            GI_BOUNCES,
            Knob {
                name: "gi-structure",
                help: "pnmt: the shaft's stored hit, no triangle test (approximate); candidates: the \
                       shaft's triangle list (exact); preillum: the stored hit's baked radiance, one \
                       bounce, no shading",
                range: KnobRange::Choice(&["pnmt", "candidates", "preillum"]),
                default: KnobValue::Choice(0),
                role: KnobRole::Quality,
            },
        ],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Gi,
        name: "ssgi",
        help: "screen-space diffuse GI (seed 000): the previous frame's lit radiance gathered on \
               --ssgi-samples spiral points per pixel on each level of a depth/normal/light MIP \
               hierarchy (near light from fine levels, far light from coarse ones), \
               joint-bilaterally upsampled, averaged over --ssgi-frames while the camera is \
               still; added to the sky's ambient. No visibility: light passes through what the \
               screen shows, and what it does not show (off screen, hidden) gives none",
        knobs: &[
            number(
                "ssgi-samples",
                "spiral samples per pixel on each level (the seed's 128; tested 16 to 256)",
                1.0,
                1024.0,
                128.0,
                &[16.0, 32.0, 64.0, 128.0, 256.0],
            ),
            Knob {
                name: "ssgi-res",
                help: "the finest level gathered, upsampled to the screen: full, half (the seed's \
                       default, ~540p at 1080p) or quarter",
                range: KnobRange::Choice(&["full", "half", "quarter"]),
                default: KnobValue::Choice(1),
                role: KnobRole::Quality,
            },
            number(
                "ssgi-radius",
                "sample radius R in pixels of each level (the seed's 40); levels go up until one \
                 radius spans the screen",
                4.0,
                256.0,
                40.0,
                &[],
            ),
            Knob {
                name: "ssgi-mip",
                help: "how the depth and normal pyramids pick each coarser texel: nearest (the \
                       seed's fast) or voting (the seed's precise, its default)",
                range: KnobRange::Choice(&["nearest", "voting"]),
                default: KnobValue::Choice(1),
                role: KnobRole::Quality,
            },
            Knob {
                name: "ssgi-falloff",
                help: "the seed's distance fall-off (1/r² becomes 1/r^2.5 beyond one scene unit) \
                       standing in for the visibility it does not test: off or on",
                range: KnobRange::Choice(&["off", "on"]),
                default: KnobValue::Choice(0),
                role: KnobRole::Quality,
            },
            number(
                "ssgi-frames",
                "the most frames the GI's running mean averages while the camera is still (then \
                 exponential, as the bounces build up)",
                1.0,
                4096.0,
                16.0,
                &[],
            ),
            Knob {
                name: "ssgi-rotation",
                help: "how the sample spirals turn: pixel (a random angle per texel, the seed's) or \
                       tile (one per 8 × 8 texels, the default: neighbours read neighbouring texels, \
                       15 % faster on an H100; one frame's noise 14 % higher, correlated within a \
                       tile until frames average it)",
                range: KnobRange::Choice(&["pixel", "tile"]),
                default: KnobValue::Choice(1),
                role: KnobRole::Quality,
            },
        ],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Media,
        name: "none",
        help: "no participating media",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Media,
        name: "march",
        help: "single scattering: each pixel's view ray marched through the media in world space \
               (light visibility from the compiler's baked volume, transmittance analytic; works \
               with the light off screen), see --media-steps",
        knobs: &[number(
            "media-steps",
            "steps along the view ray through each medium",
            1.0,
            1024.0,
            32.0,
            &[8.0, 16.0, 32.0, 64.0],
        )],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Media,
        name: "mitchell",
        help: "Mitchell's god rays (seed 002): each light's emitter (the sky for a directional \
               light, its rectangle for a rect light, a small sphere for point and spot lights) \
               blurred radially towards its screen position; image space, so no shafts from a light behind the camera or from what \
               the screen does not show; see --media-samples, --media-res, --media-exposure",
        knobs: &[
            MEDIA_SAMPLES,
            MEDIA_RES,
            artistic(number(
                "media-exposure",
                "the shafts' gain where every sample sees the emitter (the seed's exposure × n)",
                0.0,
                UNBOUNDED,
                1.921,
                &[],
            )),
        ],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Media,
        name: "sousa",
        help: "Sousa's sun shafts (seed 002, CryEngine): the depth map blurred radially towards \
               each light in three chained passes of TAPS samples (steps 1/TAPS, 1/TAPS², 1/TAPS³ \
               of the screen); image space, as mitchell; see --media-taps, --media-res, \
               --media-brightness",
        knobs: &[
            number("media-taps", "samples per pass (TAPS; 3 passes)", 1.0, 64.0, 6.0, &[3.0, 6.0, 10.0]),
            MEDIA_RES,
            artistic(number(
                "media-brightness",
                "factor on each pass's sum at 6 taps (the seed's 0.19), scaled by 6/TAPS for others",
                0.0,
                UNBOUNDED,
                0.19,
                &[],
            )),
        ],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Media,
        name: "toth",
        help: "Tóth & Umenhoffer (seed 002, its errata fixed): each view ray marched through the \
               media in world space, light visibility from the compiler's shadow maps, samples \
               interleaved over a block of pixels and blurred back together; works with the \
               light off screen; see --media-samples, --media-block, --media-phase",
        knobs: &[
            MEDIA_SAMPLES,
            number(
                "media-block",
                "side of the interleaving block: each of its block² pixels takes every block²-th \
                 sample, a block-wide blur joins them (1: every pixel takes all)",
                1.0,
                8.0,
                4.0,
                &[1.0, 2.0, 4.0],
            ),
            Knob {
                name: "media-phase",
                help: "medium: Henyey–Greenstein with the medium's g (what the reference renders); \
                       rayleigh: 3/(16π)(1 + cos²θ)",
                range: KnobRange::Choice(&["medium", "rayleigh"]),
                default: KnobValue::Choice(0),
                role: KnobRole::Scene,
            },
        ],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Aa,
        name: "none",
        help: "every frame shows its own samples",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Aa,
        name: "accumulate",
        help: "a running mean of the stochastic passes while the camera is still",
        knobs: &[],
        stochastic: false,
    },
    TechniqueInfo {
        effect: Effect::Aa,
        name: "reproject",
        help: "the running mean of the ray-traced passes carried along while the camera moves: \
               each pixel's history read where its surface point was last frame, restarted only \
               where that point was hidden (see --history-frames)",
        knobs: &[number(
            "history-frames",
            "the longest history while the camera moves: a new frame weighs at least 1/FRAMES \
             (a still camera's running mean is unbounded)",
            1.0,
            1024.0,
            32.0,
            &[8.0, 32.0],
        )],
        stochastic: true,
    },
    TechniqueInfo {
        effect: Effect::Aa,
        name: "taa",
        help: "temporal anti-aliasing (seed 000): a Halton sub-pixel jitter per frame, each frame \
               blended into a history reprojected from the last camera and clamped to the \
               current neighbourhood (YCoCg); the ray-traced passes' running mean reprojected \
               as with reproject, at most --taa-frames long while moving; see --taa-frames, \
               --taa-weights",
        knobs: &[
            number(
                "taa-frames",
                "the longest history in frames: a new frame weighs at least 1/FRAMES (the seed's \
                 blend 0.88–0.97 is 8–33 frames); longer converges further on a still camera and \
                 smears more on a moving one",
                1.0,
                1024.0,
                16.0,
                &[4.0, 8.0, 16.0, 32.0],
            ),
            Knob {
                name: "taa-weights",
                help: "luma: blend c/(1 + luma) (Karis's, the seed's: damps fireflies, darkens \
                       high-contrast edges); linear: blend the radiance itself (converges to the \
                       supersampled image)",
                range: KnobRange::Choice(&["luma", "linear"]),
                default: KnobValue::Choice(1),
                role: KnobRole::Quality,
            },
        ],
        stochastic: true,
    },
];

/// Every technique of every effect with its knobs.
pub fn catalogue() -> &'static [TechniqueInfo] {
    &CATALOGUE
}

/// The techniques of one effect, in catalogue order.
pub fn techniques_of(effect: Effect) -> impl Iterator<Item = &'static TechniqueInfo> {
    catalogue().iter().filter(move |t| t.effect == effect)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_catalogue_entry_builds_its_technique() {
        for info in catalogue() {
            let mut t = Techniques::default();
            t.set(info.effect, info.name, &[]).unwrap();
            assert_eq!(t.name_of(info.effect), info.name, "{} {}", info.effect, info.name);
            for k in info.knobs {
                k.check(k.default).unwrap();
            }
        }
        for e in Effect::ALL {
            assert!(techniques_of(e).count() >= 1, "{e} has no technique");
        }
    }

    #[test]
    fn knobs_are_checked_and_named_in_errors() {
        let mut t = Techniques::default();
        let e = t.set(Effect::Shadows, "rt", &[("light-radius", KnobValue::Number(-1.0))]).unwrap_err();
        assert!(e.contains("light-radius"), "{e}");
        let e = t.set(Effect::Shadows, "rt", &[("radius", KnobValue::Number(1.0))]).unwrap_err();
        assert!(e.contains("light-radius, sun-angle"), "{e}");
        let e = t.set(Effect::Ao, "ssao", &[]).unwrap_err();
        assert!(e.contains("none, rt, sao, gtao"), "{e}");
        t.set(Effect::Reflections, "rt", &[("reflection-res", KnobValue::Choice(1))]).unwrap();
        assert_eq!(t.reflections, Reflections::Rt { resolution: ReflectionRes::Half, max_roughness: 1.0 });
    }

    #[test]
    fn needs_follow_the_techniques() {
        let d = Techniques::default();
        assert_eq!(d.needs(), Needs { shadow_maps: true, ..Needs::FRAME });
        let rt = Techniques { ao: Ao::Rt { radius: None, reach: 0.1 }, shadows: Shadows::None, ..d };
        assert!(rt.needs().bvh && rt.needs().scene_buffers && !rt.needs().shadow_maps);
        let vis = Techniques { gbuffer: GBuffer::Visibility, ..d };
        assert!(vis.needs().scene_buffers && !vis.needs().bvh);
        let gi = Techniques { gi: Gi::Rt { bounces: 1 }, ..d };
        assert!(gi.ray_traced() && gi.needs().bvh && gi.needs().scene_buffers);
        assert_eq!(gi.without_rays().gi, Gi::None);
        // The screen-space AO techniques read the G-buffer only, and survive a file without
        // a BVH.
        for ao in [
            Ao::Sao { radius: None, reach: 0.05, samples: 16, turns: 7.0, resolution: ScreenFraction::Half },
            Ao::Gtao { radius: Some(2.0), reach: 0.05, slices: 3, steps: 3 },
        ] {
            let t = Techniques { ao, ..d };
            assert_eq!(t.needs(), d.needs(), "{ao:?}");
            assert!(!t.ray_traced());
            assert_eq!(t.without_rays().ao, ao);
        }
        assert_eq!(Ao::Gtao { radius: Some(2.0), reach: 0.05, slices: 3, steps: 3 }.world_radius(10.0), 2.0);
        assert_eq!(Ao::Rt { radius: None, reach: 0.1 }.world_radius(10.0), 1.0);
    }

    #[test]
    fn the_fallback_keeps_effects_from_baked_data_and_compiles_no_ray_traced_pass() {
        let d = Techniques::default();
        assert_eq!(d.fallback(true), None, "nothing ray traced: no fallback");
        let ssgi = Gi::Ssgi {
            samples: 8,
            resolution: ScreenFraction::Half,
            radius: 40,
            voting: true,
            falloff: false,
            frames: 16,
            tiled: true,
        };
        let gtao = Ao::Gtao { radius: None, reach: 0.05, slices: 3, steps: 3 };
        let all = Techniques {
            shadows: Shadows::Rt { light_radius: 0.1, sun_degrees: 0.5 },
            ao: Ao::Rt { radius: None, reach: 0.1 },
            reflections: Reflections::Rt { resolution: ReflectionRes::Half, max_roughness: 1.0 },
            gi: Gi::Rt { bounces: 2 },
            aa: Aa::Taa { frames: 8, luma_weights: false },
            ..d
        };
        let f = all.fallback(true).unwrap();
        assert!(!f.ray_traced() && f.reprojected_rays().is_none());
        assert_eq!(
            (f.shadows, f.ao, f.reflections, f.gi, f.aa),
            (Shadows::ShadowMap, Ao::None, Reflections::None, Gi::None, all.aa)
        );
        assert_eq!(all.fallback(false).unwrap().shadows, Shadows::None, "no shadow maps in the file");
        assert_eq!(
            all.differences(&f),
            vec![
                (Effect::Shadows, "rt", "shadowmap"),
                (Effect::Ao, "rt", "none"),
                (Effect::Reflections, "rt", "none"),
                (Effect::Gi, "rt", "none")
            ]
        );
        // Techniques that are not ray traced are kept, screen-space ones included.
        let mixed = Techniques {
            shadows: Shadows::LineSpace { light_radius: 0.0, sun_degrees: 0.0, test: LsShadowTest::Ends },
            ao: gtao,
            reflections: Reflections::Ssr { steps: 48, max_roughness: 0.6 },
            gi: ssgi,
            ..d
        };
        let f = mixed.fallback(true).unwrap();
        assert_eq!(
            (f.shadows, f.ao, f.reflections, f.gi),
            (Shadows::ShadowMap, gtao, mixed.reflections, ssgi)
        );
        assert_eq!(mixed.differences(&f), vec![(Effect::Shadows, "linespace", "shadowmap")]);
        let gi = Techniques { gi: Gi::LineSpace { bounces: 1, structure: GiStructure::Pnmt }, ..d };
        assert_eq!(gi.fallback(true), Some(Techniques { gi: Gi::None, ..d }));
        // What the fallback reads beyond the requested techniques: the shadow maps at most.
        for t in [all, mixed, gi] {
            let (n, f) = (t.needs(), t.fallback(true).unwrap().needs());
            assert_eq!(n.union(f), Needs { shadow_maps: true, ..n }, "{t:?}");
        }
    }

    #[test]
    fn media_techniques_read_only_the_sections_they_use() {
        // What `kiln plan` says of the MVIS and SHDW stages: march reads the visibility
        // volumes, toth the shadow maps, the image-space blurs neither; all read the media table.
        let none = Techniques { shadows: Shadows::None, ..Techniques::default() };
        let needs = |media| Techniques { media, ..none }.needs();
        let march = needs(Media::March { steps: 8 });
        assert!(march.media && march.media_volumes && !march.shadow_maps);
        let toth = needs(Media::Toth { samples: 16, block: 2, phase: Phase::Medium });
        assert!(toth.media && !toth.media_volumes && toth.shadow_maps);
        for blur in [
            Media::Mitchell { samples: 8, resolution: ScreenFraction::Half, exposure: 1.0 },
            Media::Sousa { taps: 6, resolution: ScreenFraction::Half, brightness: 0.19 },
        ] {
            let n = needs(blur);
            assert!(n.media && !n.media_volumes && !n.shadow_maps, "{blur:?}");
            assert!(!blur.dims_surfaces(), "{blur:?}");
        }
        assert_eq!(needs(Media::None), Needs::FRAME);
        assert!(Media::March { steps: 1 }.dims_surfaces());
        // The block splits the samples: block² of them at least.
        let mut t = Techniques::default();
        let e = t.set(Effect::Media, "toth", &[("media-samples", KnobValue::Number(8.0))]).unwrap_err();
        assert!(e.contains("media-block 4") && e.contains("16"), "{e}");
        t.set(Effect::Media, "toth", &[("media-phase", KnobValue::Choice(1))]).unwrap();
        assert_eq!(t.media, Media::Toth { samples: 60, block: 4, phase: Phase::Rayleigh });
    }

    #[test]
    fn the_catalogue_builds_ssr_with_its_knobs_and_it_needs_no_rays() {
        let mut t = Techniques::default();
        t.set(Effect::Reflections, "ssr", &[]).unwrap();
        assert_eq!(t.reflections, Reflections::Ssr { steps: 48, max_roughness: 0.6 });
        assert_eq!(t.name_of(Effect::Reflections), "ssr");
        t.set(
            Effect::Reflections,
            "ssr",
            &[("ssr-steps", KnobValue::Number(16.0)), ("ssr-max-roughness", KnobValue::Number(0.3))],
        )
        .unwrap();
        assert_eq!(t.reflections, Reflections::Ssr { steps: 16, max_roughness: 0.3 });
        // Screen space: the G-buffer only, kept on a file without a BVH.
        assert!(!t.ray_traced());
        assert_eq!(t.needs(), Techniques { reflections: Reflections::None, ..t }.needs());
        assert_eq!(t.without_rays().reflections, t.reflections);
        for (knob, bad) in [("ssr-steps", 1.5), ("ssr-steps", 0.0), ("ssr-max-roughness", 1.5)] {
            let e = t.set(Effect::Reflections, "ssr", &[(knob, KnobValue::Number(bad))]).unwrap_err();
            assert!(e.contains(knob), "{e}");
        }
    }

    #[test]
    fn the_catalogue_builds_gi_rt_with_its_bounces() {
        let mut t = Techniques::default();
        t.set(Effect::Gi, "rt", &[]).unwrap();
        assert_eq!(t.gi, Gi::Rt { bounces: 1 });
        assert_eq!(t.name_of(Effect::Gi), "rt");
        t.set(Effect::Gi, "rt", &[("gi-bounces", KnobValue::Number(3.0))]).unwrap();
        assert_eq!(t.gi, Gi::Rt { bounces: 3 });
        for bad in [0.0, 9.0, 1.5] {
            let e = t.set(Effect::Gi, "rt", &[("gi-bounces", KnobValue::Number(bad))]).unwrap_err();
            assert!(e.contains("gi-bounces"), "{e}");
        }
        let info = techniques_of(Effect::Gi).find(|i| i.name == "rt").unwrap();
        assert!(info.stochastic);
        assert_eq!(info.knobs[0].role, KnobRole::Quality);
        assert_eq!(info.knobs[0].range, KnobRange::Number { min: 1.0, max: 8.0, sweep: &[1.0, 2.0] });
        t.set(Effect::Gi, "none", &[]).unwrap();
        assert_eq!(t.gi, Gi::None);
    }
}
