//! `--bench-rays`: throughput of the compute traversal (`shaders/common/traverse.glsl`) on the
//! ray sets of a frame of the hybrid pipeline, at the requested size from the file's camera:
//! primary camera rays through pixel centres (closest hit), shadow rays from the primary hits to
//! the first light (any hit), AO rays (cosine-weighted, closest hit within a tenth of the scene
//! diagonal) and unbounded diffuse bounces. Rays stay in pixel order, as a frame traces them.
//! Times are GPU timestamps around the dispatch. Where the device has a ray-tracing pipeline, the
//! same rays go through it too ([`crate::peer`]), traces of the two interleaved, and the hits are
//! compared. Where the file has a line space, its queries run on the shadow rays (binary, binary
//! with exact end cells or filled cells, candidates any hit) and the diffuse rays (PNMT,
//! candidates closest hit), timed in the same loop, and are compared with the BVH's exact answers.

use std::time::Instant;

use glam::Vec3;
use kiln_format::SceneView;
use kiln_format::manifest::LightKind;
use kiln_format::query::offset_origin;
use serde::Serialize;

use crate::bench::quantile;
use crate::error::{Exit, PlayError, PlayResult};
use crate::scene::linespace::LineSpaceBuffers;
use crate::session::{Session, SessionOptions, open_file};
use crate::trace::{GpuHit, GpuRay, NO_HIT, RayQuery, WARMUP_TRACES};
use crate::trace_linespace::{LineSpaceQuery, LsQuery};
use kiln_format::linespace::Variants;

/// One ray set's figures.
#[derive(Debug, Clone, Serialize)]
pub struct RaySetStats {
    /// "primary", "shadow" or "diffuse".
    pub set: String,
    /// Rays in the set.
    pub rays: usize,
    /// Rays that hit something.
    pub hits: usize,
    /// Median GPU milliseconds per trace of the whole set.
    pub median_ms: f64,
    /// 10th percentile.
    pub p10_ms: f64,
    /// 90th percentile.
    pub p90_ms: f64,
    /// Million rays per second at the median.
    pub mrays_per_s: f64,
    /// The driver's ray-tracing pipeline on the same rays, when present.
    pub peer: Option<PeerStats>,
    /// The line-space queries on the same rays, when the file has a line space.
    pub line_space: Vec<LineSpaceStats>,
}

/// One line-space query's figures on a set, against kiln's BVH traversal on the same rays.
#[derive(Debug, Clone, Serialize)]
pub struct LineSpaceStats {
    /// The query ([`LsQuery::name`]).
    pub query: String,
    /// Median GPU milliseconds per trace.
    pub median_ms: f64,
    /// Million rays per second at the median.
    pub mrays_per_s: f64,
    /// Its Mrays/s over the BVH traversal's on the same set.
    pub ratio_to_bvh: f64,
    /// Rays where it reports a hit and the exact answer a miss, or the reverse.
    pub hit_miss_disagreeing: usize,
    /// Approximate queries (PNMT), where both hit: how far along the ray its point lies from the
    /// exact hit (|t − t_exact|·|d|), scene units (median, 99th percentile).
    pub position_error: Option<[f64; 2]>,
}

/// The ray-tracing pipeline's figures for one set.
#[derive(Debug, Clone, Serialize)]
pub struct PeerStats {
    /// Median GPU milliseconds per trace.
    pub median_ms: f64,
    /// Million rays per second at the median.
    pub mrays_per_s: f64,
    /// kiln's Mrays/s over the pipeline's.
    pub ratio: f64,
    /// Rays on which both agree: both miss, or both hit (any-hit sets), or the same triangle or
    /// a distance within 1e-4 relative (closest-hit sets; ties on shared edges differ).
    pub agreeing: usize,
}

/// The report.
#[derive(Debug, Clone, Serialize)]
pub struct RayBenchReport {
    /// Device name.
    pub device: String,
    /// Scene name.
    pub scene: String,
    /// Image width (primary rays per row).
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Traces of each set measured.
    pub repeats: u32,
    /// Per set.
    pub sets: Vec<RaySetStats>,
    /// GPU milliseconds the driver took to build its acceleration structures (with a peer).
    pub peer_build_ms: Option<f64>,
}

impl RayBenchReport {
    /// A human-readable table.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{} on {}, {}x{}, median of {} traces per set\n{:<8} {:>10} {:>10} {:>10} {:>10} {:>12} {:>10} {:>8}\n",
            self.scene,
            self.device,
            self.width,
            self.height,
            self.repeats,
            "set",
            "rays",
            "hits",
            "ms",
            "Mrays/s",
            "RT pipe Mr/s",
            "ratio",
            "agree %"
        );
        for r in &self.sets {
            s.push_str(&format!(
                "{:<8} {:>10} {:>10} {:>10.3} {:>10.1}",
                r.set, r.rays, r.hits, r.median_ms, r.mrays_per_s
            ));
            match &r.peer {
                Some(p) => s.push_str(&format!(
                    " {:>12.1} {:>10.3} {:>8.3}\n",
                    p.mrays_per_s,
                    p.ratio,
                    100.0 * p.agreeing as f64 / r.rays as f64
                )),
                None => s.push_str("            -          -        -\n"),
            }
            for l in &r.line_space {
                s.push_str(&format!(
                    "  line space {:<22} {:>10.3} {:>10.1}  {:>6.2}x BVH, {:>6.3} % hit/miss differ{}\n",
                    l.query,
                    l.median_ms,
                    l.mrays_per_s,
                    l.ratio_to_bvh,
                    100.0 * l.hit_miss_disagreeing as f64 / r.rays as f64,
                    l.position_error.map_or(String::new(), |[m, p]| format!(
                        ", point off by {m:.2e} (median) {p:.2e} (p99)"
                    ))
                ));
            }
        }
        match self.peer_build_ms {
            Some(ms) => s.push_str(&format!("driver acceleration structures built in {ms:.3} ms (GPU)\n")),
            None => s.push_str("no ray-tracing pipeline on this device: kiln's traversal only\n"),
        }
        s
    }
}

/// A small deterministic generator for the bounce directions.
fn unit(i: u32, salt: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9e37_79b9) ^ salt.wrapping_mul(0x85eb_ca6b);
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    (x >> 8) as f32 / 16_777_216.0
}

/// Runs the benchmark.
pub fn run(options: &SessionOptions, repeats: u32, start: Instant) -> PlayResult<RayBenchReport> {
    let mut o = options.clone();
    o.render.purpose = crate::render::Purpose::RayQueries;
    o.readback = None;
    o.pipelines = crate::session::PipelineStart::Complete;
    // Nor any frame sampling coarse texture levels: every level before the first trace.
    o.textures = crate::scene::TextureUpload::Whole;
    let session = Session::open(&o, start)?;
    let mut query = RayQuery::new(&session.gpu)?;
    query.warmup = WARMUP_TRACES;
    let mut ls_query =
        session.scene.line_space.as_ref().map(|_| LineSpaceQuery::new(&session.gpu)).transpose()?;
    if let Some(q) = &mut ls_query {
        q.warmup = WARMUP_TRACES;
    }
    let result = measure(&session, &mut query, ls_query.as_mut(), &o, repeats.max(1));
    // Before the session closes: what is made on its device goes first (each query's pool waits
    // for its last trace).
    drop((query, ls_query));
    let errors = session.close();
    let report = result?;
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    Ok(report)
}

fn measure(
    session: &Session,
    query: &mut RayQuery,
    ls_query: Option<&mut LineSpaceQuery>,
    o: &SessionOptions,
    repeats: u32,
) -> PlayResult<RayBenchReport> {
    let gpu = &session.gpu;
    let bvh = session
        .scene
        .bvh
        .as_ref()
        .ok_or_else(|| PlayError::new(Exit::BadInput, "the file has no BVH: nothing to trace"))?;
    let file = open_file(&o.file)?;
    let view = SceneView::new(&file)
        .map_err(|e| PlayError::new(Exit::BadInput, format!("invalid .kiln file: {e}")))?;
    let (w, h) = (o.width, o.height);
    let cam = &session.camera;
    let aspect = w as f64 / h as f64;
    let mut primary = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        for x in 0..w {
            let nx = (x as f64 + 0.5) / w as f64 * 2.0 - 1.0;
            let ny = 1.0 - (y as f64 + 0.5) / h as f64 * 2.0;
            let (origin, d) = cam.pixel_ray(nx, ny, aspect);
            primary.push(GpuRay {
                origin: origin.as_vec3().to_array(),
                tmin: 0.0,
                direction: d.as_vec3().to_array(),
                tmax: f32::MAX,
            });
        }
    }
    let (hits, _) = query.trace(gpu, bvh, &primary, false)?;
    let light = view.manifest.lights.first();
    let mut shadow = Vec::new();
    let mut ao = Vec::new();
    let mut diffuse = Vec::new();
    // The geometric normal each secondary ray leaves (PNMT's self-hit rule reads it).
    let mut normals = Vec::new();
    let bounds = view.manifest.bounds;
    let ao_radius = 0.1 * Vec3::from(bounds.max).distance(Vec3::from(bounds.min));
    for (i, (r, hit)) in primary.iter().zip(&hits).enumerate() {
        if hit.t == NO_HIT {
            continue;
        }
        let Some(tri) = view.triangles.get(hit.triangle as usize) else {
            return Err(PlayError::new(Exit::Gpu, "the traversal returned a triangle out of range"));
        };
        let c = tri.map(|v| Vec3::from(view.vertices[v as usize].position));
        let d = Vec3::from(r.direction);
        let p = c[0] * (1.0 - hit.u - hit.v) + c[1] * hit.u + c[2] * hit.v;
        let mut n = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
        if n.dot(d) > 0.0 {
            n = -n;
        }
        let origin = offset_origin(p, n).to_array();
        normals.push([n.x, n.y, n.z, 0.0]);
        if let Some(l) = light {
            let (dir, tmax) = match l.kind {
                LightKind::Directional => (-Vec3::from(l.direction), f32::MAX),
                _ => {
                    let to = Vec3::from(l.position) - p;
                    (to.normalize_or_zero(), to.length() * (1.0 - 1e-5))
                }
            };
            shadow.push(GpuRay { origin, tmin: 0.0, direction: dir.to_array(), tmax });
        }
        let (u1, u2) = (unit(i as u32, 1), unit(i as u32, 2));
        let (s, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
        let t = if n.z.abs() < 0.999 { Vec3::Z.cross(n).normalize() } else { Vec3::X.cross(n).normalize() };
        let b = n.cross(t);
        let dir = t * (s * phi.cos()) + b * (s * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
        diffuse.push(GpuRay { origin, tmin: 0.0, direction: dir.to_array(), tmax: f32::MAX });
        let (u1, u2) = (unit(i as u32, 3), unit(i as u32, 4));
        let (s, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
        let dir = t * (s * phi.cos()) + b * (s * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
        ao.push(GpuRay { origin, tmin: 0.0, direction: dir.to_array(), tmax: ao_radius });
    }
    let corners: Vec<[f32; 3]> =
        view.triangles.iter().flat_map(|t| t.map(|v| view.vertices[v as usize].position)).collect();
    let mut peer = crate::peer::RtPipelinePeer::new(gpu, &corners)?;
    if let Some(p) = &mut peer {
        p.warmup = WARMUP_TRACES;
    }
    // Line-space queries on the sets seed 004 routes through it: shadow feelers (any hit) and
    // diffuse bounces (closest hit), each with the variants the file has.
    let variants = session.scene.line_space.as_ref().map_or(0, |l| l.header.variants);
    let has = |v: u32| variants & v != 0;
    let shadow_ls: Vec<LsQuery> = [
        (has(Variants::BINARY), LsQuery::Binary),
        (has(Variants::BINARY), LsQuery::BinaryEnds),
        (has(Variants::BINARY), LsQuery::BinaryFilled),
        (has(Variants::CANDIDATES), LsQuery::CandidatesAny),
    ]
    .into_iter()
    .filter_map(|(ok, q)| ok.then_some(q))
    .collect();
    let diffuse_ls: Vec<LsQuery> =
        [(has(Variants::PNMT), LsQuery::Pnmt), (has(Variants::CANDIDATES), LsQuery::CandidatesClosest)]
            .into_iter()
            .filter_map(|(ok, q)| ok.then_some(q))
            .collect();
    let ls = match (ls_query, session.scene.line_space.as_ref()) {
        (Some(q), Some(b)) => Some((q, b, normals.as_slice())),
        _ => None,
    };
    let sets = [
        RaySet { name: "primary", rays: &primary, any: false, line_space: &[] },
        RaySet { name: "shadow", rays: &shadow, any: true, line_space: &shadow_ls },
        RaySet { name: "ao", rays: &ao, any: false, line_space: &[] },
        RaySet { name: "diffuse", rays: &diffuse, any: false, line_space: &diffuse_ls },
    ];
    let result = trace_sets(gpu, bvh, query, peer.as_mut(), ls, repeats, sets);
    let peer_build_ms = peer.as_ref().map(|p| p.build_ms);
    if let Some(p) = peer {
        let _ = gpu.wait_idle();
        drop(p);
    }
    Ok(RayBenchReport {
        device: gpu.name.clone(),
        scene: view.manifest.scene_name.clone(),
        width: w,
        height: h,
        repeats,
        sets: result?,
        peer_build_ms,
    })
}

/// Whether two hits of the same ray agree (see [`PeerStats::agreeing`]).
fn agree(a: &GpuHit, b: &GpuHit, any_hit: bool) -> bool {
    let (ha, hb) = (a.t != NO_HIT, b.t != NO_HIT);
    if ha != hb {
        return false;
    }
    !ha || any_hit || a.triangle == b.triangle || (a.t - b.t).abs() <= 1e-4 * a.t.abs().max(b.t.abs())
}

/// One ray set: its rays, whether any hit suffices, and the line-space queries to time on it.
struct RaySet<'a> {
    name: &'static str,
    rays: &'a [GpuRay],
    any: bool,
    line_space: &'a [LsQuery],
}

/// The line-space queries with their buffers and the rays' origin normals.
type LineSpaceRun<'a> = (&'a mut LineSpaceQuery, &'a LineSpaceBuffers, &'a [[f32; 4]]);

/// Traces each set `repeats` times through kiln's traversal and, interleaved (so that clocks and
/// temperature treat all alike), through the peer and the set's line-space queries.
fn trace_sets(
    gpu: &crate::gpu::Gpu,
    bvh: &crate::scene::BvhBuffers,
    query: &mut RayQuery,
    mut peer: Option<&mut crate::peer::RtPipelinePeer>,
    mut ls: Option<LineSpaceRun>,
    repeats: u32,
    sets: [RaySet; 4],
) -> PlayResult<Vec<RaySetStats>> {
    let mut out = Vec::new();
    for RaySet { name, rays, any, line_space } in sets {
        if rays.is_empty() {
            continue;
        }
        let mut ms = Vec::with_capacity(repeats as usize);
        let mut peer_ms = Vec::with_capacity(repeats as usize);
        let mut hits = Vec::new();
        let mut peer_hits = Vec::new();
        let queries = if ls.is_some() { line_space } else { &[] };
        let mut ls_ms = vec![Vec::with_capacity(repeats as usize); queries.len()];
        let mut ls_hits = vec![Vec::new(); queries.len()];
        for _ in 0..repeats {
            let (h, t) = query.trace(gpu, bvh, rays, any)?;
            hits = h;
            ms.push(t);
            if let Some(p) = peer.as_deref_mut() {
                let (h, t) = p.trace(gpu, rays, any)?;
                peer_hits = h;
                peer_ms.push(t);
            }
            if let Some((q, buffers, normals)) = ls.as_mut() {
                for (k, &which) in queries.iter().enumerate() {
                    let (h, t) = q.trace(gpu, bvh, buffers, rays, normals, which)?;
                    ls_hits[k] = h;
                    ls_ms[k].push(t);
                }
            }
        }
        ms.sort_by(f64::total_cmp);
        peer_ms.sort_by(f64::total_cmp);
        let median = quantile(&ms, 0.5);
        let mrays = rays.len() as f64 / (median * 1e3);
        let peer = (!peer_ms.is_empty()).then(|| {
            let m = quantile(&peer_ms, 0.5);
            let p_mrays = rays.len() as f64 / (m * 1e3);
            PeerStats {
                median_ms: m,
                mrays_per_s: p_mrays,
                ratio: mrays / p_mrays,
                agreeing: hits.iter().zip(&peer_hits).filter(|(a, b)| agree(a, b, any)).count(),
            }
        });
        let line_space = queries
            .iter()
            .zip(ls_ms.iter_mut().zip(&ls_hits))
            .map(|(&which, (times, got))| {
                times.sort_by(f64::total_cmp);
                let m = quantile(times, 0.5);
                let l_mrays = rays.len() as f64 / (m * 1e3);
                let differ =
                    got.iter().zip(&hits).filter(|(a, b)| (a.t != NO_HIT) != (b.t != NO_HIT)).count();
                let position_error = (which == LsQuery::Pnmt).then(|| {
                    let mut e: Vec<f64> = got
                        .iter()
                        .zip(&hits)
                        .zip(rays)
                        .filter(|((a, b), _)| a.t != NO_HIT && b.t != NO_HIT)
                        .map(|((a, b), r)| ((a.t - b.t).abs() * Vec3::from(r.direction).length()) as f64)
                        .collect();
                    e.sort_by(f64::total_cmp);
                    if e.is_empty() { [0.0; 2] } else { [quantile(&e, 0.5), quantile(&e, 0.99)] }
                });
                LineSpaceStats {
                    query: which.name().into(),
                    median_ms: m,
                    mrays_per_s: l_mrays,
                    ratio_to_bvh: l_mrays / mrays,
                    hit_miss_disagreeing: differ,
                    position_error,
                }
            })
            .collect();
        out.push(RaySetStats {
            set: name.into(),
            rays: rays.len(),
            hits: hits.iter().filter(|h| h.t != NO_HIT).count(),
            median_ms: median,
            p10_ms: quantile(&ms, 0.1),
            p90_ms: quantile(&ms, 0.9),
            mrays_per_s: mrays,
            peer,
            line_space,
        });
    }
    Ok(out)
}
