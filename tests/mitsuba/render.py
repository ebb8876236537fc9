"""Renders a kiln test scene with Mitsuba 3 (variant llvm_ad_rgb) and compares images with FLIP.

    render.py render SCENE.json OUT.npy SPP WIDTHxHEIGHT [SEED]
        Renders the scene that tests/mitsuba.rs wrote (variant llvm_ad_rgb, in passes of 256
        samples per pixel) and saves linear RGB radiance as float32
        (height, width, 3), row 0 at the top. Prints one JSON line: {"spp", "seconds"}.

    render.py compare REFERENCE.npy TEST.npy [FLIP_MAP.npy]
        Prints one JSON line: mean HDR-FLIP of TEST against REFERENCE, relative MSE, and the
        ratio of the images' mean radiance per channel (TEST / REFERENCE); optionally saves the
        per-pixel FLIP error.

The scene JSON (written by tests/mitsuba.rs) holds the camera, triangle meshes grouped by
material (positions, vertex indices with front faces counter-clockwise, Lambertian albedo,
emitted radiance) and one-sided rectangular lights. The conventions are kiln's reference path
tracer's (shaders/reference/pathtrace.comp), mapped to Mitsuba's:

- Lambertian surfaces reflect on both sides in kiln: `twosided(diffuse)`.
- A mesh with a `material` (base colour, metallic, roughness, the dielectric's F0 and F90, clear
  coat and its roughness, textures) is glTF's metallic-roughness BSDF, `gltf_bsdf.py`'s Python
  plugin.
- Vertex colours (a mesh's optional `colors`, linear RGB per vertex) multiply the albedo: the
  product is written as the PLY's float `r, g, b`, read through `mesh_attribute` `vertex_color`.
- Emissive triangles emit from the front face only (as Mitsuba's `area` emitter does); flat
  face normals (`face_normals`), as the kiln scenes' quads have.
- A kiln rect light is no geometry (rays pass through it, it casts no shadow) and emits its
  radiance from the side its `direction` points to: a `rectangle` with an `area` emitter and the
  `null` BSDF (paths go straight through it), `to_world` mapping Mitsuba's [-1, 1]² (normal +z)
  onto `right` × width, `direction × right` × height, normal `direction`.
- Pinhole camera, vertical field of view, box filter over the pixel: `perspective` with
  `fov_axis: y` and `rfilter: box` (kiln jitters uniformly over the pixel; a box of radius 0.5
  gives each sample to its own pixel).
- An environment (the scene's optional `environment`: an .npy of linear RGB, row 0 the zenith,
  twice as wide as tall) is Mitsuba's `envmap` emitter of that bitmap: kiln maps directions as
  envmap does (u = atan2(x, -z) / 2pi, v = acos(y) / pi, y up) and both interpolate bilinearly.
- Unbiased path tracing of unlimited length: `path` with `max_depth: -1`.
- A participating medium (the scene's optional `medium`: sigma_a, sigma_s per channel, the
  Henyey–Greenstein g) fills the whole space: a `homogeneous` medium (sigma_t = sigma_a +
  sigma_s, albedo sigma_s / sigma_t, `hg` phase) given to the camera, rendered by `volpath`.
  Surfaces without medium interfaces keep the medium a path is in, so this equals kiln's box
  medium when the box holds a closed room with the camera inside (what tests/mitsuba.rs builds).

FLIP: HDR-FLIP (Andersson et al. 2021, `flip_evaluator`), the variant for linear radiance: it
tonemaps both images over the range of exposures the reference needs and reports the mean error
over exposures and pixels, in [0, 1]. Relative MSE: mean over pixels and channels of
(test - ref)^2 / (ref^2 + 0.01).
"""

import json
import os
import sys
import tempfile
import time

import numpy as np


def write_ply(path, positions, triangles, colors=None, normals=None, uvs=None):
    """Binary PLY; `colors` (linear RGB per vertex) become float r, g, b properties, which
    Mitsuba's PLY loader turns into the `vertex_color` mesh attribute; `normals` nx, ny, nz;
    `uvs` u, v (as kiln stores them: v down the image)."""
    positions = np.asarray(positions, dtype="<f4").reshape(-1, 3)
    triangles = np.asarray(triangles, dtype="<u4").reshape(-1, 3)
    fields = [("p", "<f4", 3)]
    props = "property float x\nproperty float y\nproperty float z\n"
    if normals is not None:
        fields.append(("n", "<f4", 3))
        props += "property float nx\nproperty float ny\nproperty float nz\n"
    if uvs is not None:
        fields.append(("uv", "<f4", 2))
        props += "property float u\nproperty float v\n"
    if colors is not None:
        fields.append(("c", "<f4", 3))
        props += "property float r\nproperty float g\nproperty float b\n"
    vertices = np.zeros(len(positions), dtype=fields)
    vertices["p"] = positions
    if normals is not None:
        vertices["n"] = np.asarray(normals, dtype="<f4").reshape(-1, 3)
    if uvs is not None:
        vertices["uv"] = np.asarray(uvs, dtype="<f4").reshape(-1, 2)
    if colors is not None:
        vertices["c"] = np.asarray(colors, dtype="<f4").reshape(-1, 3)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(positions)}\n" + props +
        f"element face {len(triangles)}\n"
        "property list uchar uint vertex_indices\nend_header\n"
    )
    faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("i", "<u4", 3)])
    faces["n"] = 3
    faces["i"] = triangles
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(vertices.tobytes())
        f.write(faces.tobytes())


def rgb(value):
    return {"type": "rgb", "value": [float(v) for v in value]}


def scene_dict(mi, desc, tmp, width, height, spp, seed):
    cam = desc["camera"]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5, "hide_emitters": False},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": float(cam["vfov_degrees"]),
            "near_clip": 1e-3,
            "far_clip": 1e4,
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["position"], target=cam["target"], up=cam["up"]
            ),
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
                "component_format": "float32",
            },
        },
    }
    medium = desc.get("medium")
    if medium is not None:
        sigma_a = np.asarray(medium["sigma_a"], dtype=float)
        sigma_s = np.asarray(medium["sigma_s"], dtype=float)
        sigma_t = sigma_a + sigma_s
        scene["integrator"] = {"type": "volpath", "max_depth": -1, "rr_depth": 5, "hide_emitters": False}
        scene["sensor"]["medium"] = {
            "type": "homogeneous",
            "sigma_t": rgb(sigma_t),
            "albedo": rgb(sigma_s / np.maximum(sigma_t, 1e-30)),
            "scale": 1.0,
            "phase": {"type": "hg", "g": float(medium["g"])},
        }
    for i, m in enumerate(desc["meshes"]):
        path = os.path.join(tmp, f"mesh{i}.ply")
        colors = m.get("colors") or None
        reflectance = rgb(m["albedo"])
        if colors is not None:
            # The base colour times the vertex colour: the albedo is baked into the colours.
            colors = np.asarray(colors, dtype=float).reshape(-1, 3) * np.asarray(m["albedo"], dtype=float)
            reflectance = {"type": "mesh_attribute", "name": "vertex_color"}
        normals = m.get("normals") or None
        uvs = m.get("uvs") or None
        write_ply(path, m["positions"], m["triangles"], colors, normals, uvs)
        bsdf = {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": reflectance}}
        material = m.get("material")
        if material is not None:
            assert colors is None, "vertex colours on a glossy material are not mapped"
            number = lambda v: v if isinstance(v, (str, bool)) else float(v)
            bsdf = {"type": "kiln_gltf", **{k: number(v) for k, v in material.items()}}
            # Coverage: kiln meets the surface with this probability; Mitsuba's `mask`.
            if m.get("coverage", 1.0) < 1.0:
                bsdf = {"type": "mask", "opacity": float(m["coverage"]), "bsdf": bsdf}
        shape = {"type": "ply", "filename": path, "face_normals": normals is None, "bsdf": bsdf}
        if any(v > 0.0 for v in m["emission"]):
            radiance = rgb(m["emission"])
            if "emission_tex" in m:
                import gltf_bsdf

                radiance = gltf_bsdf.texture(m["emission_tex"], True, "repeat", True, scale=m["emission"])
            shape["emitter"] = {"type": "area", "radiance": radiance}
        scene[f"mesh{i}"] = shape
    env = desc.get("environment")
    if env is not None:
        pixels = np.load(env).astype(np.float32)
        scene["environment"] = {"type": "envmap", "bitmap": mi.Bitmap(pixels)}
    for i, l in enumerate(desc["rect_lights"]):
        d = np.asarray(l["direction"], dtype=float)
        r = np.asarray(l["right"], dtype=float)
        u = np.cross(d, r)
        m = np.identity(4)
        m[:3, 0] = r * 0.5 * l["width"]
        m[:3, 1] = u * 0.5 * l["height"]
        m[:3, 2] = d
        m[:3, 3] = l["position"]
        scene[f"rect{i}"] = {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f(m.tolist()),
            "bsdf": {"type": "null"},
            "emitter": {"type": "area", "radiance": rgb(l["radiance"])},
        }
    for i, l in enumerate(desc.get("point_lights", [])):
        scene[f"point{i}"] = {"type": "point", "position": l["position"], "intensity": rgb(l["intensity"])}
    return scene


def find_libllvm():
    """Dr.Jit's LLVM back end (vectorised: several times faster than the scalar variant on
    these scenes, and a Python BSDF is called once per wavefront, not per sample) wants an LLVM
    newer than Debian 12's default 15: `.ci/run` installs libllvm19. The newest libLLVM-NN.so
    found, unless DRJIT_LIBLLVM_PATH names one."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return
    found = []
    for folder in ("/usr/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu", "/usr/lib64", "/usr/lib"):
        for name in os.listdir(folder) if os.path.isdir(folder) else []:
            digits = name[len("libLLVM-"):-len(".so")]
            if name.startswith("libLLVM-") and name.endswith(".so") and digits.isdigit() and int(digits) >= 17:
                found.append((int(digits), os.path.join(folder, name)))
    if not found:
        sys.exit("render.py: Mitsuba's LLVM variant needs libLLVM 17 or newer "
                 "(Debian: apt-get install libllvm19), or DRJIT_LIBLLVM_PATH naming one")
    os.environ["DRJIT_LIBLLVM_PATH"] = max(found)[1]


# Samples per pixel per pass of the LLVM variant, which holds a pass's paths in memory at once.
LLVM_PASS_SPP = 256


def render(scene_path, out_path, spp, size, seed):
    width, height = (int(v) for v in size.split("x"))
    with open(scene_path) as f:
        desc = json.load(f)
    find_libllvm()
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import gltf_bsdf

    gltf_bsdf.register()
    with tempfile.TemporaryDirectory() as tmp:
        scene = mi.load_dict(scene_dict(mi, desc, tmp, width, height, spp, seed))
    t0 = time.perf_counter()
    # Passes of at most LLVM_PASS_SPP samples, each with its own seed, averaged.
    passes = [LLVM_PASS_SPP] * (spp // LLVM_PASS_SPP) + ([spp % LLVM_PASS_SPP] if spp % LLVM_PASS_SPP else [])
    total = np.zeros((height, width, 3), dtype=np.float64)
    for k, n in enumerate(passes):
        total += np.array(mi.render(scene, spp=n, seed=seed * 100003 + k), dtype=np.float64) * n
    image = (total / spp).astype(np.float32)
    seconds = time.perf_counter() - t0
    assert image.shape == (height, width, 3), image.shape
    np.save(out_path, image)
    print(json.dumps({"spp": spp, "seconds": seconds}))


def compare(reference_path, test_path, flip_map=None):
    import flip_evaluator

    ref = np.load(reference_path).astype(np.float32)
    test = np.load(test_path).astype(np.float32)
    assert ref.shape == test.shape, (ref.shape, test.shape)
    assert np.isfinite(ref).all() and np.isfinite(test).all(), "non-finite pixels"
    error_map, mean_flip, _ = flip_evaluator.evaluate(
        np.ascontiguousarray(ref), np.ascontiguousarray(test), "HDR", applyMagma=False
    )
    rel_mse = float(np.mean((test - ref) ** 2 / (ref**2 + 1e-2)))
    ratio = (test.reshape(-1, 3).mean(axis=0) / np.maximum(ref.reshape(-1, 3).mean(axis=0), 1e-30)).tolist()
    if flip_map is not None:
        np.save(flip_map, np.asarray(error_map, dtype=np.float32))
    print(json.dumps({"mean_flip": float(mean_flip), "rel_mse": rel_mse, "mean_ratio": ratio}))


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) in (5, 6) and args[0] == "render":
        render(args[1], args[2], int(args[3]), args[4], int(args[5]) if len(args) == 6 else 0)
    elif len(args) in (3, 4) and args[0] == "compare":
        compare(*args[1:])
    else:
        sys.exit(__doc__)
