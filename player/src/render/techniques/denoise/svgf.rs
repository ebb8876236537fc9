//! `--denoise svgf`: spatiotemporal variance-guided filtering (Schied et al. 2017) of the
//! ray-traced signals that the techniques declare noisy (`Technique::noisy`: GI, the emissive
//! surfaces' direct light), over their running means (`passes/denoise.rs`,
//! `shaders/denoise/`).

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::denoise::{DenoisePass, Filter};
use crate::render::techniques::knobs::{choice, number, whole};
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// The filter's knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Svgf {
    /// The filter's settings.
    pub filter: Filter,
}

impl Registered for Svgf {
    const NAME: &'static str = "svgf";
    const HELP: &'static str = "spatiotemporal variance-guided filtering (SVGF) of the ray-traced GI and of the \
                                emissive surfaces' direct light: an edge-aware à-trous filter whose strength \
                                follows each pixel's noise (its running mean's variance), so it fades out as a \
                                still camera's frames accumulate and the image converges to the same mean as \
                                without it; albedo is divided out while filtering. Takes effect where such a \
                                signal is traced (--gi rt|linespace, --direct ris|restir); with --aa \
                                reproject|taa the history follows a moving camera";
    const KNOBS: &'static [Knob] = &[
        whole(number(
            "denoise-iterations",
            "à-trous iterations: iteration i's taps lie 2^i pixels apart, so k iterations reach \
             2 (2^k − 1) pixels with 5 × 5 taps, 2^k − 1 with 3 × 3",
            1.0,
            8.0,
            5.0,
            &[3.0, 5.0],
        )),
        number(
            "denoise-sigma-luminance",
            "luminance edge-stopping: neighbours differing by this many standard deviations of \
             the noise weigh 1/e (smaller keeps more detail and more noise)",
            0.5,
            64.0,
            8.0,
            &[4.0, 8.0, 16.0],
        ),
        choice(
            "denoise-taps",
            "taps of each iteration: 3x3 (the linear B-spline) or 5x5 (SVGF's B3 spline: 25 taps \
             instead of 9, a wider reach per iteration; measured no better, at twice the cost)",
            &["3x3", "5x5"],
            0,
        ),
    ];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Svgf, String> {
        let filter = Filter {
            iterations: k.whole("denoise-iterations")?,
            sigma_luminance: k.number("denoise-sigma-luminance"),
            sigma_normal: 128.0,
            sigma_plane: 1.0,
            taps: if k.choice("denoise-taps") == "5x5" { 5 } else { 3 },
        };
        Ok(Svgf { filter })
    }
}

impl Technique for Svgf {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let signals = frame.techniques.noisy();
        if signals.is_empty() {
            return;
        }
        let reprojected = frame.techniques.reprojected_rays().is_some();
        let (gpu, filter) = (frame.gpu, self.filter);
        frame.add(Stage::Denoise, move || DenoisePass::new(gpu, signals, filter, reprojected));
    }
}
