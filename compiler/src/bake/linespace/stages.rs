//! The voxel-grid and line-space stages over the bake context.

use std::time::Instant;

use kiln_format::linespace::Variants;
use kiln_format::sections::{
    CANDIDATE_OFFSETS, CANDIDATES, GRID, PNMT, PREILLUM, SHAFT_BITS, SHAFT_RANKS, SHAFT_SLOTS, VOXEL_OFFSETS,
    VOXEL_TRIANGLES,
};

use super::BakedLineSpace;

use crate::bake::{BakeContext, Sections};
use crate::exit::CliResult;

/// The voxel-grid stage: the scene's voxel grid (shared with the plan) renumbered to the stored
/// triangle order, then the line space over it, since the grid header records the line space's
/// figures. Returns the grid's sections and the whole line space for [`line_space`].
pub fn voxel_grid(ctx: &BakeContext) -> CliResult<(Sections, BakedLineSpace)> {
    let start = Instant::now();
    let voxels = ctx.geometry.voxels(ctx.plan.voxel_res).reordered(&ctx.bvh.order);
    let voxel_ms = start.elapsed().as_secs_f64() * 1e3;
    let shading = ctx.shading();
    let shade = |p: glam::DVec3, n: glam::Vec3, v: glam::Vec3, m: u16, uv: glam::Vec2| {
        shading.radiance(p.as_vec3(), n, n, v, m as u32, uv)
    };
    let attrs = ctx.attributes();
    let plan = ctx.plan;
    let has_uvs = !attrs.uvs.is_empty();
    let work =
        super::gpu::planned_work(plan.shaft_variants, plan.pnmt_layout, has_uvs, plan.shaft_res, || {
            voxels.triangles.len()
        });
    let gpu = match work {
        Some(work) => super::gpu::for_bake(work, plan.shaft_res, plan.pnmt_layout)?,
        None => None,
    };
    let bake = |gpu: Option<&super::gpu::GpuBaker>, voxels| {
        super::bake(
            gpu,
            &attrs,
            voxels,
            voxel_ms,
            plan.shaft_res,
            plan.shaft_variants,
            plan.pnmt_layout,
            Some(&shade),
            ctx.progress,
        )
    };
    let on_gpu = gpu.is_some();
    let first = bake(gpu.as_deref(), voxels);
    drop(gpu);
    let ls = match first {
        // `auto` falls back to the CPU (the same bytes) where the GPU fails.
        Err(e) if on_gpu && !super::gpu::required() => {
            eprintln!("warning: {e}; baking the line space on the CPU");
            bake(None, ctx.geometry.voxels(plan.voxel_res).reordered(&ctx.bvh.order))?
        }
        r => r?,
    };
    let mut out = Sections::default();
    out.push(GRID, 0, bytemuck::bytes_of(&ls.header).to_vec());
    out.push(VOXEL_OFFSETS, 0, bytemuck::cast_slice(&ls.voxel_offsets).to_vec());
    out.push(VOXEL_TRIANGLES, 0, bytemuck::cast_slice(&ls.voxel_triangles).to_vec());
    Ok((out, ls))
}

/// The line-space stage: the shaft sections of the variants baked.
pub fn line_space(ls: &BakedLineSpace) -> Sections {
    let mut out = Sections::default();
    let mut add = |kind, data: &[u8]| out.push(kind, 0, data.to_vec());
    add(SHAFT_SLOTS, bytemuck::cast_slice(&ls.slots));
    add(SHAFT_BITS, bytemuck::cast_slice(&ls.bits));
    add(SHAFT_RANKS, bytemuck::cast_slice(&ls.ranks));
    let variants = ls.header.variants;
    if variants & Variants::CANDIDATES != 0 {
        add(CANDIDATE_OFFSETS, bytemuck::cast_slice(&ls.candidate_offsets));
        add(CANDIDATES, bytemuck::cast_slice(&ls.candidates));
    }
    if variants & Variants::PNMT != 0 {
        add(PNMT, bytemuck::cast_slice(&ls.pnmt));
    }
    if variants & Variants::PREILLUM != 0 {
        add(PREILLUM, bytemuck::cast_slice(&ls.preillum));
    }
    out
}
