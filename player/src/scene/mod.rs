//! A `.kiln` file made resident on the GPU: its sections uploaded in file order through the
//! staging ring, only those the enabled passes read. The rest are skipped and listed.
//!
//! The upload can come in two parts: first what the first frame reads (its [`Needs`]: a
//! fallback's, while the chosen techniques' pipelines compile), then, after that frame, the
//! sections only the chosen techniques read ([`GpuScene::load_rest`]).
//!
//! Textures can come in two parts as well ([`TextureUpload::CoarseFirst`]): their coarse levels
//! before the first frame, which samples them through views that start at the first level
//! uploaded, and their finer levels after it, in [`GpuScene::load_rest`]; then
//! [`GpuScene::use_refined_views`] hands the raster passes the full chains.

pub mod bindings;
pub mod linespace;
pub mod media;
pub mod probes;
pub mod reference;
pub mod upload;

use std::collections::HashMap;

use crate::gpu::vk;
use kiln_format::gpu::GpuVertexAttributes;
use kiln_format::manifest::{ColorSpace, Manifest, ShadowProjection, Wrap};
use kiln_format::read::KilnFile;
use kiln_format::scene::SceneView;
use kiln_format::sections::{self, GpuMaterial, PixelFormat, Swizzle, Vertex};

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Buffer, Gpu, Image, ImageDesc, Sampler, SamplerKey, View, Write};
use crate::render::{Needs, TexelDecode};
use upload::Uploader;

/// One draw: the triangles of one material, contiguous in the index buffer.
#[derive(Debug, Clone, Copy)]
pub struct Draw {
    /// Material index.
    pub material: u32,
    /// First index.
    pub first: u32,
    /// Index count.
    pub count: u32,
}

/// A resident shadow map.
#[derive(Debug)]
pub struct ShadowImage {
    /// Index in `manifest.shadow_maps`.
    pub map: usize,
    /// The depths (R32F; six layers for cube maps).
    pub image: Image,
}

/// The largest side, in texels, of the finest level a streamed texture uploads before the first
/// frame: its levels from the first this small down to 1×1 come first. 256 keeps that part a
/// small fraction of the bytes (1/64 of a 2048² texture's chain, PICA PICA's size: 1.6 %),
/// while a level of 256 texels is sharp wherever the texture spans up to 256 pixels on screen,
/// the common case in a first frame over a scene with many textures.
pub const COARSE_SIDE: u32 = 256;

/// How textures reach the GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TextureUpload {
    /// Every level before the first frame.
    #[default]
    Whole,
    /// Each texture's levels from the first at most [`COARSE_SIDE`] texels on a side before the
    /// first frame, the finer ones after it ([`GpuScene::load_rest`]).
    CoarseFirst,
}

/// The first level of a `width` × `height` texture with `mips` levels that a streamed upload
/// sends before the first frame: the first whose larger side is at most [`COARSE_SIDE`] (the
/// last level when none is: a chain cut short), 0 for a texture already that small.
pub fn first_coarse_level(width: u32, height: u32, mips: u32) -> u32 {
    let last = mips.max(1) - 1;
    (0..=last).find(|&l| (width >> l).max(height >> l).max(1) <= COARSE_SIDE).unwrap_or(last)
}

/// A texture whose finer levels are still to come: the raster passes sample it through `view`
/// (its handle is in [`GpuScene::texture_views`]; held here to be released when dropped), which
/// starts at `first`, the finest level uploaded.
#[derive(Debug)]
struct CoarseTexture {
    texture: usize,
    first: u32,
    _view: View,
}

/// A section and what happened to it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SectionFate {
    /// Kind and index, as `inspect` names them.
    pub section: String,
    /// Bytes in the file.
    pub bytes: u64,
    /// Uploaded, or why not.
    pub uploaded: bool,
    /// Why it was skipped (empty when uploaded or read on the CPU).
    pub reason: String,
    /// Uploaded after the first frame, which does not read it (or reads only a part that
    /// was uploaded before it: the triangles and texture of a file whose ray-traced passes
    /// read them again as storage buffers).
    pub after_first_frame: bool,
    /// For a streamed texture, its finer levels (finest, coarsest) that upload after the first
    /// frame; the first frame samples the levels after them.
    pub fine_mips: Option<[u32; 2]>,
}

impl SectionFate {
    /// The section as `after_first_frame` lists it: a streamed texture with the levels that
    /// come later (`texture#0 mips 0-2`, `texture#1 mip 0`).
    pub fn later_name(&self) -> String {
        match self.fine_mips {
            Some([a, b]) if a == b => format!("{} mip {a}", self.section),
            Some([a, b]) => format!("{} mips {a}-{b}", self.section),
            None => self.section.clone(),
        }
    }
}

/// The CPU side of loading, done while the device is being created: the file validated, the
/// checksums of every section to upload verified (which also pages them in), and the index
/// buffer sorted by material.
pub struct Prepared<'f> {
    view: SceneView<'f>,
    needs: Needs,
    indices: Vec<u32>,
    draws: Vec<Draw>,
    /// Triangle corners in leaf order, (x, y, z, 0) each, when the BVH is needed.
    bvh_triangles: Vec<[f32; 4]>,
    /// Emitter and texture tables of the reference path tracer.
    reference: Option<reference::ReferenceTables>,
    /// Where the line-space arrays go, when a technique reads them.
    line_space: Option<linespace::LineSpaceLayout>,
}

impl std::fmt::Debug for Prepared<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Prepared").field("draws", &self.draws.len()).finish()
    }
}

/// What one pass of the upload makes resident: the sections `now` reads, and the geometry
/// (vertices, attributes, sorted indices) in the first pass.
#[derive(Debug, Clone, Copy)]
struct Part {
    now: Needs,
    geometry: bool,
    /// How the textures uploaded in the first part go (a later part sends the finer levels
    /// of the textures the first left coarse).
    textures: TextureUpload,
}

/// The probe volume's sections.
const PROBE_KINDS: [kiln_format::table::SectionKind; 4] =
    [sections::PROBE_GRID, sections::PROBE_STATES, sections::PROBE_IRRADIANCE, sections::PROBE_VISIBILITY];

/// Whether a section of `kind` is uploaded under `needs` (geometry always).
fn uploads(kind: kiln_format::table::SectionKind, needs: Needs) -> bool {
    kind == sections::VERTICES
        || kind == sections::UVS
        || kind == sections::COLORS
        || kind == sections::TRIANGLES
        || (kind == sections::TEXTURE && needs.textures)
        || (kind == sections::BRDF_LUT && needs.brdf_lut)
        || (kind == sections::SHADOW_MAP && needs.shadow_maps)
        || (kind == sections::BVH_NODES && needs.bvh)
        || (kind == sections::MEDIA_VISIBILITY && needs.media_volumes)
        || (PROBE_KINDS.contains(&kind) && needs.probes)
        || ((kind == sections::TRIANGLE_MATERIALS || kind == sections::MATERIALS) && needs.scene_buffers)
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
        let storage = if needs.scene_buffers && needs.textures {
            (0..view.manifest.textures.len())
                .map(|i| view.texture(i).map(|t| (t.format, t.swizzle)))
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
                view.materials,
                &storage,
                emitter_luminance,
            )
        });
        Ok((Prepared { view, needs, indices, draws, bvh_triangles, reference, line_space }, decode_ms))
    }

    /// How the passes that read the texel buffer must decode it: from the texture table they
    /// read (the formats in the textures' section headers), known before any section uploads.
    pub fn texel_decode(&self) -> TexelDecode {
        self.reference.as_ref().map_or(TexelDecode::Rgba8, |r| TexelDecode::of(&r.textures))
    }
}

impl GpuScene {
    /// Descriptor writes of what every ray-traced pass reads ([`bindings::TABLE`] but the
    /// lights, which the pass writes). `None` without the BVH or the scene buffers.
    pub fn ray_writes(&self) -> Option<Vec<Write<'_>>> {
        let (bvh, r) = (self.bvh.as_ref()?, self.reference.as_ref()?);
        Some(vec![
            Write::Buffer(bindings::BVH_NODES.binding, &bvh.nodes),
            Write::Buffer(bindings::BVH_TRIANGLES.binding, &bvh.triangles),
            Write::Buffer(bindings::VERTICES.binding, &self.vertices),
            Write::Buffer(bindings::VERTEX_ATTRIBUTES.binding, &self.attributes),
            Write::Buffer(bindings::LEAF_INDICES.binding, &r.indices),
            Write::Buffer(bindings::TRIANGLE_MATERIALS.binding, &r.triangle_materials),
            Write::Buffer(bindings::MATERIALS.binding, &r.materials),
        ])
    }
}

impl Prepared<'_> {
    /// The file's manifest.
    pub fn manifest(&self) -> &kiln_format::Manifest {
        &self.view.manifest
    }
}

/// Triangle corners in leaf (file) order as `vec4`s, three per triangle: what the GPU traversal
/// reads (one load per corner instead of an index and a vertex fetch).
pub fn triangle_corners(vertices: &[Vertex], triangles: &[[u32; 3]]) -> Vec<[f32; 4]> {
    triangles
        .iter()
        .flat_map(|t| {
            t.map(|i| {
                let p = vertices[i as usize].position;
                [p[0], p[1], p[2], 0.0]
            })
        })
        .collect()
}

/// The BVH on the GPU: nodes as in the file and triangle corners in leaf order.
#[derive(Debug)]
pub struct BvhBuffers {
    /// `CwbvhNode`s (80 bytes each).
    pub nodes: Buffer,
    /// Three `vec4` corners per triangle.
    pub triangles: Buffer,
    /// Node count.
    pub node_count: u32,
    /// Triangle count.
    pub triangle_count: u32,
}

/// What the reference path tracer reads beyond the BVH, each a storage buffer.
#[derive(Debug)]
pub struct ReferenceBuffers {
    /// Vertex indices in leaf order (the file's `TRIS`).
    pub indices: Buffer,
    /// Material per triangle (`TMAT`).
    pub triangle_materials: Buffer,
    /// Materials (`MATL`).
    pub materials: Buffer,
    /// `GpuEmitter` table.
    pub emitters: Buffer,
    /// Emitter of each triangle (i32, −1 for none).
    pub triangle_emitter: Buffer,
    /// `GpuEmitter` table of the emissive triangles alone.
    pub emissive: Buffer,
    /// Mip 0 of every texture, RGBA8 words.
    pub texels: Buffer,
    /// `GpuTexture` table.
    pub textures: Buffer,
    /// Material of each triangle in draw order (the G-buffer's triangle target).
    pub raster_materials: Buffer,
    /// `GpuMedium` table.
    pub media: Buffer,
    /// How the passes that read `texels` decode it.
    pub texel_decode: TexelDecode,
    /// Entries in `emitters`.
    pub emitter_count: u32,
    /// Entries in `emissive`.
    pub emissive_count: u32,
    /// Entries in `media`.
    pub media_count: u32,
}

impl ReferenceBuffers {}

/// The scene on the GPU. Dropping it releases every resource: no submitted work may still use
/// them (its owner waits for the GPU first).
pub struct GpuScene {
    /// The file's manifest.
    pub manifest: Manifest,
    /// Positions and normals (24-byte `Vertex`).
    pub vertices: Buffer,
    /// Texture coordinates and colours per vertex (`GpuVertexAttributes`: zeros and white
    /// when the file has none).
    pub attributes: Buffer,
    /// Triangle indices sorted by material.
    pub indices: Buffer,
    /// One draw per material with triangles.
    pub draws: Vec<Draw>,
    /// Materials (pushed as constants per draw).
    pub materials: Vec<GpuMaterial>,
    /// Textures sampled through a coarse view, waiting for their finer levels (declared before
    /// `textures`: the views are dropped before their images).
    coarse: Vec<CoarseTexture>,
    /// Material textures (empty when textures are not needed).
    pub textures: Vec<Image>,
    /// The view the raster passes sample each texture through: the image's own (every level)
    /// or, until its finer levels arrive, one of its coarse levels only.
    pub texture_views: Vec<vk::ImageView>,
    /// Bytes of texture levels uploaded before the first frame (every level without streaming).
    pub coarse_texture_bytes: u64,
    /// Bytes of texture levels uploaded after it (the finer levels of streamed textures).
    pub fine_texture_bytes: u64,
    /// The sampler of each texture.
    pub texture_samplers: Vec<vk::Sampler>,
    /// The BRDF table, when the file has one and a pass needs it.
    pub brdf_lut: Option<Image>,
    /// Linear clamp sampler (BRDF table).
    pub linear_clamp: vk::Sampler,
    /// Nearest clamp sampler (shadow maps, G-buffer reads).
    pub nearest_clamp: vk::Sampler,
    /// Shadow maps, when needed.
    pub shadow_maps: Vec<ShadowImage>,
    /// The BVH, when ray queries are needed and the file has one.
    pub bvh: Option<BvhBuffers>,
    /// The reference path tracer's buffers, when asked for.
    pub reference: Option<ReferenceBuffers>,
    /// The voxel grid and line space arrays the techniques read.
    pub line_space: Option<linespace::LineSpaceBuffers>,
    /// The media table and light-visibility volumes, when a media technique reads them.
    pub media: Option<media::MediaBuffers>,
    /// The irradiance probe volume, when `--gi probes` reads it.
    pub probes: Option<probes::ProbeImages>,
    /// Every section of the file and its fate.
    pub sections: Vec<SectionFate>,
    /// Bytes uploaded.
    pub uploaded_bytes: u64,
    /// What is resident (of what the passes read; geometry always).
    pub resident: Needs,
    samplers: HashMap<SamplerKey, Sampler>,
}

impl std::fmt::Debug for GpuScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuScene")
            .field("scene", &self.manifest.scene_name)
            .field("draws", &self.draws.len())
            .finish()
    }
}

fn bad(e: kiln_format::error::FormatError) -> PlayError {
    PlayError::new(Exit::BadInput, format!("invalid .kiln file: {e}"))
}

fn wrap_mode(w: Wrap) -> vk::SamplerAddressMode {
    match w {
        Wrap::Repeat => vk::SamplerAddressMode::REPEAT,
        Wrap::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        Wrap::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
    }
}

/// Sorts triangle indices by material (a counting sort, stable within a material); returns the
/// flat index list and one draw per material that has triangles.
pub fn sort_by_material(
    triangles: &[[u32; 3]],
    triangle_materials: &[u32],
    materials: usize,
) -> (Vec<u32>, Vec<Draw>) {
    let mut counts = vec![0u32; materials];
    for &m in triangle_materials {
        counts[m as usize] += 1;
    }
    let mut starts = vec![0u32; materials];
    let mut draws = Vec::new();
    let mut sum = 0u32;
    for (m, &c) in counts.iter().enumerate() {
        starts[m] = sum;
        if c > 0 {
            draws.push(Draw { material: m as u32, first: sum * 3, count: c * 3 });
        }
        sum += c;
    }
    let mut indices = vec![0u32; triangles.len() * 3];
    for (t, &m) in triangles.iter().zip(triangle_materials) {
        let at = starts[m as usize] as usize * 3;
        indices[at..at + 3].copy_from_slice(t);
        starts[m as usize] += 1;
    }
    (indices, draws)
}

/// `UVS0` and `COL0` interleaved per vertex, as the passes read them.
fn vertex_attributes(view: &SceneView) -> Vec<GpuVertexAttributes> {
    (0..view.vertices.len())
        .map(|i| {
            let c = view.colors.get(i).copied().unwrap_or([u16::MAX; 4]);
            GpuVertexAttributes {
                uv: view.uvs.get(i).copied().unwrap_or_default(),
                color: [c[0] as u32 | (c[1] as u32) << 16, c[2] as u32 | (c[3] as u32) << 16],
            }
        })
        .collect()
}

impl GpuScene {
    /// Length of the scene's bounding-box diagonal, in scene units (what sizes relative to the
    /// scene are fractions of).
    pub fn diagonal(&self) -> f32 {
        let b = self.manifest.bounds;
        glam::Vec3::from(b.max).distance(glam::Vec3::from(b.min))
    }

    /// Uploads what `prepared` needs through `up`, of the sections beyond the geometry only
    /// those `first` reads (`prepared`'s own needs: all of them); the others are listed as
    /// uploaded after the first frame, for [`GpuScene::load_rest`]; so are the finer levels of
    /// the textures with [`TextureUpload::CoarseFirst`]. Returns when everything is recorded;
    /// the caller flushes the uploader and waits on its timeline before drawing.
    pub fn load(
        gpu: &Gpu,
        file: &KilnFile,
        prepared: &Prepared,
        first: Needs,
        textures: TextureUpload,
        up: &mut Uploader,
    ) -> PlayResult<GpuScene> {
        let view = &prepared.view;
        let sampler = |key| Sampler::new(gpu, key);
        let clamp = vk::SamplerAddressMode::CLAMP_TO_EDGE;
        let mut samplers = HashMap::new();
        let linear_key = SamplerKey { linear: true, mipmaps: false, wrap_u: clamp, wrap_v: clamp };
        let nearest_key = SamplerKey { linear: false, mipmaps: false, wrap_u: clamp, wrap_v: clamp };
        samplers.insert(linear_key, sampler(linear_key)?);
        samplers.insert(nearest_key, sampler(nearest_key)?);
        let vertex_usage = vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let vertices =
            Buffer::uploaded(gpu, "vertices", std::mem::size_of_val(view.vertices) as u64, vertex_usage)?;
        let attributes = Buffer::uploaded(
            gpu,
            "vertex attributes",
            (view.vertices.len() * std::mem::size_of::<GpuVertexAttributes>()) as u64,
            vertex_usage,
        )?;
        let indices = Buffer::uploaded(
            gpu,
            "indices",
            (prepared.indices.len() * 4) as u64,
            // Storage too: the ray-traced passes rebuild surface points from the G-buffer's triangle.
            vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let mut scene = GpuScene {
            manifest: view.manifest.clone(),
            vertices,
            attributes,
            indices,
            draws: prepared.draws.clone(),
            materials: view.materials.to_vec(),
            coarse: Vec::new(),
            textures: Vec::new(),
            texture_views: Vec::new(),
            coarse_texture_bytes: 0,
            fine_texture_bytes: 0,
            texture_samplers: Vec::new(),
            brdf_lut: None,
            linear_clamp: samplers[&linear_key].raw,
            nearest_clamp: samplers[&nearest_key].raw,
            shadow_maps: Vec::new(),
            bvh: None,
            reference: None,
            line_space: None,
            media: None,
            probes: None,
            sections: Vec::new(),
            uploaded_bytes: 0,
            resident: Needs::default(),
            samplers,
        };
        let part = Part { now: prepared.needs.minus(prepared.needs.minus(first)), geometry: true, textures };
        match scene.upload_sections(gpu, file, prepared, part, up) {
            Ok(()) => {
                scene.uploaded_bytes = up.bytes;
                Ok(scene)
            }
            Err(e) => {
                // The uploader may still reference these resources; wait for it before the scene
                // is dropped (here, on return).
                let _ = up.flush();
                let _ = gpu.wait_idle();
                Err(e)
            }
        }
    }

    /// Uploads the sections the first part left ([`GpuScene::load`] with fewer needs than
    /// `prepared`'s; `prepared` made again from the same file, with the same needs). Returns
    /// when everything is recorded; the caller flushes the uploader and waits for it.
    pub fn load_rest(
        &mut self,
        gpu: &Gpu,
        file: &KilnFile,
        prepared: &Prepared,
        up: &mut Uploader,
    ) -> PlayResult {
        let part = Part {
            now: prepared.needs.minus(self.resident),
            geometry: false,
            textures: TextureUpload::Whole,
        };
        self.upload_sections(gpu, file, prepared, part, up)?;
        self.uploaded_bytes += up.bytes;
        Ok(())
    }

    /// Whether sections the passes read wait for [`GpuScene::load_rest`].
    pub fn deferred(&self) -> bool {
        self.sections.iter().any(|s| s.after_first_frame)
    }

    /// Whether the raster passes sample some texture through a coarse view (its finer levels
    /// wait for [`GpuScene::load_rest`], or are resident and wait for
    /// [`GpuScene::use_refined_views`]).
    pub fn coarse_views(&self) -> bool {
        !self.coarse.is_empty()
    }

    /// Makes every texture's view its full chain and releases (drops) the coarse views, once
    /// [`GpuScene::load_rest`]'s finer levels are resident. No submitted work may still use the
    /// coarse views, and the caller rewrites the descriptor sets that named them.
    pub fn use_refined_views(&mut self) {
        for c in self.coarse.drain(..) {
            self.texture_views[c.texture] = self.textures[c.texture].view;
        }
    }

    fn upload_sections(
        &mut self,
        gpu: &Gpu,
        file: &KilnFile,
        prepared: &Prepared,
        part: Part,
        up: &mut Uploader,
    ) -> PlayResult {
        let (view, all, now) = (&prepared.view, prepared.needs, part.now);
        // The first part lists every section's fate; a later one only uploads.
        let first = part.geometry;
        self.resident = self.resident.union(now);
        if let (Some(tables), true) = (&prepared.reference, now.scene_buffers) {
            self.reference = Some(reference_buffers(gpu, view, tables)?);
        }
        if let (Some(layout), true) = (&prepared.line_space, now.line_space != 0) {
            self.line_space = Some(linespace::LineSpaceBuffers::new(gpu, layout, up)?);
        }
        if now.media && !view.manifest.media.is_empty() {
            self.media = Some(media::MediaBuffers::new(gpu, &view.manifest, all.media_volumes, up)?);
        }
        if now.probes {
            let volume = kiln_format::probes::ProbeVolume::read(file).map_err(bad)?.ok_or_else(|| {
                PlayError::new(
                    Exit::BadInput,
                    "--gi probes: the file has no irradiance probes; recompile it with kiln compile \
                     (probes are baked unless --probes off is given or nothing lights the scene)",
                )
            })?;
            self.probes = Some(probes::ProbeImages::new(gpu, &volume, up)?);
        }
        for s in file.sections() {
            let kind = s.entry.kind;
            let index = s.entry.index;
            let name = match s.known {
                Some(k) if k.indexed => format!("{}#{index}", k.name),
                Some(k) => k.name.to_string(),
                None => format!("{kind} (unknown to this player)"),
            };
            let mut fate = SectionFate {
                section: name,
                bytes: s.entry.raw_size,
                uploaded: true,
                reason: String::new(),
                after_first_frame: false,
                fine_mips: None,
            };
            // Sections (or parts of them) that a later part uploads.
            let scene_buffers_later = all.scene_buffers && !now.scene_buffers && first;
            if s.known.is_none() {
                fate.uploaded = false;
                fate.reason = "unknown kind or newer version".into();
            } else if prepared.line_space.as_ref().is_some_and(|l| l.uploads(kind)) {
                match &self.line_space {
                    Some(ls) if now.line_space != 0 => {
                        ls.upload(kind, &file.section_bytes(s).map_err(bad)?, up)?
                    }
                    _ => fate.after_first_frame = true,
                }
            } else if let (Some(r), true) =
                (&self.reference, now.scene_buffers && kind == sections::MATERIALS)
            {
                up.buffer(&r.materials, 0, bytemuck::cast_slice(view.materials))?;
            } else if let (Some(r), true) =
                (&self.reference, now.scene_buffers && kind == sections::TRIANGLE_MATERIALS)
            {
                up.buffer(&r.triangle_materials, 0, bytemuck::cast_slice(view.triangle_materials))?;
            } else if (kind == sections::MATERIALS || kind == sections::TRIANGLE_MATERIALS)
                && scene_buffers_later
            {
                fate.after_first_frame = true;
            } else if kind == sections::MANIFEST
                || kind == sections::MATERIALS
                || kind == sections::TRIANGLE_MATERIALS
            {
                fate.uploaded = false;
                fate.reason = "read on the CPU".into();
            } else if kind == sections::VERTICES {
                if part.geometry {
                    up.buffer(&self.vertices, 0, bytemuck::cast_slice(view.vertices))?;
                }
            } else if kind == sections::UVS || kind == sections::COLORS {
                // Interleaved with the other into one stream (below).
            } else if kind == sections::TRIANGLES {
                // Uploaded re-sorted by material, so that each material is one draw.
                if part.geometry {
                    up.buffer(&self.indices, 0, bytemuck::cast_slice(&prepared.indices))?;
                }
                match &self.reference {
                    Some(r) if now.scene_buffers => {
                        up.buffer(&r.indices, 0, bytemuck::cast_slice(view.triangles))?
                    }
                    _ => fate.after_first_frame = scene_buffers_later,
                }
            } else if kind == sections::BVH_NODES && all.bvh && !view.bvh.is_empty() && !now.bvh {
                fate.after_first_frame = first;
            } else if kind == sections::BVH_NODES && now.bvh && !view.bvh.is_empty() {
                let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
                let nodes =
                    Buffer::uploaded(gpu, "bvh nodes", std::mem::size_of_val(view.bvh) as u64, storage)?;
                let corners: &[u8] = bytemuck::cast_slice(&prepared.bvh_triangles);
                let triangles = Buffer::uploaded(gpu, "bvh triangles", corners.len() as u64, storage)?;
                let bvh = BvhBuffers {
                    nodes,
                    triangles,
                    node_count: view.bvh.len() as u32,
                    triangle_count: view.triangles.len() as u32,
                };
                let uploaded = up
                    .buffer(&bvh.nodes, 0, bytemuck::cast_slice(view.bvh))
                    .and_then(|()| up.buffer(&bvh.triangles, 0, corners));
                self.bvh = Some(bvh);
                uploaded?;
            } else if kind == sections::TEXTURE && all.textures {
                let i = index as usize;
                if now.textures {
                    let coarse_first = first && part.textures == TextureUpload::CoarseFirst;
                    if let Some(fine) = self.upload_texture(gpu, view, i, up, coarse_first)? {
                        fate.fine_mips = Some(fine);
                        fate.after_first_frame = true;
                    }
                } else if first {
                    fate.after_first_frame = true;
                } else {
                    self.refine_texture(view, i, up)?;
                }
                match (&self.reference, &prepared.reference) {
                    (Some(r), Some(tables)) if now.scene_buffers => {
                        let t = tables.textures[index as usize];
                        up.buffer(
                            &r.texels,
                            t.offset as u64 * 4,
                            view.texture(index as usize).map_err(bad)?.levels,
                        )?;
                    }
                    _ => fate.after_first_frame |= scene_buffers_later,
                }
            } else if kind == sections::MEDIA_VISIBILITY && all.media_volumes && self.media.is_some() {
                match &self.media {
                    Some(m) if now.media => {
                        m.upload_volume(index, &file.section_bytes(s).map_err(bad)?, up)?
                    }
                    _ => fate.after_first_frame = first,
                }
            } else if PROBE_KINDS.contains(&kind) && all.probes {
                // Uploaded together before this loop.
                fate.after_first_frame = !now.probes && first;
            } else if (kind == sections::BRDF_LUT && all.brdf_lut && !now.brdf_lut)
                || (kind == sections::SHADOW_MAP && all.shadow_maps && !now.shadow_maps)
            {
                fate.after_first_frame = first;
            } else if kind == sections::BRDF_LUT && now.brdf_lut {
                let res = view.manifest.brdf_lut.as_ref().map_or(0, |b| b.resolution);
                let texels: &[[u16; 2]] = file.pod(sections::BRDF_LUT, 0).map_err(bad)?.unwrap_or(&[]);
                let image = Image::new(
                    gpu,
                    "brdf lut",
                    sampled_desc(vk::Format::R16G16_UNORM, res, res, 1, 1, false),
                )?;
                up.image(&image, 4, &[(0, 0, res, res, bytemuck::cast_slice(texels))])?;
                self.brdf_lut = Some(image);
            } else if kind == sections::SHADOW_MAP && now.shadow_maps {
                let info = &view.manifest.shadow_maps[index as usize];
                let depths: &[f32] = file.pod(sections::SHADOW_MAP, index).map_err(bad)?.unwrap_or(&[]);
                let n = info.resolution;
                let cube = info.projection == ShadowProjection::Cube;
                let faces = if cube { 6 } else { 1 };
                let image = Image::new(
                    gpu,
                    "shadow map",
                    sampled_desc(vk::Format::R32_SFLOAT, n, n, 1, faces, cube),
                )?;
                let face_bytes = n as usize * n as usize * 4;
                let bytes: &[u8] = bytemuck::cast_slice(depths);
                let levels: Vec<(u32, u32, u32, u32, &[u8])> = (0..faces)
                    .map(|f| (0, f, n, n, &bytes[f as usize * face_bytes..(f as usize + 1) * face_bytes]))
                    .collect();
                up.image(&image, 4, &levels)?;
                self.shadow_maps.push(ShadowImage { map: index as usize, image });
            } else {
                fate.uploaded = false;
                fate.reason = if kind == sections::TEXTURE {
                    "textures off".into()
                } else if kind == sections::BRDF_LUT {
                    "no pass reads the BRDF table".into()
                } else if kind == sections::MEDIA_VISIBILITY {
                    no_reader(|n| n.media_volumes)
                } else if PROBE_KINDS.contains(&kind) {
                    no_reader(|n| n.probes)
                } else if kind == sections::SHADOW_MAP {
                    no_reader(|n| n.shadow_maps)
                } else {
                    "no enabled pass reads it".into()
                };
            }
            if first {
                self.sections.push(fate);
            }
        }
        if part.geometry {
            up.buffer(&self.attributes, 0, bytemuck::cast_slice(&vertex_attributes(view)))?;
        }
        if let (Some(r), Some(tables), true) = (&self.reference, &prepared.reference, now.scene_buffers) {
            up.buffer(&r.emitters, 0, bytemuck::cast_slice(&tables.emitters))?;
            up.buffer(&r.triangle_emitter, 0, bytemuck::cast_slice(&tables.triangle_emitter))?;
            up.buffer(&r.emissive, 0, bytemuck::cast_slice(&tables.emissive))?;
            up.buffer(&r.textures, 0, bytemuck::cast_slice(&tables.textures))?;
            up.buffer(&r.raster_materials, 0, bytemuck::cast_slice(&raster_materials(&prepared.draws)))?;
            up.buffer(&r.media, 0, bytemuck::cast_slice(&tables.media))?;
        }
        Ok(())
    }

    /// Creates texture `i` with its full chain and uploads its levels: all of them, or with
    /// `coarse_first` those from [`first_coarse_level`] on; returns the finer levels left for
    /// [`GpuScene::refine_texture`] (finest, coarsest), if any.
    fn upload_texture(
        &mut self,
        gpu: &Gpu,
        view: &SceneView,
        i: usize,
        up: &mut Uploader,
        coarse_first: bool,
    ) -> PlayResult<Option<[u32; 2]>> {
        let info = &view.manifest.textures[i];
        let data = view.texture(i).map_err(bad)?;
        let srgb = info.color_space == ColorSpace::Srgb;
        // The file's colour space and format were checked together (BC4 and BC5 are never sRGB).
        let format = match (data.format, srgb) {
            (PixelFormat::Rgba8, true) => vk::Format::R8G8B8A8_SRGB,
            (PixelFormat::Rgba8, false) => vk::Format::R8G8B8A8_UNORM,
            (PixelFormat::Bc7, true) => vk::Format::BC7_SRGB_BLOCK,
            (PixelFormat::Bc7, false) => vk::Format::BC7_UNORM_BLOCK,
            (PixelFormat::Bc5, _) => vk::Format::BC5_UNORM_BLOCK,
            (PixelFormat::Bc4, _) => vk::Format::BC4_UNORM_BLOCK,
        };
        if data.format.is_block_compressed() && !gpu.texture_compression_bc {
            return Err(PlayError::new(
                Exit::Unsupported,
                format!(
                    "texture {i} ('{}') is {}-compressed and {} cannot sample BC textures (no \
                     textureCompressionBC); recompile the scene with kiln compile --texture-format rgba8",
                    info.name,
                    data.format.name().to_uppercase(),
                    gpu.name
                ),
            ));
        }
        let swizzle = |s: Swizzle| match s {
            Swizzle::R => vk::ComponentSwizzle::R,
            Swizzle::G => vk::ComponentSwizzle::G,
            Swizzle::B => vk::ComponentSwizzle::B,
            Swizzle::A => vk::ComponentSwizzle::A,
            Swizzle::Zero => vk::ComponentSwizzle::ZERO,
            Swizzle::One => vk::ComponentSwizzle::ONE,
        };
        let mut desc = sampled_desc(format, info.width, info.height, info.mip_levels, 1, false);
        desc.components = vk::ComponentMapping {
            r: swizzle(data.swizzle[0]),
            g: swizzle(data.swizzle[1]),
            b: swizzle(data.swizzle[2]),
            a: swizzle(data.swizzle[3]),
        };
        let image = Image::new(gpu, &info.name, desc)?;
        let first =
            if coarse_first { first_coarse_level(info.width, info.height, info.mip_levels) } else { 0 };
        let slices = data.level_slices(info.width, info.height, info.mip_levels);
        let levels = texture_levels(info.width, info.height, &slices);
        let resident = &levels[(first as usize).min(levels.len())..];
        // Uploaded as stored: blocks go to the GPU as they are in the file.
        let uploaded =
            up.image_blocks(&image, data.format.block_dim(), data.format.block_bytes() as u64, resident);
        // Pushed first, so that the scene releases it on any error below. Textures arrive in
        // index order (file order), so position == texture number.
        debug_assert_eq!(self.textures.len(), i);
        self.texture_views.push(image.view);
        self.textures.push(image);
        uploaded?;
        self.coarse_texture_bytes += resident.iter().map(|l| l.4.len() as u64).sum::<u64>();
        if first > 0 {
            let coarse = self.textures[i].view_from_mip(gpu, first)?;
            self.texture_views[i] = coarse.raw;
            self.coarse.push(CoarseTexture { texture: i, first, _view: coarse });
        }
        let key = SamplerKey {
            linear: info.mag_linear,
            mipmaps: info.mip_levels > 1,
            wrap_u: wrap_mode(info.wrap_u),
            wrap_v: wrap_mode(info.wrap_v),
        };
        let raw = match self.samplers.get(&key) {
            Some(s) => s.raw,
            None => {
                let s = Sampler::new(gpu, key)?;
                let raw = s.raw;
                self.samplers.insert(key, s);
                raw
            }
        };
        self.texture_samplers.push(raw);
        Ok((first > 0).then(|| [0, first - 1]))
    }

    /// Uploads the finer levels that [`GpuScene::upload_texture`] left out of texture `i`,
    /// coarse to fine (nothing when it uploaded them all). Only those levels change layout:
    /// the coarse ones stay as they are, possibly sampled by a frame in flight.
    fn refine_texture(&mut self, view: &SceneView, i: usize, up: &mut Uploader) -> PlayResult {
        let Some(first) = self.coarse.iter().find(|c| c.texture == i).map(|c| c.first) else {
            return Ok(());
        };
        let info = &view.manifest.textures[i];
        let data = view.texture(i).map_err(bad)?;
        let slices = data.level_slices(info.width, info.height, info.mip_levels);
        let levels = texture_levels(info.width, info.height, &slices);
        let fine: Vec<_> = levels[..(first as usize).min(levels.len())].iter().rev().copied().collect();
        up.image_blocks(&self.textures[i], data.format.block_dim(), data.format.block_bytes() as u64, &fine)?;
        self.fine_texture_bytes += fine.iter().map(|l| l.4.len() as u64).sum::<u64>();
        Ok(())
    }
}

/// A texture's levels as the uploader takes them, finest first: (mip, layer 0, width, height,
/// bytes as stored).
fn texture_levels<'a>(width: u32, height: u32, slices: &[&'a [u8]]) -> Vec<(u32, u32, u32, u32, &'a [u8])> {
    slices
        .iter()
        .enumerate()
        .map(|(mip, bytes)| {
            let mip = mip as u32;
            (mip, 0, (width >> mip).max(1), (height >> mip).max(1), *bytes)
        })
        .collect()
}

/// The material of each triangle in draw (index buffer) order.
fn raster_materials(draws: &[Draw]) -> Vec<u32> {
    draws.iter().flat_map(|d| std::iter::repeat_n(d.material, d.count as usize / 3)).collect()
}

/// Storage buffers of the given names and sizes, filled by uploads; on failure none is left.
pub(crate) fn storage_buffers(gpu: &Gpu, sizes: &[(&str, u64)]) -> PlayResult<Vec<Buffer>> {
    sizes
        .iter()
        .map(|&(name, size)| Buffer::uploaded(gpu, name, size, vk::BufferUsageFlags::STORAGE_BUFFER))
        .collect()
}

/// Allocates the reference path tracer's buffers (filled as their sections stream past).
fn reference_buffers(
    gpu: &Gpu,
    view: &SceneView,
    tables: &reference::ReferenceTables,
) -> PlayResult<ReferenceBuffers> {
    let sizes = [
        ("leaf indices", std::mem::size_of_val(view.triangles)),
        ("triangle materials", std::mem::size_of_val(view.triangle_materials)),
        ("materials", std::mem::size_of_val(view.materials)),
        ("emitters", std::mem::size_of_val(tables.emitters.as_slice())),
        ("triangle emitters", std::mem::size_of_val(tables.triangle_emitter.as_slice())),
        ("emissive triangles", std::mem::size_of_val(tables.emissive.as_slice())),
        ("texels", tables.texel_words as usize * 4),
        ("texture table", std::mem::size_of_val(tables.textures.as_slice())),
        ("raster materials", view.triangles.len() * 4),
        ("media", std::mem::size_of_val(tables.media.as_slice())),
    ];
    let sizes = sizes.map(|(name, size)| (name, size as u64));
    let mut it = storage_buffers(gpu, &sizes)?.into_iter();
    let mut next = || it.next().expect("one buffer per size");
    Ok(ReferenceBuffers {
        indices: next(),
        triangle_materials: next(),
        materials: next(),
        emitters: next(),
        triangle_emitter: next(),
        emissive: next(),
        texels: next(),
        textures: next(),
        raster_materials: next(),
        media: next(),
        texel_decode: TexelDecode::of(&tables.textures),
        emitter_count: tables.emitters.len() as u32,
        emissive_count: tables.emissive.len() as u32,
        media_count: tables.media.len() as u32,
    })
}

/// A sampled, uploaded image.
pub fn sampled_desc(
    format: vk::Format,
    width: u32,
    height: u32,
    mips: u32,
    layers: u32,
    cube: bool,
) -> ImageDesc {
    ImageDesc {
        format,
        width,
        height,
        mips,
        layers,
        cube,
        array: false,
        usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
        uploaded: true,
        components: vk::ComponentMapping::default(),
    }
}

/// Why a section that only some techniques read is not uploaded: none of them is chosen, named
/// from the catalogue (`--shadows shadowmap or --media toth reads it`).
fn no_reader(reads: impl Fn(&crate::render::Needs) -> bool) -> String {
    format!("no chosen technique reads it ({} would)", crate::render::techniques::readers(reads).join(" or "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_coarse_level_is_the_first_at_most_coarse_side_texels() {
        assert_eq!(first_coarse_level(2048, 2048, 12), 3);
        assert_eq!(first_coarse_level(2048, 512, 12), 3);
        assert_eq!(first_coarse_level(257, 3, 9), 1);
        assert_eq!(first_coarse_level(256, 256, 9), 0);
        assert_eq!(first_coarse_level(37, 29, 6), 0);
        // A chain cut short: its last level is the coarsest there is.
        assert_eq!(first_coarse_level(2048, 2048, 2), 1);
        assert_eq!(first_coarse_level(2048, 2048, 1), 0);
    }

    #[test]
    fn sorting_by_material_keeps_every_triangle_once() {
        let tris = [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]];
        let mats = [2, 0, 2, 0];
        let (idx, draws) = sort_by_material(&tris, &mats, 3);
        assert_eq!(idx, vec![3, 4, 5, 9, 10, 11, 0, 1, 2, 6, 7, 8]);
        assert_eq!(draws.len(), 2);
        assert_eq!((draws[0].material, draws[0].first, draws[0].count), (0, 0, 6));
        assert_eq!((draws[1].material, draws[1].first, draws[1].count), (2, 6, 6));
    }
}
