//! Tables the reference path tracer reads besides the file's sections: emitters chosen in
//! proportion to their power, the emitter of each triangle, and the layout of the texel buffer.

use glam::Vec3;
use kiln_format::gpu::{
    EmissiveFlags, EmitterKinds, GpuEmissive, GpuEmitter, GpuMedium, GpuTexture, TextureFlags, emitted_power,
    luminance,
};
use kiln_format::manifest::{ColorSpace, LightKind, Manifest, Wrap};
use kiln_format::sections::{GpuMaterial, MaterialFlags, NO_TEXTURE, PixelFormat, Swizzle, Vertex};

/// The derived tables.
#[derive(Debug, Default)]
pub struct ReferenceTables {
    /// Emitters with an alias table by power (empty when nothing emits): the analytic lights
    /// first, then the emissive triangles (`rect_lights_seen` in
    /// `shaders/common/emitters.glsl` stops at the first triangle).
    pub emitters: Vec<GpuEmitter>,
    /// The emissive triangles alone, chosen in proportion to their power (the triangle entries
    /// of `emitters`, renormalised, as an alias table): what the direct light of emissive
    /// surfaces draws from.
    pub emissive: Vec<GpuEmissive>,
    /// Per triangle (leaf order): its index in `emitters`, or −1.
    pub triangle_emitter: Vec<i32>,
    /// Per texture: where its mip chain lies in the texel buffer.
    pub textures: Vec<GpuTexture>,
    /// Words (texels) in the texel buffer.
    pub texel_words: u64,
    /// The participating media (the manifest's, validated when the file was opened).
    pub media: Vec<GpuMedium>,
    /// The emitters' summed power (the units of [`environment_share`]).
    pub emitter_power: f64,
}

fn wrap_bits(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 0,
        Wrap::MirroredRepeat => 1,
        Wrap::ClampToEdge => 2,
    }
}

/// Emitted power (up to a common constant) of each analytic light: what selection is
/// proportional to. Directional lights count over the disk of the scene's bounding sphere.
fn light_power(l: &kiln_format::manifest::Light, scene_radius: f32) -> f32 {
    let i = l.intensity * luminance(l.color);
    let p = match l.kind {
        LightKind::Point => 4.0 * std::f32::consts::PI * i,
        LightKind::Spot { inner_cone, outer_cone } => {
            2.0 * std::f32::consts::PI * (1.0 - 0.5 * (inner_cone.cos() + outer_cone.cos())) * i
        }
        LightKind::Directional => std::f32::consts::PI * scene_radius * scene_radius * i,
        LightKind::Rect { width, height } => std::f32::consts::PI * width * height * i,
    };
    if p.is_finite() { p.max(0.0) } else { 0.0 }
}

pub use kiln_format::environment::alias_table;

/// The least probability either light source keeps in [`environment_share`]: a source with
/// little power is still sampled now and then (its light may be all a shadowed corner gets).
const LEAST_SHARE: f32 = 0.1;

/// The probability with which the reference path tracer's next-event estimation at a surface
/// samples the environment rather than the emitter table: one shadow ray per vertex, shared by
/// power. The environment's power is what it sends through the scene's bounding sphere, π r²
/// times its radiance integrated over the sphere of directions (4π × its mean), as a directional
/// light's is π r² times its irradiance ([`light_power`]); the emitters' is the table's sum in
/// the same units. Each source keeps at least [`LEAST_SHARE`] when both exist; 0 without an
/// environment, 1 without emitters.
pub fn environment_share(env_mean_luminance: f32, scene_radius: f32, emitter_power: f64) -> f32 {
    let pi = std::f64::consts::PI;
    let env = 4.0 * pi * pi * f64::from(scene_radius).powi(2) * f64::from(env_mean_luminance);
    if !(env > 0.0 && env.is_finite()) {
        return 0.0;
    }
    if !(emitter_power > 0.0 && emitter_power.is_finite()) {
        return 1.0;
    }
    ((env / (env + emitter_power)) as f32).clamp(LEAST_SHARE, 1.0 - LEAST_SHARE)
}

/// The radius of the scene's bounding sphere (0 where the bounds are not finite).
pub fn scene_radius(manifest: &Manifest) -> f32 {
    let b = &manifest.bounds;
    let radius = (Vec3::from(b.max) - Vec3::from(b.min)).length() * 0.5;
    if radius.is_finite() { radius } else { 0.0 }
}

/// The emissive triangles of `power` ((kind, index, power) entries) as the direct light of
/// emissive surfaces reads them: corners, emission, flags and an alias table by power.
fn emissive_table(
    power: &[(u32, u32, f32)],
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    triangle_materials: &[u32],
    materials: &[GpuMaterial],
) -> Vec<GpuEmissive> {
    let entries: Vec<(u32, f32)> =
        power.iter().filter(|p| p.0 == EmitterKinds::TRIANGLE).map(|p| (p.1, p.2)).collect();
    let total: f64 = entries.iter().map(|e| e.1 as f64).sum();
    let alias = alias_table(&entries.iter().map(|e| e.1 as f64).collect::<Vec<_>>());
    entries
        .iter()
        .zip(alias)
        .map(|(&(t, p), (keep, alias))| {
            let c = triangles[t as usize].map(|v| Vec3::from(vertices[v as usize].position));
            let m = &materials[triangle_materials[t as usize] as usize];
            let mut triangle = t & EmissiveFlags::TRIANGLE_MASK;
            if m.flags & MaterialFlags::DOUBLE_SIDED != 0 {
                triangle |= EmissiveFlags::DOUBLE_SIDED;
            }
            if m.emissive_texture != NO_TEXTURE {
                triangle |= EmissiveFlags::TEXTURED;
            }
            GpuEmissive {
                p0: c[0].to_array(),
                pdf: (p as f64 / total) as f32,
                e1: (c[1] - c[0]).to_array(),
                keep,
                e2: (c[2] - c[0]).to_array(),
                alias,
                emission: m.emission,
                triangle,
            }
        })
        .collect()
}

/// Builds the tables of a validated scene. Emissive triangles are weighed by their emitted
/// power: π × luminance × area, the luminance the file's mean over each triangle
/// (`emitter_luminance`, where an emissive texture modulates the factor) or the factor's; a
/// triangle whose texture lets nothing out leaves the tables (its light, if any, still arrives
/// through the paths that hit it).
pub fn tables(
    manifest: &Manifest,
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    triangle_materials: &[u32],
    materials: &[GpuMaterial],
    storage: &[(PixelFormat, [Swizzle; 4])],
    emitter_luminance: Option<&[f32]>,
) -> ReferenceTables {
    let radius = scene_radius(manifest);
    let mut power: Vec<(u32, u32, f32)> = manifest
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| (EmitterKinds::LIGHT, i as u32, light_power(l, radius)))
        .collect();
    for (t, (tri, &m)) in triangles.iter().zip(triangle_materials).enumerate() {
        let emission = materials[m as usize].emission;
        if luminance(emission) > 0.0 {
            let p = tri.map(|v| Vec3::from(vertices[v as usize].position));
            let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            let power_of = match emitter_luminance.and_then(|l| l.get(t)) {
                // The same constant as emitted_power: π × luminance × area.
                Some(&mean) => std::f32::consts::PI * mean * area,
                None => emitted_power(emission, area),
            };
            power.push((EmitterKinds::TRIANGLE, t as u32, power_of));
        }
    }
    power.retain(|p| p.2 > 0.0 && p.2.is_finite());
    let total: f64 = power.iter().map(|p| p.2 as f64).sum();
    let mut tables = ReferenceTables {
        triangle_emitter: vec![-1; triangles.len()],
        emitter_power: total,
        ..Default::default()
    };
    let alias = alias_table(&power.iter().map(|p| p.2 as f64).collect::<Vec<_>>());
    for (i, (&(kind, index, p), (keep, alias))) in power.iter().zip(alias).enumerate() {
        tables.emitters.push(GpuEmitter { kind, index, keep, pdf: (p as f64 / total) as f32, alias });
        if kind == EmitterKinds::TRIANGLE {
            tables.triangle_emitter[index as usize] = i as i32;
        }
    }
    tables.emissive = emissive_table(&power, vertices, triangles, triangle_materials, materials);
    tables.media = super::media::table(manifest);
    for (i, t) in manifest.textures.iter().enumerate() {
        // How the texels are stored (the section header): RGBA8 where unknown.
        let (format, swizzle) = storage.get(i).copied().unwrap_or((PixelFormat::Rgba8, Swizzle::IDENTITY));
        let mut flags = wrap_bits(t.wrap_u) << TextureFlags::WRAP_U_SHIFT
            | wrap_bits(t.wrap_v) << TextureFlags::WRAP_V_SHIFT;
        if t.color_space == ColorSpace::Srgb {
            flags |= TextureFlags::SRGB;
        }
        if t.mag_linear {
            flags |= TextureFlags::LINEAR;
        }
        flags |= t.mip_levels.min(31) << TextureFlags::LEVELS_SHIFT;
        flags |= (format as u32) << TextureFlags::FORMAT_SHIFT;
        for (k, s) in swizzle.iter().enumerate() {
            flags |= (*s as u32) << (TextureFlags::SWIZZLE_SHIFT + 3 * k as u32);
        }
        tables.textures.push(GpuTexture {
            offset: tables.texel_words as u32,
            width: t.width,
            height: t.height,
            flags,
        });
        // The manifest's level count was validated against the size when the file was opened;
        // every chain is a whole number of words (BC4's 8-byte blocks included).
        tables.texel_words += format.chain_bytes(t.width, t.height, t.mip_levels).unwrap_or(0) / 4;
    }
    tables
}

#[cfg(test)]
mod tests {
    use super::*;
    use kiln_format::manifest::Light;

    fn light(kind: LightKind, intensity: f32) -> Light {
        Light {
            name: "l".into(),
            kind,
            position: [0.0; 3],
            direction: [0.0, -1.0, 0.0],
            right: [1.0, 0.0, 0.0],
            color: [1.0; 3],
            intensity,
            range: 0.0,
            casts_shadows: true,
        }
    }

    /// The distribution an alias table samples (entry ⌊ξN⌋ kept with its probability, else its
    /// alias), summed entry by entry, against the weights normalised.
    #[test]
    fn the_alias_table_chooses_in_proportion_to_the_weights() {
        let mut x = 12345u64;
        for n in [1usize, 2, 3, 7, 100, 1000] {
            let weights: Vec<f64> = (0..n)
                .map(|i| {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    // Spread over six decades, one entry in seven a hundred times heavier.
                    let u = (x >> 11) as f64 / (1u64 << 53) as f64;
                    10f64.powf(6.0 * u - 3.0) * if i % 7 == 0 { 100.0 } else { 1.0 }
                })
                .collect();
            let table = alias_table(&weights);
            let mut chosen = vec![0.0f64; n];
            for (i, &(keep, alias)) in table.iter().enumerate() {
                assert!((0.0..=1.0).contains(&keep), "n {n}: entry {i} keeps with {keep}");
                chosen[i] += keep as f64 / n as f64;
                chosen[alias as usize] += (1.0 - keep as f64) / n as f64;
            }
            let total: f64 = weights.iter().sum();
            for i in 0..n {
                let want = weights[i] / total;
                assert!(
                    (chosen[i] - want).abs() <= 1e-6 * want.max(1.0 / n as f64),
                    "n {n}: entry {i} chosen with {} instead of {want}",
                    chosen[i]
                );
            }
        }
    }

    /// The shaders' loop over the rect lights stops at the first triangle entry: every light
    /// must come before every triangle, whatever their powers.
    #[test]
    fn the_lights_come_before_the_emissive_triangles() {
        let mut manifest = Manifest::default();
        manifest.bounds.max = [1.0; 3];
        let rect = LightKind::Rect { width: 1.0, height: 1.0 };
        manifest.lights = vec![
            light(LightKind::Point, 1e-6),
            light(rect, 5.0),
            light(LightKind::Point, 0.0),
            light(rect, 1e-6),
        ];
        let v = |x: f32, z: f32| Vertex { position: [x, 0.0, z], normal: [0.0, 1.0, 0.0] };
        let vertices = vec![v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
        let glow = GpuMaterial { emission: [100.0; 3], ..Default::default() };
        let t = tables(
            &manifest,
            &vertices,
            &[[0, 1, 2], [0, 2, 1], [1, 0, 2], [2, 1, 0]],
            &[1, 0, 1, 1],
            &[GpuMaterial::default(), glow],
            &[],
            None,
        );
        let kinds: Vec<u32> = t.emitters.iter().map(|e| e.kind).collect();
        let lights = kinds.iter().filter(|&&k| k == EmitterKinds::LIGHT).count();
        assert_eq!(lights, 3, "the dark light is dropped, the other three kept: {kinds:?}");
        assert!(kinds[..lights].iter().all(|&k| k == EmitterKinds::LIGHT), "{kinds:?}");
        assert!(kinds[lights..].iter().all(|&k| k == EmitterKinds::TRIANGLE), "{kinds:?}");
        assert_eq!(kinds.len(), 6);
    }

    #[test]
    fn selection_is_proportional_to_power_and_covers_emissive_triangles() {
        let mut manifest = Manifest::default();
        manifest.bounds.max = [1.0; 3];
        manifest.lights =
            vec![light(LightKind::Point, 1.0), light(LightKind::Point, 3.0), light(LightKind::Point, 0.0)];
        let v = |x: f32, z: f32| Vertex { position: [x, 0.0, z], normal: [0.0, 1.0, 0.0] };
        let vertices = vec![v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
        let glow = GpuMaterial { emission: [1.0; 3], ..Default::default() };
        let t = tables(
            &manifest,
            &vertices,
            &[[0, 1, 2], [0, 2, 1]],
            &[0, 1],
            &[GpuMaterial::default(), glow],
            &[],
            None,
        );
        assert_eq!(t.emitters.len(), 3, "the dark light is dropped");
        let p: Vec<f32> = t.emitters.iter().map(|e| e.pdf).collect();
        assert!((p[1] / p[0] - 3.0).abs() < 1e-5);
        assert!((p.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // What the alias table draws, entry by entry, is the pdf each entry states.
        let n = t.emitters.len();
        let mut chosen = vec![0.0f32; n];
        for (i, e) in t.emitters.iter().enumerate() {
            chosen[i] += e.keep / n as f32;
            chosen[e.alias as usize] += (1.0 - e.keep) / n as f32;
        }
        for (c, e) in chosen.iter().zip(&t.emitters) {
            assert!((c - e.pdf).abs() < 1e-6, "drawn with {c}, stated {}", e.pdf);
        }
        assert_eq!(t.triangle_emitter, vec![-1, 2]);
    }

    /// With the file's mean emitted luminance, triangles of one material are weighed by it (a
    /// texture that lets three times the light out: three times as likely) and one whose
    /// texture lets nothing out leaves the tables.
    #[test]
    fn textured_emitters_are_weighed_by_their_mean_luminance() {
        let mut manifest = Manifest::default();
        manifest.bounds.max = [1.0; 3];
        let v = |x: f32, z: f32| Vertex { position: [x, 0.0, z], normal: [0.0, 1.0, 0.0] };
        let vertices = vec![v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
        let glow = GpuMaterial { emission: [1.0; 3], emissive_texture: 0, ..Default::default() };
        let t = tables(
            &manifest,
            &vertices,
            &[[0, 1, 2], [0, 2, 1], [1, 2, 0]],
            &[0, 0, 0],
            &[glow],
            &[],
            Some(&[1.0, 3.0, 0.0]),
        );
        assert_eq!(t.triangle_emitter, vec![0, 1, -1]);
        assert!((t.emitters[1].pdf / t.emitters[0].pdf - 3.0).abs() < 1e-5);
        assert_eq!(t.emissive.len(), 2);
    }
}
