// The camera ray through a point of the image and where it meets a triangle's plane: how the
// compute passes find the exact surface point of a pixel the rasteriser drew. The includer
// declares the `frame` uniform (FrameConstants).
#ifndef KILN_PIXEL_GLSL
#define KILN_PIXEL_GLSL

// The camera: perspective from the eye frame.camera.xyz (camera.w = 0; camera_right.w and
// camera_up.w the tangents of the half fields of view) or orthographic (camera.w = 1; .w the
// half-width and half-height of the view rectangle centred on camera.xyz).
bool camera_orthographic() {
    return frame.camera.w != 0.0;
}

// Normalised device coordinates (x right, y up, [-1, 1]) of image point `at` (pixels, row 0 at
// the top, (0.5, 0.5) the first pixel's centre), and back.
vec2 image_to_ndc(vec2 at) {
    return vec2(at.x / float(frame.size.x) * 2.0 - 1.0, 1.0 - at.y / float(frame.size.y) * 2.0);
}

vec2 ndc_to_image(vec2 ndc) {
    return vec2((ndc.x + 1.0) * 0.5 * float(frame.size.x), (1.0 - ndc.y) * 0.5 * float(frame.size.y));
}

// The world point at image point `at` and reversed-Z `depth`, through `frame.inv_view_proj`
// (the jittered projection the G-buffer was drawn with).
vec3 world_at_depth(vec2 at, float depth) {
    vec4 w = frame.inv_view_proj * vec4(image_to_ndc(at), depth, 1.0);
    return w.xyz / w.w;
}

// The offset in the image plane of image point `at` (pixel units, (0.5, 0.5) the first pixel's
// centre), by the projection's own mapping, moved by this frame's sub-pixel jitter (what the
// jittered `view_proj` rasterises at `at`).
vec3 pixel_offset(vec2 at) {
    vec2 ndc = image_to_ndc(at + frame.jitter.xy);
    return frame.camera_right.xyz * (ndc.x * frame.camera_right.w) + frame.camera_up.xyz * (ndc.y * frame.camera_up.w);
}

// Origin of the camera ray through image point `at`.
vec3 pixel_origin(vec2 at) {
    return camera_orthographic() ? frame.camera.xyz + pixel_offset(at) : frame.camera.xyz;
}

// Direction of the camera ray through image point `at` (not normalised).
vec3 pixel_ray(vec2 at) {
    return camera_orthographic() ? frame.camera_forward.xyz : frame.camera_forward.xyz + pixel_offset(at);
}

// Unit direction from world point p towards the camera (the view vector).
vec3 towards_camera(vec3 p) {
    return camera_orthographic() ? -frame.camera_forward.xyz : normalize(frame.camera.xyz - p);
}

// What the distance along a camera ray is where a pixel shows the sky.
const float SKY_DISTANCE = 3.4e38;

// Distance along the unit camera ray (o, d) of image point `at` to the surface the G-buffer's
// reversed-Z `depth` holds there; SKY_DISTANCE where it holds the sky (depth 0).
float surface_distance(vec2 at, float depth, vec3 o, vec3 d) {
    if (!(depth > 0.0)) {
        return SKY_DISTANCE;
    }
    return max(dot(world_at_depth(at, depth) - o, d), 0.0);
}

// Barycentrics (of corners 1 and 2) where the camera ray from `origin` along `dir` meets the
// plane of the triangle p0, p0 + e1, p0 + e2 (Möller–Trumbore without the bounds test); 0 when
// parallel.
vec2 barycentrics(vec3 origin, vec3 dir, vec3 p0, vec3 e1, vec3 e2) {
    vec3 pv = cross(dir, e2);
    float det = dot(e1, pv);
    if (abs(det) <= 0.0) {
        return vec2(0.0);
    }
    vec3 tv = origin - p0;
    return vec2(dot(tv, pv), dot(dir, cross(tv, e1))) / det;
}

#endif
