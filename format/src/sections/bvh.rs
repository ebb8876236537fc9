//! The compressed wide BVH node the GPU traverses (Ylitie et al., HPG 2017, "Efficient Incoherent
//! Ray Traversal on GPUs Through Compressed Wide BVHs"). The layout equals obvhs's `CwBvhNode`
//! field for field, but is owned here so that a dependency upgrade cannot change files.

use bytemuck::{Pod, Zeroable};

/// Depth bound of a valid BVH: traversal stacks of this many entries never overflow, and the
/// reader rejects deeper trees.
pub const BVH_TRAVERSAL_STACK: usize = 32;

/// An 8-wide node with child boxes quantised to 8 bits per plane. 80 bytes.
///
/// Child box planes are `p + 2^(e-127) * q` per axis; quantisation rounds outwards, so the
/// decoded boxes contain the exact ones.
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
#[repr(C)]
pub struct CwbvhNode {
    /// Origin of the quantisation grid (min corner of the node's box).
    pub p: [f32; 3],
    /// Per-axis exponent byte: the grid step is `f32::from_bits(e << 23)`.
    pub e: [u8; 3],
    /// Bit i set: child slot i is an internal node.
    pub imask: u8,
    /// Index of the first child node; internal children are stored consecutively.
    pub child_base_idx: u32,
    /// Index of the first triangle of this node's leaves.
    pub primitive_base_idx: u32,
    /// Per slot: 0 = empty; internal: `0b001_xxxxx` with slot + 24 in the low bits;
    /// leaf: unary triangle count in the high 3 bits, offset from `primitive_base_idx` in the low 5.
    pub child_meta: [u8; 8],
    /// Quantised child box planes.
    pub child_min_x: [u8; 8],
    /// See `child_min_x`.
    pub child_max_x: [u8; 8],
    /// See `child_min_x`.
    pub child_min_y: [u8; 8],
    /// See `child_min_x`.
    pub child_max_y: [u8; 8],
    /// See `child_min_x`.
    pub child_min_z: [u8; 8],
    /// See `child_min_x`.
    pub child_max_z: [u8; 8],
}

const _: () = assert!(size_of::<CwbvhNode>() == 80);

impl CwbvhNode {
    /// Grid step per axis.
    pub fn extent(&self) -> [f32; 3] {
        self.e.map(|e| f32::from_bits((e as u32) << 23))
    }

    /// Whether slot `i` holds nothing.
    pub fn is_empty(&self, i: usize) -> bool {
        self.child_meta[i] == 0
    }

    /// Whether slot `i` is an internal node.
    pub fn is_internal(&self, i: usize) -> bool {
        self.imask & (1 << i) != 0
    }

    /// Node index of internal slot `i` (no range check).
    pub fn child_node(&self, i: usize) -> u64 {
        let below = (self.imask as u32) & ((1u32 << i) - 1);
        self.child_base_idx as u64 + below.count_ones() as u64
    }

    /// First triangle and triangle count of leaf slot `i` (no range check).
    pub fn leaf_range(&self, i: usize) -> (u64, u32) {
        let m = self.child_meta[i];
        (self.primitive_base_idx as u64 + (m & 0x1f) as u64, (m >> 5).count_ones())
    }

    /// Decoded box of slot `i`: (min, max).
    pub fn child_box(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        let s = self.extent();
        let lo = [self.child_min_x[i], self.child_min_y[i], self.child_min_z[i]];
        let hi = [self.child_max_x[i], self.child_max_y[i], self.child_max_z[i]];
        (
            std::array::from_fn(|a| self.p[a] + s[a] * lo[a] as f32),
            std::array::from_fn(|a| self.p[a] + s[a] * hi[a] as f32),
        )
    }
}
