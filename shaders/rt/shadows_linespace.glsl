// Soft shadows by line-space shadow feelers (seed 004 §9): the estimator of shadows.glsl, its
// rays through the binary line space with exact triangle tests in filled cells near the rays'
// ends only (SHADOW_LS_EXACT false: conservative in between, no self-shadowing) or in every
// filled cell (true: the exact answer, the bits only skipping empty shafts). The includer
// defines SHADOW_LS_EXACT.
#ifndef KILN_SHADOWS_LINESPACE_GLSL
#define KILN_SHADOWS_LINESPACE_GLSL

#include "hybrid.glsl"
#define LS_BINDING 36
#include "../common/linespace.glsl"

bool shadow_occluded(vec3 from, vec3 ng, vec3 to) {
    return ls_occluded(from, ng, to, SHADOW_LS_EXACT);
}

bool shadow_occluded_dir(vec3 from, vec3 ng, vec3 dir) {
    return ls_occluded_dir(from, ng, dir, SHADOW_LS_EXACT);
}

#include "shadows.glsl"

#endif
