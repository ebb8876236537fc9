//! What every bake stage reads, computed once before the first stage: the BVH and the triangles
//! in its leaf order, the GPU materials, the hash every stage's content hash starts from, and
//! (on first use) the BRDF table the shading scene needs.

use std::sync::OnceLock;
use std::time::Instant;

use kiln_format::manifest::InputFile;
use kiln_format::query::IndexedTriangles;
use kiln_format::sections::GpuMaterial;
use kiln_format::{ContentHash, ContentHasher};

use super::{brdf_lut, bvh, input_hash, linespace};
use crate::analyze::geometry::SceneGeometry;
use crate::analyze::plan::{Plan, Stage};
use crate::cache::{self, Cache};
use crate::exit::CliResult;
use crate::ir::Scene;
use crate::progress::Progress;
use crate::settings::Settings;
use crate::shading::ShadingScene;

/// Private section kind of a BVH cache entry: the leaf order (`u32` per triangle).
const BVH_ORDER: kiln_format::SectionKind = kiln_format::SectionKind(*b"kBOR");

/// The BVH of a cache entry, checked against the triangle count; `None` (after a warning when
/// the entry is damaged) means build it.
fn load_bvh(cache: &Cache, key: &ContentHash, triangles: usize) -> Option<bvh::BuiltBvh> {
    let check = |mut e: cache::Entry| -> Result<bvh::BuiltBvh, String> {
        let nodes = e.take(kiln_format::sections::BVH_NODES, 0).ok_or("no BVH nodes")?;
        let order = e.take(BVH_ORDER, 0).ok_or("no leaf order")?;
        let order: Vec<u32> =
            bytemuck::try_cast_slice::<u8, u32>(&order).map_err(|e| e.to_string())?.to_vec();
        let mut seen = vec![false; triangles];
        if order.len() != triangles
            || !order
                .iter()
                .all(|&i| (i as usize) < triangles && !std::mem::replace(&mut seen[i as usize], true))
        {
            return Err(format!("leaf order is not a permutation of {triangles} triangles"));
        }
        if nodes.len() % size_of::<kiln_format::sections::CwbvhNode>() != 0 {
            return Err("BVH nodes cut short".into());
        }
        let nodes = bytemuck::pod_collect_to_vec(&nodes);
        Ok(bvh::BuiltBvh { nodes, order })
    };
    match cache.load("bvh", key) {
        Ok(None) => None,
        Ok(Some(e)) => match check(e) {
            Ok(b) => Some(b),
            Err(why) => {
                eprintln!("warning: stage cache: {}: {why}; re-baking", cache.path("bvh", key).display());
                None
            }
        },
        Err(why) => {
            eprintln!("warning: stage cache: {why}; re-baking");
            None
        }
    }
}

/// The inputs of every bake stage.
#[derive(Debug)]
pub struct BakeContext<'a> {
    /// The validated scene.
    pub scene: &'a Scene,
    /// Its world-space triangles, bounds and voxel grid.
    pub geometry: &'a SceneGeometry,
    /// Settings in effect.
    pub settings: &'a Settings,
    /// The plan.
    pub plan: &'a Plan,
    /// Where stages report progress.
    pub progress: &'a Progress,
    /// Every file read, for the manifest.
    pub inputs: Vec<InputFile>,
    /// The BVH; `bvh.order` is the stored triangle order.
    pub bvh: bvh::BuiltBvh,
    /// Wall time of the BVH build (or its load from the cache), ms.
    pub bvh_ms: f64,
    /// The stage cache, when one is used.
    pub cache: Option<&'a Cache>,
    /// Whether the BVH came from the cache.
    pub bvh_cached: bool,
    /// Cache key of the BVH: the triangles' corners in scene order and the preset.
    pub bvh_key: ContentHash,
    /// Key of the stored geometry: the BVH's key, the vertices and the triangles in stored order
    /// (what every stage that traces rays through the BVH reads).
    pub geometry_key: ContentHash,
    /// Triangles in stored (BVH leaf) order.
    pub triangles: Vec<[u32; 3]>,
    /// Material of each stored triangle.
    pub triangle_materials: Vec<u32>,
    /// The material table.
    pub materials: Vec<GpuMaterial>,
    /// Hash of the inputs.
    root: ContentHash,
    /// The BRDF table, baked on first use.
    lut: OnceLock<std::sync::Arc<[[u16; 2]]>>,
    /// The environment, baked on first use (`None`: the scene has none).
    environment: OnceLock<Option<super::environment::BakedEnvironment>>,
}

impl<'a> BakeContext<'a> {
    /// Builds the BVH (the geometry is stored in its leaf order), or loads it from `cache`, and
    /// everything derived from it.
    pub fn new(
        scene: &'a Scene,
        geometry: &'a SceneGeometry,
        settings: &'a Settings,
        plan: &'a Plan,
        inputs: Vec<InputFile>,
        progress: &'a Progress,
        cache: Option<&'a Cache>,
    ) -> CliResult<BakeContext<'a>> {
        let start = Instant::now();
        // obvhs reports no progress while it builds: a spinner with the count to build over.
        progress.stage(&format!("{}: {} triangles", Stage::Bvh.name(), scene.triangles.len()));
        let bvh_key = cache::key("bvh")
            .part("preset", settings.bvh_preset.name().as_bytes())
            .part("corners", bytemuck::cast_slice(&geometry.corners))
            .finish();
        let cached = cache.and_then(|c| load_bvh(c, &bvh_key, scene.triangles.len()));
        let bvh_cached = cached.is_some();
        let built = match cached {
            Some(b) => b,
            None => {
                let built =
                    bvh::build(&bvh::triangles(geometry.corners.iter().copied()), settings.bvh_preset)?;
                if let Some(c) = cache {
                    let sections = [
                        (kiln_format::sections::BVH_NODES, 0, bytemuck::cast_slice::<_, u8>(&built.nodes)),
                        (BVH_ORDER, 0, bytemuck::cast_slice::<_, u8>(&built.order)),
                    ];
                    if let Err(e) = c.store("bvh", &bvh_key, &Default::default(), &sections) {
                        eprintln!("warning: stage cache: {e}");
                    }
                }
                built
            }
        };
        let bvh_ms = start.elapsed().as_secs_f64() * 1e3;
        let triangles: Vec<[u32; 3]> = built.order.iter().map(|&i| scene.triangles[i as usize]).collect();
        let geometry_key = cache::key("stored-geometry")
            .hash("bvh", &bvh_key)
            .part("vertices", bytemuck::cast_slice(&scene.vertices))
            .part("triangles", bytemuck::cast_slice(&triangles))
            .finish();
        Ok(BakeContext {
            root: input_hash(scene, &inputs),
            cache,
            bvh_cached,
            bvh_key,
            geometry_key,
            triangles,
            triangle_materials: built.order.iter().map(|&i| scene.triangle_materials[i as usize]).collect(),
            materials: scene.materials.iter().map(|m| m.gpu).collect(),
            bvh: built,
            bvh_ms,
            scene,
            geometry,
            settings,
            plan,
            progress,
            inputs,
            lut: OnceLock::new(),
            environment: OnceLock::new(),
        })
    }

    /// The content hash of stage `label`'s output: the inputs' hash, the label and `extra`.
    pub fn hash(&self, label: &str, extra: &[(&str, &str)]) -> ContentHash {
        let mut h = ContentHasher::new();
        h.hash("inputs", &self.root).part("stage", label.as_bytes());
        for (k, v) in extra {
            h.part(k, v.as_bytes());
        }
        h.finish()
    }

    /// The BRDF table at the configured resolution (shared by every compile in the process); empty when the plan
    /// skips it (no material has a specular lobe).
    pub fn lut(&self) -> &[[u16; 2]] {
        if !self.plan.runs(Stage::BrdfLut) {
            return &[];
        }
        self.lut.get_or_init(|| brdf_lut::table(self.settings.brdf_lut_res))
    }

    /// The environment as the `environment` stage bakes it, baked on first use (`None` without
    /// one, or when the plan skips the stage).
    pub fn environment(&self) -> Option<&super::environment::BakedEnvironment> {
        if !self.plan.runs(Stage::Environment) {
            return None;
        }
        let env = self.scene.environment.as_ref()?;
        self.environment
            .get_or_init(|| Some(super::environment::bake(env, self.settings.environment_res)))
            .as_ref()
    }

    /// The shading view of the scene, over the stored triangles.
    pub fn shading(&self) -> ShadingScene<'_> {
        ShadingScene {
            materials: &self.materials,
            textures: &self.scene.textures,
            lights: &self.scene.lights,
            bvh: &self.bvh.nodes,
            vertices: &self.scene.vertices,
            triangles: &self.triangles,
            lut: self.lut(),
            lut_res: self.settings.brdf_lut_res,
        }
    }

    /// The stored triangles as the BVH queries read them.
    pub fn indexed(&self) -> IndexedTriangles<'_> {
        IndexedTriangles { vertices: &self.scene.vertices, triangles: &self.triangles }
    }

    /// The stored triangles' attributes, as the line space reads them.
    pub fn attributes(&self) -> linespace::SceneAttributes<'_> {
        linespace::SceneAttributes {
            vertices: &self.scene.vertices,
            uvs: &self.scene.uvs,
            triangles: &self.triangles,
            materials: &self.triangle_materials,
        }
    }

    /// The BVH preset's name, part of the hashes of everything stored in BVH order.
    pub fn preset(&self) -> &'static str {
        self.settings.bvh_preset.name()
    }
}
