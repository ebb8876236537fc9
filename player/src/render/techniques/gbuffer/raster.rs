//! `--gbuffer raster`: every material attribute rasterised per fragment (five targets).

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::gbuffer::GBufferPass;
use crate::render::techniques::{Technique, plain_technique};

plain_technique! {
    /// Rasterised with every material evaluated per fragment.
    Raster,
    "raster",
    "rasterise every material attribute (five targets)"
}

impl Technique for Raster {
    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, see_through) = (frame.gpu, frame.scene.see_through);
        frame.add(Stage::GBuffer, move || GBufferPass::new(gpu, see_through));
    }
}
