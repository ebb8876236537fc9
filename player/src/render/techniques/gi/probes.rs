//! `--gi probes`: diffuse GI from the irradiance probe volume the compiler bakes (`kiln compile`,
//! stage `probes`): per pixel, the eight surrounding probes weighted trilinearly, by the
//! surface's normal and by the Chebyshev test of their distance moments, with a bias along the
//! normal and towards the camera (`passes/probes.rs`, `shaders/probes/`). No rays at run time.

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::probes::{NORMAL_BIAS, ProbesPass, VIEW_BIAS};
use crate::render::techniques::knobs::number;
use crate::render::techniques::{Knob, Knobs, Needs, Registered, Technique};

/// Baked irradiance probes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probes {
    /// The lookup point's move along the surface normal, in probe spacings.
    pub normal_bias: f32,
    /// … and towards the camera.
    pub view_bias: f32,
}

impl Eq for Probes {}

impl Registered for Probes {
    const NAME: &'static str = "probes";
    const HELP: &'static str = "the compiler's irradiance probes (path traced at every bounce): the eight probes around \
                                each pixel's surface, weighted trilinearly, by the normal and by a Chebyshev visibility \
                                test against light leaking through walls; replaces the sky's diffuse ambient and its AO, \
                                and the sky in glossy reflections that are not traced or seen on screen (the probes' \
                                irradiance along the mirror direction). \
                                No rays at run time (needs a file compiled with probes: kiln compile bakes them unless \
                                --probes off). Emissive surfaces' direct light comes from the probes only with \
                                --direct none";
    const KNOBS: &'static [Knob] = &[
        number(
            "probe-normal-bias",
            "how far the lookup point moves along the surface normal, in probe spacings (keeps \
             a surface from shadowing itself in the probes' distance maps)",
            0.0,
            1.0,
            NORMAL_BIAS,
            &[0.05, 0.2],
        ),
        number(
            "probe-view-bias",
            "how far the lookup point moves towards the camera, in probe spacings",
            0.0,
            1.0,
            VIEW_BIAS,
            &[0.1, 0.4],
        ),
    ];
    const STOCHASTIC: bool = false;

    fn new(k: &Knobs) -> Result<Probes, String> {
        Ok(Probes { normal_bias: k.number("probe-normal-bias"), view_bias: k.number("probe-view-bias") })
    }
}

impl Technique for Probes {
    fn needs(&self) -> Needs {
        Needs { probes: true, ..Needs::NONE }
    }

    fn flags(&self) -> u32 {
        kiln_format::gpu::FrameFlags::RT_GI | kiln_format::gpu::FrameFlags::PROBE_SPECULAR
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        let Probes { normal_bias, view_bias } = *self;
        frame.add(Stage::Gi, move || ProbesPass::new(gpu, normal_bias, view_bias));
    }
}
