//! `--gbuffer visibility`: a visibility buffer (the triangle under each pixel) rasterised, the
//! materials evaluated in compute: far cheaper where raster throughput is small next to compute
//! (datacenter GPUs).

use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::resolve::ResolvePass;
use crate::render::passes::visibility::VisibilityPass;
use crate::render::techniques::{Needs, Technique, plain_technique};

plain_technique! {
    /// A visibility buffer rasterised, the materials resolved in compute.
    Visibility,
    "visibility",
    "rasterise a visibility buffer (triangle per pixel), evaluate materials in compute: \
                                faster on GPUs with little raster hardware (e.g. NVIDIA H100/H200)"
}

impl Technique for Visibility {
    fn needs(&self) -> Needs {
        // The resolve reads the materials, triangles and texels as storage buffers.
        Needs { scene_buffers: true, ..Needs::NONE }
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, decode, see_through) = (frame.gpu, frame.decode, frame.scene.see_through);
        frame.add(Stage::GBuffer, move || VisibilityPass::new(gpu, see_through));
        frame.add(Stage::GBuffer, move || ResolvePass::new(gpu, decode));
    }
}
