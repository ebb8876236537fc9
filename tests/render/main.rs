//! kiln-play on lavapipe: analytic direct-light checks pixel by pixel, the demo and PICA PICA
//! scenes with the validation layer on, and damaged or minimal files.
//!
//! Every test needs a Vulkan 1.3 device; without one they print why and pass, unless
//! `KILN_REQUIRE_VULKAN` is set (as `.ci/run` does), when they fail.

// The shared harness: compile a scene, render it headless with the validation layer on, read
// the image back, and the camera and pixel arithmetic the checks are written in.
mod harness;

// The tests, by topic.
mod analytic; // one light on a diffuse plane against its closed form, per pixel
mod colors; // vertex colours in both G-buffers and the reference, against closed forms
mod denoise; // svgf: the floor under an emissive quad keeps its closed-form mean, loses its noise, bleeds nothing into the lamp; converges to the undenoised image
mod emitters; // emissive triangles as lights (ris, restir): polygon irradiance, textured emission, a white furnace
mod environment; // the environment: background mapping, a constant map against the constant sky, a white sphere against brute force (reference, direct pass)
mod files; // damaged files fail with the right exit code; minimal files render
mod gi; // path-traced GI plus direct light against the two-bounce reference
mod godrays; // Mitchell's and Sousa's image-space blurs, their failure with the light behind the camera
mod media; // single scattering in a lit slab against its closed form (reference, march, toth)
mod placement; // one room at the origin, 10⁵ out and scaled by 10⁻³ and 10³ renders the same image (reference, rt gi)
mod probes; // --gi probes: a room against the reference, no light through a wall one probe spacing thick
mod progressive; // first frames from the fallback while ray-traced pipelines compile: output, bench, switch, teardown
mod raytraced; // ray-traced AO and reflections against closed forms, accumulation
mod rect; // a rect light against the polygon irradiance: direct pass, RT shadows, reference
mod reference; // the reference path tracer's GGX in a white furnace
mod reproject; // the ray-traced running mean carried along a moving camera, restarted where disoccluded
mod scenes; // the demo and PICA PICA scenes: clean, lit, the G-buffers and pipelines agree
mod screen_ao; // SAO and GTAO: a flat floor unoccluded, an inside corner against the estimator and the closed form
mod see_through; // blended and transmitting surfaces over the lit frame: a sheet of alpha a and a glass slab in front of an emissive wall against their closed forms
mod shadows; // an occluder's umbra, from shadow maps and from ray-traced shadows
mod specular; // KHR_materials_ior and specular: a black mirror floor under a uniform sky against Schlick's closed form (reference, raster)
mod ssgi; // screen-space GI: a red wall's bleed onto the floor against its closed form, none from off screen
mod ssr; // screen-space reflections of an emitter in a mirror floor, the split sum where they leave the screen
mod streaming; // textures streamed coarse first: the first frame shows the coarse levels, output and bench come from the refined ones
mod taa; // temporal anti-aliasing and FXAA against 16× supersampling, still and moving, no ghosts
mod textures; // BC textures render within a small FLIP of RGBA8; RGBA8-only passes refuse them
