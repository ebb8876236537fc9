// Image-space god rays (`--media mitchell`, `--media sousa`): where a light lies on the screen
// and how bright its shafts are. The includer declares `frame` (FrameConstants), `lights`
// (GpuLight) and `media` (GpuMedium), and includes lights.glsl, pixel.glsl and media.glsl first.
#ifndef KILN_GODRAYS_GLSL
#define KILN_GODRAYS_GLSL

// Light `l`'s position on the screen in texture coordinates (x right, y down, the image is
// [0, 1]²; a light off screen lies outside). False when the light is behind the camera (or a
// directional light seen by an orthographic camera): a radial blur then has no centre, and the
// technique shows no shafts at all. That is these methods' known failure, left visible (seed
// 002, §8.1), not patched over.
bool light_on_screen(GpuLight l, out vec2 uv) {
    vec4 clip = l.kind == LIGHT_DIRECTIONAL ? frame.view_proj * vec4(-l.direction, 0.0)
                                            : frame.view_proj * vec4(l.position, 1.0);
    uv = vec2(0.0);
    if (!(clip.w > 0.0)) {
        return false;
    }
    // An orthographic projection keeps w = 1 behind the camera too.
    if (camera_orthographic() && dot(l.position - frame.camera.xyz, frame.camera_forward.xyz) <= 0.0) {
        return false;
    }
    vec2 ndc = clip.xy / clip.w;
    uv = vec2(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    return all(lessThan(abs(uv), vec2(1e6)));
}

// The radiance a shaft of light `l` adds per unit of the blur's amount, along the unit view ray
// d: the light's unoccluded irradiance at the camera times medium 0's single-scattering albedo
// σs/σt and its Henyey–Greenstein phase at the angle between d and the direction towards the
// light. That is what a long, fully lit path through the medium scatters towards the eye
// (σs·p·E·∫e^{−σt·s} ds → σs/σt·p·E), so an amount of 1 means "as bright as deep fog lets it be".
// The blurs' own parameters stay the seed's artistic ones; this only gives their shafts the
// medium's colour and the light's brightness. Zero without a medium.
vec3 shaft_radiance(GpuLight l, vec3 d, uint media_count) {
    if (media_count == 0u) {
        return vec3(0.0);
    }
    vec3 towards;
    float dist;
    vec3 e;
    if (!light_at_point(l, frame.camera.xyz, towards, dist, e)) {
        return vec3(0.0);
    }
    vec3 albedo = media[0].sigma_s.rgb / max(medium_sigma_t(0u), vec3(1e-30));
    return e * albedo * hg(media[0].min.w, dot(towards, d));
}

// A sample of a screen-space image at texture coordinates `uv`: 0 off the screen (a radial blur
// towards a light off screen finds nothing there, as the seed's methods do).
float on_screen(sampler2D image, vec2 uv) {
    return all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))) ? textureLod(image, uv, 0.0).r : 0.0;
}

#endif
