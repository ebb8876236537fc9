#version 460
// direct_candidates.comp, its shadow rays through the binary line space with exact triangle tests
// only in the cells at the rays' ends (`--shadows linespace`; direct.glsl).
#define DIRECT_LS_EXACT false
#include "hybrid.glsl"
#include "direct.glsl"

void main() {
    candidates_main();
}
