#version 460
// direct_reuse.comp, its shadow rays through the binary line space with exact triangle tests
// in every filled shaft (`--shadows linespace --ls-shadow-test filled`; direct.glsl).
#define DIRECT_LS_EXACT true
#include "hybrid.glsl"
#include "direct.glsl"

void main() {
    reuse_main();
}
