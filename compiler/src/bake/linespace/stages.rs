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
    // Σ triangles × shafts: the work that decides whether a GPU is worth opening.
    let shafts = kiln_format::linespace::index::shafts_per_voxel(ctx.plan.shaft_res.max(1)) as u64;
    let work = if ctx.plan.shaft_variants == 0 { 0 } else { voxels.triangles.len() as u64 * shafts };
    let gpu = super::gpu::for_bake(work, ctx.plan.shaft_res, ctx.plan.pnmt_layout)?;
    let ls = super::bake(
        gpu.as_deref(),
        &ctx.attributes(),
        voxels,
        voxel_ms,
        ctx.plan.shaft_res,
        ctx.plan.shaft_variants,
        ctx.plan.pnmt_layout,
        Some(&shade),
        ctx.progress,
    )?;
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
