//! Lighting bakes: the BRDF table against an independent quadrature, shadow maps against brute
//! force, the light-visibility volume against brute-force visibility, and pre-illuminated
//! radiance against an independent evaluation of the same shading.

#[path = "util/run.rs"]
mod run;

use kiln_compiler::bake::brdf_lut;

/// Gauss–Legendre nodes and weights on [−1, 1], 5 points.
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Composite Gauss–Legendre integral of f over [a, b] with `panels` panels.
fn quad(a: f64, b: f64, panels: usize, f: &mut dyn FnMut(f64) -> f64) -> f64 {
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let m = a + (p as f64 + 0.5) * h;
        for &(x, w) in &GL5 {
            sum += w * f(m + 0.5 * h * x);
        }
    }
    sum * 0.5 * h
}

/// An independent evaluation of the split-sum integrals: f64 tensor-product Gauss–Legendre
/// quadratures (not sampling estimates), with the height-correlated G₂ in its closed form rather
/// than through Λ. Near-normal views integrate over the half vector distributed by D(h)(n·h)
/// (θ through the GGX CDF), where the integrand is smooth when the view is steep; grazing views
/// integrate over the disk that parametrises the distribution of visible normals, where the
/// integrand G₂/G₁ stays bounded.
fn reference(n_v: f64, roughness: f64) -> (f64, f64) {
    let a = (roughness * roughness).max(1e-6);
    let a2 = a * a;
    let v = [((1.0 - n_v * n_v).max(0.0)).sqrt(), 0.0, n_v];
    let g2 = |nv: f64, nl: f64| {
        2.0 * nl * nv / (nv * (a2 + (1.0 - a2) * nl * nl).sqrt() + nl * (a2 + (1.0 - a2) * nv * nv).sqrt())
    };
    let g1 = 2.0 * n_v / (n_v + (a2 + (1.0 - a2) * n_v * n_v).sqrt());
    // Contribution of half vector h: (weight without F, v·h), or None below the horizon.
    let split = |h: [f64; 3], weight: f64| -> (f64, f64) {
        let v_h = v[0] * h[0] + v[2] * h[2];
        let n_l = 2.0 * v_h * h[2] - v[2];
        if n_l <= 0.0 || v_h <= 0.0 {
            return (0.0, 0.0);
        }
        let fc = (1.0 - v_h).powi(5);
        let w = weight * g2(n_v, n_l);
        ((1.0 - fc) * w, fc * w)
    };
    let mut total = (0.0, 0.0);
    if n_v >= 0.5 {
        // ∫ f (n·l) dl = ∫∫ G₂ (v·h) / ((n·v)(n·h)) dx dφ / 2π, cos²θ_h = (1 − x) / (1 + (α² − 1) x).
        for which in 0..2 {
            let r = quad(0.0, 1.0, 200, &mut |x| {
                let c = ((1.0 - x) / (1.0 + (a2 - 1.0) * x)).sqrt();
                let s = (1.0 - c * c).max(0.0).sqrt();
                quad(0.0, std::f64::consts::PI, 100, &mut |phi| {
                    let h = [s * phi.cos(), s * phi.sin(), c];
                    let v_h = v[0] * h[0] + v[2] * h[2];
                    let (r, g) = split(h, v_h / (n_v * c));
                    if which == 0 { r } else { g }
                }) / std::f64::consts::PI
            });
            if which == 0 { total.0 = r } else { total.1 = r }
        }
        return total;
    }
    // Visible normals: h from the disk point (r, u2) (Heitz 2018), weight G₂ / G₁.
    let len = (a2 * v[0] * v[0] + v[2] * v[2]).sqrt();
    let vh = [a * v[0] / len, 0.0, v[2] / len];
    let t2 = [-vh[2], 0.0, vh[0]];
    for which in 0..2 {
        // u1 = r² (the square root's infinite slope at 0 would stall the quadrature): du1 = 2r dr.
        let r = quad(0.0, 1.0, 200, &mut |r| {
            2.0 * r
                * quad(0.0, 1.0, 100, &mut |u2| {
                    let phi = std::f64::consts::TAU * u2;
                    let p1 = r * phi.cos();
                    let s = 0.5 * (1.0 + vh[2]);
                    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
                    let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
                    let nh = [p2 * t2[0] + p3 * vh[0], p1, p2 * t2[2] + p3 * vh[2]];
                    let ne = [a * nh[0], a * nh[1], nh[2].max(0.0)];
                    let l = (ne[0] * ne[0] + ne[1] * ne[1] + ne[2] * ne[2]).sqrt();
                    let (r, g) = split([ne[0] / l, ne[1] / l, ne[2] / l], 1.0 / g1);
                    if which == 0 { r } else { g }
                })
        });
        if which == 0 { total.0 = r } else { total.1 = r }
    }
    total
}

#[test]
fn brdf_table_matches_an_independent_quadrature() {
    let res = kiln_compiler::settings::BRDF_LUT_RES.default;
    let table = brdf_lut::bake(res);
    let mut worst = (0.0f64, 0, 0);
    // Every 16th texel in each direction plus the first and last rows and columns.
    let picks: Vec<u32> = (0..res).filter(|i| i % 16 == 7 || *i == 0 || *i == res - 1).collect();
    for &j in &picks {
        for &i in &picks {
            let (r, g) = reference((i as f64 + 0.5) / res as f64, (j as f64 + 0.5) / res as f64);
            let t = table[(j * res + i) as usize];
            let err = ((t[0] as f64 / 65535.0 - r).abs()).max((t[1] as f64 / 65535.0 - g).abs());
            if err > worst.0 {
                worst = (err, i, j);
            }
        }
    }
    eprintln!(
        "BRDF table: max abs error {:.2e} at texel {:?} ({} texels checked)",
        worst.0,
        (worst.1, worst.2),
        picks.len() * picks.len()
    );
    assert!(worst.0 <= 1e-3, "max abs error {:.2e} at texel ({}, {})", worst.0, worst.1, worst.2);
}

#[test]
fn brdf_table_has_the_known_limits() {
    // Smooth and head-on: R + G → 1 (all energy reflected), G → F_c(1) = 0.
    let (r, g) = reference(0.999, 0.02);
    assert!((r + g - 1.0).abs() < 1e-2 && g < 1e-3, "{r} {g}");
    // Rough surfaces lose energy to single scattering: R + G < 1.
    let (r, g) = reference(0.5, 1.0);
    assert!(r + g < 0.9, "{r} {g}");
}

use glam::Vec3;
use kiln_compiler::bake::shadow;
use kiln_compiler::ir::{Material, Scene};
use kiln_compiler::settings::Settings;
use kiln_format::linespace::{LineSpace, Variants};
use kiln_format::manifest::{Bounds, Light, LightKind, Medium, ShadowProjection};
use kiln_format::query::{BruteForce, IndexedTriangles, Ray, offset_origin};
use kiln_format::sections::{self, Vertex};
use kiln_format::{Checksums, KilnFile, SceneView};

fn light(kind: LightKind, position: [f32; 3], direction: [f32; 3], intensity: f32) -> Light {
    Light {
        name: "l".into(),
        kind,
        position,
        direction,
        right: [1.0, 0.0, 0.0],
        color: [1.0; 3],
        intensity,
        range: 0.0,
        casts_shadows: true,
    }
}

fn compile(scene: Scene, settings: Settings) -> Vec<u8> {
    kiln_compiler::pipeline::compile_to_bytes(scene, settings, "test").expect("bakes")
}

/// The ray of a texel reconstructed from the manifest record alone, by the documented
/// conventions (not by the compiler's own layout code).
fn texel_ray(info: &kiln_format::manifest::ShadowMapInfo, k: usize) -> Ray {
    let n = info.resolution as usize;
    let (face, rest) = (k / (n * n), k % (n * n));
    let (x, y) = ((rest % n) as f32 + 0.5, (rest / n) as f32 + 0.5);
    let origin = Vec3::from(info.origin);
    match info.projection {
        ShadowProjection::Cube => {
            let (sc, tc) = (2.0 * x / n as f32 - 1.0, 2.0 * y / n as f32 - 1.0);
            let d = [
                Vec3::new(1.0, -tc, -sc),
                Vec3::new(-1.0, -tc, sc),
                Vec3::new(sc, 1.0, tc),
                Vec3::new(sc, -1.0, -tc),
                Vec3::new(sc, -tc, 1.0),
                Vec3::new(-sc, -tc, -1.0),
            ][face];
            Ray::new(origin, d.normalize(), 0.0, f32::INFINITY)
        }
        ShadowProjection::Perspective => {
            // No matrix inverse (the compiler's way): the texel's ray from the light is the line
            // where clip.x = ndc_x·clip.w and clip.y = ndc_y·clip.w meet, two planes through the
            // eye, so its direction is the cross product of their normals (rows of the stored
            // column-major matrix, in f64), taken along the spot axis.
            let m = |r: usize, c: usize| info.view_proj[c * 4 + r] as f64;
            let (ndc_x, ndc_y) = (2.0 * x as f64 / n as f64 - 1.0, 1.0 - 2.0 * y as f64 / n as f64);
            let plane = |r: usize, ndc: f64| {
                glam::DVec3::new(m(r, 0) - ndc * m(3, 0), m(r, 1) - ndc * m(3, 1), m(r, 2) - ndc * m(3, 2))
            };
            let mut d = plane(0, ndc_x).cross(plane(1, ndc_y)).normalize();
            if d.dot(glam::DVec3::from(info.direction.map(f64::from))) < 0.0 {
                d = -d;
            }
            Ray::new(origin, d.as_vec3(), 0.0, f32::INFINITY)
        }
        ShadowProjection::Orthographic => {
            // In f64: the stored matrix of a perspective map with a far/near ratio near 10⁴
            // inverts badly in f32 (texel directions then stray by a tenth of a texel).
            let inv = glam::DMat4::from_cols_array(&info.view_proj.map(f64::from)).inverse();
            let (ndc_x, ndc_y) = (2.0 * x as f64 / n as f64 - 1.0, 1.0 - 2.0 * y as f64 / n as f64);
            let near = inv.project_point3(glam::DVec3::new(ndc_x, ndc_y, 0.0));
            let far = inv.project_point3(glam::DVec3::new(ndc_x, ndc_y, 1.0));
            let d = (far - near).normalize().as_vec3();
            Ray::new(near.as_vec3(), d, 0.0, f32::INFINITY)
        }
    }
}

#[test]
fn shadow_maps_agree_with_brute_force_ray_casts() {
    let mut scene = kiln_compiler::import::demo::cornell_box();
    scene.lights = vec![
        light(LightKind::Directional, [0.0; 3], [-0.3, -1.0, -0.2], 2.0),
        light(LightKind::Spot { inner_cone: 0.4, outer_cone: 0.6 }, [0.3, 1.8, 0.4], [0.0, -1.0, 0.1], 5.0),
        light(LightKind::Point, [0.0, 1.5, 0.0], [0.0, -1.0, 0.0], 5.0),
        light(LightKind::Rect { width: 0.5, height: 0.4 }, [0.0, 1.98, 0.0], [0.0, -1.0, 0.0], 10.0),
        // Grazing incidence: a spot 2 cm above the floor looking along it, so most texels hit
        // the floor at a few degrees and a texel ray a tenth of a texel off lands far away.
        light(
            LightKind::Spot { inner_cone: 0.3, outer_cone: 0.5 },
            [-0.95, 0.02, 0.1],
            [1.0, -0.03, -0.05],
            5.0,
        ),
    ];
    let bytes = compile(scene, Settings { shadow_res: 64, shaft_variants: Some(0), ..Default::default() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let brute = BruteForce::new(&tris);
    let kinds: Vec<ShadowProjection> = view.manifest.shadow_maps.iter().map(|m| m.projection).collect();
    assert_eq!(
        kinds,
        [
            ShadowProjection::Orthographic,
            ShadowProjection::Perspective,
            ShadowProjection::Cube,
            ShadowProjection::Cube,
            ShadowProjection::Perspective
        ]
    );
    let mut rng = kiln_compiler::raycheck::Rng::new(3);
    let mut failed = Vec::new();
    for (i, info) in view.manifest.shadow_maps.iter().enumerate() {
        let depths: &[f32] = file.pod(sections::SHADOW_MAP, i as u32).unwrap().unwrap();
        let mut worst = (0.0f32, 0);
        let mut bad = Vec::new();
        for _ in 0..1500 {
            let k = rng.below(depths.len());
            let want = brute.closest_hit(&texel_ray(info, k)).map_or(shadow::NO_OCCLUDER, |h| h.t);
            let got = depths[k];
            if (got == shadow::NO_OCCLUDER) != (want == shadow::NO_OCCLUDER) {
                bad.push(format!("texel {k}: stored {got}, brute force {want}"));
                continue;
            }
            let rel = if want == shadow::NO_OCCLUDER { 0.0 } else { (got - want).abs() / want.max(1.0) };
            if rel > worst.0 {
                worst = (rel, k);
            }
            if rel > 1e-5 {
                bad.push(format!("texel {k}: stored {got}, brute force {want}"));
            }
        }
        eprintln!(
            "shadow map {i} ({:?}): worst relative depth error {:.1e} at texel {}",
            info.projection, worst.0, worst.1
        );
        if !bad.is_empty() {
            failed.push(format!(
                "map {i}: {} of 1500 texels differ, e.g. {:?}",
                bad.len(),
                &bad[..bad.len().min(3)]
            ));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn lights_that_see_nothing_and_lights_inside_geometry() {
    let mut scene = kiln_compiler::import::demo::cornell_box();
    // A spot pointing away from the scene sees nothing; a point light inside the tall block
    // sees the block's inside in every direction (closed on 5 sides: the floor closes it).
    scene.lights = vec![
        light(LightKind::Spot { inner_cone: 0.2, outer_cone: 0.3 }, [0.0, 5.0, 0.0], [0.0, 1.0, 0.0], 1.0),
        light(LightKind::Point, [-0.35, 0.6, -0.3], [0.0, -1.0, 0.0], 1.0),
    ];
    let bytes = compile(scene, Settings { shadow_res: 32, shaft_variants: Some(0), ..Default::default() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let away: &[f32] = file.pod(sections::SHADOW_MAP, 0).unwrap().unwrap();
    assert!(away.iter().all(|&d| d == shadow::NO_OCCLUDER));
    let inside: &[f32] = file.pod(sections::SHADOW_MAP, 1).unwrap().unwrap();
    assert!(
        inside.iter().all(|&d| d < 1.0),
        "a ray escaped the block: {:?}",
        inside.iter().cloned().fold(0.0f32, f32::max)
    );
}

fn floor_and_blocker() -> Scene {
    let mut s = Scene { name: "floor".into(), ..Default::default() };
    s.materials.push(Material {
        name: "grey".into(),
        gpu: kiln_compiler::import::demo::lambert_material([0.5, 0.5, 0.5]),
    });
    let mut quad = |c: [Vec3; 4]| {
        let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
        let b = s.vertices.len() as u32;
        for p in c {
            s.vertices.push(Vertex { position: p.to_array(), normal: n.to_array() });
            s.uvs.push([0.0; 2]);
        }
        s.triangles.extend([[b, b + 1, b + 2], [b, b + 2, b + 3]]);
        s.triangle_materials.extend([0, 0]);
    };
    quad([
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(-1.0, 0.0, -1.0),
    ]);
    // A small blocker above the floor, facing down.
    quad([
        Vec3::new(-0.2, 0.5, -0.2),
        Vec3::new(0.2, 0.5, -0.2),
        Vec3::new(0.2, 0.5, 0.2),
        Vec3::new(-0.2, 0.5, 0.2),
    ]);
    s.lights.push(light(LightKind::Point, [0.1, 1.5, 0.05], [0.0, -1.0, 0.0], 3.0));
    s.cameras.push(kiln_format::manifest::Camera {
        name: "c".into(),
        position: [0.0, 1.0, 3.0],
        target: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        vfov_degrees: 45.0,
        znear: 0.01,
        zfar: 0.0,
    });
    s
}

/// Pre-illuminated radiance against an independent evaluation: Lambert (albedo / π) times the
/// point light's I cos θ / d², zero where a brute-force shadow ray is blocked.
#[test]
fn preilluminated_radiance_matches_direct_evaluation() {
    let bytes = compile(
        floor_and_blocker(),
        Settings {
            voxel_res: kiln_compiler::settings::VoxelRes::Cells(4),
            shaft_res: Some(3),
            shaft_variants: Some(Variants::PNMT | Variants::PREILLUM),
            ..Default::default()
        },
    );
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let ls = LineSpace::new(&file, view.triangles.len(), view.materials.len()).unwrap().unwrap();
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let brute = BruteForce::new(&tris);
    let h = &ls.header;
    let light_pos = Vec3::new(0.1, 1.5, 0.05);
    let (mut checked, mut lit, mut shadowed) = (0, 0, 0);
    let wps = kiln_format::linespace::words_per_slot(h.shaft_res);
    for (c, &slot) in ls.slots.iter().enumerate() {
        if slot == kiln_format::linespace::NO_SLOT {
            continue;
        }
        let cmin = h.cell_min(h.cell_coords(c));
        for w in 0..wps {
            let word = ls.bits[slot as usize * wps + w];
            for bit in 0..32 {
                if word & (1 << bit) == 0 {
                    continue;
                }
                let shaft = (w * 32 + bit) as u32;
                let rank = ls.rank(slot, shaft).unwrap();
                let Some(hit) = ls.pnmt_layout.decode(ls.record(rank, false), cmin, h.cell) else { continue };
                // The viewer of a front record is the centre of the shaft's front patch.
                let (fa, pa, _, _) = kiln_format::linespace::index::shaft_parts(shaft, h.shaft_res);
                let (ua, va) = kiln_format::linespace::index::face_uv_axes(fa);
                let mut eye = glam::DVec3::ZERO;
                eye[(fa / 2) as usize] = (fa % 2) as f64;
                eye[ua] = ((pa / h.shaft_res) as f64 + 0.5) / h.shaft_res as f64;
                eye[va] = ((pa % h.shaft_res) as f64 + 0.5) / h.shaft_res as f64;
                let eye = (cmin + eye * h.cell).as_vec3();
                let p = hit.position.as_vec3();
                // Only records on the floor's upper side (normal +y) are checked.
                if hit.normal.y < 0.99 || p.y.abs() > 1e-3 {
                    continue;
                }
                let to = light_pos - p;
                let d = to.length();
                let origin = offset_origin(p, Vec3::Y);
                let blocked = eye.y > p.y
                    && brute.closest_hit(&Ray::new(origin, to / d, 0.0, d * (1.0 - 1e-5))).is_some();
                // Seen from below, the floor's underside faces away from the light.
                let from_above = eye.y > p.y;
                let expected = if blocked || !from_above {
                    0.0
                } else {
                    0.5 / std::f32::consts::PI * 3.0 * (to.y / d) / (d * d)
                };
                let got = half::f16::from_bits(ls.preillum[rank][0]).to_f32();
                assert!(
                    (got - expected).abs() <= 2e-3 * expected.max(1e-3) + 1e-5,
                    "record at {p:?}: stored {got}, expected {expected}"
                );
                checked += 1;
                if blocked { shadowed += 1 } else { lit += 1 }
            }
        }
    }
    assert!(checked > 200 && lit > 50 && shadowed > 5, "checked {checked}: {lit} lit, {shadowed} shadowed");
}

#[test]
fn light_visibility_volume_matches_brute_force() {
    let mut scene = floor_and_blocker();
    scene.media.push(Medium {
        bounds: Bounds { min: [-1.0, 0.0, -1.0], max: [1.0, 1.4, 1.0] },
        sigma_a: [0.01; 3],
        sigma_s: [0.1; 3],
        g: 0.3,
    });
    scene.lights.push(light(LightKind::Directional, [0.0; 3], [0.2, -1.0, 0.1], 1.0));
    let bytes =
        compile(scene, Settings { media_volume_res: 16, shaft_variants: Some(0), ..Default::default() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let info = view.manifest.media_visibility.clone().expect("volume baked");
    assert_eq!(info.lights, [0, 1]);
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let brute = BruteForce::new(&tris);
    let medium = &view.manifest.media[0];
    // FORMAT.md: cells are per axis (box / dims), and here not cubic (1.4 / 12 against 2 / 16).
    let ext: [f32; 3] = std::array::from_fn(|a| medium.bounds.max[a] - medium.bounds.min[a]);
    assert_eq!(info.dims, [16, 12, 16]);
    let mut rng = kiln_compiler::raycheck::Rng::new(5);
    let mut under_blocker = 0;
    for (i, &l) in info.lights.iter().enumerate() {
        let cells: &[u8] = file.pod(sections::MEDIA_VISIBILITY, i as u32).unwrap().unwrap();
        let light = &view.manifest.lights[l as usize];
        for _ in 0..400 {
            let c = [
                rng.below(info.dims[0] as usize) as u32,
                rng.below(info.dims[1] as usize) as u32,
                rng.below(info.dims[2] as usize) as u32,
            ];
            let seen = (0..info.samples)
                .filter(|&k| {
                    let p = kiln_compiler::bake::media::sample_point(medium, info.dims, c, k);
                    for a in 0..3 {
                        let size = ext[a] as f64 / info.dims[a] as f64;
                        let lo = medium.bounds.min[a] as f64 + size * c[a] as f64;
                        assert!(
                            (lo - 1e-6..=lo + size + 1e-6).contains(&(p[a] as f64)),
                            "cell {c:?} sample {k}: {p} outside the cell's span on axis {a}"
                        );
                    }
                    let (d, tmax) = match light.kind {
                        LightKind::Directional => (-Vec3::from(light.direction).normalize(), f32::INFINITY),
                        _ => {
                            let to = Vec3::from(light.position) - p;
                            (to.normalize(), to.length() * (1.0 - 1e-5))
                        }
                    };
                    brute.closest_hit(&Ray::new(p, d, 0.0, tmax)).is_none()
                })
                .count();
            let want = (seen as f32 / info.samples as f32 * 255.0).round() as u8;
            let got = cells[(c[0] + info.dims[0] * (c[1] + info.dims[1] * c[2])) as usize];
            assert_eq!(got, want, "light {l}, cell {c:?}");
            under_blocker += (got < 255) as u32;
        }
    }
    assert!(under_blocker > 0, "no sampled cell was in a shadow");
}

#[test]
fn plan_skips_each_lighting_bake_with_its_reason() {
    let plan = |scene: Scene| {
        let loaded = kiln_compiler::pipeline::finish(
            scene,
            Settings::default(),
            "t",
            &Default::default(),
            true,
            std::time::Instant::now(),
        )
        .unwrap();
        loaded.plan.stages.iter().map(|d| (d.stage.name(), d.run, d.reason.clone())).collect::<Vec<_>>()
    };
    fn find(p: &[(&'static str, bool, String)], n: &str) -> (&'static str, bool, String) {
        p.iter().find(|d| d.0 == n).cloned().unwrap()
    }
    // The demo: all Lambertian, no medium, one shadow-casting light.
    let p = plan(kiln_compiler::import::demo::cornell_box());
    assert_eq!(
        find(&p, "brdf-lut"),
        ("brdf-lut", false, "every material is pure Lambertian: no specular lobe to pre-integrate".into())
    );
    assert!(find(&p, "shadow-maps").1);
    assert_eq!(find(&p, "media-visibility").2, "the scene has no participating medium");
    // No shadow casters.
    let mut s = floor_and_blocker();
    s.lights[0].casts_shadows = false;
    s.media.push(Medium {
        bounds: Bounds { min: [-1.0; 3], max: [1.0; 3] },
        sigma_a: [0.0; 3],
        sigma_s: [0.1; 3],
        g: 0.0,
    });
    let p = plan(s);
    assert_eq!(find(&p, "shadow-maps").2, "no light casts shadows");
    assert!(!find(&p, "media-visibility").1);
    // No lights at all.
    let mut s = floor_and_blocker();
    s.lights.clear();
    let p = plan(s);
    assert_eq!(find(&p, "shadow-maps").2, "the scene has no analytic lights");
    assert!(!find(&p, "line-space").1);
    // Nothing lights it: no probes; lit, they run and say who reads them.
    assert!(find(&p, "probes").2.starts_with("nothing lights the scene"), "{:?}", find(&p, "probes"));
    let lit = find(&plan(floor_and_blocker()), "probes");
    assert!(lit.1 && lit.2.contains("read by kiln-play --gi probes"), "{lit:?}");
    // A glossy material needs the table, and its probes four times the paths.
    assert!(lit.2.contains("256 paths each (every material Lambertian"), "{lit:?}");
    let mut s = floor_and_blocker();
    s.materials[0].gpu.flags = 0;
    let p = plan(s);
    assert!(find(&p, "brdf-lut").1);
    let glossy = find(&p, "probes");
    assert!(glossy.2.contains("1024 paths each (glossy materials"), "{glossy:?}");
}

#[test]
fn export_writes_readable_images() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = floor_and_blocker();
    scene.materials[0].gpu.flags = 0;
    std::fs::write(
        dir.path().join("s.kiln"),
        compile(
            scene,
            Settings {
                shadow_res: 32,
                brdf_lut_res: 16,
                shaft_variants: Some(0),
                // 4 × 1 × 4 probes over the 2 × 0.5 × 2 bounds.
                probe_spacing: Some(kiln_compiler::settings::ProbeSpacing(0.5)),
                probe_rays: Some(16),
                ..Default::default()
            },
        ),
    )
    .unwrap();
    for (section, out) in [
        ("brdf-lut", "lut.pfm"),
        ("brdf-lut", "lut.png"),
        ("brdf-lut", "lut.exr"),
        ("shadow-map:0", "sm.pfm"),
        ("shadow-map", "sm.png"),
        ("probe-irradiance", "irr.pfm"),
        ("probe-visibility:0", "vis.exr"),
    ] {
        run::kiln(dir.path(), &["export", "s.kiln", section, "-o", out]).expect(0);
    }
    // PFM: header, then little-endian floats, bottom row first.
    let pfm = std::fs::read(dir.path().join("sm.pfm")).unwrap();
    assert!(pfm.starts_with(b"Pf\n16 96\n-1.0\n"), "{:?}", String::from_utf8_lossy(&pfm[..16]));
    assert_eq!(pfm.len(), 14 + 16 * 96 * 4);
    let lut = image::open(dir.path().join("lut.png")).unwrap();
    assert_eq!((lut.width(), lut.height()), (16, 16));
    let exr = image::open(dir.path().join("lut.exr")).unwrap().into_rgba32f();
    assert!(exr.pixels().all(|p| p[0] + p[1] <= 1.0 + 1e-4 && p[0] >= 0.0));
    // The probes' z slice: four 10 × 10 irradiance tiles (8 × 8 and a border) side by side.
    let irr = std::fs::read(dir.path().join("irr.pfm")).unwrap();
    assert!(irr.starts_with(b"PF\n40 10\n-1.0\n"), "{:?}", String::from_utf8_lossy(&irr[..16]));
    let vis = image::open(dir.path().join("vis.exr")).unwrap();
    assert_eq!((vis.width(), vis.height()), (64, 16));
    // Four z slices, one layer (nothing emits): no slice 4.
    run::kiln(dir.path(), &["export", "s.kiln", "probe-irradiance:4", "-o", "x.pfm"])
        .expect(1)
        .says("no probe-irradiance:4");
    let inspect = run::kiln(dir.path(), &["inspect", "s.kiln"]);
    assert!(inspect.expect(0).stdout.contains("irradiance probes 4x1x4 every 0.5000 units"), "{inspect:?}");
    run::kiln(dir.path(), &["export", "s.kiln", "shadow-map:7", "-o", "x.pfm"])
        .expect(1)
        .says("no shadow-map:7");
    run::kiln(dir.path(), &["export", "s.kiln", "bvh", "-o", "x.pfm"]).expect(2).says("exportable");
    // A bake that would trace more paths than the limit is refused before it starts, saying what
    // to change; so is a spacing that puts more probes on an axis than an atlas holds.
    run::kiln(dir.path(), &["demo", "-o", "p.kiln", "--probe-spacing", "0.02", "--probe-rays", "512"])
        .expect(2)
        .says("lower --probe-rays or raise --probe-spacing");
    run::kiln(dir.path(), &["demo", "-o", "p.kiln", "--probe-regularize", "1.5"])
        .expect(2)
        .says("not a roughness from 0 to 1");
    run::kiln(dir.path(), &["demo", "-o", "p.kiln", "--probe-spacing", "0.001"])
        .expect(2)
        .says("raise it to at least");
    run::kiln(dir.path(), &["demo", "-o", "p.kiln", "--probe-spacing", "-1"])
        .expect(2)
        .says("not a positive distance");
    run::kiln(dir.path(), &["export", "s.kiln", "brdf-lut", "-o", "x.bmp"])
        .expect(2)
        .says("unknown image type");
}

/// Each emissive triangle's mean emitted luminance (`EMLU`): two triangles of one material whose
/// emissive texture is black on its left half and white on its right (4 × 1 texels, clamped),
/// one mapped inside the black texels' reach of bilinear filtering, one inside the white's: 0 and
/// the factor's luminance. A triangle of a material without texture keeps its factor's; a
/// non-emitter 0.
#[test]
fn emitted_luminance_averages_the_emissive_texture_over_each_triangle() {
    use kiln_compiler::ir::{Texture, TextureRole};
    use kiln_format::manifest::Wrap;
    let mut s = Scene { name: "emitters".into(), ..Default::default() };
    s.textures.push(Texture {
        name: "half".into(),
        width: 4,
        height: 1,
        rgba: [0u8, 0, 255, 255].iter().flat_map(|&c| [c, c, c, 255]).collect(),
        role: TextureRole::Color,
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        mag_linear: true,
    });
    let factor = [2.0f32, 1.0, 0.5];
    let mut textured = kiln_compiler::import::demo::lambert_material([0.5; 3]);
    textured.emission = factor;
    textured.emissive_texture = 0;
    let mut plain = kiln_compiler::import::demo::lambert_material([0.5; 3]);
    plain.emission = [0.0, 3.0, 0.0];
    for (name, gpu) in [
        ("textured", textured),
        ("plain", plain),
        ("dark", kiln_compiler::import::demo::lambert_material([0.5; 3])),
    ] {
        s.materials.push(Material { name: name.into(), gpu });
    }
    // Four triangles side by side on the floor, with their texture coordinates.
    let tris: [(f32, [f32; 2], u32); 4] =
        [(0.0, [0.02, 0.2], 0), (1.0, [0.8, 0.98], 0), (2.0, [0.5, 0.5], 1), (3.0, [0.5, 0.5], 2)];
    for (x, [u0, u1], m) in tris {
        let b = s.vertices.len() as u32;
        for (p, uv) in
            [([x, 0.0, 0.0], [u0, 0.5]), ([x + 0.9, 0.0, 0.0], [u1, 0.5]), ([x, 0.0, -0.9], [u0, 0.5])]
        {
            s.vertices.push(Vertex { position: p, normal: [0.0, 1.0, 0.0] });
            s.uvs.push(uv);
        }
        s.triangles.push([b, b + 1, b + 2]);
        s.triangle_materials.push(m);
    }
    let bytes = compile(s, Settings { shaft_variants: Some(0), ..Default::default() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let lum: &[f32] = view.emitter_luminance().unwrap().expect("an emissive texture: the section");
    let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    // By material, in the file's (BVH) order.
    for (t, &m) in view.triangle_materials.iter().enumerate() {
        let tri = view.triangles[t];
        let x = view.vertices[tri[0] as usize].position[0].min(view.vertices[tri[1] as usize].position[0]);
        let want = match (m, x < 0.5) {
            (0, true) => 0.0,
            (0, false) => luminance(factor),
            (1, _) => luminance([0.0, 3.0, 0.0]),
            _ => 0.0,
        };
        assert!(
            (lum[t] - want).abs() <= 1e-4 * want.max(1.0),
            "triangle {t} (material {m}, x {x}): {} against {want}",
            lum[t]
        );
    }
}

/// A triangle over a two-texel ramp of its emissive texture (white then black, bilinear,
/// clamped) weighs what it emits on average. Its texture coordinates (0, 0), (1, 0), (1, 1) make
/// u = s + r of its barycentric weights, whose density over the triangle is 2u; the radiance is
/// 1 up to u = 1/4, 0 past 3/4 and 3/2 − 2u between, so the mean is
/// ∫₀^¼ 2u du + ∫_¼^¾ (3/2 − 2u) 2u du = 1/16 + 5/24 = 13/48 of the factor (0.2708).
#[test]
fn emitted_luminance_of_a_triangle_over_a_few_texels_is_its_mean() {
    use kiln_compiler::ir::{Texture, TextureRole};
    use kiln_format::manifest::Wrap;
    let mut s = Scene { name: "ramp".into(), ..Default::default() };
    s.textures.push(Texture {
        name: "ramp".into(),
        width: 2,
        height: 1,
        rgba: vec![255, 255, 255, 255, 0, 0, 0, 255],
        role: TextureRole::Color,
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        mag_linear: true,
    });
    let mut m = kiln_compiler::import::demo::lambert_material([0.5; 3]);
    m.emission = [1.0; 3];
    m.emissive_texture = 0;
    s.materials.push(Material { name: "ramp".into(), gpu: m });
    for (p, uv) in
        [([0.0, 0.0, 0.0], [0.0, 0.0]), ([1.0, 0.0, 0.0], [1.0, 0.0]), ([1.0, 0.0, -1.0], [1.0, 1.0])]
    {
        s.vertices.push(Vertex { position: p, normal: [0.0, 1.0, 0.0] });
        s.uvs.push(uv);
    }
    s.triangles.push([0, 1, 2]);
    s.triangle_materials.push(0);
    let bytes = compile(s, Settings { shaft_variants: Some(0), ..Default::default() });
    let file = KilnFile::from_bytes(&bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let lum: &[f32] = view.emitter_luminance().unwrap().expect("an emissive texture: the section");
    let want = 13.0 / 48.0;
    assert!((lum[0] - want).abs() < 0.03 * want, "mean emitted luminance {} against {want}", lum[0]);
}

#[test]
fn the_environment_on_the_command_line_plans_inspects_and_exports() {
    let dir = tempfile::tempdir().unwrap();
    let quick = ["--probes", "off", "--shaft-variants", "none", "--environment-res", "64"];
    let mut args = vec!["demo", "-o", "e.kiln", "--environment", "studio"];
    args.extend(quick);
    run::kiln(dir.path(), &args).expect(0);
    let inspect = run::kiln(dir.path(), &["inspect", "e.kiln"]);
    assert!(inspect.expect(0).stdout.contains("environment 64x32: 6 GGX levels from 64x32"), "{inspect:?}");
    run::kiln(dir.path(), &["export", "e.kiln", "environment-map", "-o", "map.exr"]).expect(0);
    // The studio (docs/sidecar.md): a dome of 0.8 + 0.2 y over a floor of 0.3; the top row
    // averages y close to 1, the bottom row is floor.
    let map = image::open(dir.path().join("map.exr")).unwrap().into_rgb32f();
    assert_eq!(map.dimensions(), (64, 32));
    for x in [0, 20, 63] {
        let (top, bottom) = (map.get_pixel(x, 0)[1], map.get_pixel(x, 31)[1]);
        assert!((top - 1.0).abs() < 0.01 && (bottom - 0.3).abs() < 0.01, "column {x}: {top}, {bottom}");
    }
    run::kiln(dir.path(), &["export", "e.kiln", "environment-filtered:5", "-o", "f5.exr"]).expect(0);
    assert_eq!(image::open(dir.path().join("f5.exr")).unwrap().into_rgb32f().dimensions(), (2, 1));
    run::kiln(dir.path(), &["export", "e.kiln", "environment-filtered:6", "-o", "x.exr"])
        .expect(1)
        .says("no environment-filtered:6");
    // Without an environment there is nothing to export.
    run::kiln(dir.path(), &["demo", "-o", "plain.kiln", "--probes", "off", "--shaft-variants", "none"])
        .expect(0);
    run::kiln(dir.path(), &["export", "plain.kiln", "environment-map", "-o", "x.exr"])
        .expect(1)
        .says("no environment-map");
    // Usage: the environment's options need --environment; sun keys need their source.
    run::kiln(dir.path(), &["demo", "-o", "x.kiln", "--environment-sun", "off"]).expect(2);
    std::fs::write(dir.path().join("bad.toml"), "[sky]\nturbidity = 4.0\n").unwrap();
    run::kiln(dir.path(), &["demo", "-o", "x.kiln", "-c", "bad.toml"]).expect(1).says("preetham");
    std::fs::write(dir.path().join("both.toml"), "[sky]\nmodel = \"studio\"\nimage = \"a.hdr\"\n").unwrap();
    run::kiln(dir.path(), &["demo", "-o", "x.kiln", "-c", "both.toml"]).expect(1).says("not both");
}
