//! `--gbuffer raster`: every material attribute rasterised per fragment (five targets).

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::gbuffer::GBufferPass;
use crate::render::techniques::{Knobs, Registered, Technique};

/// Rasterised with every material evaluated per fragment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Raster;

impl Registered for Raster {
    const NAME: &'static str = "raster";
    const HELP: &'static str = "rasterise every material attribute (five targets)";

    fn new(_: &Knobs) -> Result<Raster, String> {
        Ok(Raster)
    }
}

impl Technique for Raster {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let gpu = frame.gpu;
        frame.add(Stage::GBuffer, move || GBufferPass::new(gpu));
    }
}
