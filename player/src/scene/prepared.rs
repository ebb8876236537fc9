//! The CPU side of loading a file: validated, checksums verified, indices sorted by material,
//! the tables the upload copies, while the driver creates the device.

use kiln_format::read::KilnFile;
use kiln_format::scene::SceneView;
use kiln_format::sections::PixelFormat;

use super::geometry::{see_through_bounds, sort_by_material, triangle_corners};
use super::{Draw, bad, linespace, reference, uploads};
use crate::error::PlayResult;
use crate::render::{Needs, TexelDecode};

/// The largest texel buffer decoded to RGBA8: 2²⁷ bytes, the storage-buffer range every Vulkan
/// device offers (lavapipe's limit). Beyond it the blocks stay, decoded in the shader.
const DECODED_TEXELS_MAX: u64 = 1 << 27;

/// The CPU side of loading, done while the device is being created: the file validated, the
/// checksums of every section to upload verified (which also pages them in), and the index
/// buffer sorted by material.
pub struct Prepared<'f> {
    pub(super) view: SceneView<'f>,
    pub(super) needs: Needs,
    pub(super) indices: Vec<u32>,
    pub(super) draws: Vec<Draw>,
    /// [`super::GpuScene::see_through_bounds`], found once here.
    pub(super) see_through_bounds: Option<[glam::Vec3; 2]>,
    /// Triangle corners in leaf order, (x, y, z, 0) each, when the BVH is needed.
    pub(super) bvh_triangles: Vec<[f32; 4]>,
    /// Emitter and texture tables of the reference path tracer.
    pub(super) reference: Option<reference::ReferenceTables>,
    /// Where the line-space arrays go, when a technique reads them.
    pub(super) line_space: Option<linespace::LineSpaceLayout>,
}

impl std::fmt::Debug for Prepared<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Prepared").field("draws", &self.draws.len()).finish()
    }
}

impl<'f> Prepared<'f> {
    /// Validates `file` and prepares what the upload of `needs` copies. First verifies and
    /// decodes, on all cores, the compressed sections that an upload of `first` reads (the rest
    /// decode when first read), and returns the wall time of that too: run while the driver
    /// creates the device, it leaves the upload only copies.
    pub fn new(file: &'f KilnFile, needs: Needs, first: Needs) -> PlayResult<(Prepared<'f>, f64)> {
        let t = std::time::Instant::now();
        let positions: Vec<usize> = file
            .sections()
            .iter()
            .filter(|s| {
                s.known.is_some()
                    && (uploads(s.entry.kind, first)
                        || linespace::LineSpaceLayout::may_upload(s.entry.kind, first.line_space))
            })
            .map(|s| s.position)
            .collect();
        // Sections whose length a record fixes are compared with it first, without decoding.
        kiln_format::scene::check_declared_sizes(file).map_err(bad)?;
        file.decode_sections(&positions).map_err(bad)?;
        let decode_ms = t.elapsed().as_secs_f64() * 1e3;
        let view = SceneView::new(file).map_err(bad)?;
        let line_space = if needs.line_space & linespace::LsArrays::ALL != 0 {
            linespace::LineSpaceLayout::new(
                file,
                view.triangles.len(),
                view.materials.len(),
                needs.line_space,
            )?
        } else {
            None
        };
        for s in file.sections() {
            let ls = line_space.as_ref().is_some_and(|l| l.uploads(s.entry.kind));
            if s.known.is_some() && (uploads(s.entry.kind, needs) || ls) {
                file.verify_section(s.position).map_err(bad)?;
            }
        }
        let (indices, draws) =
            sort_by_material(view.triangles, view.triangle_materials, view.materials.len());
        let bvh_triangles =
            if needs.bvh { triangle_corners(view.vertices, view.triangles) } else { Vec::new() };
        // The ray-traced passes read each texture as stored (RGBA8 or BC blocks, the GLSL decodes
        // them); their table needs each texture's format and swizzle from its section header.
        // How the texel buffer stores each texture: as the file does, or RGBA8 of the stored
        // channels where the run decodes the blocks at upload (the swizzle is unchanged) and the
        // decoded chains fit one storage buffer of the size every device allows.
        let decode = needs.decoded_texels
            && view
                .manifest
                .textures
                .iter()
                .map(|t| PixelFormat::Rgba8.chain_bytes(t.width, t.height, t.mip_levels).unwrap_or(0))
                .sum::<u64>()
                <= DECODED_TEXELS_MAX;
        let stored = |format| if decode { PixelFormat::Rgba8 } else { format };
        let storage = if needs.scene_buffers && needs.textures {
            (0..view.manifest.textures.len())
                .map(|i| view.texture(i).map(|t| (stored(t.format), t.swizzle)))
                .collect::<Result<Vec<_>, _>>()
                .map_err(bad)?
        } else {
            Vec::new()
        };
        let emitter_luminance = view.emitter_luminance().map_err(bad)?;
        let reference = needs.scene_buffers.then(|| {
            reference::tables(
                &view.manifest,
                view.vertices,
                view.triangles,
                view.triangle_materials,
                &view.materials,
                &storage,
                emitter_luminance,
            )
        });
        let see_through_bounds = see_through_bounds(&draws, &indices, view.vertices, &view.materials);
        Ok((
            Prepared {
                view,
                needs,
                indices,
                draws,
                see_through_bounds,
                bvh_triangles,
                reference,
                line_space,
            },
            decode_ms,
        ))
    }

    /// How the passes that read the texel buffer must decode it: from the texture table they
    /// read (the formats in the textures' section headers), known before any section uploads.
    pub fn texel_decode(&self) -> TexelDecode {
        self.reference.as_ref().map_or(TexelDecode::Rgba8, |r| TexelDecode::of(&r.textures))
    }
}

impl Prepared<'_> {
    /// The file's manifest.
    pub fn manifest(&self) -> &kiln_format::Manifest {
        &self.view.manifest
    }

    /// The world bounds of the see-through triangles ([`super::GpuScene::see_through_bounds`]).
    pub fn see_through_bounds(&self) -> Option<[glam::Vec3; 2]> {
        self.see_through_bounds
    }
}
