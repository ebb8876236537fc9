//! The scene as every shader that traces rays and shades their hits reads it (the ray-traced
//! passes through `shaders/rt/hybrid.glsl`, the reference path tracer): one binding table, from
//! which both the descriptor writes ([`super::GpuScene::ray_writes`]) and the GLSL declarations
//! (`shaders/common/scene_bindings.glsl`, generated; a test fails when it drifts) come.

/// One binding of the table: number, GLSL block name, member declaration, and what it holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneBinding {
    /// Binding number in set 0.
    pub binding: u32,
    /// GLSL block name.
    pub block: &'static str,
    /// The block's one member.
    pub member: &'static str,
    /// What it holds.
    pub what: &'static str,
}

/// BVH nodes (`CwbvhNode`s as `uvec4`s).
pub const BVH_NODES: SceneBinding = SceneBinding {
    binding: 1,
    block: "BvhNodes",
    member: "uvec4 bvh_nodes[]",
    what: "the baked CWBVH, 80-byte nodes as uvec4s",
};
/// Triangle corners in leaf order.
pub const BVH_TRIANGLES: SceneBinding = SceneBinding {
    binding: 2,
    block: "BvhTriangles",
    member: "vec4 bvh_tris[]",
    what: "three corners per triangle in leaf order, xyz",
};
/// Vertices (position and normal, 6 floats each).
pub const VERTICES: SceneBinding = SceneBinding {
    binding: 3,
    block: "Vertices",
    member: "float vertex_data[]",
    what: "position and normal, 6 floats each",
};
/// Texture coordinates and colours.
pub const VERTEX_ATTRIBUTES: SceneBinding = SceneBinding {
    binding: 4,
    block: "VertexAttributes",
    member: "GpuVertexAttributes vertex_attributes[]",
    what: "texture coordinates (zeros without) and colours (white without) per vertex",
};
/// Vertex indices in leaf order.
pub const LEAF_INDICES: SceneBinding = SceneBinding {
    binding: 5,
    block: "Indices",
    member: "uint indices[]",
    what: "vertex indices in leaf order",
};
/// Material of each triangle in leaf order.
pub const TRIANGLE_MATERIALS: SceneBinding = SceneBinding {
    binding: 6,
    block: "TriMaterials",
    member: "uint tri_materials[]",
    what: "material of each triangle in leaf order",
};
/// Materials.
pub const MATERIALS: SceneBinding = SceneBinding {
    binding: 7,
    block: "Materials",
    member: "GpuMaterialLayout materials[]",
    what: "the file's materials",
};
/// Analytic lights (written by the pass: the lights' soft-shadow radii are per run).
pub const LIGHTS: SceneBinding =
    SceneBinding { binding: 8, block: "Lights", member: "GpuLight lights[]", what: "the analytic lights" };

/// The table, in binding order.
pub const TABLE: [SceneBinding; 8] = [
    BVH_NODES,
    BVH_TRIANGLES,
    VERTICES,
    VERTEX_ATTRIBUTES,
    LEAF_INDICES,
    TRIANGLE_MATERIALS,
    MATERIALS,
    LIGHTS,
];

/// The text of `shaders/common/scene_bindings.glsl`.
pub fn glsl() -> String {
    let mut s = String::from(
        "// Generated from player/src/scene/bindings.rs by its test (KILN_BLESS=1 cargo test -p kiln-player\n\
         // scene_bindings): the scene as the passes that trace rays and shade their hits read it.\n\
         // Do not edit by hand.\n\
         #ifndef KILN_SCENE_BINDINGS_GLSL\n\
         #define KILN_SCENE_BINDINGS_GLSL\n\n\
         #include \"layout.glsl\"\n\n",
    );
    for b in TABLE {
        s.push_str(&format!(
            "// {}\nlayout(set = 0, binding = {}, std430) readonly buffer {} {{ {}; }};\n",
            b.what, b.binding, b.block, b.member
        ));
    }
    s.push_str("\n#endif\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_bindings_glsl_is_committed() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders/common/scene_bindings.glsl");
        let text = glsl();
        if std::env::var_os("KILN_BLESS").is_some() {
            std::fs::write(&path, &text).expect("write the generated file");
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == text,
            "{} differs from the generated text; run KILN_BLESS=1 cargo test -p kiln-player scene_bindings",
            path.display()
        );
    }

    #[test]
    fn bindings_are_numbered_in_order_without_gaps() {
        for (i, b) in TABLE.iter().enumerate() {
            assert_eq!(b.binding, i as u32 + 1, "{}", b.block);
        }
    }
}
