#version 460
#include "common.glsl"

layout(location = 0) rayPayloadInEXT Payload payload;

void main() {
    payload.t = NO_HIT;
}
