// The hooks of the GI estimator (gi.glsl) answered by the line space (seed 004): the includer
// defines GI_LS_STRUCTURE, then includes this file.
//   GI_LS_PNMT (0):       bounce rays take the PNMT record of the shaft they pass through (no
//                         triangle test); records of emissive materials and specular-lobe rays
//                         are re-traced through the CWBVH, exactly (the estimator weighs emission
//                         by its triangle, and a mirror would show an approximate hit);
//   GI_LS_CANDIDATES (1): bounce rays through the candidate lists (exact);
//   GI_LS_PREILLUM (2):   one PNMT lookup per pixel, and the radiance baked for that record
//                         (emission and the analytic lights' direct light, shadowed): no shading,
//                         no shadow ray, no further bounce; it lacks the sky's and emissive
//                         triangles' light at the hit and every longer path.
// Shadow rays (next-event estimation, the sky at the last hit) go through the binary line space,
// exact near their ends (ls_occluded_binary).
#ifndef KILN_GI_LINESPACE_GLSL
#define KILN_GI_LINESPACE_GLSL

#define GI_LS_PNMT 0
#define GI_LS_CANDIDATES 1
#define GI_LS_PREILLUM 2

#include "hybrid.glsl"
#define LS_BINDING 36
#include "../common/linespace.glsl"

// The surface of a PNMT record seen along `dir`: its stored normal as both geometric and
// shading normal (normal maps are not applied), its material at its stored uv.
Surface surface_of_record(LsRecord rec, vec3 dir) {
    Surface s;
    s.triangle = 0xffffffffu;
    vec3 n = rec.normal;
    s.front = dot(n, dir) < 0.0;
    if (!s.front) {
        n = -n;
    }
    s.ng = n;
    s.ns = n;
    s.nc = n;
    // The stored point is quantised (up to a 65535th of the cell per axis), so it may lie a hair
    // behind the surface it stands for; lifted by the quantisation step plus the margin towards
    // the ray, the rays leaving it do not hit that surface again.
    s.p = rec.position + n * grid.pnmt_step;
    // PNMT records hold no vertex colour (FORMAT.md, COL0): white.
    surface_material(s, materials[rec.material], rec.uv, vec4(1.0));
    return s;
}

bool gi_hit(TraceRay r, vec3 origin_ng, bool exact, out Surface s) {
#if GI_LS_STRUCTURE == GI_LS_CANDIDATES
    TraceHit h = ls_trace_candidates(r, false);
    if (h.t == NO_HIT) {
        return false;
    }
    s = surface_at(r, h);
    return true;
#else
    if (exact) {
        return trace_surface(r, s);
    }
    LsRecord rec;
    if (!ls_pnmt_hit(r.origin, r.direction, r.tmin, r.tmax, origin_ng, rec)) {
        return false;
    }
    if (any(greaterThan(materials[rec.material].emission, vec3(0.0)))) {
        return trace_surface(r, s);
    }
    s = surface_of_record(rec, r.direction);
    return true;
#endif
}

bool gi_occluded(vec3 from, vec3 ng, vec3 to) {
    return ls_occluded(from, ng, to, false);
}

bool gi_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return ls_occluded_dir(from, ng, dir, false);
}

#if GI_LS_STRUCTURE == GI_LS_PREILLUM
#define GI_HIT_RADIANCE
bool gi_hit_radiance(TraceRay r, vec3 origin_ng, out vec3 radiance) {
    LsRecord rec;
    if (!ls_pnmt_hit(r.origin, r.direction, r.tmin, r.tmax, origin_ng, rec)) {
        return false;
    }
    radiance = ls_preillum(rec);
    return true;
}
#endif

#include "gi.glsl"

#endif
