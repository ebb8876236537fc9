//! glTF 2.0 import (`.gltf` with external or data-URI buffers and images, `.glb`).
//!
//! Every accessor is checked against its buffer before it is read, so that a hostile or
//! truncated file gives an error naming the mesh, primitive and accessor instead of a panic.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::{Accessor, Document, Gltf};
use glam::{DMat3, DMat4, DVec3};
use kiln_format::manifest::{Camera, Light, LightKind, OrthographicCamera};
use kiln_format::sections::Vertex;

mod buffers;
mod checks;
mod clearcoat;
mod extent;
mod lights_image_based;
mod material;
mod skinning;
mod spec_defaults;
mod specular;
mod transmission;
mod uri;
mod uv_mapping;

use super::geometry::{
    Sharing, check_position, corner_normals, given_corner_normals, split_by_normal, stored, unorm16,
};
use super::images::{TextureRequest, decode_all};
use super::read_input;
use crate::exit::{CliError, CliResult, Exit};
use crate::ir::{Scene, TextureRole, WarningClass};
use crate::settings::Normals;
use buffers::load_buffers;
use checks::{check_glb_header, check_references, guard, named, node_parents};
use extent::declared_extent;
use uv_mapping::UvMapping;

/// Extensions whose meaning kiln implements; a file requiring any other is refused.
const SUPPORTED_EXTENSIONS: &[&str] = &[
    "EXT_lights_image_based",
    "KHR_lights_punctual",
    "KHR_materials_clearcoat",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_texture_transform",
];

/// World triangles beyond this are refused (instancing can multiply a small file's geometry).
const MAX_TRIANGLES: usize = 1 << 28;

/// An accessor without a buffer view (sparse values over zeros) may expand to at most the larger
/// of this many bytes and [`SPARSE_EXPANSION_RATIO`] times the bytes of the file's buffers: enough
/// for any sparse morph target, colour or matrix set beside geometry the buffers hold, never the
/// gigabytes that a `count` in a tiny file would ask for.
const SPARSE_EXPANSION_FLOOR: usize = 16 << 20;
/// See [`SPARSE_EXPANSION_FLOOR`].
const SPARSE_EXPANSION_RATIO: usize = 4;

/// What an accessor without a buffer view may expand to beside `file_bytes` bytes of buffers
/// ([`SPARSE_EXPANSION_FLOOR`]), with the bound spelled out for an error message.
fn expansion_limit(file_bytes: usize) -> (usize, String) {
    let limit = SPARSE_EXPANSION_FLOOR.max(SPARSE_EXPANSION_RATIO.saturating_mul(file_bytes));
    let why = format!(
        "{limit} bytes: {} MiB or {SPARSE_EXPANSION_RATIO} × the file's {file_bytes} buffer bytes, the larger",
        SPARSE_EXPANSION_FLOOR >> 20
    );
    (limit, why)
}

struct Importer<'a> {
    file: String,
    base: PathBuf,
    doc: &'a Document,
    buffers: Vec<Vec<u8>>,
    scene: &'a mut Scene,
    /// glTF material index → IR material index.
    materials: HashMap<Option<usize>, u32>,
    /// (glTF texture index, role) → IR texture index.
    textures: HashMap<(usize, TextureRole), u32>,
    /// IR material index → how its textures read texture coordinates.
    uv_mappings: HashMap<u32, UvMapping>,
    requests: Vec<TextureRequest>,
    /// Normals where a primitive has no NORMAL attribute.
    normals: Normals,
    /// Parent of each node (skins need their joints' scene transforms), checked by
    /// [`node_parents`]: one parent at most, no cycle.
    parents: Vec<Option<usize>>,
    /// Per mesh: the nodes that place it, and the triangles one placement adds.
    mesh_uses: HashMap<usize, (usize, usize)>,
    /// Images that name files outside the confinement (`files::check_confined`): the import fails.
    escapes: Vec<String>,
}

/// Where a mesh's vertices go.
enum Placement {
    /// One transform for every vertex: the node's.
    Rigid(DMat4),
    /// Linear blend skinning with these joint matrices (JOINTS_n / WEIGHTS_n per vertex); the
    /// node's transform serves a primitive without weights.
    Skinned { joints: Vec<DMat4>, node: DMat4 },
}

/// Imports a `.gltf` or `.glb` file into `scene`.
///
/// Hostile files are refused by validation before the `gltf` crate sees what it would panic
/// on ([`check_references`], [`node_parents`], the accessor checks). As a last line of defence,
/// a panic that still escapes the import (in the `gltf` crate or here) is caught and reported as
/// a bad input, naming the file, rather than as kiln's internal error: it can only come from
/// something in the file that the checks missed (and is then a bug to report as well).
pub fn import(path: &Path, scene: &mut Scene, normals: Normals) -> CliResult<()> {
    let file = path.display().to_string();
    guard(&file, || import_checked(path, scene, normals))
}

fn import_checked(path: &Path, scene: &mut Scene, normals: Normals) -> CliResult<()> {
    let bytes = read_input(path, &mut scene.inputs)?;
    let file = path.display().to_string();
    check_glb_header(&bytes, &file)?;
    let gltf = match Gltf::from_slice_without_validation(&bytes) {
        Ok(gltf) => gltf,
        Err(e) => {
            let invalid = || CliError::input(format!("{file}: not a valid glTF 2.0 file: {e}"));
            // The gltf crate's parser requires what the spec lets a file omit (`scenes[].nodes`),
            // and reads animations strictly (a channel target without `node`, which the spec
            // allows for extensions such as KHR_animation_pointer, is a parse error); kiln bakes
            // no animation, so a file that parses without them compiles, with a warning.
            let parse = |drop| {
                let (fixed, dropped) = spec_defaults::with_defaults(&bytes, drop)?;
                Some((Gltf::from_slice_without_validation(&fixed).ok()?, dropped))
            };
            let (gltf, dropped) = parse(false).or_else(|| parse(true)).ok_or_else(invalid)?;
            if dropped > 0 {
                scene.warn(format!(
                    "{file}: {dropped} animation(s) dropped unread: the gltf crate does not parse them ({e}); \
                     kiln bakes no animation"
                ));
            }
            gltf
        }
    };
    let unsupported: Vec<&str> =
        gltf.document.extensions_required().filter(|e| !SUPPORTED_EXTENSIONS.contains(e)).collect();
    if !unsupported.is_empty() {
        return Err(CliError::new(
            Exit::Unsupported,
            format!("{file}: requires glTF extensions kiln does not support: {}", unsupported.join(", ")),
        ));
    }
    let blob = gltf.blob;
    let mut json = gltf.document.into_json();
    // Every required extension is one kiln reads (checked above); the gltf crate's validation
    // refuses those it does not parse itself (kiln reads `KHR_materials_clearcoat` and
    // `EXT_lights_image_based` from their JSON), so they are not handed to it.
    json.extensions_required.clear();
    check_references(&json, &file)?;
    let mut omitted = Vec::new();
    let zeros = spec_defaults::fill(&mut json, &mut omitted);
    for w in omitted {
        scene.warn(format!("{file}: {w}"));
    }
    let invalid =
        |e: ::gltf::Error| CliError::input(format!("{file}: invalid glTF: {}", describe_validation(&e)));
    let doc = match Document::from_json(json.clone()) {
        Ok(doc) => doc,
        // Animations are never baked: a malformed one costs nothing to drop, so it is a warning
        // (the rest must validate without it).
        Err(e @ ::gltf::Error::Validation(_)) if only_animations(&e) => {
            scene.warn(format!(
                "{file}: {} animation(s) dropped unread, as they are malformed: {}",
                json.animations.len(),
                describe_validation(&e)
            ));
            json.animations.clear();
            Document::from_json(json).map_err(invalid)?
        }
        Err(e) => return Err(invalid(e)),
    };
    for ext in doc.extensions_used().filter(|e| !SUPPORTED_EXTENSIONS.contains(e)) {
        scene.warn(format!("{file}: extension {ext} is used but not supported; its effect is ignored"));
    }
    let parents = node_parents(&doc, &file)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    // External buffers and images are read through `load_uri`, within `super::files`' bounds.
    let buffers = load_buffers(&doc, blob, zeros, &file, &base, &mut scene.inputs)?;
    let mut imp = Importer {
        file,
        base,
        doc: &doc,
        buffers,
        scene,
        materials: HashMap::new(),
        textures: HashMap::new(),
        uv_mappings: HashMap::new(),
        requests: Vec::new(),
        normals,
        parents,
        mesh_uses: HashMap::new(),
        escapes: Vec::new(),
    };
    imp.walk_scene()?;
    imp.image_based_light();
    if !imp.escapes.is_empty() {
        return Err(CliError::input(format!("{}: {}", imp.file, imp.escapes.join("; "))));
    }
    imp.warn_flattened_instances();
    let (textures, warnings) = decode_all(std::mem::take(&mut imp.requests));
    for w in warnings {
        imp.scene.warn(format!("{}: {w}", imp.file));
    }
    imp.scene.textures.extend(textures);
    Ok(())
}

/// Whether every validation error of `e` lies inside the `animations` array.
fn only_animations(e: &::gltf::Error) -> bool {
    match e {
        ::gltf::Error::Validation(list) => {
            !list.is_empty() && list.iter().all(|(path, _)| path.as_str().starts_with("animations["))
        }
        _ => false,
    }
}

fn describe_validation(e: &::gltf::Error) -> String {
    match e {
        ::gltf::Error::Validation(list) => list
            .iter()
            .take(8)
            .map(|(path, err)| format!("{}: {err}", path.as_str()))
            .collect::<Vec<_>>()
            .join("; "),
        other => other.to_string(),
    }
}

impl Importer<'_> {
    fn walk_scene(&mut self) -> CliResult<()> {
        let doc = self.doc;
        let roots: Vec<::gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s.nodes().collect(),
            // No scene: every node that is nobody's child is a root.
            None => doc.nodes().filter(|n| self.parents[n.index()].is_none()).collect(),
        };
        let animations = doc.animations().count();
        if animations > 0 {
            self.scene.warn(format!(
                "{}: {animations} animation(s) not baked: the scene is compiled at the nodes' rest \
                 transforms and default morph weights",
                self.file
            ));
        }
        // Depth first, children in their order, on a stack of its own: the hierarchy's depth is
        // bounded by the file, not by the thread's stack. [`node_parents`] made it a forest, so
        // the walk ends and visits a node once per root above it.
        // The transforms first, then the origin positions are stored relative to (from the
        // meshes' declared extents), then what the nodes place.
        let mut stack: Vec<(::gltf::Node, DMat4)> =
            roots.into_iter().rev().map(|r| (r, DMat4::IDENTITY)).collect();
        let mut placed = Vec::new();
        while let Some((node, parent)) = stack.pop() {
            let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
            let world = parent * local;
            if !world.is_finite() {
                return Err(CliError::input(format!(
                    "{}: node {} has a non-finite transform",
                    self.file,
                    node.index()
                )));
            }
            let children: Vec<::gltf::Node> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
            placed.push((node, world));
        }
        self.scene.origin = declared_extent(&placed).origin().to_array();
        for (node, world) in placed {
            self.visit(&node, world)?;
        }
        Ok(())
    }

    /// Where positions are measured from ([`Scene::origin`]).
    fn origin(&self) -> DVec3 {
        DVec3::from(self.scene.origin)
    }

    /// Adds what `node` places (mesh, camera, light) under its scene transform `world`.
    fn visit(&mut self, node: &::gltf::Node, world: DMat4) -> CliResult<()> {
        if let Some(mesh) = node.mesh() {
            // glTF: a node's morph weights override its mesh's; absent weights are 0.
            let weights: Vec<f32> = node.weights().or(mesh.weights()).unwrap_or(&[]).to_vec();
            let placement = match node.skin() {
                Some(skin) => {
                    Placement::Skinned { joints: self.joint_matrices(&skin, node.index())?, node: world }
                }
                None => Placement::Rigid(world),
            };
            self.add_mesh(&mesh, &placement, &weights)?;
        }
        if let Some(camera) = node.camera() {
            self.add_camera(&camera, &world, node.index());
        }
        if let Some(light) = node.light() {
            self.add_light(&light, &world, node.index())?;
        }
        Ok(())
    }

    /// The transform of `node` in the scene: its ancestors' local transforms composed with its
    /// own (the rest pose the nodes describe; animations are not applied).
    fn global_transform(&self, node: usize) -> CliResult<DMat4> {
        let mut m = DMat4::IDENTITY;
        let mut at = Some(node);
        let mut steps = 0;
        while let Some(n) = at {
            steps += 1;
            if steps > self.parents.len() {
                return Err(CliError::input(format!(
                    "{}: node hierarchy has a cycle through node {n}",
                    self.file
                )));
            }
            let local = self.doc.nodes().nth(n).map(|n| n.transform().matrix()).unwrap_or_default();
            m = DMat4::from_cols_array_2d(&local.map(|c| c.map(f64::from))) * m;
            at = self.parents[n];
        }
        Ok(m)
    }

    fn mesh_name(mesh: &::gltf::Mesh) -> String {
        named("mesh", mesh.index(), mesh.name())
    }

    fn add_mesh(&mut self, mesh: &::gltf::Mesh, placement: &Placement, weights: &[f32]) -> CliResult<()> {
        let before = self.scene.triangles.len();
        self.add_primitives(mesh, placement, weights)?;
        let added = self.scene.triangles.len() - before;
        let uses = self.mesh_uses.entry(mesh.index()).or_insert((0, added));
        uses.0 += 1;
        Ok(())
    }

    /// One warning (class `performance`) for every mesh placed by several nodes: the file
    /// stores world-space triangles, so each placement is a copy.
    fn warn_flattened_instances(&mut self) {
        let (mut meshes, mut copies) = (0usize, 0usize);
        for &(uses, tris) in self.mesh_uses.values() {
            if uses > 1 {
                meshes += 1;
                copies += (uses - 1) * tris;
            }
        }
        if copies > 0 {
            let total = self.scene.triangles.len();
            self.scene.warn_as(
                WarningClass::Performance,
                format!(
                    "{}: {meshes} mesh(es) are placed by several nodes; kiln stores world-space triangles, so {copies} of the scene's {total} triangles ({:.0}%) are copies of instances",
                    self.file,
                    100.0 * copies as f64 / total.max(1) as f64
                ),
            );
        }
    }

    fn add_primitives(
        &mut self,
        mesh: &::gltf::Mesh,
        placement: &Placement,
        weights: &[f32],
    ) -> CliResult<()> {
        for prim in mesh.primitives() {
            let at = format!("{}: {} primitive {}", self.file, Self::mesh_name(mesh), prim.index());
            let mode = prim.mode();
            if matches!(mode, Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
                self.scene.warn(format!("{at}: mode {mode:?} has no triangles; skipped"));
                continue;
            }
            let material = self.material(prim.material())?;
            let pos_acc = prim
                .get(&::gltf::Semantic::Positions)
                .ok_or_else(|| CliError::input(format!("{at}: has no POSITION attribute")))?;
            self.check_accessor(&pos_acc, &at, "POSITION", &[Dimensions::Vec3], &[DataType::F32], false)?;
            let count = pos_acc.count();
            let reader = prim.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
            let mut local_pos: Vec<[f32; 3]> = reader
                .read_positions()
                .ok_or_else(|| {
                    CliError::input(format!("{at}: POSITION accessor {} has no data", pos_acc.index()))
                })?
                .collect();
            // A non-finite value is reported as the accessor holds it, before morphing or transforms.
            if let Some((i, p)) = local_pos.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite()))
            {
                return Err(CliError::input(format!(
                    "{at}: POSITION accessor {} element {i} is not finite: {p:?}",
                    pos_acc.index()
                )));
            }
            // Morph targets at the default weights (the scene is static: no animation moves them).
            let mut normal_deltas: Vec<(f32, Vec<[f32; 3]>)> = Vec::new();
            for (k, target) in prim.morph_targets().enumerate() {
                let w = weights.get(k).copied().unwrap_or(0.0);
                if !w.is_finite() {
                    return Err(CliError::input(format!("{at}: morph weight {k} is not finite: {w}")));
                }
                // TANGENT deltas are not applied, but reading the targets reads them too.
                let accessors = [
                    (target.positions(), "POSITION"),
                    (target.normals(), "NORMAL"),
                    (target.tangents(), "TANGENT"),
                ];
                for (acc, what) in accessors {
                    if let Some(acc) = acc {
                        let name = format!("morph target {k} {what}");
                        self.check_accessor(&acc, &at, &name, &[Dimensions::Vec3], &[DataType::F32], false)?;
                        self.check_count(&acc, count, &at, &name)?;
                    }
                }
            }
            for (k, (positions, normals, _)) in reader.read_morph_targets().enumerate() {
                let w = weights.get(k).copied().unwrap_or(0.0);
                if w == 0.0 {
                    continue;
                }
                if let Some(deltas) = positions {
                    for (p, d) in local_pos.iter_mut().zip(deltas) {
                        for a in 0..3 {
                            p[a] += w * d[a];
                        }
                    }
                }
                if let Some(deltas) = normals {
                    normal_deltas.push((w, deltas.collect()));
                }
            }
            // One matrix for a rigid mesh, one per vertex for a skinned one.
            let matrices: Vec<DMat4> = match placement {
                Placement::Rigid(m) => vec![*m],
                Placement::Skinned { joints, node } => match self.skin_matrices(&prim, joints, count, &at)? {
                    Some(m) => m,
                    None => {
                        self.scene.warn(format!(
                            "{at}: its node is skinned but it has no JOINTS_0/WEIGHTS_0: placed by the node's transform"
                        ));
                        vec![*node]
                    }
                },
            };
            let matrix = |i: usize| per_vertex(&matrices, i);
            let origin = self.origin();
            let mut positions = Vec::with_capacity(count);
            for (i, p) in local_pos.iter().enumerate() {
                let w = stored(matrix(i).transform_point3(DVec3::from(p.map(f64::from))), origin);
                check_position(w, || {
                    format!(
                        "{at}: POSITION accessor {} element {i} (accessor value {p:?}) after its node transform",
                        pos_acc.index()
                    )
                })?;
                positions.push(w);
            }

            let normals_in: Option<Vec<[f32; 3]>> = match prim.get(&::gltf::Semantic::Normals) {
                Some(acc) => {
                    self.check_accessor(&acc, &at, "NORMAL", &[Dimensions::Vec3], &[DataType::F32], false)?;
                    self.check_count(&acc, count, &at, "NORMAL")?;
                    reader.read_normals().map(|it| {
                        let mut n: Vec<[f32; 3]> = it.collect();
                        for (w, deltas) in &normal_deltas {
                            for (v, d) in n.iter_mut().zip(deltas) {
                                for a in 0..3 {
                                    v[a] += w * d[a];
                                }
                            }
                        }
                        n
                    })
                }
                None => None,
            };
            let mapping = self.uv_mappings.get(&material).copied().unwrap_or(UvMapping::of(0, None));
            let set = mapping.set;
            let uv_name = format!("TEXCOORD_{set}");
            let uvs: Option<Vec<[f32; 2]>> = match prim.get(&::gltf::Semantic::TexCoords(set)) {
                Some(acc) => {
                    self.check_accessor(
                        &acc,
                        &at,
                        &uv_name,
                        &[Dimensions::Vec2],
                        &[DataType::F32, DataType::U8, DataType::U16],
                        true,
                    )?;
                    self.check_count(&acc, count, &at, &uv_name)?;
                    reader.read_tex_coords(set).map(|it| it.into_f32().map(|uv| mapping.apply(uv)).collect())
                }
                None => None,
            };
            if let Some((i, uv)) =
                uvs.iter().flatten().enumerate().find(|(_, uv)| !uv.iter().all(|c| c.is_finite()))
            {
                return Err(CliError::input(format!("{at}: {uv_name} element {i} is not finite: {uv:?}")));
            }

            // COLOR_0 (linear RGB or RGBA) multiplies the base colour.
            let colors: Option<Vec<[u16; 4]>> = match prim.get(&::gltf::Semantic::Colors(0)) {
                Some(acc) => {
                    self.check_accessor(
                        &acc,
                        &at,
                        "COLOR_0",
                        &[Dimensions::Vec3, Dimensions::Vec4],
                        &[DataType::F32, DataType::U8, DataType::U16],
                        true,
                    )?;
                    self.check_count(&acc, count, &at, "COLOR_0")?;
                    let raw: Vec<[f32; 4]> =
                        reader.read_colors(0).map(|c| c.into_rgba_f32().collect()).unwrap_or_default();
                    if let Some((i, c)) =
                        raw.iter().enumerate().find(|(_, c)| !c.iter().all(|v| v.is_finite()))
                    {
                        return Err(CliError::input(format!(
                            "{at}: COLOR_0 accessor {} element {i} is not finite: {c:?}",
                            acc.index()
                        )));
                    }
                    Some(raw.iter().map(|c| c.map(unorm16)).collect())
                }
                None => None,
            };

            let indices: Vec<u32> = match prim.indices() {
                Some(acc) => {
                    self.check_accessor(
                        &acc,
                        &at,
                        "indices",
                        &[Dimensions::Scalar],
                        &[DataType::U8, DataType::U16, DataType::U32],
                        false,
                    )?;
                    let idx: Vec<u32> = reader
                        .read_indices()
                        .ok_or_else(|| {
                            CliError::input(format!("{at}: indices accessor {} has no data", acc.index()))
                        })?
                        .into_u32()
                        .collect();
                    if let Some((i, &v)) = idx.iter().enumerate().find(|&(_, &v)| v as usize >= count) {
                        return Err(CliError::input(format!(
                            "{at}: indices accessor {} element {i} is {v}, but there are {count} vertices",
                            acc.index()
                        )));
                    }
                    idx
                }
                None => (0..count as u32).collect(),
            };
            let mut tris = assemble(mode, &indices);
            if tris.is_empty() {
                self.scene.warn(format!("{at}: has no triangles"));
                continue;
            }
            // A mirroring transform turns counter-clockwise into clockwise.
            for t in &mut tris {
                if matrix(t[0] as usize).determinant() < 0.0 {
                    t.swap(1, 2);
                }
            }

            // Without NORMAL, glTF 2.0 ("Vertex attributes") says: "client implementations MUST
            // calculate flat normals"; `--normals smooth[:ANGLE]` asks otherwise.
            let corners = match normals_in {
                Some(n) => {
                    let normal_matrices: Vec<DMat3> =
                        matrices.iter().map(|m| DMat3::from_mat4(*m).inverse().transpose()).collect();
                    let given: Vec<[f32; 3]> = n
                        .iter()
                        .enumerate()
                        .map(|(i, n)| {
                            (per_vertex(&normal_matrices, i) * DVec3::from(n.map(f64::from)))
                                .try_normalize()
                                .map_or([f32::NAN; 3], |v| v.as_vec3().to_array())
                        })
                        .collect();
                    let bad = given.iter().filter(|n| n[0].is_nan()).count();
                    let (corners, replaced) = given_corner_normals(&positions, &tris, &given);
                    if bad > 0 {
                        self.scene.warn(format!(
                            "{at}: {bad} NORMAL values are zero or not finite; the {replaced} triangle corners using them take their triangle's face normal (flat)"
                        ));
                    }
                    corners
                }
                None => corner_normals(&positions, &tris, sharing(self.normals)),
            };
            let (source, normals, tris) = split_by_normal(count, &tris, &corners);

            if self.scene.triangles.len() + tris.len() > MAX_TRIANGLES {
                return Err(CliError::input(format!(
                    "{}: the scene expands to more than {MAX_TRIANGLES} triangles",
                    self.file
                )));
            }
            let base = self.scene.vertices.len() as u32;
            self.scene.vertices.extend(
                source
                    .iter()
                    .zip(&normals)
                    .map(|(&i, n)| Vertex { position: positions[i as usize], normal: *n }),
            );
            match uvs {
                Some(uv) => self.scene.uvs.extend(source.iter().map(|&i| uv[i as usize])),
                None => self.scene.uvs.extend(std::iter::repeat_n([0.0; 2], source.len())),
            }
            self.scene
                .set_colors(base as usize, colors.map(|c| source.iter().map(|&i| c[i as usize]).collect()));
            self.scene.triangles.extend(tris.iter().map(|t| t.map(|i| i + base)));
            self.scene.triangle_materials.extend(std::iter::repeat_n(material, tris.len()));
        }
        Ok(())
    }

    fn check_count(&self, acc: &Accessor, count: usize, at: &str, what: &str) -> CliResult<()> {
        if acc.count() != count {
            return Err(CliError::input(format!(
                "{at}: {what} accessor {} has {} elements but POSITION has {count}",
                acc.index(),
                acc.count()
            )));
        }
        Ok(())
    }

    /// Checks type and byte ranges of an accessor (and its sparse parts) against the loaded
    /// buffers, so that reading it can neither fail silently nor run out of bounds.
    fn check_accessor(
        &self,
        acc: &Accessor,
        at: &str,
        what: &str,
        dims: &[Dimensions],
        types: &[DataType],
        normalized_ok: bool,
    ) -> CliResult<()> {
        let name = format!("{at}: {what} accessor {}", acc.index());
        let bad = |msg: String| Err(CliError::input(format!("{name} {msg}")));
        if !dims.contains(&acc.dimensions()) || !types.contains(&acc.data_type()) {
            return bad(format!(
                "has type {:?} {:?}, expected {dims:?} of {types:?}",
                acc.dimensions(),
                acc.data_type()
            ));
        }
        if acc.data_type() != DataType::F32 && normalized_ok && !acc.normalized() {
            return bad("is an integer type but not normalized".into());
        }
        let count = acc.count();
        if count == 0 {
            return bad("has no elements".into());
        }
        let elem = acc.size();
        self.check_range(&name, acc.view(), acc.offset(), elem, count)?;
        if acc.view().is_none() && acc.sparse().is_none() {
            return bad("has neither a buffer view nor sparse data".into());
        }
        if let Some(sparse) = acc.sparse() {
            let sc = sparse.count();
            if sc == 0 || sc > count {
                return bad(format!("has {sc} sparse elements for {count} elements"));
            }
            if acc.view().is_none() {
                // Zeros but for the sparse values: no buffer bounds `count`, so the file's size
                // bounds what the accessor may expand to (checked before anything is allocated).
                let (limit, why) = expansion_limit(self.buffers.iter().map(Vec::len).sum());
                if count.checked_mul(elem).is_none_or(|b| b > limit) {
                    return bad(format!(
                        "has no buffer view: its {count} elements of {elem} bytes would be zeros but for \
                         {sc} sparse values, more than such an accessor may expand to ({why})"
                    ));
                }
            }
            let idx = sparse.indices();
            let isize = idx.index_type().size();
            self.check_range(&format!("{name} sparse indices"), Some(idx.view()), idx.offset(), isize, sc)?;
            let vals = sparse.values();
            self.check_range(&format!("{name} sparse values"), Some(vals.view()), vals.offset(), elem, sc)?;
            // Indices must be strictly increasing and below count (glTF 2.0, 3.6.2.3).
            let view = idx.view();
            let data = &self.buffers[view.buffer().index()][view.offset()..view.offset() + view.length()];
            let stride = view.stride().unwrap_or(isize);
            let mut prev: Option<u64> = None;
            for k in 0..sc {
                let o = idx.offset() + k * stride;
                let v = match isize {
                    1 => data[o] as u64,
                    2 => u16::from_le_bytes([data[o], data[o + 1]]) as u64,
                    _ => u32::from_le_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]) as u64,
                };
                if v >= count as u64 || prev.is_some_and(|p| v <= p) {
                    return bad(format!(
                        "sparse index {k} is {v}: indices must increase and stay below {count}"
                    ));
                }
                prev = Some(v);
            }
        }
        Ok(())
    }

    fn check_range(
        &self,
        name: &str,
        view: Option<::gltf::buffer::View>,
        offset: usize,
        elem: usize,
        count: usize,
    ) -> CliResult<()> {
        let Some(view) = view else { return Ok(()) };
        let stride = view.stride().unwrap_or(elem);
        if stride < elem {
            return Err(CliError::input(format!(
                "{name}: byte stride {stride} is smaller than its {elem}-byte elements"
            )));
        }
        let need = stride
            .checked_mul(count - 1)
            .and_then(|v| v.checked_add(offset))
            .and_then(|v| v.checked_add(elem));
        if need.is_none_or(|n| n > view.length()) {
            return Err(CliError::input(format!(
                "{name}: {count} elements of {elem} bytes (stride {stride}) at offset {offset} do not fit in buffer view {} of {} bytes",
                view.index(),
                view.length()
            )));
        }
        let buf = &self.buffers[view.buffer().index()];
        if view.offset().checked_add(view.length()).is_none_or(|end| end > buf.len()) {
            return Err(CliError::input(format!(
                "{name}: buffer view {} ({} bytes at {}) runs past the end of buffer {} ({} bytes)",
                view.index(),
                view.length(),
                view.offset(),
                view.buffer().index(),
                buf.len()
            )));
        }
        Ok(())
    }

    fn add_camera(&mut self, camera: &::gltf::Camera, world: &DMat4, node: usize) {
        let name = camera.name().map_or_else(|| format!("camera{}", camera.index()), str::to_string);
        // Orthographic: (xmag, ymag), and the field of view under which a perspective camera sees
        // the same height one unit ahead (its target), for manifest-1 readers.
        let (vfov, znear, zfar, ortho) = match camera.projection() {
            ::gltf::camera::Projection::Perspective(p) => {
                (p.yfov().to_degrees(), p.znear(), p.zfar().unwrap_or(0.0), None)
            }
            ::gltf::camera::Projection::Orthographic(o) => {
                let (x, y) = (o.xmag().abs(), o.ymag().abs());
                let ok = x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0;
                if !ok {
                    self.scene.warn(format!(
                        "{}: orthographic camera '{name}' on node {node} has xmag {} and ymag {}; skipped",
                        self.file,
                        o.xmag(),
                        o.ymag()
                    ));
                    return;
                }
                ((2.0 * y.atan()).to_degrees(), o.znear(), o.zfar(), Some((x, y)))
            }
        };
        let position = world.transform_point3(DVec3::ZERO) - self.origin();
        let forward = world.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
        let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
        let cam = Camera {
            name,
            position: position.as_vec3().to_array(),
            target: (position + forward).as_vec3().to_array(),
            up: up.as_vec3().to_array(),
            vfov_degrees: vfov,
            znear,
            zfar,
        };
        let vals = [cam.position, cam.target, cam.up].concat();
        if forward == DVec3::ZERO
            || up == DVec3::ZERO
            || !vals.iter().all(|v| v.is_finite())
            || !vfov.is_finite()
        {
            self.scene.warn(format!(
                "{}: camera '{}' on node {node} has a degenerate transform; skipped",
                self.file, cam.name
            ));
            return;
        }
        if let Some((xmag, ymag)) = ortho {
            let camera = self.scene.cameras.len() as u32;
            self.scene.orthographic.push(OrthographicCamera { camera, xmag, ymag });
        }
        self.scene.cameras.push(cam);
    }

    fn add_light(
        &mut self,
        light: &::gltf::khr_lights_punctual::Light,
        world: &DMat4,
        node: usize,
    ) -> CliResult<()> {
        use ::gltf::khr_lights_punctual::Kind;
        let name = light.name().map_or_else(|| format!("light{}", light.index()), str::to_string);
        let kind = match light.kind() {
            Kind::Point => LightKind::Point,
            Kind::Directional => LightKind::Directional,
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                LightKind::Spot { inner_cone: inner_cone_angle, outer_cone: outer_cone_angle }
            }
        };
        let position = stored(world.transform_point3(DVec3::ZERO), self.origin());
        let direction = world.transform_vector3(DVec3::NEG_Z).normalize_or_zero().as_vec3().to_array();
        let l = Light {
            name,
            kind,
            position,
            direction,
            right: [0.0; 3],
            color: light.color(),
            intensity: light.intensity(),
            range: light.range().unwrap_or(0.0),
            casts_shadows: true,
        };
        let vals = [&l.position[..], &l.direction, &l.color, &[l.intensity, l.range]].concat();
        if !vals.iter().all(|v| v.is_finite()) {
            return Err(CliError::input(format!(
                "{}: light '{}' on node {node} has a non-finite value",
                self.file, l.name
            )));
        }
        if l.direction == [0.0; 3] && !matches!(l.kind, LightKind::Point) {
            self.scene.warn(format!(
                "{}: light '{}' on node {node} has no direction (degenerate transform); skipped",
                self.file, l.name
            ));
            return Ok(());
        }
        self.scene.lights.push(l);
        Ok(())
    }
}

/// How triangles without given normals share them: flat unless asked otherwise.
fn sharing(normals: Normals) -> Sharing<'static> {
    match normals {
        Normals::Asset | Normals::Flat => Sharing::Flat,
        Normals::Smooth { crease_degrees } => Sharing::Smooth(crease_degrees.map(f64::from)),
    }
}

/// Triangles from an index list in the given mode (glTF 2.0, 3.7.2.1).
fn assemble(mode: Mode, idx: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => {
            (0..idx.len().saturating_sub(2))
                .map(|i| {
                    if i % 2 == 0 {
                        [idx[i], idx[i + 1], idx[i + 2]]
                    } else {
                        [idx[i + 1], idx[i], idx[i + 2]]
                    }
                })
                .collect()
        }
        Mode::TriangleFan => (1..idx.len().saturating_sub(1)).map(|i| [idx[i], idx[i + 1], idx[0]]).collect(),
        _ => Vec::new(),
    }
}

/// Vertex `i`'s entry of `m`: one per vertex (skinned), or one for all (rigid).
fn per_vertex<T: Copy>(m: &[T], i: usize) -> T {
    m[if m.len() == 1 { 0 } else { i }]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_escaping_the_checks_is_reported_as_bad_input() {
        // The last line of defence of `import`: no known input reaches it, so it is tested here.
        let e = guard::<()>("x.gltf", || panic!("index out of bounds")).unwrap_err();
        assert_eq!(e.exit, Exit::BadInput);
        assert!(e.message.starts_with("x.gltf: malformed glTF"), "{}", e.message);
        assert!(e.message.contains("(index out of bounds)"), "{}", e.message);
        assert_eq!(guard("x.gltf", || Ok(7)).unwrap(), 7);
    }
}
