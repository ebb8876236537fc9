//! Wavefront OBJ/MTL import through `tobj`.
//!
//! A first pass over the OBJ text checks what `tobj` would reject or silently accept (face
//! references out of range, polygons with fewer than three corners, non-finite positions) and
//! reports it with its line number; then `tobj` loads the file.
//!
//! Smoothing groups (`s N`, `s off`), which `tobj` does not expose, are read in the same first
//! pass: one group per triangle, in file order (a face of n corners gives n − 2 triangles). They
//! are matched to `tobj`'s output by order: `tobj` appends each face's triangles (its own fan,
//! n − 2 of them) to the current model in file order, and starts a new model (also in file
//! order) at `o`, `g` or a `usemtl` that changes the material, so its models' triangles, read
//! model after model, are the file's triangles in file order. Where the totals disagree, normals
//! are flat and a warning says so.
//!
//! MTL → PBR rule (documented in docs/compiler.md, "OBJ/MTL"):
//! - `d` (or `1 - Tr`) is the alpha. Roughness is `Pr`, or from the Phong exponent `Ns` as
//!   `(2 / (Ns + 2))^(1/4)` (Walter et al.'s Beckmann–Phong correspondence α = √(2/(Ns+2)), with
//!   perceptual roughness √α); without either 1, or 0 for a mirror (`illum` 3 or 5).
//! - `Ks 0 0 0` (or no `Ks`) with no metalness `Pm` → **pure Lambertian diffuse** of albedo
//!   `Kd` (`map_Kd` its texture): no specular lobe at all (flag `DIFFUSE_ONLY`).
//! - No `Pm` and a specular colour that is what one sees — `Kd` black (every channel ≤ 0.04), or
//!   `illum` 3/5 with `Ks` at least as bright as `Kd` → a **metal of base colour `Ks`** (a
//!   dielectric would render black). `Kd` dropped that way gets a warning.
//! - Otherwise a GGX dielectric-or-`Pm` material of base colour `Kd`, metallic `Pm` (default 0);
//!   `Ks` only decides that a specular lobe exists (F0 = 0.04); its colour and strength are not
//!   kept (no warning: that is the reading of almost every OBJ material, and `--strict` must not
//!   fail them all).
//! - `Ke` is emitted radiance in W/(sr·m²), `map_Ke` its texture; `norm`/`map_Bump` a normal map.

use std::collections::HashMap;
use std::path::Path;

use kiln_format::manifest::Wrap;
use kiln_format::sections::{AlphaMode, GpuMaterial, MaterialFlags, NO_TEXTURE, Vertex};

use super::files::ReadError;
use super::mtl::TextureStatement;
use glam::DVec3;

use super::geometry::{
    Extent, Sharing, check_position, corner_normals, given_corner_normals, split_by_normal, stored, unorm16,
};
use super::images::{TextureRequest, decode_all};
use super::read_input;
use crate::exit::{CliError, CliResult};
use crate::ir::{Material, Scene, TextureRole};
use crate::settings::Normals;

/// Imports an `.obj` file (and the MTL files it names) into `scene`.
pub fn import(path: &Path, scene: &mut Scene, normals_mode: Normals) -> CliResult<()> {
    let file = path.display().to_string();
    let text = read_input(path, &mut scene.inputs)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let Precheck { libs: mtllibs, groups, warnings, large_faces, uses, extent } = precheck(&file, &text)?;
    // Positions are stored relative to the origin the `v` lines' extent calls for, from the
    // file's own digits: tobj reads them in double precision (its `use_f64`).
    let origin = extent.origin();
    scene.origin = origin.to_array();
    let text = if large_faces { split_large_faces(&text) } else { text };
    for w in warnings {
        scene.warn(w);
    }
    let options =
        tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    // tobj takes its material loader as `Fn`: the warnings it finds go through a RefCell.
    let mtl_warnings = std::cell::RefCell::new(Vec::new());
    // Files named outside the confinement (`files::check_confined`): the import fails.
    let escapes = std::cell::RefCell::new(Vec::new());
    let (models, materials) = tobj::load_obj_buf(&mut std::io::Cursor::new(&text), &options, |p| {
        let full = base.join(p);
        // Read within bounds, and with the statements tobj would panic on or take as NaN
        // dropped (each a warning), before tobj parses it.
        let what = format!("material library '{}'", p.display());
        let bytes = super::files::read_referenced(&what, &full).map_err(|e| {
            match e {
                ReadError::Confined(e) => escapes.borrow_mut().push(e),
                ReadError::Unreadable(e) => mtl_warnings.borrow_mut().push(format!("{file}: {e}")),
            }
            tobj::LoadError::OpenFileFailed
        })?;
        let text = super::mtl::sanitize(
            &full.display().to_string(),
            &String::from_utf8_lossy(&bytes),
            &mut mtl_warnings.borrow_mut(),
        );
        tobj::load_mtl_buf(&mut std::io::Cursor::new(text.as_bytes()))
    })
    .map_err(|e| CliError::input(format!("{file}: cannot read OBJ: {e}")))?;
    let mut escapes = escapes.into_inner();
    for w in mtl_warnings.into_inner() {
        scene.warn(w);
    }
    for lib in &mtllibs {
        let full = base.join(lib);
        if full.is_file() && !scene.inputs.contains(&full) {
            scene.inputs.push(full);
        }
    }
    let loaded = materials.is_ok();
    let materials = match materials {
        Ok(m) => m,
        Err(e) => {
            let which = if mtllibs.is_empty() {
                "names no material library".to_string()
            } else {
                format!("material library {} cannot be read ({e})", mtllibs.join(", "))
            };
            scene.warn(format!("{file}: {which}; every face gets the default material"));
            Vec::new()
        }
    };

    // A name no library defines: tobj gives its faces no material (the default), silently. (A
    // library that could not be read has its own warning.)
    if loaded {
        for (line, name) in uses.iter().filter(|(_, n)| !materials.iter().any(|m| &m.name == n)) {
            scene.warn(format!(
                "{file}:{line}: usemtl '{name}' names no material of {}; its faces get the default material",
                mtllibs.join(", ")
            ));
        }
    }
    let mut requests: Vec<TextureRequest> = Vec::new();
    let mut tex_cache: HashMap<(String, TextureRole, bool), u32> = HashMap::new();
    let first_material = scene.materials.len() as u32;
    let mtl_base = |name: &str| base.join(name);
    let mut material_warnings = Vec::new();
    let mut texture_warnings = Vec::new();
    for m in &materials {
        let mut warnings = Vec::new();
        let gpu = convert_material(
            m,
            &mut |statement: &TextureStatement, role| {
                let (name, wrap) = (statement.name.as_str(), statement.wrap);
                if let Some(&i) = tex_cache.get(&(name.to_string(), role, wrap == Wrap::ClampToEdge)) {
                    return i;
                }
                let mut full = mtl_base(name);
                if !full.exists() {
                    // Written on Windows (backslashes) or on a file system that ignores case.
                    if let Some(found) = super::files::resolve_case_insensitive(&base, name) {
                        texture_warnings.push(format!(
                            "{file}: texture '{name}' is not there as written; using {}",
                            found.display()
                        ));
                        full = found;
                    }
                }
                let bytes = super::files::read_referenced(&format!("texture '{name}'"), &full).map_err(|e| {
                    if let ReadError::Confined(e) = &e {
                        escapes.push(e.clone());
                    }
                    e.to_string()
                });
                if bytes.is_ok() && !scene.inputs.contains(&full) {
                    scene.inputs.push(full.clone());
                }
                let i = (scene.textures.len() + requests.len()) as u32;
                requests.push(TextureRequest {
                    name: name.to_string(),
                    bytes,
                    role,
                    wrap_u: wrap,
                    wrap_v: wrap,
                    mag_linear: true,
                });
                tex_cache.insert((name.to_string(), role, wrap == Wrap::ClampToEdge), i);
                i
            },
            &mut warnings,
        );
        material_warnings.extend(warnings.into_iter().map(|w| format!("{file}: material '{}': {w}", m.name)));
        scene.materials.push(Material { name: m.name.clone(), gpu });
    }
    if !escapes.is_empty() {
        return Err(CliError::input(format!("{file}: {}", escapes.join("; "))));
    }
    for w in material_warnings.into_iter().chain(texture_warnings) {
        scene.warn(w);
    }
    let mut default_material: Option<u32> = None;
    let tobj_triangles: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    let groups = if tobj_triangles == groups.len() {
        groups
    } else {
        if normals_mode == Normals::Asset {
            scene.warn(format!(
                "{file}: {} triangles read, {tobj_triangles} loaded: smoothing groups cannot be matched to faces; normals not given are flat",
                groups.len()
            ));
        }
        vec![0; tobj_triangles]
    };
    // The next model's first triangle in `groups`.
    let mut next_triangle = 0;

    for model in &models {
        let mesh = &model.mesh;
        let at = format!("{file}: object '{}'", model.name);
        let positions: Vec<[f32; 3]> =
            mesh.positions.chunks_exact(3).map(|p| stored(DVec3::new(p[0], p[1], p[2]), origin)).collect();
        for (i, p) in positions.iter().enumerate() {
            check_position(*p, || format!("{at}: vertex {i}"))?;
        }
        let tris: Vec<[u32; 3]> = mesh.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        let tri_groups = &groups[next_triangle..next_triangle + tris.len()];
        next_triangle += tris.len();
        if tris.is_empty() {
            continue;
        }
        let corners = if mesh.normals.len() == mesh.positions.len() {
            let given: Vec<[f32; 3]> = mesh
                .normals
                .chunks_exact(3)
                .map(|n| {
                    DVec3::new(n[0], n[1], n[2])
                        .try_normalize()
                        .map_or([f32::NAN; 3], |v| v.as_vec3().to_array())
                })
                .collect();
            let (corners, replaced) = given_corner_normals(&positions, &tris, &given);
            if replaced > 0 {
                scene.warn(format!(
                    "{at}: {replaced} triangle corners have a zero or non-finite normal (vn); they take their triangle's face normal (flat)"
                ));
            }
            corners
        } else {
            let sharing = match normals_mode {
                Normals::Asset => Sharing::Groups(tri_groups),
                Normals::Flat => Sharing::Flat,
                Normals::Smooth { crease_degrees } => Sharing::Smooth(crease_degrees.map(f64::from)),
            };
            corner_normals(&positions, &tris, sharing)
        };
        let (source, normals, tris) = split_by_normal(positions.len(), &tris, &corners);
        // OBJ's v runs up the image; kiln (like glTF) stores v running down.
        let uvs: Vec<[f32; 2]> = if mesh.texcoords.len() / 2 == positions.len() {
            mesh.texcoords.chunks_exact(2).map(|t| [t[0] as f32, (1.0 - t[1]) as f32]).collect()
        } else {
            vec![[0.0; 2]; positions.len()]
        };
        if let Some(i) = uvs.iter().position(|uv| !uv.iter().all(|c| c.is_finite())) {
            return Err(CliError::input(format!("{at}: texture coordinate {i} is not finite")));
        }
        let material = match mesh.material_id {
            Some(id) if id < materials.len() => first_material + id as u32,
            _ => *default_material.get_or_insert_with(|| {
                scene.materials.push(Material { name: "default".into(), gpu: lambert([0.8; 3]) });
                scene.materials.len() as u32 - 1
            }),
        };
        let base_index = scene.vertices.len() as u32;
        scene.vertices.extend(
            source.iter().zip(&normals).map(|(&i, n)| Vertex { position: positions[i as usize], normal: *n }),
        );
        scene.uvs.extend(source.iter().map(|&i| uvs[i as usize]));
        // The `v x y z r g b` extension (MeshLab, ZBrush), read as linear like glTF's COLOR_0.
        let colors = (mesh.vertex_color.len() == 3 * positions.len())
            .then(|| {
                let rgb: Vec<[u16; 4]> = mesh
                    .vertex_color
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2], 1.0].map(|c| unorm16(c as f32)))
                    .collect();
                if mesh.vertex_color.iter().any(|c| !c.is_finite()) {
                    return Err(CliError::input(format!("{at}: a vertex colour is not finite")));
                }
                Ok(source.iter().map(|&i| rgb[i as usize]).collect())
            })
            .transpose()?;
        scene.set_colors(base_index as usize, colors);
        scene.triangles.extend(tris.iter().map(|t| t.map(|i| i + base_index)));
        scene.triangle_materials.extend(std::iter::repeat_n(material, tris.len()));
    }
    let (textures, warnings) = decode_all(requests);
    for w in warnings {
        scene.warn(format!("{file}: {w}"));
    }
    scene.textures.extend(textures);
    Ok(())
}

/// A pure Lambertian material with albedo `kd`.
pub(crate) fn lambert(kd: [f32; 3]) -> GpuMaterial {
    GpuMaterial {
        base_color: [kd[0], kd[1], kd[2], 1.0],
        metallic: 0.0,
        roughness: 1.0,
        flags: MaterialFlags::DIFFUSE_ONLY,
        ..GpuMaterial::default()
    }
}

fn param(m: &tobj::Material, key: &str) -> Option<f32> {
    m.unknown_param.get(key).and_then(|v| v.split_whitespace().next()?.parse().ok())
}

/// Largest channel at or below which a diffuse colour (`Kd`) counts as black, and above which a
/// specular colour (`Ks`) counts as significant: 4 %, about the darkest real diffuse albedos
/// (charcoal, fresh asphalt) and the normal-incidence reflectance of common dielectrics.
const NEAR_BLACK: f32 = 0.04;

fn max3(c: [f32; 3]) -> f32 {
    c[0].max(c[1]).max(c[2])
}

/// The MTL → PBR rule (module documentation and docs/compiler.md). Warnings where the mapping drops
/// information go to `warnings`.
fn convert_material(
    m: &tobj::Material,
    texture: &mut dyn FnMut(&TextureStatement, TextureRole) -> u32,
    warnings: &mut Vec<String>,
) -> GpuMaterial {
    // tobj reads MTL in double precision (its `use_f64`, for the OBJ's positions); kiln's
    // materials are single.
    let f3 = |c: Option<[f64; 3]>| c.map(|c| c.map(|v| v as f32));
    let kd = f3(m.diffuse).unwrap_or([0.8; 3]);
    let ks = f3(m.specular).unwrap_or([0.0; 3]);
    let metallic = param(m, "Pm");
    let alpha = m
        .dissolve
        .map(|d| d as f32)
        .or_else(|| param(m, "Tr").map(|t| 1.0 - t))
        .unwrap_or(1.0)
        .clamp(0.0, 1.0);
    // `illum` 3 and 5 turn on ray-traced reflection (5 with Fresnel): a mirror.
    let mirror = matches!(m.illumination_model, Some(3 | 5));
    // Roughness: `Pr`, or from the Phong exponent `Ns`; without either 1, or 0 for a mirror.
    let roughness = param(m, "Pr")
        .unwrap_or_else(|| match m.shininess {
            Some(ns) => (2.0 / (ns.max(0.0) + 2.0)).powf(0.25) as f32,
            None if mirror => 0.0,
            None => 1.0,
        })
        .clamp(0.0, 1.0);
    let (kd_max, ks_max) = (max3(kd), max3(ks));
    let mut gpu = if ks == [0.0; 3] && metallic.is_none_or(|v| v == 0.0) {
        lambert(kd)
    } else if metallic.is_none() && ks != [0.0; 3] && (kd_max <= NEAR_BLACK || (mirror && ks_max >= kd_max)) {
        // The specular colour is what is seen: a metal of colour Ks (a dielectric of base
        // colour Kd would be black).
        if kd_max > NEAR_BLACK {
            warnings.push(format!(
                "Kd {kd:?} is dropped: illum {} with Ks {ks:?} at least as bright makes it a metal of colour Ks, which has no diffuse lobe",
                m.illumination_model.unwrap_or(0)
            ));
        }
        GpuMaterial {
            base_color: [ks[0], ks[1], ks[2], 1.0],
            metallic: 1.0,
            roughness,
            ..GpuMaterial::default()
        }
    } else {
        // Ks then only decides that a specular lobe exists (F0 0.04): its colour and strength
        // are not kept, without a warning — that is the usual reading of most OBJ materials
        // (Kd 0.8, Ks 0.5), and warning on each would fail every such file under --strict.
        GpuMaterial {
            base_color: [kd[0], kd[1], kd[2], 1.0],
            metallic: metallic.unwrap_or(0.0).clamp(0.0, 1.0),
            roughness,
            ..GpuMaterial::default()
        }
    };
    gpu.base_color[3] = alpha;
    if alpha < 1.0 {
        gpu.flags |= (AlphaMode::Blend as u32) << MaterialFlags::ALPHA_MODE_SHIFT;
    }
    gpu.emission = f3(m.emissive).unwrap_or([0.0; 3]);
    // The statement's options read, and those kiln does not apply warned about.
    let mut statement = |key: &str, value: &str| {
        let t = TextureStatement::parse(value);
        warnings.extend(t.ignored.iter().map(|why| format!("{key} {}: {why}", t.name)));
        t
    };
    if let Some(t) = &m.diffuse_texture {
        gpu.base_color_texture = texture(&statement("map_Kd", t), TextureRole::Color);
    }
    if let Some(t) = m.unknown_param.get("map_Ke") {
        gpu.emissive_texture = texture(&statement("map_Ke", t), TextureRole::Color);
        if gpu.emission == [0.0; 3] {
            gpu.emission = [1.0; 3];
        }
    }
    // `bump`/`map_Bump` (tobj's normal texture) or `norm`: kiln reads either as a tangent-space
    // normal map.
    if let Some((key, t)) = m
        .normal_texture
        .as_ref()
        .map(|t| ("bump", t))
        .or_else(|| m.unknown_param.get("norm").map(|t| ("norm", t)))
    {
        gpu.normal_texture = texture(&statement(key, t), TextureRole::Normal);
    }
    // Maps kiln's materials have no slot for (`map_Ka` is ambient, which physically based
    // shading replaces by the light itself: not worth a warning).
    let unused = [
        ("map_Ks", m.specular_texture.as_ref()),
        ("map_Ns", m.shininess_texture.as_ref()),
        ("map_d", m.dissolve_texture.as_ref()),
    ];
    for (key, t) in unused.into_iter().filter_map(|(k, t)| Some((k, t?))) {
        warnings.push(format!("{key} {t} is not applied (kiln's materials have no slot for it)"));
    }
    for key in ["disp", "decal", "refl"] {
        if let Some(t) = m.unknown_param.get(key) {
            warnings.push(format!("{key} {t} is not applied (kiln's materials have no slot for it)"));
        }
    }
    // Non-finite MTL values are replaced by defaults here; the validator would refuse them.
    for v in gpu.base_color.iter_mut().chain(gpu.emission.iter_mut()) {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    debug_assert!(gpu.textures().iter().all(|&t| t == NO_TEXTURE || t < u32::MAX));
    gpu
}

/// What the first pass over the OBJ text finds besides errors.
struct Precheck {
    /// `mtllib` names.
    libs: Vec<String>,
    /// Smoothing group of each triangle in file order (a face of n corners gives n − 2): `0` for
    /// `s off`, `s 0` or no `s` statement yet.
    groups: Vec<u32>,
    /// Warnings, with line numbers.
    warnings: Vec<String>,
    /// Whether a face has more than [`FAN_LIMIT`] corners.
    large_faces: bool,
    /// Each material name `usemtl` names, with the line it is first named on.
    uses: Vec<(usize, String)>,
    /// Extent of the `v` positions, in double precision.
    extent: Extent,
}

/// Corners beyond which a face is not fanned (by tobj) but split by halving (here). A fan of
/// 100,000 corners is 100,000 slivers through one corner, every box overlapping the next: the
/// BVH builder (PLOC) merges one pair per pass over them, quadratic time and a tree as deep as
/// the face is wide (a minute, then a stack overflow). Halving gives the same n − 2 triangles,
/// most of them between neighbouring corners, in the same winding.
const FAN_LIMIT: usize = 64;

/// The statements of `text` with the number of the line each starts on: lines ending in a
/// backslash continue on the next one (joined with a space).
fn logical_lines(text: &str) -> impl Iterator<Item = (usize, String)> + '_ {
    let mut logical = String::new();
    let mut first_line = 0;
    text.lines().enumerate().filter_map(move |(i, raw)| {
        if logical.is_empty() {
            first_line = i + 1;
        }
        if let Some(stripped) = raw.strip_suffix('\\') {
            logical.push_str(stripped);
            logical.push(' ');
            return None;
        }
        logical.push_str(raw);
        Some((first_line, std::mem::take(&mut logical)))
    })
}

/// `text` with every face of more than [`FAN_LIMIT`] corners written as the triangles of its
/// halving: the chain of corners a..=b (first the whole face, closed by its last edge) gives the
/// triangle (a, m, b) at its middle m, then the chains a..=m and m..=b. Linear in the corners.
/// Other lines are kept (continued lines joined); relative references stay valid, as no vertex
/// comes between.
fn split_large_faces(text: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(text);
    let mut out = String::with_capacity(text.len() * 2);
    for (_, line) in logical_lines(&text) {
        let body = line.split('#').next().unwrap_or("");
        let mut words = body.split_whitespace();
        let corners: Vec<&str> = if words.next() == Some("f") { words.collect() } else { Vec::new() };
        if corners.len() <= FAN_LIMIT {
            out.push_str(&line);
            out.push('\n');
            continue;
        }
        let mut chains = vec![(0, corners.len() - 1)];
        while let Some((a, b)) = chains.pop() {
            if b - a < 2 {
                continue;
            }
            let m = (a + b) / 2;
            out.push_str(&format!("f {} {} {}\n", corners[a], corners[m], corners[b]));
            chains.push((m, b));
            chains.push((a, m));
        }
    }
    out.into_bytes()
}

/// Checks face references and positions line by line; reads `mtllib` names and smoothing
/// groups.
fn precheck(file: &str, text: &[u8]) -> CliResult<Precheck> {
    let text = String::from_utf8_lossy(text);
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    let mut libs = Vec::new();
    let mut faces = 0u64;
    let mut large_faces = false;
    let mut uses: Vec<(usize, String)> = Vec::new();
    // The names in `uses`: a file may name many materials many times.
    let mut used = std::collections::HashSet::new();
    let (mut group, mut groups, mut warnings) = (0u32, Vec::new(), Vec::new());
    let mut extent = Extent::default();
    for (first_line, line) in logical_lines(&text) {
        let line = line.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        let at = |msg: String| CliError::input(format!("{file}:{first_line}: {msg}"));
        match words.next() {
            Some("v") => {
                nv += 1;
                let vals: Vec<f64> = words.take(3).map(|w| w.parse::<f64>().unwrap_or(f64::NAN)).collect();
                if vals.len() < 3 || vals.iter().any(|v| !v.is_finite()) {
                    return Err(at(format!("vertex position '{}' is not three finite numbers", line.trim())));
                }
                check_position([vals[0] as f32, vals[1] as f32, vals[2] as f32], || {
                    format!("{file}:{first_line}: vertex position")
                })?;
                extent.add(DVec3::new(vals[0], vals[1], vals[2]));
            }
            Some("vt") => nt += 1,
            Some("vn") => nn += 1,
            Some("mtllib") => libs.extend(words.map(str::to_string)),
            Some("usemtl") => {
                let name = words.collect::<Vec<_>>().join(" ");
                if used.insert(name.clone()) {
                    uses.push((first_line, name));
                }
            }
            Some("s") => {
                group = match words.next() {
                    Some("off") => 0,
                    Some(w) if w.parse::<u32>().is_ok() => w.parse().unwrap_or(0),
                    other => {
                        warnings.push(format!(
                            "{file}:{first_line}: smoothing group '{}' is neither a number nor 'off'; read as off (flat)",
                            other.unwrap_or("")
                        ));
                        0
                    }
                };
            }
            Some("f") => {
                faces += 1;
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(at(format!("face has {} vertices; a face needs at least 3", corners.len())));
                }
                groups.extend(std::iter::repeat_n(group, corners.len() - 2));
                large_faces |= corners.len() > FAN_LIMIT;
                for (k, c) in corners.iter().enumerate() {
                    for (slot, (part, count, what)) in c
                        .split('/')
                        .zip([(nv, "position"), (nt, "texture coordinate"), (nn, "normal")])
                        .map(|(p, (n, w))| (p, n, w))
                        .enumerate()
                    {
                        if part.is_empty() && slot > 0 {
                            continue;
                        }
                        let idx: i64 = part.parse().map_err(|_| {
                            at(format!("face vertex {} '{c}' is not a valid reference", k + 1))
                        })?;
                        let resolved = if idx < 0 { count + 1 + idx } else { idx };
                        if idx == 0 || resolved < 1 || resolved > count {
                            return Err(at(format!(
                                "face vertex {} refers to {what} {idx}, but only {count} are defined before this line",
                                k + 1
                            )));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    if faces == 0 {
        return Err(CliError::input(format!("{file}: has no faces")));
    }
    Ok(Precheck { libs, groups, warnings, large_faces, uses, extent })
}
