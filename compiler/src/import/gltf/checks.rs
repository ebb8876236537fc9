//! Checks of a glTF document before the importer walks it: what the `gltf` crates would panic
//! on rather than report (indices they read unchecked, images without a source, cameras without
//! their projection), one parent per node and no cycle, and the last line of defence that turns
//! a panic escaping them into a bad-input error.

use ::gltf::Document;

use crate::exit::{CliError, CliResult};

/// Runs `f`, turning a panic into a bad-input error about `file`.
pub(super) fn guard<T>(file: &str, f: impl FnOnce() -> CliResult<T>) -> CliResult<T> {
    // The scene `f` fills is dropped by the caller on error, so nothing sees it half-built.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".into());
        Err(CliError::input(format!(
            "{file}: malformed glTF that kiln's checks missed: reading it failed ({what}); please \
             report this file as a kiln bug too"
        )))
    })
}

/// Refuses a GLB whose header declares fewer bytes than the header itself: the gltf crate
/// subtracts the header's 12 from the declared length unchecked (an overflow).
pub(super) fn check_glb_header(bytes: &[u8], file: &str) -> CliResult<()> {
    if let Some(length) = bytes.strip_prefix(b"glTF").and_then(|b| b.get(4..8)) {
        let declared = u32::from_le_bytes([length[0], length[1], length[2], length[3]]);
        if declared < 12 {
            return Err(CliError::input(format!(
                "{file}: not a valid glTF 2.0 file: its GLB header declares {declared} bytes, less than the 12 of the header"
            )));
        }
    }
    Ok(())
}

/// `kind index 'name'`, or `kind index` for an unnamed object.
pub(super) fn named(kind: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) => format!("{kind} {index} '{n}'"),
        None => format!("{kind} {index}"),
    }
}

/// Checks what the `gltf` crate would panic on instead of reporting, before it validates or reads
/// the document: the accessors a primitive names (its validation indexes the accessors with
/// POSITION's index unchecked), an image's source (read by `unwrap`: a `uri` or a `bufferView`,
/// the latter with a `mimeType`), and a camera's projection (the object its `type` names is
/// unwrapped). Every other index is checked by `gltf`'s validation, which reports rather than
/// panics.
pub(super) fn check_references(json: &::gltf::json::Root, file: &str) -> CliResult<()> {
    use ::gltf::json::camera::Type;
    use ::gltf::json::validation::Checked;
    let bad = |msg: String| Err(CliError::input(format!("{file}: invalid glTF: {msg}")));
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let mut refs: Vec<(String, usize)> = prim
                .attributes
                .iter()
                .map(|(k, a)| (format!("attribute {}", k.to_string()), a.value()))
                .collect();
            refs.extend(prim.indices.map(|a| ("indices".to_string(), a.value())));
            for (t, target) in prim.targets.iter().flatten().enumerate() {
                for (what, a) in
                    [("POSITION", target.positions), ("NORMAL", target.normals), ("TANGENT", target.tangents)]
                {
                    refs.extend(a.map(|a| (format!("morph target {t} {what}"), a.value())));
                }
            }
            if let Some((what, a)) = refs.into_iter().find(|&(_, a)| a >= accessors) {
                let plural = if accessors == 1 { "" } else { "s" };
                return bad(format!(
                    "{} primitive {p}: {what} names accessor {a}, but the file has {accessors} \
                     accessor{plural}",
                    named("mesh", m, mesh.name.as_deref())
                ));
            }
        }
    }
    for (i, img) in json.images.iter().enumerate() {
        let at = named("image", i, img.name.as_deref());
        if img.uri.is_none() && img.buffer_view.is_none() {
            return bad(format!("{at} has neither a uri nor a bufferView"));
        }
        if img.buffer_view.is_some() && img.mime_type.is_none() {
            return bad(format!("{at} has a bufferView but no mimeType"));
        }
    }
    for (c, cam) in json.cameras.iter().enumerate() {
        let missing = match cam.type_ {
            Checked::Valid(Type::Perspective) if cam.perspective.is_none() => "perspective",
            Checked::Valid(Type::Orthographic) if cam.orthographic.is_none() => "orthographic",
            _ => continue,
        };
        return bad(format!(
            "{} has type {missing} but no {missing} object",
            named("camera", c, cam.name.as_deref())
        ));
    }
    Ok(())
}

/// The parent of every node, checking that the nodes form disjoint strict trees as glTF 2.0
/// requires ("Nodes and Hierarchy"): a node is listed once among its parent's children and has
/// one parent at most (a child listed twice, chained, doubles the walk at every level), and no
/// node is its own ancestor. Linear in nodes and children, without recursion.
pub(super) fn node_parents(doc: &Document, file: &str) -> CliResult<Vec<Option<usize>>> {
    let mut parents: Vec<Option<usize>> = vec![None; doc.nodes().len()];
    for node in doc.nodes() {
        let p = node.index();
        for child in node.children() {
            let c = child.index();
            let at = named("node", c, child.name());
            match parents[c] {
                None => parents[c] = Some(p),
                Some(q) if q == p => {
                    return Err(CliError::input(format!(
                        "{file}: invalid glTF: {at} is listed twice among the children of node {p}; a \
                         node has one parent"
                    )));
                }
                Some(q) => {
                    return Err(CliError::input(format!(
                        "{file}: invalid glTF: {at} is a child of both node {q} and node {p}; a node \
                         has one parent"
                    )));
                }
            }
        }
    }
    // Each node has one parent at most, so a cycle is found by following parents. State per node:
    // 0 not seen, 1 on the path being followed, 2 known to reach a root.
    let mut state = vec![0u8; parents.len()];
    let mut path = Vec::new();
    for start in 0..parents.len() {
        let mut at = Some(start);
        while let Some(n) = at {
            match state[n] {
                2 => break,
                1 => {
                    return Err(CliError::input(format!(
                        "{file}: invalid glTF: node hierarchy has a cycle through node {n}"
                    )));
                }
                _ => {
                    state[n] = 1;
                    path.push(n);
                    at = parents[n];
                }
            }
        }
        for n in path.drain(..) {
            state[n] = 2;
        }
    }
    Ok(parents)
}
