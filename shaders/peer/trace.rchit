#version 460
#include "common.glsl"

layout(location = 0) rayPayloadInEXT Payload payload;
hitAttributeEXT vec2 barycentrics;

void main() {
    payload.t = gl_HitTEXT;
    payload.triangle = uint(gl_PrimitiveID);
    payload.uv = barycentrics;
}
