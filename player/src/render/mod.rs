//! The frame: G-buffer raster, the ray-traced shadows, AO and reflections of the hybrid pipeline
//! (each optional, compute traversal of the baked BVH), direct light and composition in compute,
//! tone mapping. Pipelines are built without the scene (so they compile while it uploads);
//! [`Renderer::new`] then binds the scene.
//!
//! The ray-traced passes take one sample per pixel per frame and average frames while the
//! camera is still (a running mean); any change of the view or projection restarts the average
//! (no reprojection: a moving camera sees the one-sample image).

pub mod lights;
pub mod spirv;
pub mod targets;

use ash::vk;
use gpu_allocator::MemoryLocation;
use kiln_format::gpu::{FrameConstants, FrameFlags, GpuMaterialLayout, LightKinds, RtConstants};
use kiln_format::sections::{MaterialFlags, NO_TEXTURE};

use crate::camera::Camera;
use crate::error::PlayResult;
use crate::gpu::{
    Binding, BindingKind, Buffer, ComputePipeline, Gpu, GraphicsDesc, GraphicsPipeline, Image, Recorder,
    SetLayout, TimestampPool, Use, Write,
};
use crate::scene::upload::Uploader;
use crate::scene::{GpuScene, sampled_desc};
use targets::{DEPTH_FORMAT, GBUFFER_FORMATS, RtShape, TRIANGLE_TARGET, Targets};

/// Shadow maps of each kind the direct-light pass can bind, and lights with a ray-traced shadow
/// layer: defined once in `kiln_format::gpu`, which also emits them into the shaders' `layout.glsl`.
pub use kiln_format::gpu::{MAX_RT_SHADOW_LIGHTS, MAX_SHADOW_MAPS};

/// Passes timed with timestamps, in order (a pass that is off takes 0 ms).
pub const PASSES: [&str; 7] = ["gbuffer", "resolve", "shadows", "ao", "reflections", "direct", "tonemap"];

/// How to render.
#[derive(Debug, Clone, Copy)]
pub struct RenderSettings {
    /// Shadows from the baked shadow maps.
    pub shadow_maps: bool,
    /// Upload the BVH for ray queries (ray-traced passes, `RayQuery`).
    pub rays: bool,
    /// Upload what the reference path tracer reads (implies `rays`).
    pub reference: bool,
    /// Exposure in stops (the radiance is multiplied by 2^exposure before tone mapping).
    pub exposure: f32,
    /// The ray-traced passes.
    pub rt: RtSettings,
    /// How the G-buffer is made.
    pub gbuffer: GBufferMode,
}

/// How the G-buffer is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GBufferMode {
    /// Rasterised with every material evaluated per fragment (five targets).
    #[default]
    Raster,
    /// A visibility buffer (the triangle under each pixel) rasterised, the materials evaluated in
    /// compute: far cheaper where raster throughput is small next to compute (datacenter GPUs).
    Visibility,
}

impl Default for RenderSettings {
    /// What `kiln-play` does without options: shadow maps, no ray-traced passes, raster G-buffer.
    fn default() -> RenderSettings {
        RenderSettings {
            shadow_maps: true,
            rays: false,
            reference: false,
            exposure: 0.0,
            rt: RtSettings::OFF,
            gbuffer: GBufferMode::Raster,
        }
    }
}

impl RenderSettings {
    /// Whether the passes read the scene's buffers beyond geometry (texel buffer, materials).
    pub fn needs_scene_buffers(&self) -> bool {
        self.reference || self.rt.any() || self.gbuffer == GBufferMode::Visibility
    }
}

/// Resolution of the ray-traced reflections.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReflectionRes {
    /// One ray per pixel.
    Full,
    /// One ray per 2 × 2 pixels, upsampled with normal- and plane-aware weights.
    Half,
}

/// The hybrid pipeline's ray-traced passes and their parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RtSettings {
    /// Ray-traced soft shadows (replace the shadow maps).
    pub shadows: bool,
    /// Ray-traced ambient occlusion.
    pub ao: bool,
    /// Ray-traced glossy reflections.
    pub reflections: Option<ReflectionRes>,
    /// Sphere radius of point and spot lights for soft shadows (0: hard).
    pub light_radius: f32,
    /// Angular diameter of directional lights in degrees (0: hard).
    pub sun_degrees: f32,
    /// AO ray length; `None`: a tenth of the scene's bounding-box diagonal.
    pub ao_radius: Option<f32>,
    /// Surfaces rougher than this get the split-sum ambient instead of traced reflections.
    pub max_roughness: f32,
    /// Average frames while the camera is still.
    pub accumulate: bool,
}

impl RtSettings {
    /// Every ray-traced pass off.
    pub const OFF: RtSettings = RtSettings {
        shadows: false,
        ao: false,
        reflections: None,
        light_radius: 0.0,
        sun_degrees: 0.0,
        ao_radius: None,
        max_roughness: 1.0,
        accumulate: true,
    };

    /// Whether any ray-traced pass is on.
    pub fn any(&self) -> bool {
        self.shadows || self.ao || self.reflections.is_some()
    }

    /// The accumulation images these settings need for a scene of `lights` lights.
    pub fn shape(&self, lights: usize) -> RtShape {
        RtShape {
            shadow_layers: if self.shadows { lights.clamp(1, MAX_RT_SHADOW_LIGHTS) as u32 } else { 0 },
            ao: self.ao,
            reflection_step: match self.reflections {
                None => 0,
                Some(ReflectionRes::Full) => 1,
                Some(ReflectionRes::Half) => 2,
            },
            reflection_lights: if self.reflections.is_some() {
                lights.min(MAX_RT_SHADOW_LIGHTS) as u32
            } else {
                0
            },
        }
    }
}

/// Layouts and pipelines (independent of the scene).
#[derive(Debug)]
pub struct Pipelines {
    frame_layout: SetLayout,
    material_layout: SetLayout,
    direct_layout: SetLayout,
    tonemap_layout: SetLayout,
    gbuffer: GraphicsPipeline,
    direct: ComputePipeline,
    tonemap: ComputePipeline,
    rt: Option<RtPipelines>,
    visibility: Option<VisibilityPipelines>,
}

/// The visibility-buffer G-buffer: raster pass and compute resolve.
#[derive(Debug)]
struct VisibilityPipelines {
    raster: GraphicsPipeline,
    opaque: GraphicsPipeline,
    layout: SetLayout,
    resolve: ComputePipeline,
}

/// The ray-traced passes (one set layout for all three).
#[derive(Debug)]
struct RtPipelines {
    layout: SetLayout,
    shadows: ComputePipeline,
    ao: ComputePipeline,
    reflections: ComputePipeline,
    reflection_shadows: ComputePipeline,
}

fn b(kind: BindingKind) -> Binding {
    Binding { kind, count: 1 }
}

impl Pipelines {
    /// Builds every pipeline (through the pipeline cache); the ray-traced ones when `rt`.
    pub fn new(gpu: &Gpu, rt: bool, mode: GBufferMode) -> PlayResult<Pipelines> {
        use BindingKind::*;
        let frame_layout = SetLayout::new(gpu, &[b(Uniform)], 1)?;
        let material_layout = SetLayout::new(gpu, &[b(Sampled); 5], 64)?;
        let mut direct_bindings = vec![b(Uniform), b(Storage), b(Storage), b(Sampled)];
        direct_bindings.push(Binding { kind: Sampled, count: MAX_SHADOW_MAPS as u32 });
        direct_bindings.push(Binding { kind: Sampled, count: MAX_SHADOW_MAPS as u32 });
        direct_bindings.extend([b(Sampled); 5]);
        direct_bindings.extend([b(StorageImage); 4]);
        let direct_layout = SetLayout::new(gpu, &direct_bindings, 1)?;
        let tonemap_layout = SetLayout::new(gpu, &[b(Uniform), b(StorageImage), b(StorageImage)], 1)?;
        let gbuffer = GraphicsPipeline::new(
            gpu,
            &GraphicsDesc {
                vertex: spirv::GBUFFER_VERT,
                fragment: spirv::GBUFFER_FRAG,
                vertex_strides: &[24, 8],
                attributes: &[
                    (0, 0, vk::Format::R32G32B32_SFLOAT, 0),
                    (1, 0, vk::Format::R32G32B32_SFLOAT, 12),
                    (2, 1, vk::Format::R32G32_SFLOAT, 0),
                ],
                colors: &GBUFFER_FORMATS,
                depth: DEPTH_FORMAT,
                sets: &[&frame_layout, &material_layout],
                push_bytes: std::mem::size_of::<GpuMaterialLayout>() as u32,
                cull_back: false,
            },
        )?;
        let visibility = if mode == GBufferMode::Visibility {
            let raster = |fragment: &[u8], cull_back: bool| {
                GraphicsPipeline::new(
                    gpu,
                    &GraphicsDesc {
                        vertex: spirv::GBUFFER_VERT,
                        fragment,
                        vertex_strides: &[24, 8],
                        attributes: &[
                            (0, 0, vk::Format::R32G32B32_SFLOAT, 0),
                            (1, 0, vk::Format::R32G32B32_SFLOAT, 12),
                            (2, 1, vk::Format::R32G32_SFLOAT, 0),
                        ],
                        colors: &[GBUFFER_FORMATS[TRIANGLE_TARGET]],
                        depth: DEPTH_FORMAT,
                        sets: &[&frame_layout, &material_layout],
                        push_bytes: std::mem::size_of::<GpuMaterialLayout>() as u32,
                        cull_back,
                    },
                )
            };
            // Opaque one-sided materials: culled in hardware and a shader without `discard`, so
            // the depth test runs before shading; masked or double-sided ones decide in the shader.
            let opaque = raster(spirv::VISIBILITY_OPAQUE_FRAG, true)?;
            let raster = raster(spirv::VISIBILITY_FRAG, false)?;
            let mut bindings = vec![b(Uniform)];
            bindings.extend([b(Storage); 7]);
            bindings.extend([b(StorageImage); 5]);
            bindings.push(b(Sampled));
            let layout = SetLayout::new(gpu, &bindings, 1)?;
            let resolve = ComputePipeline::new(gpu, spirv::RESOLVE, &[&layout], 0)?;
            Some(VisibilityPipelines { raster, opaque, layout, resolve })
        } else {
            None
        };
        let direct = ComputePipeline::new(gpu, spirv::DIRECT, &[&direct_layout], 0)?;
        let tonemap = ComputePipeline::new(gpu, spirv::TONEMAP, &[&tonemap_layout], 0)?;
        let rt = if rt {
            let mut bindings = vec![b(Uniform)];
            bindings.extend([b(Storage); 11]);
            bindings.extend([b(Sampled); 4]);
            bindings.extend([b(StorageImage); 6]);
            let layout = SetLayout::new(gpu, &bindings, 1)?;
            let push = std::mem::size_of::<RtConstants>() as u32;
            Some(RtPipelines {
                shadows: ComputePipeline::new(gpu, spirv::RT_SHADOWS, &[&layout], push)?,
                ao: ComputePipeline::new(gpu, spirv::RT_AO, &[&layout], push)?,
                reflections: ComputePipeline::new(gpu, spirv::RT_REFLECTIONS, &[&layout], push)?,
                reflection_shadows: ComputePipeline::new(
                    gpu,
                    spirv::RT_REFLECTION_SHADOWS,
                    &[&layout],
                    push,
                )?,
                layout,
            })
        } else {
            None
        };
        Ok(Pipelines {
            frame_layout,
            material_layout,
            direct_layout,
            tonemap_layout,
            gbuffer,
            direct,
            tonemap,
            rt,
            visibility,
        })
    }

    /// Releases layouts and pipelines.
    pub fn destroy(&mut self, gpu: &Gpu) {
        self.gbuffer.destroy(gpu);
        self.direct.destroy(gpu);
        self.tonemap.destroy(gpu);
        if let Some(v) = &mut self.visibility {
            v.raster.destroy(gpu);
            v.opaque.destroy(gpu);
            v.resolve.destroy(gpu);
            v.layout.destroy(gpu);
        }
        if let Some(rt) = &mut self.rt {
            rt.shadows.destroy(gpu);
            rt.ao.destroy(gpu);
            rt.reflections.destroy(gpu);
            rt.reflection_shadows.destroy(gpu);
            rt.layout.destroy(gpu);
        }
        for l in [
            &mut self.frame_layout,
            &mut self.material_layout,
            &mut self.direct_layout,
            &mut self.tonemap_layout,
        ] {
            l.destroy(gpu);
        }
    }
}

/// Placeholder images for descriptors that must be valid but are never read.
#[derive(Debug)]
pub struct Dummies {
    /// 1 × 1 white RGBA8 (absent textures, absent BRDF table).
    pub white: Image,
    /// 1 × 1 R32F at f32::MAX (unused 2D shadow slots).
    pub shadow_2d: Image,
    /// 1 × 1 × 6 R32F cube at f32::MAX (unused cube slots).
    pub shadow_cube: Image,
}

impl Dummies {
    /// Creates and uploads the placeholders.
    pub fn new(gpu: &Gpu, up: &mut Uploader) -> PlayResult<Dummies> {
        let white = Image::new(gpu, "white", sampled_desc(vk::Format::R8G8B8A8_UNORM, 1, 1, 1, 1, false))?;
        up.image(&white, 4, &[(0, 0, 1, 1, &[255u8; 4])])?;
        let far = f32::MAX.to_le_bytes();
        let shadow_2d =
            Image::new(gpu, "no shadow 2d", sampled_desc(vk::Format::R32_SFLOAT, 1, 1, 1, 1, false))?;
        up.image(&shadow_2d, 4, &[(0, 0, 1, 1, &far)])?;
        let shadow_cube =
            Image::new(gpu, "no shadow cube", sampled_desc(vk::Format::R32_SFLOAT, 1, 1, 1, 6, true))?;
        let faces: Vec<(u32, u32, u32, u32, &[u8])> = (0..6).map(|f| (0, f, 1, 1, &far[..])).collect();
        up.image(&shadow_cube, 4, &faces)?;
        Ok(Dummies { white, shadow_2d, shadow_cube })
    }

    /// Releases the images.
    pub fn destroy(&mut self, gpu: &Gpu) {
        self.white.destroy(gpu);
        self.shadow_2d.destroy(gpu);
        self.shadow_cube.destroy(gpu);
    }
}

/// GPU times of one frame's passes, in milliseconds (order of [`PASSES`]).
pub type PassTimes = [f64; 7];

/// Renders a resident scene.
pub struct Renderer {
    pipelines: Pipelines,
    dummies: Dummies,
    /// The images of the current size.
    pub targets: Targets,
    frame_ubo: Buffer,
    lights: Buffer,
    shadows: Buffer,
    frame_set: vk::DescriptorSet,
    material_sets: Vec<vk::DescriptorSet>,
    direct_set: vk::DescriptorSet,
    tonemap_set: vk::DescriptorSet,
    rt_set: vk::DescriptorSet,
    resolve_set: vk::DescriptorSet,
    rt_constants: RtConstants,
    /// Frames averaged at the current camera.
    accumulated: u32,
    last_view_proj: Option<[f32; 16]>,
    /// Materials as pushed, with texture numbers of absent textures cleared.
    materials: Vec<GpuMaterialLayout>,
    light_count: u32,
    slots_2d: Vec<usize>,
    slots_cube: Vec<usize>,
    flags: u32,
    lut_resolution: u32,
    sky: [f32; 3],
    settings: RenderSettings,
    timestamps: TimestampPool,
    /// Frames rendered.
    pub frame: u64,
    /// Notes for the user (e.g. lights left unshadowed).
    pub warnings: Vec<String>,
}

impl std::fmt::Debug for Renderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderer").field("size", &(self.targets.width, self.targets.height)).finish()
    }
}

fn host_buffer(gpu: &Gpu, name: &str, bytes: &[u8], usage: vk::BufferUsageFlags) -> PlayResult<Buffer> {
    let mut buf = Buffer::new(gpu, name, bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
    buf.write(bytes)?;
    Ok(buf)
}

impl Renderer {
    /// Binds `scene` to `pipelines`, rendering into `targets`.
    pub fn new(
        gpu: &Gpu,
        mut pipelines: Pipelines,
        dummies: Dummies,
        targets: Targets,
        scene: &GpuScene,
        settings: RenderSettings,
    ) -> PlayResult<Renderer> {
        let mut settings = settings;
        let mut plan = lights::plan(&scene.manifest, &scene.shadow_maps, settings.shadow_maps);
        if settings.rt.any() && pipelines.rt.is_none() {
            plan.warnings.push("the ray-traced passes are off: their pipelines were not built".into());
            settings.rt = RtSettings::OFF;
        }
        if settings.rt.any() && (scene.bvh.is_none() || scene.reference.is_none()) {
            plan.warnings.push("the ray-traced passes are off: the file has no BVH".into());
            settings.rt = RtSettings::OFF;
        }
        if settings.rt.shadows && plan.lights_used as usize > MAX_RT_SHADOW_LIGHTS {
            plan.warnings.push(format!(
                "{} light(s) are drawn without ray-traced shadows: at most {MAX_RT_SHADOW_LIGHTS} have them",
                plan.lights_used as usize - MAX_RT_SHADOW_LIGHTS
            ));
        }
        for l in &mut plan.lights {
            l.radius = match l.kind {
                LightKinds::POINT | LightKinds::SPOT => settings.rt.light_radius.max(0.0),
                LightKinds::DIRECTIONAL => (settings.rt.sun_degrees.max(0.0) * 0.5).to_radians(),
                _ => 0.0,
            };
        }
        let lights = host_buffer(
            gpu,
            "lights",
            bytemuck::cast_slice(&plan.lights),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let shadows = host_buffer(
            gpu,
            "shadows",
            bytemuck::cast_slice(&plan.shadows),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let frame_ubo = Buffer::new(
            gpu,
            "frame",
            std::mem::size_of::<FrameConstants>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        let frame_set = pipelines.frame_layout.allocate(gpu)?;
        pipelines.frame_layout.write(gpu, frame_set, &[Write::Buffer(0, &frame_ubo)]);

        let white = (dummies.white.view, scene.linear_clamp);
        let texture = |t: u32| -> (vk::ImageView, vk::Sampler) {
            match scene.textures.get(t as usize) {
                Some(img) if t != NO_TEXTURE => (img.view, scene.texture_samplers[t as usize]),
                _ => white,
            }
        };
        let mut material_sets = Vec::with_capacity(scene.materials.len());
        let mut materials = Vec::with_capacity(scene.materials.len());
        for m in &scene.materials {
            let set = pipelines.material_layout.allocate(gpu)?;
            let writes: Vec<Write> = m
                .textures()
                .iter()
                .enumerate()
                .map(|(i, &t)| Write::Sampled(i as u32, vec![texture(t)]))
                .collect();
            pipelines.material_layout.write(gpu, set, &writes);
            material_sets.push(set);
            let mut layout: GpuMaterialLayout = bytemuck::cast(*m);
            // Textures the scene did not upload (textures off) read as absent.
            for t in [
                &mut layout.base_color_texture,
                &mut layout.metallic_roughness_texture,
                &mut layout.normal_texture,
                &mut layout.occlusion_texture,
                &mut layout.emissive_texture,
            ] {
                if *t as usize >= scene.textures.len() {
                    *t = NO_TEXTURE;
                }
            }
            materials.push(layout);
        }
        let direct_set = pipelines.direct_layout.allocate(gpu)?;
        let tonemap_set = pipelines.tonemap_layout.allocate(gpu)?;
        let rt_set = match &mut pipelines.rt {
            Some(rt) if settings.rt.any() => rt.layout.allocate(gpu)?,
            _ => vk::DescriptorSet::null(),
        };
        if settings.gbuffer == GBufferMode::Visibility && scene.reference.is_none() {
            plan.warnings.push("the visibility-buffer G-buffer needs the scene buffers: rasterising".into());
            settings.gbuffer = GBufferMode::Raster;
        }
        let resolve_set = match &mut pipelines.visibility {
            Some(v) if settings.gbuffer == GBufferMode::Visibility => v.layout.allocate(gpu)?,
            _ => vk::DescriptorSet::null(),
        };
        let bounds = scene.manifest.bounds;
        let diagonal = glam::Vec3::from(bounds.max).distance(glam::Vec3::from(bounds.min));
        // The same shape the targets were made with (one layer at least, even without lights).
        let shape = settings.rt.shape(plan.lights_used as usize);
        let rt_constants = RtConstants {
            ao_radius: settings.rt.ao_radius.unwrap_or(0.1 * diagonal).max(1e-6),
            max_roughness: settings.rt.max_roughness,
            shadow_lights: shape.shadow_layers.min(plan.lights_used),
            reflection_step: shape.reflection_step.max(1),
            reflection_lights: shape.reflection_lights,
            ..Default::default()
        };
        let mut flags = if plan.shadows_bound && !settings.rt.shadows { FrameFlags::SHADOW_MAPS } else { 0 };
        if settings.rt.shadows {
            flags |= FrameFlags::RT_SHADOWS;
        }
        if settings.rt.ao {
            flags |= FrameFlags::RT_AO;
        }
        match settings.rt.reflections {
            Some(ReflectionRes::Full) => flags |= FrameFlags::RT_REFLECTIONS,
            Some(ReflectionRes::Half) => flags |= FrameFlags::RT_REFLECTIONS | FrameFlags::REFLECTIONS_HALF,
            None => {}
        }
        let mut renderer = Renderer {
            pipelines,
            dummies,
            targets,
            frame_ubo,
            lights,
            shadows,
            frame_set,
            material_sets,
            direct_set,
            tonemap_set,
            rt_set,
            resolve_set,
            rt_constants,
            accumulated: 0,
            last_view_proj: None,
            materials,
            light_count: plan.lights_used,
            slots_2d: plan.slots_2d,
            slots_cube: plan.slots_cube,
            flags,
            lut_resolution: scene.brdf_lut.as_ref().map_or(0, |i| i.desc.width),
            sky: scene.manifest.sky.radiance,
            settings,
            timestamps: TimestampPool::new(gpu, PASSES.len() as u32 + 1)?,
            frame: 0,
            warnings: plan.warnings,
        };
        renderer.write_frame_sets(gpu, scene);
        Ok(renderer)
    }

    /// Points the direct-light and tone-mapping sets at the current targets and the scene.
    fn write_frame_sets(&mut self, gpu: &Gpu, scene: &GpuScene) {
        let near = scene.nearest_clamp;
        let lut = scene
            .brdf_lut
            .as_ref()
            .map_or((self.dummies.white.view, scene.linear_clamp), |i| (i.view, scene.linear_clamp));
        let mut maps_2d = vec![(self.dummies.shadow_2d.view, near); MAX_SHADOW_MAPS];
        let mut maps_cube = vec![(self.dummies.shadow_cube.view, near); MAX_SHADOW_MAPS];
        for (slot, &i) in self.slots_2d.iter().enumerate() {
            maps_2d[slot] = (scene.shadow_maps[i].image.view, near);
        }
        for (slot, &i) in self.slots_cube.iter().enumerate() {
            maps_cube[slot] = (scene.shadow_maps[i].image.view, near);
        }
        let t = &self.targets;
        let g = |i: usize| vec![(t.gbuffer[i].view, near)];
        self.pipelines.direct_layout.write(
            gpu,
            self.direct_set,
            &[
                Write::Buffer(0, &self.frame_ubo),
                Write::Buffer(1, &self.lights),
                Write::Buffer(2, &self.shadows),
                Write::Sampled(3, vec![lut]),
                Write::Sampled(4, maps_2d),
                Write::Sampled(5, maps_cube),
                Write::Sampled(6, vec![(t.depth.view, near)]),
                Write::Sampled(7, g(0)),
                Write::Sampled(8, g(1)),
                Write::Sampled(9, g(2)),
                Write::Sampled(10, g(3)),
                Write::StorageImage(11, t.radiance.view),
                Write::StorageImage(12, t.rt_shadows.view),
                Write::StorageImage(13, t.rt_ao.view),
                Write::StorageImage(14, t.rt_reflections.view),
            ],
        );
        if let (Some(v), Some(r)) = (&self.pipelines.visibility, &scene.reference)
            && self.resolve_set != vk::DescriptorSet::null()
        {
            v.layout.write(
                gpu,
                self.resolve_set,
                &[
                    Write::Buffer(0, &self.frame_ubo),
                    Write::Buffer(1, &scene.vertices),
                    Write::Buffer(2, &scene.uvs),
                    Write::Buffer(3, &scene.indices),
                    Write::Buffer(4, &r.raster_materials),
                    Write::Buffer(5, &r.materials),
                    Write::Buffer(6, &r.texels),
                    Write::Buffer(7, &r.textures),
                    Write::StorageImage(8, t.gbuffer[TRIANGLE_TARGET].view),
                    Write::StorageImage(9, t.gbuffer[0].view),
                    Write::StorageImage(10, t.gbuffer[1].view),
                    Write::StorageImage(11, t.gbuffer[2].view),
                    Write::StorageImage(12, t.gbuffer[3].view),
                    Write::Sampled(13, vec![(t.depth.view, scene.nearest_clamp)]),
                ],
            );
        }
        if let (Some(rt), Some(common), Some(r)) = (&self.pipelines.rt, scene.ray_writes(), &scene.reference)
            && self.rt_set != vk::DescriptorSet::null()
        {
            let mut writes = vec![Write::Buffer(0, &self.frame_ubo)];
            writes.extend(common);
            writes.extend([
                Write::Buffer(8, &self.lights),
                Write::Buffer(9, &r.texels),
                Write::Buffer(10, &r.textures),
                Write::Buffer(11, &scene.indices),
                Write::Sampled(12, g(4)),
                Write::Sampled(13, g(0)),
                Write::Sampled(14, g(1)),
                Write::Sampled(15, g(2)),
                Write::StorageImage(16, t.rt_shadows.view),
                Write::StorageImage(17, t.rt_ao.view),
                Write::StorageImage(18, t.rt_reflections.view),
                Write::StorageImage(19, t.refl_partial.view),
                Write::StorageImage(20, t.refl_origin.view),
                Write::StorageImage(21, t.refl_lights.view),
            ]);
            rt.layout.write(gpu, self.rt_set, &writes);
        }
        self.pipelines.tonemap_layout.write(
            gpu,
            self.tonemap_set,
            &[
                Write::Buffer(0, &self.frame_ubo),
                Write::StorageImage(1, t.radiance.view),
                Write::StorageImage(2, t.display.view),
            ],
        );
    }

    /// Recreates the targets for a new size (the GPU must be idle).
    pub fn resize(&mut self, gpu: &Gpu, scene: &GpuScene, width: u32, height: u32) -> PlayResult {
        let shape = self.targets.rt;
        self.targets.destroy(gpu);
        self.targets = Targets::new(gpu, width.max(1), height.max(1), shape)?;
        self.accumulated = 0;
        self.write_frame_sets(gpu, scene);
        Ok(())
    }

    /// Writes the frame constants for `camera` (the previous frame must have finished).
    pub fn update(&mut self, camera: &Camera) -> PlayResult {
        let (w, h) = (self.targets.width, self.targets.height);
        let (view_proj, inv_view_proj) = camera.matrices(w, h);
        if !self.settings.rt.accumulate || self.last_view_proj != Some(view_proj) {
            self.accumulated = 0;
        }
        self.last_view_proj = Some(view_proj);
        let p = camera.position.as_vec3();
        let right = camera.forward.cross(camera.up).normalize_or(glam::DVec3::X);
        let up = right.cross(camera.forward);
        let tan_half = (camera.vfov_degrees.to_radians() * 0.5).tan();
        let aspect = w as f64 / h as f64;
        let v4 = |v: glam::DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        let constants = FrameConstants {
            view_proj,
            inv_view_proj,
            camera: [p.x, p.y, p.z, 0.0],
            sky: [self.sky[0], self.sky[1], self.sky[2], 0.0],
            size: [w, h, self.light_count, self.flags],
            params: [
                2f32.powf(self.settings.exposure),
                self.lut_resolution as f32,
                self.frame as f32,
                self.settings.rt.max_roughness,
            ],
            camera_right: v4(right, tan_half * aspect),
            camera_up: v4(up, tan_half),
            camera_forward: v4(camera.forward, 0.0),
        };
        self.frame_ubo.write(bytemuck::bytes_of(&constants))
    }

    /// Records one frame: G-buffer, direct light, tone mapping. Leaves `radiance` and `display`
    /// in GENERAL layout (storage).
    pub fn record(&mut self, rec: &Recorder, scene: &GpuScene) {
        let t = &self.targets;
        rec.reset_timestamps(&self.timestamps);
        rec.timestamp(&self.timestamps, 0);
        let visibility =
            self.pipelines.visibility.as_ref().filter(|_| self.resolve_set != vk::DescriptorSet::null());
        let colors: Vec<&Image> = match visibility {
            Some(_) => vec![&t.gbuffer[TRIANGLE_TARGET]],
            None => t.gbuffer.iter().collect(),
        };
        for img in &colors {
            rec.transition(img, Use::DISCARD, Use::COLOR);
        }
        rec.transition(&t.depth, Use::DISCARD, Use::DEPTH);
        // The visibility buffer is not cleared (a full-screen clear costs as much as a target's
        // writes on GPUs with few raster units): the resolve marks pixels at the far plane empty.
        rec.begin_rendering(&colors, &t.depth, visibility.is_none());
        if !scene.draws.is_empty() {
            rec.bind_geometry(&[&scene.vertices, &scene.uvs], &scene.indices);
            let mut bound: Option<&GraphicsPipeline> = None;
            for d in &scene.draws {
                let m = &self.materials[d.material as usize];
                let opaque_one_sided = m.flags & MaterialFlags::DOUBLE_SIDED == 0
                    && (m.flags >> MaterialFlags::ALPHA_MODE_SHIFT) & 3 != 1;
                let p = match visibility {
                    Some(v) if opaque_one_sided => &v.opaque,
                    Some(v) => &v.raster,
                    None => &self.pipelines.gbuffer,
                };
                if bound.is_none_or(|b| !std::ptr::eq(b, p)) {
                    rec.bind_graphics(p, &[self.frame_set]);
                    bound = Some(p);
                }
                rec.bind_graphics_set(p, 1, self.material_sets[d.material as usize]);
                rec.push_graphics(p, bytemuck::bytes_of(&self.materials[d.material as usize]));
                rec.draw_indexed(d.count, d.first);
            }
        }
        rec.end_rendering();
        rec.transition(&t.depth, Use::DEPTH, Use::SAMPLED);
        rec.timestamp(&self.timestamps, 1);
        match visibility {
            Some(v) => {
                rec.transition(&t.gbuffer[TRIANGLE_TARGET], Use::COLOR, Use::STORAGE);
                for img in &t.gbuffer[..TRIANGLE_TARGET] {
                    rec.transition(img, Use::DISCARD, Use::STORAGE);
                }
                rec.dispatch_2d(&v.resolve, &[self.resolve_set], t.width, t.height);
                for img in &t.gbuffer {
                    rec.transition(img, Use::STORAGE, Use::SAMPLED);
                }
            }
            None => {
                for img in &colors {
                    rec.transition(img, Use::COLOR, Use::SAMPLED);
                }
            }
        }
        rec.timestamp(&self.timestamps, 2);
        let rt_images =
            [&t.rt_shadows, &t.rt_ao, &t.rt_reflections, &t.refl_partial, &t.refl_origin, &t.refl_lights];
        for img in rt_images {
            // Fresh images are discarded once; after that they carry the running average.
            let from = if t.rt_fresh { Use::DISCARD } else { Use::STORAGE };
            rec.transition(img, from, Use::STORAGE);
        }
        self.rt_constants.accumulated = self.accumulated;
        self.rt_constants.seed = self.frame as u32;
        let push = bytemuck::bytes_of(&self.rt_constants);
        let step = self.rt_constants.reflection_step;
        let rt = self.pipelines.rt.as_ref().filter(|_| self.rt_set != vk::DescriptorSet::null());
        let passes: [(Option<&ComputePipeline>, u32, u32); 3] = [
            (rt.filter(|_| self.settings.rt.shadows).map(|r| &r.shadows), t.width, t.height),
            (rt.filter(|_| self.settings.rt.ao).map(|r| &r.ao), t.width, t.height),
            (
                rt.filter(|_| self.settings.rt.reflections.is_some()).map(|r| &r.reflections),
                t.width.div_ceil(step),
                t.height.div_ceil(step),
            ),
        ];
        for (i, (pipeline, w, h)) in passes.into_iter().enumerate() {
            if let Some(p) = pipeline {
                rec.dispatch(p, &[self.rt_set], push, [w.div_ceil(8), h.div_ceil(8), 1]);
                if let (2, Some(rt)) = (i, rt) {
                    // The reflection hits' shadow rays, in their own small kernel.
                    for img in [&t.refl_partial, &t.refl_origin, &t.refl_lights] {
                        rec.transition(img, Use::STORAGE, Use::STORAGE);
                    }
                    rec.dispatch(
                        &rt.reflection_shadows,
                        &[self.rt_set],
                        push,
                        [w.div_ceil(8), h.div_ceil(8), 1],
                    );
                }
            }
            rec.timestamp(&self.timestamps, 3 + i as u32);
        }
        for img in rt_images {
            rec.transition(img, Use::STORAGE, Use::STORAGE);
        }
        self.targets.rt_fresh = false;
        let t = &self.targets;
        rec.transition(&t.radiance, Use::DISCARD, Use::STORAGE);
        rec.dispatch_2d(&self.pipelines.direct, &[self.direct_set], t.width, t.height);
        rec.timestamp(&self.timestamps, 6);
        rec.transition(&t.radiance, Use::STORAGE, Use::STORAGE);
        rec.transition(&t.display, Use::DISCARD, Use::STORAGE);
        rec.dispatch_2d(&self.pipelines.tonemap, &[self.tonemap_set], t.width, t.height);
        rec.timestamp(&self.timestamps, 7);
        self.frame += 1;
        self.accumulated = (self.accumulated + 1).min(1 << 24);
    }

    /// Frames averaged into the ray-traced images at the current camera (after the last
    /// recorded frame).
    pub fn accumulated(&self) -> u32 {
        self.accumulated
    }

    /// GPU milliseconds of each pass of the last completed frame.
    pub fn pass_times(&self, gpu: &Gpu) -> PlayResult<PassTimes> {
        let ns = self.timestamps.read_ns(gpu)?;
        Ok(std::array::from_fn(|i| (ns[i + 1] - ns[i]) * 1e-6))
    }

    /// Releases everything the renderer owns (the GPU must be idle).
    pub fn destroy(&mut self, gpu: &Gpu) {
        self.targets.destroy(gpu);
        self.dummies.destroy(gpu);
        self.frame_ubo.destroy(gpu);
        self.lights.destroy(gpu);
        self.shadows.destroy(gpu);
        self.timestamps.destroy(gpu);
        self.pipelines.destroy(gpu);
    }
}

/// Which image of a frame to read back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Readable {
    /// The tone-mapped RGBA8 image.
    Display,
    /// The linear RGBA32F radiance.
    Radiance,
}

/// A host-visible copy of one of a frame's images.
#[derive(Debug)]
pub struct Readback {
    /// The pixels, tightly packed.
    pub buffer: Buffer,
    /// Which image.
    pub image: Readable,
}

impl Readback {
    /// A buffer for `image` of targets of `width` × `height`.
    pub fn new(gpu: &Gpu, image: Readable, width: u32, height: u32) -> PlayResult<Readback> {
        let texel = if image == Readable::Display { 4 } else { 16 };
        let size = width as u64 * height as u64 * texel;
        let buffer =
            Buffer::new(gpu, "readback", size, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
        Ok(Readback { buffer, image })
    }

    /// Records the copy of the image (in STORAGE use) into the buffer.
    pub fn record(&self, rec: &Recorder, targets: &Targets) {
        let img = if self.image == Readable::Display { &targets.display } else { &targets.radiance };
        rec.transition(img, Use::STORAGE, Use::TRANSFER_SRC);
        rec.copy_from_image(img, &self.buffer);
        rec.memory_barrier(
            vk::PipelineStageFlags2::TRANSFER,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::HOST,
            vk::AccessFlags2::HOST_READ,
        );
    }

    /// Releases the buffer.
    pub fn destroy(&mut self, gpu: &Gpu) {
        self.buffer.destroy(gpu);
    }
}
