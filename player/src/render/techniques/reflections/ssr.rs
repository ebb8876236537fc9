//! `--reflections ssr`: screen-space reflections (seed 000 §3.9, traced hierarchically after
//! McGuire & Mara 2014 and AMD's FidelityFX SSSR): the mirror direction marched through a
//! closest-depth (Hi-Z) pyramid, a hit accepted at the coarsest level the roughness's cone
//! covers, showing the previous frame's lit radiance; the split-sum ambient where the ray misses
//! or leaves the screen (`passes/ssr.rs`, `passes/hiz.rs`).

use kiln_format::gpu::FrameFlags;

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::hiz::HizPass;
use crate::render::passes::ssr::SsrPass;
use crate::render::techniques::knobs::{number, whole};
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// Screen-space reflections.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ssr {
    /// The most iterations of the hierarchical march per pixel.
    pub steps: u32,
    /// Surfaces rougher than this keep the split-sum ambient.
    pub max_roughness: f32,
}

impl Registered for Ssr {
    const NAME: &'static str = "ssr";
    const HELP: &'static str = "screen-space reflections (seed 000, traced hierarchically after McGuire & Mara 2014 and \
                                AMD's SSSR): the mirror direction marched through a closest-depth pyramid, showing \
                                the previous frame's lit radiance at the hit; rougher surfaces accept coarser hits; \
                                the split-sum ambient where the ray misses or leaves the screen (faded near its \
                                edges) and above --ssr-max-roughness; see --ssr-steps";
    const KNOBS: &'static [Knob] = &[
        whole(number(
            "ssr-steps",
            "most iterations of the hierarchical march per pixel: each skips a cell of empty space \
             (a level up) or refines a potential hit (a level down); 48 crosses a 1080p screen \
             with room to refine, fewer lose distant hits",
            1.0,
            1024.0,
            48.0,
            &[16.0, 32.0, 48.0, 96.0],
        )),
        number(
            "ssr-max-roughness",
            "surfaces rougher than this keep the split-sum ambient (faded over the last fifth): \
             above about 0.6 the cone covers much of the screen, where one ray says little",
            0.0,
            1.0,
            0.6,
            &[0.3, 0.6],
        ),
    ];
    // Not noisy, but it shows the previous frame's radiance (the first frame its own, without
    // what its reflections add: frames differ until the bounces settle).
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Ssr, String> {
        Ok(Ssr { steps: k.whole("ssr-steps")?, max_roughness: k.number("ssr-max-roughness") })
    }
}

impl Technique for Ssr {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        frame.lit_pyramid();
        let gpu = frame.gpu;
        frame.add(Stage::Reflections, move || HizPass::new(gpu));
        frame.add(Stage::Reflections, move || SsrPass::new(gpu, self.steps, self.max_roughness));
    }

    fn flags(&self) -> u32 {
        FrameFlags::SCREEN_REFLECTIONS
    }

    fn reads_previous_frame(&self) -> bool {
        true
    }
}
