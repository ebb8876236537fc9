//! The geometry as the passes read it: indices sorted into one draw per material for the raster
//! passes, vertex attributes interleaved, triangle corners in leaf order for the traversal.

use kiln_format::gpu::GpuVertexAttributes;
use kiln_format::scene::SceneView;
use kiln_format::sections::{GpuMaterial, Vertex};

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
pub(super) fn vertex_attributes(view: &SceneView) -> Vec<GpuVertexAttributes> {
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

/// The material of each triangle in draw (index buffer) order.
pub(super) fn raster_materials(draws: &[Draw]) -> Vec<u32> {
    draws.iter().flat_map(|d| std::iter::repeat_n(d.material, d.count as usize / 3)).collect()
}

/// The world bounds (min, max) of the triangles of the draws whose material is see-through
/// ([`GpuMaterial::see_through`]), `None` where no such draw exists: where the see-through
/// layer may show.
pub fn see_through_bounds(
    draws: &[Draw],
    indices: &[u32],
    vertices: &[Vertex],
    materials: &[GpuMaterial],
) -> Option<[glam::Vec3; 2]> {
    let mut bounds: Option<[glam::Vec3; 2]> = None;
    for d in draws.iter().filter(|d| materials.get(d.material as usize).is_some_and(|m| m.see_through())) {
        let range = d.first as usize..(d.first + d.count) as usize;
        for &i in indices.get(range).unwrap_or(&[]) {
            let Some(v) = vertices.get(i as usize) else { continue };
            let p = glam::Vec3::from(v.position);
            bounds = Some(bounds.map_or([p, p], |[lo, hi]| [lo.min(p), hi.max(p)]));
        }
    }
    bounds
}

#[cfg(test)]
mod tests {
    use super::*;

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
