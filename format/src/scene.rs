//! A validated view of a file's scene sections: every cross-reference checked once, so that
//! the player and the queries can index without further checks.

use std::borrow::Cow;

use crate::error::{FormatError, Result};
use crate::manifest::{ColorSpace, LightKind, Manifest};
use crate::read::KilnFile;
use crate::sections::{
    BRDF_LUT, BVH_NODES, BVH_TRAVERSAL_STACK, COLORS, CwbvhNode, GpuMaterial, GpuMaterialV1, GpuMaterialV2,
    MATERIALS, MEDIA_VISIBILITY, MaterialFlags, NO_TEXTURE, SHADOW_MAP, TEXTURE, TRIANGLE_MATERIALS,
    TRIANGLES, TextureData, UVS, VERTICES, Vertex, decode_texture, possible_v2_lengths,
};

/// Borrowed, validated scene data of a [`KilnFile`].
#[derive(Debug)]
pub struct SceneView<'a> {
    /// The decoded manifest.
    pub manifest: Manifest,
    /// Vertices (empty if the file has no geometry).
    pub vertices: &'a [Vertex],
    /// Texture coordinates per vertex (empty when no material samples a texture).
    pub uvs: &'a [[f32; 2]],
    /// Vertex colours, unorm16 linear RGBA per vertex (empty: every vertex white).
    pub colors: &'a [[u16; 4]],
    /// Triangles as vertex index triples, in BVH leaf order.
    pub triangles: &'a [[u32; 3]],
    /// Material of each triangle.
    pub triangle_materials: &'a [u32],
    /// Materials: borrowed from a version 3 `MATL`, converted from versions 1 and 2 (no clear coat,
    /// no transmission).
    pub materials: Cow<'a, [GpuMaterial]>,
    /// BVH nodes (empty if the file has no BVH).
    pub bvh: &'a [CwbvhNode],
    /// The file, for sections read on demand (textures).
    file: &'a KilnFile,
}

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl<'a> SceneView<'a> {
    /// Reads and validates the scene sections of `file`.
    pub fn new(file: &'a KilnFile) -> Result<SceneView<'a>> {
        let manifest = file.manifest()?;
        let vertices: &[Vertex] = file.pod(VERTICES, 0)?.unwrap_or(&[]);
        let uvs: &[[f32; 2]] = file.pod(UVS, 0)?.unwrap_or(&[]);
        let colors: &[[u16; 4]] = file.pod(COLORS, 0)?.unwrap_or(&[]);
        let triangles: &[[u32; 3]] = file.pod(TRIANGLES, 0)?.unwrap_or(&[]);
        let triangle_materials: &[u32] = file.pod(TRIANGLE_MATERIALS, 0)?.unwrap_or(&[]);
        let materials: Cow<'a, [GpuMaterial]> = match file.find(MATERIALS, 0).map(|s| s.entry.version) {
            Some(1) => {
                let old: &[GpuMaterialV1] = file.pod(MATERIALS, 0)?.unwrap_or(&[]);
                old.iter().map(|m| GpuMaterial::from_words(&m.words)).collect::<Vec<_>>().into()
            }
            Some(2) => {
                let old: &[GpuMaterialV2] = file.pod(MATERIALS, 0)?.unwrap_or(&[]);
                old.iter().map(|m| GpuMaterial::from_words(&m.words)).collect::<Vec<_>>().into()
            }
            _ => file.pod(MATERIALS, 0)?.unwrap_or(&[]).into(),
        };
        let bvh: &[CwbvhNode] = file.pod(BVH_NODES, 0)?.unwrap_or(&[]);
        // Texture sizes are checked here from the table; their bytes (the bulk of most files)
        // are checksummed when first read, through `texture`.
        for (i, info) in manifest.textures.iter().enumerate() {
            let s = file.find(TEXTURE, i as u32).ok_or_else(|| {
                FormatError::invalid(format!(
                    "manifest lists texture {i} ('{}') but no texture#{i} section exists",
                    info.name
                ))
            })?;
            let impossible = || {
                FormatError::invalid(format!(
                    "texture {i} has impossible dimensions {}x{} with {} mip levels",
                    info.width, info.height, info.mip_levels
                ))
            };
            // Version 1 is bare RGBA8; version 2's exact length depends on the format in its
            // header (read with the bytes, in `texture`), so here it must be one of the lengths
            // some format gives.
            let fits = match s.entry.version {
                1 => {
                    let expected =
                        mip_chain_bytes(info.width, info.height, info.mip_levels).ok_or_else(impossible)?;
                    s.entry.raw_size == expected
                }
                _ => {
                    let lengths = possible_v2_lengths(info.width, info.height, info.mip_levels);
                    if lengths.is_empty() {
                        return Err(impossible());
                    }
                    lengths.contains(&s.entry.raw_size)
                }
            };
            if !fits {
                return Err(FormatError::invalid(format!(
                    "texture {i} is {} bytes, which no {}x{} mip chain of a version-{} texture section has",
                    s.entry.raw_size, info.width, info.height, s.entry.version
                ))
                .in_section(s.position, TEXTURE, i as u32));
            }
        }
        if file.all_of(TEXTURE).len() != manifest.textures.len() {
            return Err(FormatError::invalid(format!(
                "{} texture sections but the manifest lists {} textures",
                file.all_of(TEXTURE).len(),
                manifest.textures.len()
            )));
        }
        let view = SceneView {
            manifest,
            vertices,
            uvs,
            colors,
            triangles,
            triangle_materials,
            materials,
            bvh,
            file,
        };
        view.check_geometry()?;
        view.check_materials()?;
        view.check_manifest()?;
        view.check_bvh()?;
        view.check_lighting()?;
        Ok(view)
    }

    /// The mean emitted luminance of each triangle (`EMLU`), when the file has it.
    pub fn emitter_luminance(&self) -> Result<Option<&'a [f32]>> {
        self.file.pod(crate::sections::EMITTER_LUMINANCE, 0)
    }

    /// Texels of texture `i` (its mip chain, level 0 first, with its pixel format and swizzle),
    /// checksummed and checked against the manifest on first access.
    pub fn texture(&self, i: usize) -> Result<TextureData<'a>> {
        let missing = || {
            FormatError::invalid(format!(
                "texture {i} does not exist ({} textures)",
                self.manifest.textures.len()
            ))
        };
        let info = self.manifest.textures.get(i).ok_or_else(missing)?;
        let s = self.file.find(TEXTURE, i as u32).ok_or_else(missing)?;
        let words: &'a [u32] = self.file.pod(TEXTURE, i as u32)?.ok_or_else(missing)?;
        decode_texture(
            s.entry.version,
            bytemuck::cast_slice(words),
            info.width,
            info.height,
            info.mip_levels,
            info.color_space == ColorSpace::Srgb,
        )
        .map_err(|e| e.in_section(s.position, TEXTURE, i as u32).or_offset(s.entry.offset))
    }

    fn check_geometry(&self) -> Result<()> {
        let nv = self.vertices.len() as u64;
        if self.triangle_materials.len() != self.triangles.len() {
            return Err(FormatError::invalid(format!(
                "{} triangles but {} triangle materials",
                self.triangles.len(),
                self.triangle_materials.len()
            )));
        }
        if let Some((i, v)) =
            self.vertices.iter().enumerate().find(|(_, v)| !finite(&v.position) || !finite(&v.normal))
        {
            return Err(FormatError::invalid(format!("vertex {i} has a non-finite value: {v:?}")));
        }
        if !self.uvs.is_empty() && self.uvs.len() != self.vertices.len() {
            return Err(FormatError::invalid(format!(
                "{} texture coordinates for {} vertices",
                self.uvs.len(),
                self.vertices.len()
            )));
        }
        if !self.colors.is_empty() && self.colors.len() != self.vertices.len() {
            return Err(FormatError::invalid(format!(
                "{} vertex colours for {} vertices",
                self.colors.len(),
                self.vertices.len()
            )));
        }
        if let Some(i) = self.uvs.iter().position(|uv| !finite(uv)) {
            return Err(FormatError::invalid(format!("texture coordinate {i} is not finite")));
        }
        let textured = self.materials.iter().any(|m| m.textures().iter().any(|&t| t != NO_TEXTURE));
        if textured && self.uvs.is_empty() && !self.vertices.is_empty() {
            return Err(FormatError::invalid(
                "materials sample textures but the file has no texture coordinates",
            ));
        }
        if let Some((i, t)) =
            self.triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&x| x as u64 >= nv))
        {
            return Err(FormatError::invalid(format!(
                "triangle {i} uses vertex indices {t:?} but there are {nv} vertices"
            )));
        }
        let nm = self.materials.len() as u64;
        if let Some((i, m)) = self.triangle_materials.iter().enumerate().find(|&(_, &m)| m as u64 >= nm) {
            return Err(FormatError::invalid(format!(
                "triangle {i} uses material {m} but there are {nm} materials"
            )));
        }
        Ok(())
    }

    fn check_materials(&self) -> Result<()> {
        if self.materials.len() != self.manifest.materials.len() {
            return Err(FormatError::invalid(format!(
                "{} materials but the manifest names {}",
                self.materials.len(),
                self.manifest.materials.len()
            )));
        }
        let nt = self.manifest.textures.len() as u64;
        for (i, m) in self.materials.iter().enumerate() {
            let scalars = [
                m.metallic,
                m.roughness,
                m.alpha_cutoff,
                m.normal_scale,
                m.occlusion_strength,
                m.clearcoat,
                m.clearcoat_roughness,
                m.transmission,
            ];
            if !finite(&m.base_color) || !finite(&m.emission) || !finite(&scalars) {
                return Err(FormatError::invalid(format!("material {i} has a non-finite parameter")));
            }
            if let Some(t) = m.textures().into_iter().find(|&t| t != NO_TEXTURE && t as u64 >= nt) {
                return Err(FormatError::invalid(format!(
                    "material {i} uses texture {t} but there are {nt} textures"
                )));
            }
            if m.flags & !MaterialFlags::ALL != 0 || m.alpha_mode().is_none() {
                return Err(FormatError::invalid(format!(
                    "material {i} has undefined flag bits {:#x}",
                    m.flags
                )));
            }
            let (f0, f90) = m.dielectric();
            let unit = |v: &f32| (0.0..=1.0).contains(v);
            if (m.flags & MaterialFlags::SPECULAR == 0 && m.specular != [0; 2])
                || !f0.iter().chain([&f90]).all(unit)
            {
                return Err(FormatError::invalid(format!(
                    "material {i}'s dielectric reflectance is not four halves in [0, 1] (F0 {f0:?}, F90 {f90})"
                )));
            }
            if !unit(&m.clearcoat) || !unit(&m.clearcoat_roughness) {
                return Err(FormatError::invalid(format!(
                    "material {i}'s clear coat {} or its roughness {} is outside [0, 1]",
                    m.clearcoat, m.clearcoat_roughness
                )));
            }
            if !unit(&m.transmission) || m.reserved != [0; 2] {
                return Err(FormatError::invalid(format!(
                    "material {i}'s transmission {} is outside [0, 1] or its reserved words {:?} are not zero",
                    m.transmission, m.reserved
                )));
            }
        }
        Ok(())
    }

    fn check_manifest(&self) -> Result<()> {
        let m = &self.manifest;
        if !finite(&m.bounds.min) || !finite(&m.bounds.max) {
            return Err(FormatError::invalid("scene bounds are not finite"));
        }
        for (i, l) in m.lights.iter().enumerate() {
            let extra = match l.kind {
                LightKind::Spot { inner_cone, outer_cone } => vec![inner_cone, outer_cone],
                LightKind::Rect { width, height } => vec![width, height],
                _ => vec![],
            };
            if ![&l.position[..], &l.direction, &l.right, &l.color, &[l.intensity, l.range], &extra]
                .iter()
                .all(|v| finite(v))
            {
                return Err(FormatError::invalid(format!("light {i} ('{}') has a non-finite value", l.name)));
            }
        }
        for (i, c) in m.cameras.iter().enumerate() {
            if ![&c.position[..], &c.target, &c.up, &[c.vfov_degrees, c.znear, c.zfar]]
                .iter()
                .all(|v| finite(v))
            {
                return Err(FormatError::invalid(format!(
                    "camera {i} ('{}') has a non-finite value",
                    c.name
                )));
            }
        }
        for (k, o) in m.orthographic.iter().enumerate() {
            if o.camera as usize >= m.cameras.len()
                || m.orthographic[..k].iter().any(|p| p.camera == o.camera)
            {
                return Err(FormatError::invalid(format!(
                    "orthographic entry {k} names camera {} ({} cameras, each at most once)",
                    o.camera,
                    m.cameras.len()
                )));
            }
            if !(o.xmag.is_finite() && o.ymag.is_finite() && o.xmag > 0.0 && o.ymag > 0.0) {
                return Err(FormatError::invalid(format!(
                    "orthographic camera {} has extents {} × {}, not positive and finite",
                    o.camera, o.xmag, o.ymag
                )));
            }
        }
        Ok(())
    }

    /// Checks the BRDF table, shadow maps and light-visibility volumes against their manifest
    /// records.
    fn check_lighting(&self) -> Result<()> {
        let m = &self.manifest;
        let file = self.file;
        match (&m.brdf_lut, file.find(BRDF_LUT, 0)) {
            (None, None) => {}
            (Some(info), Some(_)) => {
                // The length against the record before decoding; then only a zero size is left.
                let want = info.resolution as u64 * info.resolution as u64;
                file.pod_exact::<[u16; 2]>(BRDF_LUT, 0, want, "BRDF table")?;
                if info.resolution == 0 {
                    return Err(FormatError::invalid("BRDF table of 0 texels, manifest says 0x0"));
                }
            }
            _ => return Err(FormatError::invalid("BRDF table and its manifest record must come together")),
        }
        if file.all_of(SHADOW_MAP).len() != m.shadow_maps.len() {
            return Err(FormatError::invalid(format!(
                "{} shadow-map sections but the manifest lists {}",
                file.all_of(SHADOW_MAP).len(),
                m.shadow_maps.len()
            )));
        }
        for (i, info) in m.shadow_maps.iter().enumerate() {
            // The length against the record (`depth_count`) before decoding.
            let depths: &[f32] = file
                .pod_exact(SHADOW_MAP, i as u32, info.depth_count(), &format!("shadow map {i}"))?
                .ok_or_else(|| FormatError::invalid(format!("shadow map {i} is missing")))?;
            let n = info.resolution;
            if info.light as usize >= m.lights.len() || n == 0 {
                return Err(FormatError::invalid(format!(
                    "shadow map {i}: light {} of {}, {} depths for {n}x{n}",
                    info.light,
                    m.lights.len(),
                    depths.len()
                )));
            }
            let numbers =
                [&info.view_proj[..], &info.origin, &info.direction, &[info.near, info.far, info.texel]]
                    .concat();
            if !finite(&numbers) || depths.iter().any(|d| !(*d >= 0.0)) {
                return Err(FormatError::invalid(format!(
                    "shadow map {i} has a non-finite parameter or a negative or NaN depth"
                )));
            }
        }
        crate::probes::ProbeVolume::read(file)?;
        crate::environment::Environment::read(file)?;
        if let Some(l) = self.emitter_luminance()? {
            if l.len() != self.triangles.len() {
                return Err(FormatError::invalid(format!(
                    "emitter-luminance holds {} values for {} triangles",
                    l.len(),
                    self.triangles.len()
                )));
            }
            if let Some(t) = l.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(FormatError::invalid(format!(
                    "emitter-luminance: triangle {t}'s value is negative or not finite"
                )));
            }
        }
        let volumes = file.all_of(MEDIA_VISIBILITY).len();
        match &m.media_visibility {
            None if volumes == 0 => {}
            None => return Err(FormatError::invalid("light-visibility volumes without a manifest record")),
            Some(v) => {
                let cells = v.cells();
                if v.medium as usize >= m.media.len() || v.dims.contains(&0) || volumes != v.lights.len() {
                    return Err(FormatError::invalid(format!(
                        "light-visibility volume: medium {} of {}, dims {:?}, {volumes} sections for {} lights",
                        v.medium,
                        m.media.len(),
                        v.dims,
                        v.lights.len()
                    )));
                }
                let sky = v.sky_index();
                for (i, &l) in v.lights.iter().enumerate() {
                    // The length against the record before decoding.
                    let what = format!("light-visibility volume {i}");
                    file.pod_exact::<u8>(MEDIA_VISIBILITY, i as u32, cells, &what)?
                        .ok_or_else(|| FormatError::invalid(format!("{what} is missing")))?;
                    // The sky's three entries, consecutive and red first: no light's index.
                    let of_sky = sky.is_some_and(|s| (s..s + 3).contains(&i));
                    if l as usize >= m.lights.len() && !of_sky {
                        return Err(FormatError::invalid(format!(
                            "light-visibility volume {i}: light {l} of {}",
                            m.lights.len()
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Checks that the BVH is a tree over exactly the triangles: every node reached once, child
    /// and triangle ranges in bounds, every triangle in exactly one leaf, depth within the
    /// traversal stack; and that its boxes bound what they hold (without tracing a ray): a
    /// child node's boxes lie in its parent's box for it, within the child's own quantisation
    /// step (each level rounds outwards from its own origin), and a leaf's triangles lie in the
    /// leaf's box, within a few ulps of the coordinates (decoding adds in f32).
    fn check_bvh(&self) -> Result<()> {
        if self.bvh.is_empty() {
            return Ok(());
        }
        let n = self.bvh.len();
        let nt = self.triangles.len();
        let mut node_seen = vec![false; n];
        let mut tri_seen = vec![false; nt];
        // (node, depth, the parent's box for it).
        let mut stack = vec![(0usize, 1usize, None)];
        node_seen[0] = true;
        let ulps = |v: f32| 4.0 * f32::EPSILON * v.abs();
        while let Some((i, depth, parent_box)) = stack.pop() {
            let node = &self.bvh[i];
            let bad = |msg: String| FormatError::invalid(format!("BVH node {i}: {msg}"));
            if depth > BVH_TRAVERSAL_STACK {
                return Err(bad(format!("deeper than {BVH_TRAVERSAL_STACK} levels")));
            }
            if !finite(&node.p) || node.e.iter().any(|&e| e == 0 || e == 255) {
                return Err(bad("non-finite origin or degenerate scale".into()));
            }
            let step = node.extent();
            for slot in (0..8).filter(|&s| !node.is_empty(s)) {
                let (lo, hi) = node.child_box(slot);
                let inside = parent_box.is_none_or(|(plo, phi): ([f32; 3], [f32; 3])| {
                    (0..3).all(|a| {
                        lo[a] >= plo[a] - step[a] - ulps(plo[a]) && hi[a] <= phi[a] + step[a] + ulps(phi[a])
                    })
                });
                if !inside || (0..3).any(|a| lo[a] > hi[a]) {
                    return Err(bad(format!(
                        "slot {slot}'s box {lo:?}..{hi:?} is not within its parent's box {parent_box:?}"
                    )));
                }
            }
            for slot in 0..8 {
                let meta = node.child_meta[slot];
                if node.is_internal(slot) {
                    if meta != 0b0010_0000 | (24 + slot as u8) {
                        return Err(bad(format!("internal slot {slot} has meta {meta:#010b}")));
                    }
                    let c = node.child_node(slot);
                    if c as usize >= n || c == 0 {
                        return Err(bad(format!("child {c} out of range (nodes: {n})")));
                    }
                    if std::mem::replace(&mut node_seen[c as usize], true) {
                        return Err(bad(format!("child {c} is referenced twice")));
                    }
                    stack.push((c as usize, depth + 1, Some(node.child_box(slot))));
                } else if meta != 0 {
                    let (first, count) = node.leaf_range(slot);
                    let unary = meta >> 5;
                    if unary & (unary + 1) != 0 || first + count as u64 > nt as u64 {
                        return Err(bad(format!(
                            "leaf slot {slot} meta {meta:#010b} invalid for {nt} triangles"
                        )));
                    }
                    let (lo, hi) = node.child_box(slot);
                    for t in first..first + count as u64 {
                        if std::mem::replace(&mut tri_seen[t as usize], true) {
                            return Err(bad(format!("triangle {t} is in two leaves")));
                        }
                        // Indices were checked against the vertices by check_geometry.
                        for &v in &self.triangles[t as usize] {
                            let p = self.vertices[v as usize].position;
                            if (0..3).any(|a| p[a] < lo[a] - ulps(lo[a]) || p[a] > hi[a] + ulps(hi[a])) {
                                return Err(bad(format!(
                                    "triangle {t}'s corner {p:?} lies outside its leaf's box {lo:?}..{hi:?}"
                                )));
                            }
                        }
                    }
                }
            }
        }
        if let Some(i) = node_seen.iter().position(|s| !s) {
            return Err(FormatError::invalid(format!("BVH node {i} is not reachable from the root")));
        }
        if let Some(t) = tri_seen.iter().position(|s| !s) {
            return Err(FormatError::invalid(format!("triangle {t} is in no BVH leaf")));
        }
        Ok(())
    }
}

/// Compares, without decoding any, the table's decoded size of every section whose length a
/// manifest record or a header fixes (BRDF table, shadow maps, light-visibility volumes, probe
/// and environment sections) with that length. Readers that decode sections in bulk before
/// validating them (`kiln verify`, the player's parallel decode) run it first, so that a small
/// file claiming gigabytes is refused before they are spent; [`SceneView::new`] makes the same
/// comparisons as it reads.
pub fn check_declared_sizes(file: &KilnFile) -> Result<()> {
    let m = file.manifest()?;
    if let Some(b) = &m.brdf_lut {
        let texels = b.resolution as u64 * b.resolution as u64;
        file.expect_count(BRDF_LUT, 0, texels, 4, "BRDF table")?;
    }
    for (i, info) in m.shadow_maps.iter().enumerate() {
        file.expect_count(SHADOW_MAP, i as u32, info.depth_count(), 4, &format!("shadow map {i}"))?;
    }
    if let Some(v) = &m.media_visibility {
        for i in 0..v.lights.len() {
            file.expect_count(
                MEDIA_VISIBILITY,
                i as u32,
                v.cells(),
                1,
                &format!("light-visibility volume {i}"),
            )?;
        }
    }
    use crate::environment::ENVIRONMENT_KINDS;
    use crate::sections::{ENVIRONMENT_FILTERED, ENVIRONMENT_MAP, ENVIRONMENT_TABLE};
    if let Some(h) = file.group_header::<crate::gpu::EnvironmentHeader>(&ENVIRONMENT_KINDS, "environment")? {
        h.check()?;
        let [map, filtered, table] = h.section_counts();
        file.expect_count(ENVIRONMENT_MAP, 0, map, 4, "environment-map")?;
        file.expect_count(ENVIRONMENT_FILTERED, 0, filtered, 4, "environment-filtered")?;
        let cell = size_of::<crate::gpu::EnvironmentCell>();
        file.expect_count(ENVIRONMENT_TABLE, 0, table, cell, "environment-table")?;
    }
    use crate::probes::{PROBE_KINDS, ProbeHeader, ProbeState};
    use crate::sections::{PROBE_IRRADIANCE, PROBE_STATES, PROBE_VISIBILITY};
    if let Some(h) = file.group_header::<ProbeHeader>(&PROBE_KINDS, "probe volume")? {
        h.check()?;
        let [probes, irradiance, visibility] = h.section_counts();
        let state = size_of::<ProbeState>();
        file.expect_count(PROBE_STATES, 0, probes, state, "probe-states")?;
        file.expect_count(PROBE_IRRADIANCE, 0, irradiance, 4, "probe-irradiance")?;
        file.expect_count(PROBE_VISIBILITY, 0, visibility, 4, "probe-visibility")?;
    }
    Ok(())
}

/// Bytes of a full RGBA8 mip chain, or `None` if the description is impossible (zero size,
/// wrong level count, overflow).
pub fn mip_chain_bytes(width: u32, height: u32, levels: u32) -> Option<u64> {
    if width == 0 || height == 0 || levels != mip_levels(width, height) {
        return None;
    }
    let mut total: u64 = 0;
    for l in 0..levels {
        let w = (width >> l).max(1) as u64;
        let h = (height >> l).max(1) as u64;
        total = total.checked_add(w.checked_mul(h)?.checked_mul(4)?)?;
    }
    Some(total)
}

/// Number of levels of a full mip chain down to 1×1.
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}
