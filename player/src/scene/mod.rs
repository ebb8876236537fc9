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
pub mod environment;
mod geometry;
pub mod linespace;
pub mod media;
mod prepared;
pub mod probes;
pub mod reference;
mod textures;
pub mod upload;

pub use geometry::{Draw, sort_by_material, triangle_corners};
use geometry::{raster_materials, vertex_attributes};
pub use prepared::Prepared;
use textures::CoarseTexture;
pub use textures::{COARSE_SIDE, TextureUpload, first_coarse_level};

use std::collections::HashMap;

use crate::gpu::vk;
use kiln_format::gpu::GpuVertexAttributes;
use kiln_format::manifest::{Manifest, ShadowProjection};
use kiln_format::read::KilnFile;
use kiln_format::scene::SceneView;
use kiln_format::sections::{self, GpuMaterial};

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{Buffer, Gpu, Image, ImageDesc, Sampler, SamplerKey, Write};
use crate::render::{Needs, TexelDecode};
use upload::Uploader;

/// A resident shadow map.
#[derive(Debug)]
pub struct ShadowImage {
    /// Index in `manifest.shadow_maps`.
    pub map: usize,
    /// The depths (R32F; six layers for cube maps).
    pub image: Image,
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
        || (kiln_format::probes::PROBE_KINDS.contains(&kind) && needs.any_probes())
        || kiln_format::environment::ENVIRONMENT_KINDS.contains(&kind)
        || ((kind == sections::TRIANGLE_MATERIALS || kind == sections::MATERIALS) && needs.scene_buffers)
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

impl GpuScene {
    /// The descriptor writes of the environment's two buffers at `first` and `first + 1`
    /// (`shaders/common/environment.glsl`'s `ENV_BINDING`).
    pub fn environment_writes(&self, first: u32) -> PlayResult<[Write<'_>; 2]> {
        self.environment.as_ref().map(|e| e.writes(first)).ok_or_else(|| {
            PlayError::new(Exit::Gpu, "the environment's buffers were not uploaded with the geometry")
        })
    }
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
    /// The emitters' summed power ([`reference::ReferenceTables::emitter_power`]).
    pub emitter_power: f64,
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
    /// The world bounds (min, max) of the see-through materials' triangles
    /// ([`GpuMaterial::see_through`]), if any: the see-through layer draws only where they
    /// project.
    pub see_through_bounds: Option<[glam::Vec3; 2]>,
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
    /// The environment (placeholders without one), uploaded with the geometry.
    pub environment: Option<environment::EnvironmentBuffers>,
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
            see_through_bounds: prepared.see_through_bounds,
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
            environment: None,
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
        if first {
            self.environment = Some(environment::EnvironmentBuffers::new(gpu, file, up)?);
        }
        // Once: a later stage may ask again (the reflections' `probes_if_present` after the
        // first frame's `--gi probes`), and replacing them would free images bound in flight.
        if now.any_probes() && self.probes.is_none() {
            match kiln_format::probes::ProbeVolume::read(file).map_err(bad)? {
                Some(volume) => self.probes = Some(probes::ProbeImages::new(gpu, &volume, up)?),
                None if now.probes => {
                    return Err(PlayError::new(
                        Exit::BadInput,
                        "--gi probes: the file has no irradiance probes; recompile it with kiln compile \
                         (probes are baked unless --probes off is given or nothing lights the scene)",
                    ));
                }
                None => {}
            }
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
                up.buffer(&r.materials, 0, bytemuck::cast_slice(&view.materials))?;
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
                        let data = view.texture(index as usize).map_err(bad)?;
                        if t.pixel_format() == data.format {
                            up.buffer(&r.texels, t.offset as u64 * 4, data.levels)?;
                        } else {
                            // The table says RGBA8 where the file stores blocks
                            // (`Needs::decoded_texels`): decoded here, once.
                            let info = &view.manifest.textures[index as usize];
                            let rgba = data.decoded_chain(info.width, info.height, info.mip_levels);
                            up.buffer(&r.texels, t.offset as u64 * 4, &rgba)?;
                        }
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
            } else if kiln_format::environment::ENVIRONMENT_KINDS.contains(&kind) {
                // Uploaded with the geometry, before this loop.
            } else if kiln_format::probes::PROBE_KINDS.contains(&kind) && all.any_probes() {
                // Uploaded together before this loop.
                fate.after_first_frame = !now.any_probes() && first;
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
                } else if kiln_format::probes::PROBE_KINDS.contains(&kind) {
                    no_reader(|n| n.any_probes())
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
        ("materials", std::mem::size_of_val(&*view.materials)),
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
        emitter_power: tables.emitter_power,
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
