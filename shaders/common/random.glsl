// Random numbers for the ray-traced passes: a PCG state per invocation, seeded by hashing.
#ifndef KILN_RANDOM_GLSL
#define KILN_RANDOM_GLSL

uint rng;
uint pcg() {
    uint s = rng;
    rng = s * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}
float rnd() {
    return float(pcg() >> 8) * (1.0 / 16777216.0);
}
uint hash(uint x) {
    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
    return x;
}

#endif
