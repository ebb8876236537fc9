//! `--gi ssgi`: screen-space diffuse GI (seed 000): the previous frame's lit radiance gathered
//! on spirals over a MIP hierarchy of depth, normals and light, joint-bilaterally upsampled;
//! added to the sky's ambient (`passes/ssgi.rs`, `shaders/ssgi/`).

use kiln_format::gpu::FrameFlags;

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::depth_pyramid::{self, Reduction};
use crate::render::passes::ssgi::SsgiPass;
use crate::render::techniques::knobs::{choice, number, whole};
use crate::render::techniques::{Knob, Knobs, Registered, ScreenFraction, Technique};

/// Screen-space diffuse GI.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ssgi {
    /// Spiral samples per pixel and level (the seed's 128).
    pub samples: u32,
    /// The finest level gathered: full, half (the seed's default, ~540p at 1080p) or quarter.
    pub resolution: ScreenFraction,
    /// Sample radius R in pixels of each level (the seed's 40).
    pub radius: u32,
    /// The depth and normal pyramids reduced by the seed's voting filter (else nearest).
    pub voting: bool,
    /// The seed's distance fall-off in place of visibility.
    pub falloff: bool,
    /// The most frames the running mean averages while the camera is still.
    pub frames: u32,
    /// One spiral rotation per 8 × 8 block of texels instead of per texel.
    pub tiled: bool,
}

impl Registered for Ssgi {
    const NAME: &'static str = "ssgi";
    const HELP: &'static str = "screen-space diffuse GI (seed 000): the previous frame's lit radiance gathered on \
                                --ssgi-samples spiral points per pixel on each level of a depth/normal/light MIP \
                                hierarchy (near light from fine levels, far light from coarse ones), \
                                joint-bilaterally upsampled, averaged over --ssgi-frames while the camera is \
                                still; added to the sky's ambient. No visibility: light passes through what the \
                                screen shows, and what it does not show (off screen, hidden) gives none";
    const KNOBS: &'static [Knob] = &[
        whole(number(
            "ssgi-samples",
            "spiral samples per pixel on each level (the seed's 128; tested 16 to 256)",
            1.0,
            1024.0,
            128.0,
            &[16.0, 32.0, 64.0, 128.0, 256.0],
        )),
        choice(
            "ssgi-res",
            "the finest level gathered, upsampled to the screen: full, half (the seed's \
             default, ~540p at 1080p) or quarter",
            &["full", "half", "quarter"],
            1,
        ),
        whole(number(
            "ssgi-radius",
            "sample radius R in pixels of each level (the seed's 40); levels go up until one \
             radius spans the screen",
            4.0,
            256.0,
            40.0,
            &[],
        )),
        choice(
            "ssgi-mip",
            "how the depth and normal pyramids pick each coarser texel: nearest (the \
             seed's fast) or voting (the seed's precise, its default)",
            &["nearest", "voting"],
            1,
        ),
        choice(
            "ssgi-falloff",
            "the seed's distance fall-off (1/r² becomes 1/r^2.5 beyond one scene unit) \
             standing in for the visibility it does not test: off or on",
            &["off", "on"],
            0,
        ),
        whole(number(
            "ssgi-frames",
            "the most frames the GI's running mean averages while the camera is still (then \
             exponential, as the bounces build up)",
            1.0,
            4096.0,
            16.0,
            &[],
        )),
        choice(
            "ssgi-rotation",
            "how the sample spirals turn: pixel (a random angle per texel, the seed's) or \
             tile (one per 8 × 8 texels, the default: neighbours read neighbouring texels, \
             15 % faster on an H100; one frame's noise 14 % higher, correlated within a \
             tile until frames average it)",
            &["pixel", "tile"],
            1,
        ),
    ];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Ssgi, String> {
        Ok(Ssgi {
            samples: k.whole("ssgi-samples")?,
            resolution: ScreenFraction::named(k.choice("ssgi-res")),
            radius: k.whole("ssgi-radius")?,
            voting: k.choice("ssgi-mip") == "voting",
            falloff: k.choice("ssgi-falloff") == "on",
            frames: k.whole("ssgi-frames")?,
            tiled: k.choice("ssgi-rotation") == "tile",
        })
    }
}

impl Technique for Ssgi {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let reduction = if self.voting { Reduction::Voting } else { Reduction::Nearest };
        frame.depth_pyramid(reduction, true, depth_pyramid::TOP);
        frame.lit_pyramid();
        let gpu = frame.gpu;
        let Ssgi { samples, resolution, radius, falloff, frames, tiled, .. } = *self;
        frame.add(Stage::Gi, move || SsgiPass::new(gpu, samples, resolution, radius, falloff, frames, tiled));
    }

    fn flags(&self) -> u32 {
        FrameFlags::SCREEN_GI
    }

    fn reads_previous_frame(&self) -> bool {
        true
    }
}
