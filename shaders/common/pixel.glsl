// The camera ray through a point of the image and where it meets a triangle's plane: how the
// compute passes find the exact surface point of a pixel the rasteriser drew. The includer
// declares the `frame` uniform (FrameConstants).
#ifndef KILN_PIXEL_GLSL
#define KILN_PIXEL_GLSL

// Direction of the camera ray through image point `at` (pixel units, (0.5, 0.5) the first
// pixel's centre), by the projection's own mapping.
vec3 pixel_ray(vec2 at) {
    vec2 ndc = vec2(at.x / float(frame.size.x) * 2.0 - 1.0, 1.0 - at.y / float(frame.size.y) * 2.0);
    return frame.camera_forward.xyz + frame.camera_right.xyz * (ndc.x * frame.camera_right.w)
        + frame.camera_up.xyz * (ndc.y * frame.camera_up.w);
}

// Barycentrics (of corners 1 and 2) where the camera ray along `dir` meets the plane of the
// triangle p0, p0 + e1, p0 + e2 (Möller–Trumbore without the bounds test); 0 when parallel.
vec2 barycentrics(vec3 dir, vec3 p0, vec3 e1, vec3 e2) {
    vec3 pv = cross(dir, e2);
    float det = dot(e1, pv);
    if (abs(det) <= 0.0) {
        return vec2(0.0);
    }
    vec3 tv = frame.camera.xyz - p0;
    return vec2(dot(tv, pv), dot(dir, cross(tv, e1))) / det;
}

#endif
