//! `--media toth`: Tóth & Umenhoffer's ray march through the baked shadow maps (seed 002,
//! errata fixed), interleaved over block × block pixels and blurred back together
//! (`passes/toth.rs`, `shaders/toth/`).

use kiln_format::gpu::Phases;

use super::{MEDIA_SAMPLES, casters, no_medium};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::toth::TothPass;
use crate::render::techniques::knobs::{choice, number, whole, scene};
use crate::render::techniques::{Knob, Knobs, Needs, Registered, Technique};

/// Tóth & Umenhoffer's shadow-map ray march.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Toth {
    /// Samples along the view ray's part inside the media, over a block.
    pub samples: u32,
    /// Side of the interleaving block in pixels.
    pub block: u32,
    /// Phase function.
    pub phase: Phase,
}

/// The phase function of `--media toth`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Henyey–Greenstein with the medium's g.
    Medium,
    /// Rayleigh.
    Rayleigh,
}

impl Registered for Toth {
    const NAME: &'static str = "toth";
    const HELP: &'static str = "Tóth & Umenhoffer (seed 002, its errata fixed): each view ray marched through the \
                                media in world space, light visibility from the compiler's shadow maps, samples \
                                interleaved over a block of pixels and blurred back together; works with the \
                                light off screen; see --media-samples, --media-block, --media-phase";
    const KNOBS: &'static [Knob] = &[
        MEDIA_SAMPLES,
        whole(number(
            "media-block",
            "side of the interleaving block: each of its block² pixels takes every block²-th \
             sample, a block-wide blur joins them (1: every pixel takes all)",
            1.0,
            8.0,
            4.0,
            &[1.0, 2.0, 4.0],
        )),
        // What the reference renders: a sweep holds it.
        scene(choice(
            "media-phase",
            "medium: Henyey–Greenstein with the medium's g (what the reference renders); \
             rayleigh: 3/(16π)(1 + cos²θ)",
            &["medium", "rayleigh"],
            0,
        )),
    ];

    fn new(k: &Knobs) -> Result<Toth, String> {
        let samples = k.whole("media-samples")?;
        let block = k.whole("media-block")?;
        if block * block > samples {
            return Err(format!(
                "{}: media-block {block} splits the samples over {} pixels: give at least \
                 that many media-samples (there are {samples}), or a smaller block",
                k.technique(),
                block * block
            ));
        }
        let phase = if k.choice("media-phase") == "rayleigh" { Phase::Rayleigh } else { Phase::Medium };
        Ok(Toth { samples, block, phase })
    }
}

impl Technique for Toth {
    fn needs(&self) -> Needs {
        Needs { media: true, shadow_maps: true, ..Needs::NONE }
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        let phase = match self.phase {
            Phase::Medium => Phases::HENYEY_GREENSTEIN,
            Phase::Rayleigh => Phases::RAYLEIGH,
        };
        frame.add(Stage::Media, move || TothPass::new(gpu, self.samples, self.block, phase));
    }

    fn dims_surfaces(&self) -> bool {
        true
    }

    fn warnings(&self, flag: &str, manifest: &kiln_format::Manifest, warnings: &mut Vec<String>) {
        if !no_medium(flag, manifest, warnings) && manifest.shadow_maps.is_empty() && casters(manifest) {
            warnings.push(format!("{flag}: the file has no shadow maps; shafts of light are unshadowed"));
        }
    }
}
