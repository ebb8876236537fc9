//! What both raster passes share: the frame and material set layouts, one material set per
//! material (its five textures), the materials as pushed, and the draw loop (one draw per
//! material, pipelines switched only when the material's kind changes).

use crate::gpu::vk;
use kiln_format::gpu::GpuMaterialLayout;
use kiln_format::sections::{MATERIAL_SLOTS, NO_TEXTURE};

use super::Shared;
use crate::error::PlayResult;
use crate::gpu::{
    Binding, BindingKind, Gpu, GraphicsDesc, GraphicsPipeline, Landing, Recorder, SetLayout, Write,
};
use crate::scene::GpuScene;

/// Vertex buffer strides of the raster passes: positions + normals (`Vertex`), texture
/// coordinates + colours (`GpuVertexAttributes`).
pub const VERTEX_STRIDES: [u32; 2] = [24, 16];

/// (location, binding, format, offset) of the raster passes' vertex attributes: position,
/// normal, texture coordinates, colour.
pub const ATTRIBUTES: [(u32, u32, vk::Format, u32); 4] = [
    (0, 0, vk::Format::R32G32B32_SFLOAT, 0),
    (1, 0, vk::Format::R32G32B32_SFLOAT, 12),
    (2, 1, vk::Format::R32G32_SFLOAT, 0),
    (3, 1, vk::Format::R16G16B16A16_UNORM, 8),
];

/// Whether a material as pushed is see-through ([`kiln_format::sections::GpuMaterial::see_through`]).
pub fn see_through(m: &GpuMaterialLayout) -> bool {
    bytemuck::cast::<GpuMaterialLayout, kiln_format::sections::GpuMaterial>(*m).see_through()
}

/// Set layouts, sets and pushed materials of a raster pass (the layouts, and the sets with
/// them, released when dropped).
#[derive(Debug)]
pub struct SceneDraws {
    /// The frame's set: its constants, and with [`SceneDraws::see_through`] the opaque
    /// G-buffer's depth (binding 1) and the split-sum table (binding 2).
    frame_layout: SetLayout,
    see_through: bool,
    material_layout: SetLayout,
    frame_set: vk::DescriptorSet,
    material_sets: Vec<vk::DescriptorSet>,
    /// Materials as pushed, with texture numbers of absent textures cleared.
    pub materials: Vec<GpuMaterialLayout>,
}

impl SceneDraws {
    /// The layouts (sets are allocated by [`SceneDraws::bind`]).
    pub fn new(gpu: &Gpu) -> PlayResult<SceneDraws> {
        Self::make(gpu, false)
    }

    /// [`SceneDraws::new`] for the see-through layer: its frame set also samples the opaque
    /// G-buffer's depth (binding 1) and the split-sum table (binding 2).
    pub fn see_through(gpu: &Gpu) -> PlayResult<SceneDraws> {
        Self::make(gpu, true)
    }

    fn make(gpu: &Gpu, see_through: bool) -> PlayResult<SceneDraws> {
        use BindingKind::{Sampled, Uniform};
        let frame_bindings = [Binding::one(Uniform), Binding::one(Sampled), Binding::one(Sampled)];
        let frame_layout = SetLayout::new(gpu, &frame_bindings[..if see_through { 3 } else { 1 }], 1)?;
        let material_layout = SetLayout::new(gpu, &[Binding::one(BindingKind::Sampled); MATERIAL_SLOTS], 64)?;
        Ok(SceneDraws {
            frame_layout,
            see_through,
            material_layout,
            frame_set: vk::DescriptorSet::null(),
            material_sets: Vec::new(),
            materials: Vec::new(),
        })
    }

    /// A triangle-list pipeline over the scene's vertex layout (`shaders/gbuffer/gbuffer.vert`)
    /// with these sets and `fragment`, writing `colors` and the depth target.
    pub fn pipeline(
        &self,
        gpu: &Gpu,
        fragment: &[u8],
        colors: &[vk::Format],
        depth: vk::Format,
        cull_back: bool,
        landing: Landing,
    ) -> PlayResult<GraphicsPipeline> {
        GraphicsPipeline::new(
            gpu,
            &GraphicsDesc {
                vertex: crate::render::spirv::shader!("gbuffer/gbuffer.vert"),
                fragment,
                vertex_strides: &VERTEX_STRIDES,
                attributes: &ATTRIBUTES,
                colors,
                depth,
                sets: &[&self.frame_layout, &self.material_layout],
                push_bytes: std::mem::size_of::<GpuMaterialLayout>() as u32,
                cull_back,
                landing,
            },
        )
    }

    /// Allocates the sets the first time and writes them, each time: a texture's view changes
    /// once its finer levels arrive ([`crate::scene::GpuScene::texture_views`]).
    pub fn bind(&mut self, gpu: &Gpu, shared: &Shared) -> PlayResult {
        let scene = shared.scene;
        if self.frame_set == vk::DescriptorSet::null() {
            self.frame_set = self.frame_layout.allocate(gpu)?;
            self.frame_layout.write(gpu, self.frame_set, &[Write::Buffer(0, shared.frame_ubo)]);
            for m in &scene.materials {
                self.material_sets.push(self.material_layout.allocate(gpu)?);
                let mut layout: GpuMaterialLayout = bytemuck::cast(*m);
                // Textures the scene did not upload (textures off) read as absent.
                for t in [
                    &mut layout.base_color_texture,
                    &mut layout.metallic_roughness_texture,
                    &mut layout.normal_texture,
                    &mut layout.occlusion_texture,
                    &mut layout.emissive_texture,
                    &mut layout.clearcoat_texture,
                    &mut layout.clearcoat_roughness_texture,
                    &mut layout.transmission_texture,
                ] {
                    if *t as usize >= scene.textures.len() {
                        *t = NO_TEXTURE;
                    }
                }
                self.materials.push(layout);
            }
        }
        if self.see_through {
            // Written at every bind: the depth target is remade on a resize.
            let depth = shared.images.get(&super::gbuffer::DEPTH).view;
            let lut = scene.brdf_lut.as_ref().map_or(shared.dummies.white.view, |i| i.view);
            self.frame_layout.write(
                gpu,
                self.frame_set,
                &[
                    Write::Sampled(1, vec![(depth, scene.nearest_clamp)]),
                    Write::Sampled(2, vec![(lut, scene.linear_clamp)]),
                ],
            );
        }
        let white = (shared.dummies.white.view, scene.linear_clamp);
        let texture = |t: u32| -> (vk::ImageView, vk::Sampler) {
            match scene.texture_views.get(t as usize) {
                Some(&view) if t != NO_TEXTURE => (view, scene.texture_samplers[t as usize]),
                _ => white,
            }
        };
        for (m, &set) in scene.materials.iter().zip(&self.material_sets) {
            let writes: Vec<Write> = m
                .textures()
                .iter()
                .enumerate()
                .map(|(i, &t)| Write::Sampled(i as u32, vec![texture(t)]))
                .collect();
            self.material_layout.write(gpu, set, &writes);
        }
        Ok(())
    }

    /// Records one draw per material, with the pipeline `pick` chooses for its material (none:
    /// the material is not drawn).
    pub fn draw<'p>(
        &self,
        rec: &Recorder,
        scene: &GpuScene,
        pick: impl Fn(&GpuMaterialLayout) -> Option<&'p GraphicsPipeline>,
    ) {
        if scene.draws.is_empty() {
            return;
        }
        rec.bind_geometry(&[&scene.vertices, &scene.attributes], &scene.indices);
        let mut bound: Option<&GraphicsPipeline> = None;
        for d in &scene.draws {
            let m = &self.materials[d.material as usize];
            let Some(p) = pick(m) else { continue };
            if bound.is_none_or(|b| !std::ptr::eq(b, p)) {
                rec.bind_graphics(p, &[self.frame_set]);
                bound = Some(p);
            }
            rec.bind_graphics_set(p, 1, self.material_sets[d.material as usize]);
            rec.push_graphics(p, bytemuck::bytes_of(m));
            rec.draw_indexed(d.count, d.first);
        }
    }
}
