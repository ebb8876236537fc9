//! The bake plan: every stage with *run* or *skip* and the reason, decided from the scene and
//! settings alone, before any bake work.

use serde::Serialize;

use crate::ir::Scene;
use kiln_format::manifest::LightKind;
use kiln_format::readers;

use crate::analyze::budget::{self, Choice, Request};
use crate::analyze::geometry::SceneGeometry;
use crate::analyze::limits::{Product, Spending};
use crate::bake::linespace::voxelize::auto_resolution;
use crate::settings::{PnmtRecords, SHAFT_RES, Settings, VoxelRes, variants_name};
use kiln_format::linespace::{PnmtLayout, Variants};

/// The bake stages, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stage {
    /// Vertices, triangles (in BVH order) and per-triangle materials.
    Geometry,
    /// Texture coordinates.
    Uvs,
    /// Vertex colours.
    VertexColors,
    /// Material table.
    Materials,
    /// Texture mip chains.
    Textures,
    /// The compressed wide BVH.
    Bvh,
    /// The split-sum BRDF table.
    BrdfLut,
    /// Shadow maps of the shadow-casting lights.
    ShadowMaps,
    /// Light-visibility volume of the participating medium.
    MediaVisibility,
    /// The environment: radiance map, prefiltered levels, harmonics, sampling table.
    Environment,
    /// Irradiance probe volume, path traced.
    Probes,
    /// Cell triangle lists of the voxel grid.
    VoxelGrid,
    /// Shafts per non-empty cell: binary, candidates, PNMT.
    LineSpace,
}

impl Stage {
    /// Name as printed by `kiln plan` and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Geometry => "geometry",
            Stage::Uvs => "uvs",
            Stage::VertexColors => "vertex-colors",
            Stage::Materials => "materials",
            Stage::Textures => "textures",
            Stage::Bvh => "bvh",
            Stage::BrdfLut => "brdf-lut",
            Stage::ShadowMaps => "shadow-maps",
            Stage::MediaVisibility => "media-visibility",
            Stage::Environment => "environment",
            Stage::Probes => "probes",
            Stage::VoxelGrid => "voxel-grid",
            Stage::LineSpace => "line-space",
        }
    }
}

/// What the player's emitter table will hold (it is built at load from the materials and
/// triangles): the emissive triangles, how many materials they use and their total power.
fn emitters(scene: &Scene) -> String {
    use kiln_format::gpu::{emitted_power, luminance};
    let (mut triangles, mut power) = (0usize, 0.0f64);
    let mut used = vec![false; scene.materials.len()];
    for (t, &m) in scene.triangles.iter().zip(&scene.triangle_materials) {
        let Some(material) = scene.materials.get(m as usize) else { continue };
        let emission = material.gpu.emission;
        if luminance(emission) <= 0.0 {
            continue;
        }
        // The player's rule (scene/reference.rs): f32 corners, and a triangle enters the table
        // when its power is positive and finite.
        let p = t.map(|v| glam::Vec3::from(scene.vertices[v as usize].position));
        let p = emitted_power(emission, 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length());
        if p > 0.0 && p.is_finite() {
            triangles += 1;
            power += p as f64;
            used[m as usize] = true;
        }
    }
    if triangles == 0 {
        return "no emissive triangles (the player's direct light of emissive surfaces has nothing to sample)".to_string();
    }
    let materials = used.iter().filter(|&&u| u).count();
    format!(
        "emitter table: {triangles} emissive triangles of {materials} material{}, total power {power:.4} (pi x \
         luminance x area; {} KiB at load: 80 bytes a triangle in the path tracer's table and the direct \
         light's), sampled by the player's direct light of emissive surfaces and its \
         path tracers",
        if materials == 1 { "" } else { "s" },
        (triangles * 80).div_ceil(1024)
    )
}

/// The probe stage's decision and layout; the error (a usage error) says why the spacing asked
/// for does not fit.
fn probe_plan(
    scene: &Scene,
    geometry: &SceneGeometry,
    settings: &Settings,
    lit: bool,
) -> Result<(Decision, Option<crate::bake::probes::ProbeLayout>), String> {
    use crate::bake::probes;
    let skip = |why: &str| Ok((Decision { stage: Stage::Probes, run: false, reason: why.into() }, None));
    if settings.probes == crate::settings::Probes::Off {
        return skip("disabled by --probes off");
    }
    if scene.triangles.is_empty() {
        return skip("the scene has no triangles: nothing to light or to occlude");
    }
    if !lit {
        return skip(
            "nothing lights the scene (no light, emissive surface or sky): every probe would be black",
        );
    }
    let emits = scene.triangle_materials.iter().any(|&m| {
        scene.materials.get(m as usize).is_some_and(|m| kiln_format::gpu::luminance(m.gpu.emission) > 0.0)
    });
    let layers = if emits { 2 } else { 1 };
    let budget = settings.probe_budget as u64 * (1 << 20);
    let glossy = scene
        .triangle_materials
        .iter()
        .any(|&m| scene.materials.get(m as usize).is_some_and(|m| !m.gpu.diffuse_only()));
    let rays = settings.probe_rays.unwrap_or(if glossy {
        crate::settings::PROBE_RAYS_GLOSSY
    } else {
        crate::settings::PROBE_RAYS.default
    });
    let layout = probes::layout(
        &geometry.bounds,
        settings.probe_spacing.map(|s| s.0),
        budget,
        layers,
        rays,
        settings.probe_regularize.0,
    )?;
    // Paths a bake may trace: 2^28 (minutes on 16 cores; a hostile sidecar asks for more).
    const MAX_PATHS: u64 = 1 << 28;
    if layout.count() * layout.rays as u64 > MAX_PATHS {
        return Err(format!(
            "{} probes x {} paths each is more than the {MAX_PATHS} paths a bake may trace: lower --probe-rays or raise --probe-spacing",
            layout.count(),
            layout.rays
        ));
    }
    let [x, y, z] = layout.dims;
    let why_spacing = match settings.probe_spacing {
        Some(_) => String::new(),
        None => format!(
            " (the longest extent over {}, within --probe-budget {} MiB)",
            probes::AUTO_PROBES,
            settings.probe_budget
        ),
    };
    let why_rays = match (settings.probe_rays, glossy) {
        (Some(_), _) => "",
        (None, true) => " (glossy materials: the default for them, --probe-rays)",
        (None, false) => " (every material Lambertian: --probe-rays)",
    };
    let reason = format!(
        "{x}x{y}x{z} probes every {} scene units{why_spacing}, {}, {} paths each{why_rays}{}{}; read by kiln-play {}",
        short(layout.spacing as f64),
        if layout.bytes() < 1 << 20 {
            format!("{:.1} KiB", layout.bytes() as f64 / 1024.0)
        } else {
            mib(layout.bytes())
        },
        layout.rays,
        if layout.min_roughness > 0.0 {
            format!(" (surfaces met at least {} rough: --probe-regularize)", layout.min_roughness)
        } else {
            String::new()
        },
        if emits { ", emissive surfaces' direct light in a layer of its own" } else { "" },
        readers::list(readers::PROBES)
    );
    Ok((Decision { stage: Stage::Probes, run: true, reason }, Some(layout)))
}

/// One stage's decision.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Decision {
    /// Stage.
    pub stage: Stage,
    /// Whether it runs.
    pub run: bool,
    /// Why (for runs: what it will produce).
    pub reason: String,
}

/// The plan for a scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// Every stage, in order.
    pub stages: Vec<Decision>,
    /// Voxel grid cells along the longest axis (resolved from `auto`).
    pub voxel_res: u32,
    /// Shaft resolution N (resolved from the default by the budget).
    pub shaft_res: u32,
    /// Line-space variants to bake (0: none).
    pub shaft_variants: u32,
    /// How PNMT records are stored (resolved from the setting: without uv where no material
    /// samples a texture, full where materials outnumber the compact record's).
    #[serde(skip)]
    pub pnmt_layout: PnmtLayout,
    /// The line space's configuration, its estimated size and why (when baked).
    pub line_space: Option<Choice>,
    /// Where the irradiance probes go (when baked).
    #[serde(skip)]
    pub probes: Option<crate::bake::probes::ProbeLayout>,
}

impl Plan {
    /// Decides every stage; `geometry` is `scene`'s (its voxel grids are built here for the size
    /// estimate, and the chosen one reused by the bake). The error (a usage error) says why no
    /// line-space configuration fits the budget.
    pub fn new(scene: &Scene, geometry: &SceneGeometry, settings: &Settings) -> Result<Plan, String> {
        let run = |stage, reason: String| Decision { stage, run: true, reason };
        let skip = |stage, reason: &str| Decision { stage, run: false, reason: reason.to_string() };
        let textured =
            scene.materials.iter().filter(|m| m.gpu.textures().iter().any(|&t| t != u32::MAX)).count();
        let stages = vec![
            run(
                Stage::Geometry,
                format!("{} triangles, {} vertices", scene.triangles.len(), scene.vertices.len()),
            ),
            if textured > 0 {
                run(Stage::Uvs, format!("{textured} materials sample textures"))
            } else {
                skip(Stage::Uvs, "no material samples a texture")
            },
            if scene.colors.is_empty() {
                skip(Stage::VertexColors, "no vertex has a colour other than white")
            } else {
                run(Stage::VertexColors, format!("{} vertices coloured", scene.colors.len()))
            },
            run(Stage::Materials, format!("{} materials; {}", scene.materials.len(), emitters(scene))),
            if scene.textures.is_empty() {
                skip(Stage::Textures, "the scene has no textures")
            } else {
                run(
                    Stage::Textures,
                    format!(
                        "{} textures with full mip chains, --texture-format {}",
                        scene.textures.len(),
                        settings.texture_format.name()
                    ),
                )
            },
            run(Stage::Bvh, format!("CWBVH, preset {}", settings.bvh_preset.name())),
        ];
        let mut stages = stages;
        let specular = scene.materials.iter().filter(|m| !m.gpu.diffuse_only()).count();
        stages.push(if specular == 0 {
            skip(Stage::BrdfLut, "every material is pure Lambertian: no specular lobe to pre-integrate")
        } else {
            run(
                Stage::BrdfLut,
                format!(
                    "{0}x{0} texels for {specular} materials with a specular lobe",
                    settings.brdf_lut_res
                ),
            )
        });
        let casters = scene.lights.iter().filter(|l| l.casts_shadows).count();
        let mut spending = Spending::default();
        stages.push(if scene.lights.is_empty() {
            skip(Stage::ShadowMaps, "the scene has no analytic lights")
        } else if casters == 0 {
            skip(Stage::ShadowMaps, "no light casts shadows")
        } else {
            let cubes = scene
                .lights
                .iter()
                .filter(|l| l.casts_shadows && matches!(l.kind, LightKind::Point | LightKind::Rect { .. }))
                .count();
            // The maps as the bake lays them out (cube faces at half the resolution).
            let texels: u64 = scene
                .lights
                .iter()
                .enumerate()
                .filter_map(|(i, l)| {
                    crate::bake::shadow::layout(l, i as u32, &geometry.bounds, settings.shadow_res)
                })
                .map(|l| l.info.depth_count())
                .sum();
            let (res, face) = (settings.shadow_res, (settings.shadow_res / 2).max(1));
            let maps = [
                (casters - cubes > 0).then(|| format!("{} shadow maps of {res}x{res}", casters - cubes)),
                (cubes > 0).then(|| format!("{cubes} cube maps of 6x{face}x{face}")),
            ];
            spending.add(Product {
                what: format!(
                    "{} (--shadow-res {res})",
                    maps.into_iter().flatten().collect::<Vec<_>>().join(" and ")
                ),
                bytes: texels * 4,
                rays: texels,
            })?;
            run(
                Stage::ShadowMaps,
                format!(
                    "{} maps of {1}x{1}, {cubes} cube maps of 6x{2}x{2}; read by kiln-play {3}",
                    casters - cubes,
                    settings.shadow_res,
                    (settings.shadow_res / 2).max(1),
                    readers::list(readers::SHADOW_MAPS)
                ),
            )
        });
        // The sky's grids (three: red, green, blue) where a sky lights the scene.
        let sky = scene.sky_lights();
        stages.push(if scene.media.is_empty() {
            skip(Stage::MediaVisibility, "the scene has no participating medium")
        } else if casters == 0 && !sky {
            skip(Stage::MediaVisibility, "no light casts shadows and no sky lights the scene")
        } else {
            let dims = crate::bake::media::dims(&scene.media[0], settings.media_volume_res);
            let cells = dims.iter().map(|&d| d as u64).product::<u64>();
            let sky_grids = if sky { 3 } else { 0 };
            spending.add(Product {
                what: format!(
                    "light-visibility volumes of {}x{}x{} cells for {casters} lights{} (--media-volume-res {})",
                    dims[0],
                    dims[1],
                    dims[2],
                    if sky { " and the sky" } else { "" },
                    settings.media_volume_res
                ),
                bytes: cells * (casters as u64 + sky_grids),
                rays: cells
                    * (casters as u64 * crate::bake::media::SAMPLES as u64
                        + if sky { crate::bake::media::SKY_SAMPLES as u64 } else { 0 }),
            })?;
            run(
                Stage::MediaVisibility,
                format!(
                    "medium 0, {casters} lights{}, {} cells on the longest axis; read by kiln-play {}",
                    if sky { " and the sky (3 grids)" } else { "" },
                    settings.media_volume_res,
                    readers::list(readers::MEDIA_VISIBILITY)
                ),
            )
        });
        stages.push(match &scene.environment {
            None => skip(
                Stage::Environment,
                "no environment: the sky is a constant (give [sky] image or model, or --environment)",
            ),
            Some(env) => {
                let w = (settings.environment_res.min(env.width) & !1).max(2);
                // The map in E5B9G9R9 and its resampling in f32 RGB.
                spending.add(Product {
                    what: format!(
                        "an environment map {w} wide (--environment-res {})",
                        settings.environment_res
                    ),
                    bytes: w as u64 * (w / 2) as u64 * 16,
                    rays: 0,
                })?;
                let fw = crate::bake::environment::FILTERED_WIDTH.min(w);
                run(
                    Stage::Environment,
                    format!(
                        "{} ({}x{}): radiance map {w}x{}, {} GGX levels from {fw}x{}, irradiance harmonics, \
                         {}x{} sampling table; lights every technique and the reference",
                        env.name,
                        env.width,
                        env.height,
                        w / 2,
                        crate::bake::environment::LEVELS,
                        fw / 2,
                        crate::bake::environment::TABLE_WIDTH.min(w),
                        crate::bake::environment::TABLE_WIDTH.min(w) / 2
                    ),
                )
            }
        });
        let lit = scene.lit();
        let (probe_decision, probes) = probe_plan(scene, geometry, settings, lit)?;
        stages.push(probe_decision);
        if let Some(p) = &probes {
            spending.add(Product {
                what: format!("{} probes (--probe-spacing, --probe-budget)", p.count()),
                bytes: p.bytes(),
                rays: 0,
            })?;
        }
        let requested_res = match settings.voxel_res {
            VoxelRes::Auto => auto_resolution(scene.triangles.len()),
            VoxelRes::Cells(n) => n,
        };
        // When line space pays: whenever rays are traced through the scene, that is, whenever
        // something emits light. Even on the 32-triangle Cornell box (N = 4, 8^3 cells) the
        // binary variant's any-hit query ran 1.34x the BVH's any hit (5.0 vs 3.7 Mrays/s, one
        // thread, `cargo bench --bench queries`), and its line space is small (under 8 MiB at
        // auto resolution), so no triangle minimum would save anything worth a missing variant.
        // On the GPU (docs/linespace.md, "The line space on the GPU") the queries are no faster
        // than the player's CWBVH where their answer is usable; the technique that pays there is
        // GI from pre-illuminated records, which needs `--shaft-variants …,preillum` (its bake
        // shades every record: 90 s for the bunny-count box on 16 cores, too slow for a default).
        let wanted = match settings.shaft_variants {
            Some(v) => v != 0,
            None => lit,
        };
        // The default budget scales with the geometry sections the file will hold.
        let vertex_bytes =
            24 + if textured > 0 { 8 } else { 0 } + if scene.colors.is_empty() { 0 } else { 8 };
        let geometry_bytes =
            scene.vertices.len() as u64 * vertex_bytes + scene.triangles.len() as u64 * (12 + 4);
        let default_budget = budget::default_budget_mib(geometry_bytes);
        let (pnmt_layout, layout_why) = match settings.pnmt_records {
            PnmtRecords::Full => (PnmtLayout::Full, String::new()),
            PnmtRecords::Compact
                if scene.materials.len() > PnmtLayout::Compact.max_material() as usize + 1 =>
            {
                (
                    PnmtLayout::Full,
                    format!(
                        ", full PNMT records: {} materials are more than compact records address",
                        scene.materials.len()
                    ),
                )
            }
            PnmtRecords::Compact if textured == 0 => (PnmtLayout::CompactNoUv, String::new()),
            PnmtRecords::Compact => (PnmtLayout::Compact, String::new()),
        };
        if wanted {
            // The grid the line space's estimate builds first: a count and an offset per cell,
            // and the count's copy while they are summed.
            let g = crate::bake::linespace::voxelize::grid(&geometry.bounds, requested_res);
            let cells = g.dims.iter().map(|&d| d as u64).product::<u64>();
            spending.add(Product {
                what: format!(
                    "a voxel grid of {}x{}x{} cells (--voxel-res {requested_res})",
                    g.dims[0], g.dims[1], g.dims[2]
                ),
                bytes: cells * 12,
                rays: 0,
            })?;
        }
        let choice = if wanted {
            Some(budget::choose(
                geometry,
                Request {
                    voxel_res: (requested_res, matches!(settings.voxel_res, VoxelRes::Cells(_))),
                    shaft_res: (
                        settings.shaft_res.unwrap_or(SHAFT_RES.default),
                        settings.shaft_res.is_some(),
                    ),
                    variants: settings.shaft_variants,
                    budget_mib: (
                        settings.line_space_budget.unwrap_or(default_budget),
                        settings.line_space_budget.is_some(),
                    ),
                    pnmt_layout,
                },
            )?)
        } else {
            None
        };
        let (voxel_res, shaft_res, shaft_variants) = match &choice {
            Some(c) => (c.estimate.voxel_res, c.estimate.shaft_res, c.variants),
            None => (requested_res, settings.shaft_res.unwrap_or(SHAFT_RES.default), 0),
        };
        match &choice {
            None => {
                let why = if settings.shaft_variants.is_some() {
                    "disabled by --shaft-variants none"
                } else {
                    "nothing emits light, so no shadow or GI query needs it (ask with --shaft-variants)"
                };
                stages.push(skip(Stage::VoxelGrid, why));
                stages.push(skip(Stage::LineSpace, why));
            }
            Some(c) => {
                let e = &c.estimate;
                spending.add(Product {
                    what: format!(
                        "the line space at {} cells and N = {} (--voxel-res, --shaft-res, --line-space-budget)",
                        e.voxel_res, e.shaft_res
                    ),
                    bytes: c.bytes,
                    rays: 0,
                })?;
                let auto = match settings.voxel_res {
                    VoxelRes::Auto if voxel_res == requested_res => {
                        format!(" (auto: cube root of {} triangles)", scene.triangles.len())
                    }
                    _ => String::new(),
                };
                stages.push(run(
                    Stage::VoxelGrid,
                    format!(
                        "{voxel_res} cells on the longest axis{auto}, {}x{}x{}, cell {} scene units, {} non-empty",
                        e.dims[0],
                        e.dims[1],
                        e.dims[2],
                        short(e.cell),
                        e.slots
                    ),
                ));
                let budget = c.budget.map_or(String::new(), |b| format!(" of {} MiB", b >> 20));
                let default_why = match (c.budget, settings.line_space_budget) {
                    (Some(_), None) => format!(
                        "; the default budget is {}x the geometry's {} within {}..={} MiB: raise --line-space-budget for finer cells",
                        budget::DEFAULT_BUDGET_PER_GEOMETRY,
                        if geometry_bytes < 1 << 20 {
                            format!("{:.1} KiB", geometry_bytes as f64 / 1024.0)
                        } else {
                            mib(geometry_bytes)
                        },
                        budget::DEFAULT_BUDGET_MIN_MIB,
                        budget::DEFAULT_BUDGET_MAX_MIB
                    ),
                    _ => String::new(),
                };
                stages.push(run(
                    Stage::LineSpace,
                    format!(
                        "N = {shaft_res} (shafts span 1/{shaft_res} of a cell: patches of {} scene units), {}{}, about {}{budget} ({}); \
                         read by kiln-play {}{default_why}",
                        short(e.patch()),
                        variants_name(shaft_variants),
                        if shaft_variants & Variants::PNMT != 0 {
                            format!(
                                " ({} PNMT records of {} bytes{layout_why})",
                                pnmt_layout.name(),
                                4 * pnmt_layout.words()
                            )
                        } else {
                            String::new()
                        },
                        mib(c.bytes),
                        c.why,
                        readers::list(readers::LINE_SPACE)
                    ),
                ));
            }
        }
        Ok(Plan { stages, voxel_res, shaft_res, shaft_variants, pnmt_layout, line_space: choice, probes })
    }

    /// Whether `stage` runs.
    pub fn runs(&self, stage: Stage) -> bool {
        self.stages.iter().any(|d| d.stage == stage && d.run)
    }
}

/// `x` with four significant digits.
fn short(x: f64) -> String {
    format!("{x:.4}").trim_end_matches('0').trim_end_matches('.').to_string().replace("-0", "0")
}

/// Bytes as MiB with one decimal.
fn mib(b: u64) -> String {
    format!("{:.1} MiB", b as f64 / (1 << 20) as f64)
}
