// Sousa's radial blur (seed 002 §6, Listing A.7): from texture coordinates `uv`, up to
// `gc.samples` (TAPS) samples of `image` a fixed `gc.step` apart towards the light at
// `light_uv`, stopping once past the light; their sum times the brightness. Each pass's output
// is the next one's input, with steps TAPS⁻¹, TAPS⁻², TAPS⁻³: interleaved sampling. The
// includer declares `gc` and includes godrays.glsl.
float sousa_sum(sampler2D image, vec2 uv, vec2 light_uv) {
    vec2 v = light_uv - uv;
    float len = length(v);
    if (!(len > 0.0)) {
        return float(gc.samples) * gc.gain * on_screen(image, uv);
    }
    vec2 stp = gc.step * v / len;
    float max_steps = len / gc.step;
    float sum = 0.0;
    vec2 p = uv;
    [[dont_unroll]] for (uint i = 0u; i < gc.samples; i++) {
        if (float(i) >= max_steps) {
            break;
        }
        sum += on_screen(image, p);
        p += stp;
    }
    return sum * gc.gain;
}
