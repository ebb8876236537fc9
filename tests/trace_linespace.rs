//! The GPU line-space queries (`shaders/common/linespace.glsl`) against the CPU queries of
//! `kiln-format` (double precision) and brute force, on the ray classes of `kiln verify --rays`
//! (random, aimed, axis-aligned, at vertices and edges, grazing, from surfaces, through grid
//! corners and edges, in cell planes, from inside cells, finite segments): a soup, a grid far from
//! the origin, and the shared Cornell box; and the same answers, bit for bit, when the arrays are
//! split over several storage buffers.
//!
//! - candidates, closest and any hit: exactly the CPU's answers (up to ties in distance);
//! - binary: never a miss where brute force hits (conservative); the CPU's answer on all but a
//!   few rays whose line passes within rounding of a patch border (bounded below);
//! - binary with exact ends: between brute force and the binary answer;
//! - binary with exact filled cells: exactly brute force;
//! - PNMT: the CPU's record (hit or miss, `t`, material, uv) on all but a few border rays, in
//!   each record layout: compact with uv (the textured soup), full (the far grid), compact
//!   without uv (the Cornell box).
//!
//! Needs a Vulkan device; without one the tests say so and pass, unless `KILN_REQUIRE_VULKAN`
//! is set (as `.ci/run` does).

use std::time::Instant;

use glam::Vec3;
use kiln_compiler::raycheck::{RayClass, RaySample, Rng, generate_grid};
use kiln_compiler::settings::{PnmtRecords, Settings, VoxelRes};
use kiln_format::linespace::{LineSpace, PnmtLayout, Variants};
use kiln_format::query::{BruteForce, IndexedTriangles, Ray, TriangleSource, intersect_triangle};
use kiln_format::{Checksums, KilnFile, SceneView};
use kiln_player::session::Session;
use kiln_player::trace::{GpuHit, GpuRay, NO_HIT};
use kiln_player::trace_linespace::{LineSpaceQuery, LsQuery};
use kiln_test_support::{require, vulkan};
use kiln_tests::shapes::{height_grid, soup, transformed};
use kiln_tests::{Options, compile, scene_of, shared_scenes};

fn settings(res: u32, n: u32) -> Settings {
    Settings {
        voxel_res: VoxelRes::Cells(res),
        shaft_res: Some(n),
        shaft_variants: Some(Variants::ALL),
        shadow_res: 16,
        ..Default::default()
    }
}

/// Every query's GPU answers for `rays`, with storage buffers capped at `cap` bytes.
fn gpu_answers(bytes: &[u8], rays: &[GpuRay], normals: &[[f32; 4]], cap: Option<u64>) -> Vec<Vec<GpuHit>> {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("scene.kiln");
    std::fs::write(&file, bytes).unwrap();
    let mut options = Options::new(file, 8, 8).unshadowed().rays().build();
    options.gpu.max_storage_buffer = cap;
    let session = Session::open(&options, Instant::now()).unwrap();
    let bvh = session.scene.bvh.as_ref().expect("the BVH is resident");
    let ls = session.scene.line_space.as_ref().expect("the line space is resident");
    if let Some(cap) = cap {
        assert!(ls.chunks.len() >= 2, "a cap of {cap} bytes should split the line space");
        assert!(ls.chunks.iter().all(|c| c.size <= cap), "a chunk exceeds the cap");
    }
    let mut query = LineSpaceQuery::new(&session.gpu).unwrap();
    let answers = LsQuery::ALL
        .iter()
        .map(|&q| query.trace(&session.gpu, bvh, ls, rays, normals, q).unwrap().0)
        .collect();
    drop(query);
    assert_eq!(session.close(), 0, "validation errors");
    answers
}

/// Bytes of the line-space sections in the file.
fn line_space_bytes(file: &KilnFile) -> u64 {
    use kiln_format::sections::*;
    [
        VOXEL_OFFSETS,
        VOXEL_TRIANGLES,
        SHAFT_SLOTS,
        SHAFT_BITS,
        SHAFT_RANKS,
        CANDIDATE_OFFSETS,
        CANDIDATES,
        PNMT,
        PREILLUM,
    ]
    .iter()
    .filter_map(|&k| file.find(k, 0))
    .map(|s| s.entry.raw_size)
    .sum()
}

/// Share of the general rays on which binary or PNMT may differ from the CPU: those passing
/// within rounding of a patch border, where single and double precision pick neighbouring shafts.
const GENERAL_SHARE: f64 = 0.005;
/// The same for the rays aimed exactly at cell corners and edges or lying in cell planes, where
/// every ray is a border case.
const BORDER_SHARE: f64 = 0.15;

fn check(bytes: &[u8], n: u64, seed: u64, what: &str, layout: PnmtLayout) {
    let file = KilnFile::from_bytes(bytes, Checksums::Eager).unwrap();
    let view = SceneView::new(&file).unwrap();
    let tris = IndexedTriangles { vertices: view.vertices, triangles: view.triangles };
    let ls =
        LineSpace::new(&file, view.triangles.len(), view.materials.len()).unwrap().expect("a line space");
    assert_eq!(ls.pnmt_layout, layout, "{what}: PNMT records");
    let (lo, hi) = (Vec3::from(view.manifest.bounds.min), Vec3::from(view.manifest.bounds.max));
    let samples: Vec<RaySample> = generate_grid(&tris, &ls, lo, hi, n, seed);
    let rays: Vec<Ray> = samples.iter().map(|s| s.ray).collect();
    // The geometric normal of the surface a ray leaves, on the side it leaves into.
    let normals: Vec<Option<Vec3>> = samples
        .iter()
        .map(|s| {
            s.origin_triangle.map(|t| {
                let [a, b, c] = tris.corners(t as usize);
                let n = (b - a).cross(c - a).normalize_or(Vec3::Z);
                if n.dot(s.ray.direction) < 0.0 { -n } else { n }
            })
        })
        .collect();
    let gpu_rays: Vec<GpuRay> = rays
        .iter()
        .map(|r| GpuRay {
            origin: r.origin.to_array(),
            tmin: r.tmin,
            direction: r.direction.to_array(),
            tmax: r.tmax,
        })
        .collect();
    let gpu_normals: Vec<[f32; 4]> =
        normals.iter().map(|n| n.map_or([0.0; 4], |n| n.extend(0.0).to_array())).collect();

    let whole = gpu_answers(bytes, &gpu_rays, &gpu_normals, None);
    // Split into 3 to 6 buffers: every answer must stay the same, bit for bit.
    let cap = (line_space_bytes(&file) / 6).next_power_of_two().max(16);
    let split = gpu_answers(bytes, &gpu_rays, &gpu_normals, Some(cap));
    for (q, (a, b)) in LsQuery::ALL.iter().zip(whole.iter().zip(&split)) {
        let differ =
            a.iter().zip(b).filter(|(x, y)| bytemuck::bytes_of(*x) != bytemuck::bytes_of(*y)).count();
        assert_eq!(differ, 0, "{what}: {}: {differ} answers change when the arrays are split", q.name());
    }
    let answer = |q: LsQuery| &whole[q as usize];

    let brute = BruteForce::new(&tris);
    let (mut ties, mut binary_extra, mut ends_extra) = (0, 0, 0);
    // Disagreements with the CPU, [general rays, rays on cell borders].
    let (mut binary_differ, mut pnmt_differ, mut count) = ([0u32; 2], [0u32; 2], [0u32; 2]);
    for (i, ray) in rays.iter().enumerate() {
        let truth = brute.any_hit(ray);
        let border =
            matches!(samples[i].class, RayClass::VoxelCorner | RayClass::VoxelEdge | RayClass::FacePlane)
                as usize;
        count[border] += 1;
        // Candidates: the CPU's closest hit, up to ties.
        let want = ls.closest_hit(&tris, ray);
        let got = answer(LsQuery::CandidatesClosest)[i];
        match want {
            None => {
                assert_eq!(got.t, NO_HIT, "{what}: ray {i} {ray:?}: GPU candidates hit {got:?}, CPU none")
            }
            Some(w) => {
                assert!(got.t != NO_HIT, "{what}: ray {i} {ray:?}: GPU candidates missed, CPU hit {w:?}");
                let tol = 1e-6 * w.t.abs().max(1e-30);
                assert!((got.t - w.t).abs() <= tol, "{what}: ray {i}: GPU t {} vs CPU t {}", got.t, w.t);
                if got.triangle != w.triangle {
                    let other = intersect_triangle(ray, tris.corners(got.triangle as usize), f32::INFINITY)
                        .unwrap_or_else(|| {
                            panic!("{what}: ray {i}: GPU triangle {} is not hit", got.triangle)
                        });
                    assert!((other.t - w.t).abs() <= tol, "{what}: ray {i}: a tie that is not one");
                    ties += 1;
                }
            }
        }
        let any = answer(LsQuery::CandidatesAny)[i].t != NO_HIT;
        assert_eq!(any, ls.any_hit(&tris, ray), "{what}: ray {i} {ray:?}: candidates any-hit disagrees");
        // Exact any hit with the bits as a skip test: brute force.
        let filled = answer(LsQuery::BinaryFilled)[i].t != NO_HIT;
        assert_eq!(
            filled, truth,
            "{what}: ray {i} {ray:?}: binary with exact filled cells disagrees with brute force"
        );
        // Binary: conservative, and the CPU's answer but for border rays.
        let binary = answer(LsQuery::Binary)[i].t != NO_HIT;
        assert!(binary || !truth, "{what}: ray {i} {ray:?}: binary false miss");
        binary_differ[border] += (binary != ls.any_hit_binary(ray)) as u32;
        binary_extra += (binary && !truth) as u32;
        // Exact ends: between the two.
        let ends = answer(LsQuery::BinaryEnds)[i].t != NO_HIT;
        assert!(ends || !truth, "{what}: ray {i} {ray:?}: binary with exact ends misses a hit");
        assert!(!ends || binary, "{what}: ray {i} {ray:?}: exact ends report a hit the bits do not");
        ends_extra += (ends && !truth) as u32;
        // PNMT: the CPU's record.
        let p = answer(LsQuery::Pnmt)[i];
        match ls.pnmt_hit(ray, normals[i]) {
            None => pnmt_differ[border] += (p.t != NO_HIT) as u32,
            Some(w) => {
                // The same record: t within its single-precision rounding (a ten-thousandth of a
                // cell, 6 times the position's quantisation step, or 1e-6 relative).
                let tol = 1e-4 * ls.header.cell / ray.direction.length() as f64 + 1e-6 * w.t.abs();
                let same = p.t != NO_HIT
                    && (p.t as f64 - w.t).abs() <= tol
                    && p.triangle == w.hit.material as u32
                    && (p.u, p.v) == (w.hit.uv.x, w.hit.uv.y);
                pnmt_differ[border] += !same as u32;
            }
        }
    }
    eprintln!(
        "{what}: {} rays ({} general, {} on cell borders), {ties} ties; binary: {binary_differ:?} differ from the \
         CPU, {binary_extra} false hits (exact ends: {ends_extra}); PNMT: {pnmt_differ:?} differ from the CPU; \
         split into {cap}-byte buffers",
        rays.len(),
        count[0],
        count[1]
    );
    for (k, (limit, name)) in
        [(GENERAL_SHARE, "general"), (BORDER_SHARE, "cell-border")].into_iter().enumerate()
    {
        let allowed = (limit * count[k] as f64).ceil() as u32;
        assert!(
            binary_differ[k] <= allowed,
            "{what}: binary differs from the CPU on {} {name} rays",
            binary_differ[k]
        );
        assert!(
            pnmt_differ[k] <= allowed,
            "{what}: PNMT differs from the CPU on {} {name} rays",
            pnmt_differ[k]
        );
    }
    assert!(ends_extra <= binary_extra, "{what}: exact ends add false hits");
}

/// `scene` with texture coordinates (a different pair at every vertex) and a base-colour
/// texture, so that its PNMT records keep their uv.
fn textured(mut scene: kiln_compiler::ir::Scene) -> kiln_compiler::ir::Scene {
    scene.uvs = scene
        .vertices
        .iter()
        .map(|v| [v.position[0] * 3.0 - 1.0, v.position[1] + 0.5 * v.position[2]])
        .collect();
    scene.textures.push(kiln_compiler::ir::Texture {
        name: "checker".into(),
        width: 4,
        height: 4,
        rgba: (0..16).flat_map(|i| if (i + i / 4) % 2 == 0 { [230; 4] } else { [40, 40, 40, 255] }).collect(),
        role: kiln_compiler::ir::TextureRole::Color,
        wrap_u: kiln_format::manifest::Wrap::Repeat,
        wrap_v: kiln_format::manifest::Wrap::Repeat,
        mag_linear: true,
    });
    scene.materials[0].gpu.base_color_texture = 0;
    scene
}

#[test]
fn gpu_line_space_equals_the_cpu_queries_on_shapes() {
    require!(vulkan());
    let mut rng = Rng::new(11);
    let soup = textured(scene_of(&soup(&mut rng, 1500, 0.15)));
    check(&compile(soup, settings(8, 4)), 3000, 1, "textured soup", PnmtLayout::Compact);
    let grid = height_grid(12, 0.2, &mut rng);
    check(
        &compile(
            scene_of(&transformed(&grid, 1.0, Vec3::splat(1e5))),
            Settings { pnmt_records: PnmtRecords::Full, ..settings(6, 3) },
        ),
        3000,
        2,
        "grid at 1e5",
        PnmtLayout::Full,
    );
}

#[test]
fn gpu_line_space_equals_the_cpu_queries_on_the_cornell_box() {
    require!(vulkan());
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let scene = kiln_compiler::import::import(&scenes.join("cornell_box").join("scene.gltf")).unwrap();
    check(&compile(scene, settings(8, 4)), 4000, 5, "cornell_box", PnmtLayout::CompactNoUv);
}
