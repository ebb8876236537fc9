//! Shared helpers of the workspace-level tests: scenes built in code and compiled in memory, and
//! the player options the tests render with.

use std::path::PathBuf;

use glam::Vec3;
use kiln_compiler::ir::{Material, Scene};
use kiln_compiler::settings::Settings;
use kiln_format::sections::Vertex;
use kiln_player::camera::{CameraOverride, CameraPath};
use kiln_player::gpu::GpuOptions;
use kiln_player::render::techniques::gi::linespace::GiStructure;
use kiln_player::render::techniques::reflections::rt::ReflectionRes;
use kiln_player::render::techniques::shadows::linespace::LsShadowTest;
use kiln_player::render::techniques::{
    Direct, KnobValue, ao as ao_techniques, direct, gbuffer, gi, media, reflections, shadows,
};
use kiln_player::render::{
    Aa, Ao, Effect, GBuffer as GBufferTechnique, Gi, Media, Purpose, Reflections as ReflectionsTechnique,
    Shadows,
};
use kiln_player::scene::TextureUpload;
use kiln_player::session::{PipelineStart, SessionOptions};

pub mod boxes;
pub mod corpus;
pub mod equirect;
pub mod exact;

/// The shared scene folder (`../shared/scenes` beside the checkout), if present; if not, says
/// that the test skips.
pub fn shared_scenes() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/scenes");
    if !dir.is_dir() {
        eprintln!("skipping: ../shared/scenes is not here");
        return None;
    }
    Some(dir)
}

/// A scene of the given triangles (one grey Lambertian material, flat normals; a Lambertian
/// scene needs no BRDF table, which keeps compiling thousands of test scenes quick).
pub fn scene_of(tris: &[[Vec3; 3]]) -> Scene {
    let mut s = Scene { name: "test".into(), ..Default::default() };
    s.materials
        .push(Material { name: "m".into(), gpu: kiln_compiler::import::demo::lambert_material([0.5; 3]) });
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(Vec3::Z);
        let base = s.vertices.len() as u32;
        for p in t {
            s.vertices.push(Vertex { position: p.to_array(), normal: n.to_array() });
        }
        s.triangles.push([base, base + 1, base + 2]);
        s.triangle_materials.push(0);
    }
    s
}

/// Compiles a scene in memory (as `kiln compile` would) and returns the file's bytes.
pub fn compile(scene: Scene, settings: Settings) -> Vec<u8> {
    kiln_compiler::pipeline::compile_to_bytes(scene, settings, "test").expect("valid scene")
}

/// Re-writes a file with one section's bytes changed by `edit` (checksums made right again), so
/// that only the contents' validation can refuse it.
pub fn rewrite(bytes: &[u8], kind: kiln_format::SectionKind, edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    use kiln_format::{Checksums, ContentHash, FileWriter, KilnFile};
    let file = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    let mut w = FileWriter::new();
    let mut edit = Some(edit);
    for s in file.sections() {
        let mut data = file.section_bytes(s).unwrap().into_owned();
        if s.entry.kind == kind {
            (edit.take().unwrap())(&mut data);
        }
        w.raw(s.entry.kind, s.entry.index, s.entry.version, data, ContentHash::default()).unwrap();
    }
    w.to_bytes().unwrap()
}

/// How a G-buffer is made, as the tests name it (see [`Options::gbuffer`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GBuffer {
    /// Rasterised, every material evaluated per fragment.
    Raster,
    /// A visibility buffer resolved in compute.
    Visibility,
}

/// The resolution of the ray-traced reflections (see [`Options::rt_reflections`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reflections {
    /// One ray per pixel.
    Full,
    /// One ray per 2 × 2 pixels, upsampled.
    Half,
}

/// The player options a test renders with, built from what the test means ("no shadows",
/// "ray-traced AO of radius r"). This is the one place the tests spell out the player's settings
/// types: a change to them is made here, not in every test.
#[derive(Debug, Clone)]
pub struct Options(SessionOptions);

impl Options {
    /// `file` at `width` × `height` with the validation layer on, otherwise what `kiln-play` does
    /// without flags but for its one ray-traced pass: shadow maps, no direct light of emissive
    /// surfaces (`--direct none`; [`Options::ris`], [`Options::restir`] turn it on), and the
    /// raster G-buffer (kiln-play's default is the visibility buffer; the tests that judge a
    /// technique keep the G-buffer they were written with; `scenes.rs`, `textures.rs` and
    /// `analytic.rs` compare the two).
    pub fn new(file: impl Into<PathBuf>, width: u32, height: u32) -> Options {
        let mut o = SessionOptions {
            gpu: GpuOptions { validate: true, ..Default::default() },
            ..SessionOptions::new(file, width, height)
        };
        o.render.techniques.direct = Direct::Off(direct::none::Off);
        o.render.techniques.gbuffer = GBufferTechnique::Raster(gbuffer::raster::Raster);
        Options(o)
    }

    /// The emissive surfaces' direct light by resampled importance sampling of `candidates`
    /// candidates per pixel and frame (`--direct ris`).
    pub fn ris(mut self, candidates: u32) -> Options {
        self.0.render.techniques.direct =
            Direct::Ris(direct::ris::Ris { candidates, spatial: 0, temporal: 0 });
        self
    }

    /// The emissive surfaces' direct light by ReSTIR DI (`--direct restir`): `candidates` per
    /// pixel, `spatial` neighbours, the previous frame capped at `temporal` times the candidates.
    pub fn restir(mut self, candidates: u32, spatial: u32, temporal: u32) -> Options {
        self.0.render.techniques.direct =
            Direct::Restir(direct::restir::Restir { candidates, spatial, temporal });
        self
    }

    /// The denoiser (`--denoise svgf`) with `iterations` à-trous iterations of `taps` × `taps`
    /// (3 or 5), the other knobs at their defaults.
    pub fn svgf(mut self, iterations: u32, taps: u32) -> Options {
        let knobs = [
            ("denoise-iterations", KnobValue::Number(iterations as f32)),
            ("denoise-taps", KnobValue::Choice(if taps == 5 { 1 } else { 0 })),
        ];
        self.0.render.techniques.set(Effect::Denoise, "svgf", &knobs).expect("svgf's knobs");
        self
    }

    /// The player's default direct light of emissive surfaces (`kiln-play` without `--direct`).
    pub fn default_direct(mut self) -> Options {
        self.0.render.techniques.direct = Direct::default();
        self
    }

    /// No shadow maps (`--shadows none`; with a ray-traced pass, only what that pass gives).
    pub fn unshadowed(mut self) -> Options {
        let t = &mut self.0.render.techniques;
        if t.name_of(Effect::Shadows) == "shadowmap" {
            t.shadows = Shadows::Off(shadows::none::Off);
        }
        self
    }

    /// Looks through `camera` instead of the file's.
    pub fn camera(mut self, camera: CameraOverride) -> Options {
        self.0.camera = Some(camera);
        self
    }

    /// Makes the G-buffer the given way.
    pub fn gbuffer(mut self, gbuffer: GBuffer) -> Options {
        self.0.render.techniques.gbuffer = match gbuffer {
            GBuffer::Raster => GBufferTechnique::Raster(gbuffer::raster::Raster),
            GBuffer::Visibility => GBufferTechnique::Visibility(gbuffer::visibility::Visibility),
        };
        self
    }

    /// Ray-traced shadows instead of shadow maps, point and spot lights spheres of
    /// `light_radius`, directional lights `sun_degrees` wide (0 and 0: hard shadows).
    pub fn rt_shadows(mut self, light_radius: f32, sun_degrees: f32) -> Options {
        self.0.render.techniques.shadows = Shadows::Rt(shadows::rt::Rt { light_radius, sun_degrees });
        self
    }

    /// Line-space shadow feelers (`--shadows linespace`) with hard lights, exact in filled
    /// shafts (`exact`) or near the rays' ends only.
    pub fn line_space_shadows(mut self, exact: bool) -> Options {
        let test = if exact { LsShadowTest::Filled } else { LsShadowTest::Ends };
        self.0.render.techniques.shadows =
            Shadows::LineSpace(shadows::linespace::LineSpace { light_radius: 0.0, sun_degrees: 0.0, test });
        self
    }

    /// Ray-traced ambient occlusion, rays of length `radius` (`None`: the player's default).
    pub fn rt_ao(mut self, radius: Option<f32>) -> Options {
        self.0.render.techniques.ao =
            Ao::Rt(ao_techniques::rt::Rt { radius: ao_techniques::Radius { radius, reach: 0.1 } });
        self
    }

    /// Ambient occlusion by `ao` (any technique).
    pub fn ao(mut self, ao: Ao) -> Options {
        self.0.render.techniques.ao = ao;
        self
    }

    /// Ray-traced reflections at the given resolution.
    pub fn rt_reflections(mut self, res: Reflections) -> Options {
        let res = match res {
            Reflections::Full => ReflectionRes::Full,
            Reflections::Half => ReflectionRes::Half,
        };
        self.0.render.techniques.reflections = ReflectionsTechnique::Rt(reflections::rt::Rt {
            resolution: res,
            max_roughness: 1.0,
            metal_bounce: reflections::rt::METAL_BOUNCE,
        });
        self
    }

    /// With ray-traced reflections: metal hits smoother than `roughness` reflect by one more
    /// traced ray (`--reflection-metal-bounce`; 0: never).
    pub fn metal_bounce(mut self, roughness: f32) -> Options {
        if let ReflectionsTechnique::Rt(r) = &mut self.0.render.techniques.reflections {
            r.metal_bounce = roughness;
        }
        self
    }

    /// Reflections by `reflections` (any technique).
    pub fn reflections(mut self, reflections: ReflectionsTechnique) -> Options {
        self.0.render.techniques.reflections = reflections;
        self
    }

    /// Path-traced diffuse GI counting `bounces` scattering events after the visible surface.
    pub fn rt_gi(mut self, bounces: u32) -> Options {
        let regularize = gi::GI_REGULARIZE.default.number();
        self.0.render.techniques.gi = Gi::Rt(gi::rt::Rt { bounces, regularize });
        self
    }

    /// Path-traced GI through the line space with `bounces` bounces, bounce rays through
    /// `structure`.
    pub fn line_space_gi(mut self, bounces: u32, structure: GiStructure) -> Options {
        let regularize = gi::GI_REGULARIZE.default.number();
        self.0.render.techniques.gi =
            Gi::LineSpace(gi::linespace::LineSpace { bounces, structure, regularize });
        self
    }

    /// Global illumination by `gi` (any technique).
    pub fn gi(mut self, gi: Gi) -> Options {
        self.0.render.techniques.gi = gi;
        self
    }

    /// Participating media by ray marching (`--media march`) with `steps` steps per medium.
    pub fn media_march(mut self, steps: u32) -> Options {
        self.0.render.techniques.media = Media::March(media::march::March { steps });
        self
    }

    /// Participating media by `media` (any technique).
    pub fn media(mut self, media: Media) -> Options {
        self.0.render.techniques.media = media;
        self
    }

    /// Samples across frames by `aa` (`--aa`).
    pub fn aa(mut self, aa: Aa) -> Options {
        self.0.render.techniques.aa = aa;
        self
    }

    /// Moves the camera through `path` over the frames (`--camera-path`).
    pub fn camera_path(mut self, path: CameraPath) -> Options {
        self.0.camera_path = Some(path);
        self
    }

    /// Textures streamed: the first frame samples their coarse levels, the finer ones upload
    /// after it (what `kiln-play` does without `--no-texture-streaming`).
    pub fn streaming(mut self) -> Options {
        self.0.textures = TextureUpload::CoarseFirst;
        self
    }

    /// The first frames from the fallback while the ray-traced pipelines compile (what
    /// `kiln-play` does without `--no-progressive-pipelines`).
    pub fn progressive(mut self) -> Options {
        self.0.pipelines = PipelineStart::Progressive;
        self
    }

    /// The techniques a session shows while the ray-traced pipelines compile, chosen instead
    /// (to render what the fallback renders, with every pipeline built first).
    pub fn as_fallback(mut self, file_has_shadow_maps: bool) -> Options {
        let t = &mut self.0.render.techniques;
        *t = t.fallback(file_has_shadow_maps).expect("a ray-traced technique is chosen");
        self
    }

    /// Uploads the BVH for ray queries (`RayQuery`).
    pub fn rays(mut self) -> Options {
        self.0.render.purpose = Purpose::RayQueries;
        self
    }

    /// Uploads what the reference path tracer reads.
    pub fn reference(mut self) -> Options {
        self.0.render.purpose = Purpose::Reference;
        self
    }

    /// The player's options.
    pub fn build(self) -> SessionOptions {
        self.0
    }
}

/// Shapes the query tests share.
pub mod shapes {
    use glam::Vec3;
    use kiln_compiler::raycheck::Rng;

    /// `n` random triangles of edge up to `size` in [−1, 1]³.
    pub fn soup(rng: &mut Rng, n: usize, size: f32) -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|_| {
                let c = rng.in_box(Vec3::splat(-1.0), Vec3::splat(1.0));
                [c, c + rng.direction() * size * rng.f32(), c + rng.direction() * size * rng.f32()]
            })
            .collect()
    }

    /// A height field of `n × n` quads over [0, 1]² sharing edges and vertices, heights up to
    /// `amplitude`.
    pub fn height_grid(n: usize, amplitude: f32, rng: &mut Rng) -> Vec<[Vec3; 3]> {
        let h: Vec<f32> = (0..(n + 1) * (n + 1)).map(|_| rng.f32() * amplitude).collect();
        let p = |i: usize, j: usize| Vec3::new(i as f32 / n as f32, h[i * (n + 1) + j], j as f32 / n as f32);
        (0..n * n)
            .flat_map(|k| {
                let (i, j) = (k / n, k % n);
                [[p(i, j), p(i + 1, j), p(i + 1, j + 1)], [p(i, j), p(i + 1, j + 1), p(i, j + 1)]]
            })
            .collect()
    }

    /// Scaled and moved copies.
    pub fn transformed(tris: &[[Vec3; 3]], scale: f32, offset: Vec3) -> Vec<[Vec3; 3]> {
        tris.iter().map(|t| t.map(|p| p * scale + offset)).collect()
    }

    /// A closed unit sphere of `nu` × `nv` quads (triangles at the poles).
    pub fn sphere(nu: usize, nv: usize) -> Vec<[Vec3; 3]> {
        let p = |i: usize, j: usize| {
            let (u, v) =
                (i as f32 / nu as f32 * std::f32::consts::TAU, j as f32 / nv as f32 * std::f32::consts::PI);
            if j == 0 {
                Vec3::Y
            } else if j == nv {
                Vec3::NEG_Y
            } else {
                Vec3::new(v.sin() * u.cos(), v.cos(), v.sin() * u.sin())
            }
        };
        let mut tris = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (a, b, c, d) = (p(i, j), p((i + 1) % nu, j), p((i + 1) % nu, j + 1), p(i, j + 1));
                if j != 0 {
                    tris.push([a, b, d]);
                }
                if j != nv - 1 {
                    tris.push([b, c, d]);
                }
            }
        }
        tris
    }

    /// The surface of the cube [−h, h]³ on the integer lattice: each face `2h × 2h` unit squares,
    /// split along alternating diagonals. Every corner, edge midpoint and edge quarter point is
    /// exact in `f32`, and from the centre every such point has a dominant coordinate of ±h.
    pub fn lattice_cube(h: i32) -> Vec<[Vec3; 3]> {
        let mut tris = Vec::new();
        for axis in 0..3 {
            for side in [-h, h] {
                let p = |i: i32, j: i32| {
                    let mut v = [0.0; 3];
                    v[axis] = side as f32;
                    v[(axis + 1) % 3] = i as f32;
                    v[(axis + 2) % 3] = j as f32;
                    Vec3::from(v)
                };
                for i in -h..h {
                    for j in -h..h {
                        let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                        if (i + j) % 2 == 0 {
                            tris.extend([[a, b, c], [a, c, d]]);
                        } else {
                            tris.extend([[a, b, d], [b, c, d]]);
                        }
                    }
                }
            }
        }
        tris
    }

    /// The surface |x| + |y| + |z| = m on the integer lattice: each of the eight faces cut into
    /// m² triangles. Its faces are not axis-aligned, and directions from inside to its lattice
    /// points mostly have dominant coordinates that are not powers of two.
    pub fn lattice_octahedron(m: i32) -> Vec<[Vec3; 3]> {
        let mut tris = Vec::new();
        for signs in 0..8 {
            let s = Vec3::new(
                if signs & 1 == 0 { 1.0 } else { -1.0 },
                if signs & 2 == 0 { 1.0 } else { -1.0 },
                if signs & 4 == 0 { 1.0 } else { -1.0 },
            );
            let p = |i: i32, j: i32| Vec3::new(i as f32, j as f32, (m - i - j) as f32) * s;
            for i in 0..m {
                for j in 0..m - i {
                    tris.push([p(i, j), p(i + 1, j), p(i, j + 1)]);
                    if i + j < m - 1 {
                        tris.push([p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]);
                    }
                }
            }
        }
        tris
    }

    /// The same triangles with their corners rotated (and, for half of them, reversed) at
    /// random: a triangle test handles its three edges in different expressions, and a shared
    /// edge should meet every pair of them.
    pub fn shuffled_corners(tris: &[[Vec3; 3]], rng: &mut Rng) -> Vec<[Vec3; 3]> {
        tris.iter()
            .map(|&t| {
                let r = rng.below(3);
                let t = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
                if rng.below(2) == 0 { t } else { [t[0], t[2], t[1]] }
            })
            .collect()
    }

    /// The corners of `tris` and the points at a quarter, half and three quarters along each
    /// edge, each once.
    pub fn corners_and_edge_points(tris: &[[Vec3; 3]]) -> Vec<Vec3> {
        let mut seen = std::collections::BTreeSet::new();
        let mut out = Vec::new();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for f in [0.0, 0.25, 0.5, 0.75] {
                    let p = a + (b - a) * f;
                    if seen.insert(p.to_array().map(f32::to_bits)) {
                        out.push(p);
                    }
                }
            }
        }
        out
    }
}
