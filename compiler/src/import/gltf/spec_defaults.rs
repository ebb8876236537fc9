//! What glTF 2.0 lets a file leave out, supplied before the `gltf` crate parses or validates it:
//! the crate is stricter than the specification in places, and a spec-valid file must compile.
//!
//! - `scenes[].nodes` is optional (an empty scene); the crate's parser requires it.
//! - An accessor without `bufferView` and without `sparse` is all zeros; the crate's validation
//!   requires one of them. Such accessors get views into one zero-filled buffer of their own.
//! - A primitive without POSITION is skipped, as the specification says renderers should.
//! - A POSITION accessor must have `min` and `max`; a file without them is read anyway (kiln
//!   computes its own bounds), with a warning.
//! - Animations the crate cannot parse (a channel target without `node`, which extensions such
//!   as KHR_animation_pointer use) are dropped: kiln bakes none.

use ::gltf::json::accessor::Type;
use ::gltf::json::validation::{Checked, USize64};
use ::gltf::json::{self, Index, Root};

/// The glTF or GLB `bytes` with what the parser needs and the specification lets a file omit
/// filled in (`scenes[].nodes`), and, when `drop_animations`, without the `animations` array;
/// with how many animations were dropped. `None` when the JSON does not parse or nothing changed.
pub(super) fn with_defaults(bytes: &[u8], drop_animations: bool) -> Option<(Vec<u8>, usize)> {
    let fix = |json: &[u8]| -> Option<(Vec<u8>, usize)> {
        let mut value: serde_json::Value = serde_json::from_slice(json).ok()?;
        let root = value.as_object_mut()?;
        let mut changed = false;
        for scene in root.get_mut("scenes").and_then(|s| s.as_array_mut()).into_iter().flatten() {
            if let Some(s) = scene.as_object_mut().filter(|s| !s.contains_key("nodes")) {
                s.insert("nodes".into(), serde_json::Value::Array(Vec::new()));
                changed = true;
            }
        }
        let dropped = match drop_animations {
            true => root.remove("animations").map_or(0, |a| a.as_array().map_or(1, Vec::len)),
            false => 0,
        };
        (changed || dropped > 0).then_some(())?;
        Some((serde_json::to_vec(&value).ok()?, dropped))
    };
    if bytes.starts_with(b"glTF") {
        let glb = ::gltf::Glb::from_slice(bytes).ok()?;
        let (json, dropped) = fix(&glb.json)?;
        let fixed = ::gltf::Glb { header: glb.header, json: json.into(), bin: glb.bin }.to_vec().ok()?;
        Some((fixed, dropped))
    } else {
        fix(bytes)
    }
}

/// The buffer [`fill`] added for accessors without data: its index and length in bytes.
#[derive(Debug, Clone, Copy)]
pub(super) struct ZeroBuffer {
    pub index: usize,
    pub length: usize,
}

/// Fills in, on the parsed JSON, what the specification lets a file omit and the crate's
/// validation requires: a view into a new zero-filled buffer for each accessor that has neither
/// `bufferView` nor `sparse`, and placeholder `min`/`max` for POSITION accessors without them
/// (each warned about in `warnings`). The zero buffer's bytes are the caller's to supply.
pub(super) fn fill(json: &mut Root, warnings: &mut Vec<String>) -> Option<ZeroBuffer> {
    // "When positions are not specified, client implementations SHOULD skip primitive's
    // rendering" (glTF 2.0, 3.7.2.1); the crate's validation requires them.
    let positions_key = Checked::Valid(json::mesh::Semantic::Positions);
    for (m, mesh) in json.meshes.iter_mut().enumerate() {
        let before = mesh.primitives.len();
        mesh.primitives.retain(|p| p.attributes.contains_key(&positions_key));
        if mesh.primitives.len() < before {
            warnings.push(format!(
                "mesh {m}: {} primitive(s) without POSITION skipped, as glTF says (nothing to place)",
                before - mesh.primitives.len()
            ));
        }
    }
    let positions: Vec<usize> = json
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .filter_map(|p| p.attributes.get(&Checked::Valid(json::mesh::Semantic::Positions)))
        .map(|a| a.value())
        .collect();
    for &a in &positions {
        let Some(acc) = json.accessors.get_mut(a) else { continue };
        if acc.min.is_none() || acc.max.is_none() {
            warnings.push(format!(
                "POSITION accessor {a} lacks min or max, which glTF requires; read anyway (kiln bounds the data itself)"
            ));
            let zero = serde_json::json!([0.0, 0.0, 0.0]);
            acc.min.get_or_insert_with(|| zero.clone());
            acc.max.get_or_insert(zero);
        }
    }
    let buffer = json.buffers.len();
    let mut length = 0usize;
    let mut views = Vec::new();
    for (i, acc) in json.accessors.iter_mut().enumerate() {
        if acc.buffer_view.is_some() || acc.sparse.is_some() {
            continue;
        }
        // Left to validation when the type is not one glTF defines.
        let (Checked::Valid(component), Checked::Valid(ty)) = (&acc.component_type, &acc.type_) else {
            continue;
        };
        let comp = component.0.size();
        // Matrix columns start on 4-byte boundaries (glTF 2.0, "Data Alignment").
        let element = match ty {
            Type::Mat2 => 2 * (2 * comp).next_multiple_of(4),
            Type::Mat3 => 3 * (3 * comp).next_multiple_of(4),
            _ => ty.multiplicity() * comp,
        };
        let Some(bytes) = usize::try_from(acc.count.0).ok().and_then(|c| c.checked_mul(element)) else {
            continue;
        };
        let offset = length.next_multiple_of(4);
        let Some(end) = offset.checked_add(bytes) else { continue };
        length = end;
        views.push((i, offset, bytes));
    }
    if views.is_empty() {
        return None;
    }
    json.buffers.push(json::Buffer {
        byte_length: USize64(length as u64),
        name: Some("zeros of accessors without data".into()),
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    for (i, offset, bytes) in views {
        let view = Index::push(
            &mut json.buffer_views,
            json::buffer::View {
                buffer: Index::new(buffer as u32),
                byte_length: USize64(bytes as u64),
                byte_offset: Some(USize64(offset as u64)),
                byte_stride: None,
                name: None,
                target: None,
                extensions: None,
                extras: Default::default(),
            },
        );
        json.accessors[i].buffer_view = Some(view);
        json.accessors[i].byte_offset = None;
    }
    Some(ZeroBuffer { index: buffer, length })
}
