//! Filling the shafts of one cell: for each triangle and face pair, a hierarchical search over
//! patch ranges (a range pair is the hull of two rectangles, tested exactly by
//! [`Prepared::overlaps_sweep`]) finds every shaft the triangle meets without testing each
//! (triangle, shaft) pair; then the bits, the sorted candidate lists and the PNMT records.

use glam::{DVec3, Vec2, Vec3};
use kiln_format::linespace::index::{
    FACE_PAIRS, face_axis, face_uv_axes, pair_faces, shaft_parts, shafts_per_voxel,
};
use kiln_format::linespace::{PnmtRecord, entry, words_per_slot};

use super::geometry::{Prepared, clip_to_box};

/// What one cell contributes to the line space.
#[derive(Debug, Clone, Default)]
pub struct CellShafts {
    /// Bit words of the slot.
    pub bits: Vec<u32>,
    /// Candidate entries of each filled shaft, in shaft order (empty without candidates).
    pub lists: Vec<Vec<u32>>,
    /// Front and back records of each filled shaft, in shaft order (empty without PNMT).
    pub pnmt: Vec<[PnmtRecord; 2]>,
    /// Front and back radiance (binary16 RGB, 0) of each filled shaft (empty without it).
    pub preillum: Vec<[u16; 8]>,
    /// Overlap tests run (for the bake report).
    pub tests: u64,
}

/// Scene data the PNMT records need, per global triangle number.
pub trait HitAttributes: Sync {
    /// World corners.
    fn corners(&self, t: u32) -> [Vec3; 3];
    /// Shading normal at barycentrics (u, v).
    fn normal(&self, t: u32, u: f32, v: f32) -> Vec3;
    /// Texture coordinates at barycentrics (u, v).
    fn uv(&self, t: u32, u: f32, v: f32) -> Vec2;
    /// Material.
    fn material(&self, t: u32) -> u16;
}

/// A face rectangle as a (degenerate) box in cell-local coordinates: (centre, half extents).
fn face_box(face: u32, u: (f64, f64), v: (f64, f64)) -> (DVec3, DVec3) {
    let (ua, va) = face_uv_axes(face);
    let mut c = DVec3::ZERO;
    let mut h = DVec3::ZERO;
    c[face_axis(face)] = (face % 2) as f64;
    c[ua] = (u.0 + u.1) * 0.5;
    h[ua] = (u.1 - u.0) * 0.5;
    c[va] = (v.0 + v.1) * 0.5;
    h[va] = (v.1 - v.0) * 0.5;
    (c, h)
}

/// Outward normal of a face.
fn outward(face: u32) -> DVec3 {
    let mut n = DVec3::ZERO;
    n[face_axis(face)] = if face.is_multiple_of(2) { -1.0 } else { 1.0 };
    n
}

/// The four corners of a face rectangle.
fn corners(face: u32, u: (f64, f64), v: (f64, f64)) -> [DVec3; 4] {
    let (ua, va) = face_uv_axes(face);
    let mut base = DVec3::ZERO;
    base[face_axis(face)] = (face % 2) as f64;
    [(u.0, v.0), (u.1, v.0), (u.1, v.1), (u.0, v.1)].map(|(x, y)| {
        let mut p = base;
        p[ua] = x;
        p[va] = y;
        p
    })
}

/// Patch index range `[lo, hi)` along one face axis covering the interval `[a, b]` widened by
/// `pad`.
fn index_range(a: f64, b: f64, pad: f64, n: u32) -> (u32, u32) {
    let nf = n as f64;
    let lo = ((a - pad) * nf).floor().clamp(0.0, nf) as u32;
    let hi = (((b + pad) * nf).floor() + 1.0).clamp(0.0, nf) as u32;
    (lo.min(n), hi.max(lo).min(n))
}

/// Patch ranges on face `to` that segments from the rectangle `from_rect` (corners on face `from`)
/// through `poly` can reach: the bounding rectangle of the central projections of every polygon
/// vertex from every rectangle corner onto `to`'s plane. The union of segments through the
/// polygon lies in the convex hull of these projections when `p_j − x_j` has one sign for all
/// corners x and vertices p (j = `to`'s axis): the projection is then monotone in each corner
/// coordinate and linear-fractional in the vertex. `None` when that condition fails or the
/// projection degenerates (a vertex on the source plane): callers fall back to exact tests.
fn reach(from_rect: &[DVec3; 4], poly: &[DVec3], to: u32, n: u32, pad: f64) -> Option<[u32; 4]> {
    let j = face_axis(to);
    let bj = (to % 2) as f64;
    let (ua, va) = face_uv_axes(to);
    let (mut umin, mut umax, mut vmin, mut vmax) =
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    let mut sign = 0.0f64;
    for x in from_rect {
        let reach = bj - x[j];
        for p in poly {
            let d = p[j] - x[j];
            // d and reach must share one strict sign, with |d| not tiny (else the image is far away).
            if d * reach <= 1e-9 || (sign != 0.0 && d.signum() != sign) {
                return None;
            }
            sign = d.signum();
            let y = *x + (*p - *x) * (reach / d);
            umin = umin.min(y[ua]);
            umax = umax.max(y[ua]);
            vmin = vmin.min(y[va]);
            vmax = vmax.max(y[va]);
        }
    }
    let (u0, u1) = index_range(umin, umax, pad, n);
    let (v0, v1) = index_range(vmin, vmax, pad, n);
    Some([u0, u1, v0, v1])
}

/// Calls `found(shaft)` for every shaft of face pair `pair` that the triangle `tri` (clipped to
/// the widened cell: `poly`) meets, and possibly for a few it only nearly meets (see
/// [`reach`]): for each patch on face a that the triangle can be seen through, the patches
/// on face b its projection reaches. Where the projection is undefined or reaches many patches,
/// exact tests decide (a hierarchical search over patch ranges, see [`exact_search`]).
#[allow(clippy::too_many_arguments)]
fn search(
    tri: &Prepared,
    poly: &[DVec3],
    pair: u32,
    n: u32,
    margin: f64,
    direct_limit: u32,
    stack: &mut Vec<[u32; 8]>,
    tests: &mut u64,
    found: &mut impl FnMut(u32),
) {
    let (fa, fb) = pair_faces(pair);
    if poly.is_empty() {
        return;
    }
    let s = 1.0 / n as f64;
    let n2 = n * n;
    let prange = reach(&corners(fb, (0.0, 1.0), (0.0, 1.0)), poly, fa, n, margin).unwrap_or([0, n, 0, n]);
    for au in prange[0]..prange[1] {
        for av in prange[2]..prange[3] {
            let p_rect =
                corners(fa, (au as f64 * s, (au + 1) as f64 * s), (av as f64 * s, (av + 1) as f64 * s));
            match reach(&p_rect, poly, fb, n, margin) {
                Some(q) if (q[1] - q[0]) * (q[3] - q[2]) <= direct_limit => {
                    for bu in q[0]..q[1] {
                        for bv in q[2]..q[3] {
                            found(pair * n2 * n2 + (au * n + av) * n2 + bu * n + bv);
                        }
                    }
                }
                q => {
                    let q = q.unwrap_or([0, n, 0, n]);
                    exact_search(
                        tri,
                        pair,
                        n,
                        margin,
                        [au, au + 1, av, av + 1, q[0], q[1], q[2], q[3]],
                        stack,
                        tests,
                        found,
                    );
                }
            }
        }
    }
}

/// Exact hierarchical search from the range pair `start`: ranges whose hull misses the
/// triangle are dropped, ranges it covers are emitted whole, others split.
#[allow(clippy::too_many_arguments)]
fn exact_search(
    tri: &Prepared,
    pair: u32,
    n: u32,
    margin: f64,
    start: [u32; 8],
    stack: &mut Vec<[u32; 8]>,
    tests: &mut u64,
    found: &mut impl FnMut(u32),
) {
    let (fa, fb) = pair_faces(pair);
    let s = 1.0 / n as f64;
    let n2 = n * n;
    let emit = |r: &[u32; 8], found: &mut dyn FnMut(u32)| {
        for au in r[0]..r[1] {
            for av in r[2]..r[3] {
                for bu in r[4]..r[5] {
                    for bv in r[6]..r[7] {
                        found(pair * n2 * n2 + (au * n + av) * n2 + bu * n + bv);
                    }
                }
            }
        }
    };
    stack.clear();
    stack.push(start);
    while let Some(r) = stack.pop() {
        if (0..4).any(|k| r[2 * k] >= r[2 * k + 1]) {
            continue;
        }
        let ua = (r[0] as f64 * s, r[1] as f64 * s);
        let va = (r[2] as f64 * s, r[3] as f64 * s);
        let ub = (r[4] as f64 * s, r[5] as f64 * s);
        let vb = (r[6] as f64 * s, r[7] as f64 * s);
        let (ca, ha) = face_box(fa, ua, va);
        let (cb, hb) = face_box(fb, ub, vb);
        *tests += 1;
        if !tri.overlaps_sweep(ca, cb - ca, ha, hb - ha, margin) {
            continue;
        }
        // Split the widest of the four ranges (the first on ties); a pair of single patches is
        // a shaft. Ranges of four or more shafts are first checked for full coverage.
        let mut widest = 0;
        for k in 1..4 {
            if r[2 * k + 1] - r[2 * k] > r[2 * widest + 1] - r[2 * widest] {
                widest = k;
            }
        }
        let (lo, hi) = (r[2 * widest], r[2 * widest + 1]);
        if hi - lo == 1 {
            emit(&r, found);
            continue;
        }
        let leaves = (r[1] - r[0]) * (r[3] - r[2]) * (r[5] - r[4]) * (r[7] - r[6]);
        if leaves >= 4
            && tri.separates(ca, ha, cb, hb, margin)
            && tri.covers(&corners(fa, ua, va), &corners(fb, ub, vb), margin)
        {
            emit(&r, found);
            continue;
        }
        let mid = (lo + hi) / 2;
        let mut left = r;
        left[2 * widest + 1] = mid;
        let mut right = r;
        right[2 * widest] = mid;
        stack.push(right);
        stack.push(left);
    }
}

/// Largest number of face-b patches a projection may reach and still be taken without exact
/// tests. Small reaches come from triangles small against a patch, where the bounding rectangle of
/// the projection is nearly exact; larger ones are tested shaft by shaft.
pub const DIRECT_LIMIT: u32 = 4;

/// Quantises a key in [lo, lo + 2] to 0..=255, rounding down (`up` false) or up.
fn quantise(key: f64, lo: f64, up: bool) -> u32 {
    let x = (key - lo) * (255.0 / 2.0);
    let q = if up { x.ceil() } else { x.floor() };
    q.clamp(0.0, 255.0) as u32
}

/// The first hit found so far from one end of a shaft's midpoint segment, or the fallback
/// triangle when the segment misses everything.
#[derive(Debug, Clone, Copy)]
struct End {
    /// Segment parameter of the hit (front: smallest, back: largest), NaN if none yet.
    t: f32,
    triangle: u32,
    u: f32,
    v: f32,
    /// Fallback: key bound (front: smallest key minimum, back: largest key maximum) and the
    /// cell-local triangle and pair to take a point from.
    key: f64,
    local: u32,
}

/// Buffers reused across the cells one worker thread bakes (allocating them per cell costs
/// page faults on every cell).
#[derive(Debug, Default)]
pub struct Scratch {
    stack: Vec<[u32; 8]>,
    hits: Vec<(u32, u8, u8, u16)>,
    sorted: Vec<(u32, u8, u8, u16)>,
    counts: Vec<u32>,
    ends: Vec<[End; 2]>,
    polys: Vec<Vec<DVec3>>,
}

const NO_END: End = End { t: f32::NAN, triangle: u32::MAX, u: 0.0, v: 0.0, key: f64::NAN, local: u32::MAX };

/// Bakes one cell. `tris` are the cell's global triangle numbers, `local` their grid-local
/// corners, `cell_min` the cell's grid-local minimum corner.
///
/// Every (triangle, shaft) pair found updates, in one pass: the shaft's bit; its candidate list
/// (bucketed by shaft, then ordered by key); and the nearest hits of its midpoint segment from
/// either end (the PNMT records). No per-shaft list is needed for PNMT.
#[allow(clippy::too_many_arguments)]
pub fn bake_cell(
    tris: &[u32],
    local: &[[DVec3; 3]],
    cell_min: DVec3,
    world_cell_min: DVec3,
    cell: f64,
    n: u32,
    margin: f64,
    candidates: bool,
    pnmt: bool,
    attrs: &dyn HitAttributes,
    shade: Option<&Shade<'_>>,
    scratch: &mut Scratch,
) -> CellShafts {
    let records_needed = pnmt || shade.is_some();
    let shafts = shafts_per_voxel(n) as usize;
    let mut out = CellShafts { bits: vec![0; words_per_slot(n)], ..Default::default() };
    let Scratch { stack, hits, sorted, counts, ends, polys } = scratch;
    // (shaft, key min, key max, local triangle)
    hits.clear();
    ends.clear();
    if records_needed {
        ends.resize(shafts, [NO_END; 2]);
    }
    polys.clear();
    let lo_box = DVec3::splat(-margin);
    let hi_box = DVec3::splat(1.0 + margin);
    // Midpoint segments: patch centres in world space, per face and patch.
    let centres: Vec<Vec<Vec3>> = (0..6)
        .map(|face| {
            (0..n * n)
                .map(|patch| {
                    let (ua, va) = face_uv_axes(face);
                    let mut p = DVec3::ZERO;
                    p[face_axis(face)] = (face % 2) as f64;
                    p[ua] = ((patch / n) as f64 + 0.5) / n as f64;
                    p[va] = ((patch % n) as f64 + 0.5) / n as f64;
                    (world_cell_min + p * cell).as_vec3()
                })
                .collect()
        })
        .collect();
    for (li, &t) in tris.iter().enumerate() {
        let v = local[t as usize].map(|p| p - cell_min);
        let prep = Prepared::new(v);
        let poly = clip_to_box(v, lo_box, hi_box);
        let seg = SegmentTest::new(if records_needed { attrs.corners(t) } else { [Vec3::ZERO; 3] });
        for pair in 0..FACE_PAIRS {
            let (fa, fb) = pair_faces(pair);
            let w = outward(fb) - outward(fa);
            let key_lo = w.min(DVec3::ZERO).element_sum();
            let (kmin, kmax) = if poly.is_empty() {
                (f64::NEG_INFINITY, f64::INFINITY)
            } else {
                poly.iter()
                    .map(|p| p.dot(w))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), k| (a.min(k), b.max(k)))
            };
            let (qmin, qmax) =
                (quantise(kmin - 2.0 * margin, key_lo, false), quantise(kmax + 2.0 * margin, key_lo, true));
            search(&prep, &poly, pair, n, margin, DIRECT_LIMIT, stack, &mut out.tests, &mut |shaft| {
                out.bits[(shaft / 32) as usize] |= 1 << (shaft % 32);
                if candidates {
                    hits.push((shaft, qmin as u8, qmax as u8, li as u16));
                }
                if records_needed {
                    let (_, pa, _, pb) = shaft_parts(shaft, n);
                    let (o, e) = (centres[fa as usize][pa as usize], centres[fb as usize][pb as usize]);
                    let end = &mut ends[shaft as usize];
                    if let Some(h) = seg.hit(o, e) {
                        if !(h.t >= end[0].t) {
                            end[0] = End { t: h.t, triangle: t, u: h.u, v: h.v, ..end[0] };
                        }
                        if !(h.t <= end[1].t) {
                            end[1] = End { t: h.t, triangle: t, u: h.u, v: h.v, ..end[1] };
                        }
                    }
                    if !(kmin >= end[0].key) {
                        end[0].key = kmin;
                        end[0].local = li as u32;
                    }
                    if !(kmax <= end[1].key) {
                        end[1].key = kmax;
                        end[1].local = li as u32;
                    }
                }
            });
        }
        polys.push(poly);
    }
    if candidates {
        // Bucket by shaft (stable: triangle order), then order each bucket by key.
        counts.clear();
        counts.resize(shafts + 1, 0);
        for h in hits.iter() {
            counts[h.0 as usize + 1] += 1;
        }
        for i in 0..shafts {
            counts[i + 1] += counts[i];
        }
        sorted.clear();
        sorted.resize(hits.len(), (0, 0, 0, 0));
        for h in hits.iter() {
            let slot = &mut counts[h.0 as usize];
            sorted[*slot as usize] = *h;
            *slot += 1;
        }
        // counts[s] now ends bucket s; bucket s starts where bucket s − 1 ended.
        for shaft in 0..shafts {
            let start = if shaft == 0 { 0 } else { counts[shaft - 1] as usize };
            let group = &mut sorted[start..counts[shaft] as usize];
            if group.is_empty() {
                continue;
            }
            group.sort_unstable_by_key(|h| (h.1, h.2, h.3));
            let mut running = 0u32;
            out.lists.push(
                group
                    .iter()
                    .map(|&(_, kmin, kmax, li)| {
                        running = running.max(kmax as u32);
                        entry::pack(li as u32, kmin as u32, running)
                    })
                    .collect(),
            );
        }
    }
    if records_needed {
        for (shaft, end) in ends.iter().enumerate() {
            if out.bits[shaft / 32] & (1 << (shaft % 32)) == 0 {
                continue;
            }
            let pair = shaft as u32 / (n * n * n * n);
            let (fa, fb) = pair_faces(pair);
            let w = outward(fb) - outward(fa);
            let record = |e: &End, front: bool| -> PnmtRecord {
                if e.t.is_finite() {
                    let [a, b, c] = attrs.corners(e.triangle);
                    let p = (a * (1.0 - e.u - e.v) + b * e.u + c * e.v).as_dvec3();
                    return PnmtRecord::encode(
                        p,
                        attrs.normal(e.triangle, e.u, e.v),
                        attrs.material(e.triangle),
                        attrs.uv(e.triangle, e.u, e.v),
                        world_cell_min,
                        cell,
                    );
                }
                // The midpoint segment missed: the triangle reaching furthest towards this end,
                // at its clipped vertex nearest that end.
                let Some(poly) = polys.get(e.local as usize) else { return PnmtRecord::NONE };
                let best = poly.iter().copied().min_by(|x, y| {
                    let (kx, ky) = (x.dot(w), y.dot(w));
                    if front { kx.total_cmp(&ky) } else { ky.total_cmp(&kx) }
                });
                let Some(q) = best else { return PnmtRecord::NONE };
                let t = tris[e.local as usize];
                let world = world_cell_min + q.clamp(DVec3::ZERO, DVec3::ONE) * cell;
                let (u, v) = barycentric(attrs.corners(t), world.as_vec3());
                PnmtRecord::encode(
                    world,
                    attrs.normal(t, u, v),
                    attrs.material(t),
                    attrs.uv(t, u, v),
                    world_cell_min,
                    cell,
                )
            };
            let pair_records = [record(&end[0], true), record(&end[1], false)];
            if let Some(shade) = shade {
                let (_, pa, _, pb) = shaft_parts(shaft as u32, n);
                let mut rgb = [0u16; 8];
                for (k, r) in pair_records.iter().enumerate() {
                    let Some(hit) = r.decode(world_cell_min, cell) else { continue };
                    // The viewer of the front record is at the front patch, of the back one at the back.
                    let eye = if k == 0 {
                        centres[fa as usize][pa as usize]
                    } else {
                        centres[fb as usize][pb as usize]
                    };
                    let v = (eye.as_dvec3() - hit.position).as_vec3().normalize_or(hit.normal);
                    let radiance = shade(hit.position, hit.normal, v, hit.material, hit.uv);
                    for c in 0..3 {
                        rgb[4 * k + c] = half::f16::from_f32(radiance[c].min(65504.0)).to_bits();
                    }
                }
                out.preillum.push(rgb);
            }
            if pnmt {
                out.pnmt.push(pair_records);
            }
        }
    }
    out
}

/// Radiance leaving a decoded record: (position, normal, direction to the viewer, material,
/// texture coordinates) → linear RGB.
pub type Shade<'a> = dyn Fn(DVec3, Vec3, Vec3, u16, glam::Vec2) -> Vec3 + Sync + 'a;

/// A segment–triangle test for midpoint segments (PNMT records need the nearest hit, not a
/// watertight one): plane crossing, then three edge functions.
#[derive(Debug, Clone, Copy)]
struct SegmentTest {
    c: [Vec3; 3],
    n: Vec3,
    n2: f32,
}

impl SegmentTest {
    fn new(c: [Vec3; 3]) -> SegmentTest {
        let n = (c[1] - c[0]).cross(c[2] - c[0]);
        SegmentTest { c, n, n2: n.length_squared() }
    }

    /// (t, u, v) where the segment o → e crosses the triangle.
    fn hit(&self, o: Vec3, e: Vec3) -> Option<Intersection> {
        let d = e - o;
        let denom = self.n.dot(d);
        if denom == 0.0 || self.n2 == 0.0 {
            return None;
        }
        let t = self.n.dot(self.c[0] - o) / denom;
        if !(0.0..=1.0).contains(&t) {
            return None;
        }
        let p = o + d * t;
        let [a, b, c] = self.c;
        let w0 = self.n.dot((b - a).cross(p - a));
        let w1 = self.n.dot((c - b).cross(p - b));
        let w2 = self.n.dot((a - c).cross(p - c));
        (w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0).then(|| Intersection { t, u: w2 / self.n2, v: w0 / self.n2 })
    }
}

/// Where a midpoint segment crosses a triangle.
#[derive(Debug, Clone, Copy)]
struct Intersection {
    t: f32,
    u: f32,
    v: f32,
}

/// Barycentric weights (of corners 1 and 2) of the point of the triangle's plane nearest `p`.
fn barycentric(c: [Vec3; 3], p: Vec3) -> (f32, f32) {
    let (e1, e2, d) = (c[1] - c[0], c[2] - c[0], p - c[0]);
    let (a, b, cc) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (x, y) = (d.dot(e1), d.dot(e2));
    let det = a * cc - b * b;
    if det == 0.0 {
        return (0.0, 0.0);
    }
    ((cc * x - b * y) / det, (a * y - b * x) / det)
}

/// Whether any of `tris` (grid-local corners `local`) meets the widened shaft of cell `cell_min`
/// exactly: the reference for the false-fill measurement of the bake.
pub fn meets_exactly(
    tris: &[u32],
    local: &[[DVec3; 3]],
    cell_min: DVec3,
    shaft: u32,
    n: u32,
    margin: f64,
) -> bool {
    let (fa, pa, fb, pb) = shaft_parts(shaft, n);
    let s = 1.0 / n as f64;
    let rect =
        |p: u32| (((p / n) as f64 * s, (p / n + 1) as f64 * s), ((p % n) as f64 * s, (p % n + 1) as f64 * s));
    let ((ua, va), (ub, vb)) = (rect(pa), rect(pb));
    let (ca, ha) = face_box(fa, ua, va);
    let (cb, hb) = face_box(fb, ub, vb);
    tris.iter().any(|&t| {
        Prepared::new(local[t as usize].map(|p| p - cell_min)).overlaps_sweep(
            ca,
            cb - ca,
            ha,
            hb - ha,
            margin,
        )
    })
}
