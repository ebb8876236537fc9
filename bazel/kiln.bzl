"""kiln_scene: compiles a glTF or OBJ scene into a .kiln file as one hermetic Bazel action.

The action's inputs are the scene file, every file it refers to (`srcs`: buffers, images, MTL
libraries), the optional sidecar and the kiln binary; its outputs are `<name>.kiln` and
`<name>.report.json`. kiln's output depends only on the bytes of those inputs and the settings
(not on where the files sit, nor on the thread count), so the action is cacheable locally
(`--disk_cache`), remotely (`--remote_cache`) and runs unchanged on remote workers.
"""

def _kiln_scene_impl(ctx):
    out = ctx.actions.declare_file(ctx.attr.out or ctx.label.name + ".kiln")
    report = ctx.actions.declare_file(ctx.label.name + ".report.json")
    args = ctx.actions.args()
    args.add("compile")
    args.add(ctx.file.scene)
    inputs = [ctx.file.scene] + ctx.files.srcs
    if ctx.file.config:
        args.add("--config", ctx.file.config)
        inputs.append(ctx.file.config)
    for key in sorted(ctx.attr.bake.keys()):
        if key.startswith("-") or key in _NOT_BAKE_SETTINGS:
            fail("bake: %r is not a bake setting; write a setting's name without dashes (e.g. \"voxel-res\")" % key)
        args.add("--" + key, ctx.attr.bake[key])
    if ctx.attr.strict:
        args.add("--strict")
    if ctx.attr.threads > 0:
        args.add("--threads", str(ctx.attr.threads))
    args.add("-q")
    args.add("-o", out)
    args.add("--report", report)
    ctx.actions.run(
        executable = ctx.executable.kiln,
        arguments = [args],
        inputs = depset(inputs),
        outputs = [out, report],
        mnemonic = "KilnCompile",
        progress_message = "Compiling scene %s" % ctx.label,
    )
    return [
        DefaultInfo(files = depset([out]), runfiles = ctx.runfiles(files = [out])),
        OutputGroupInfo(report = depset([report])),
    ]

# Options of `kiln compile` that are not bake settings: the rule sets them itself.
_NOT_BAKE_SETTINGS = ["o", "output", "config", "c", "report", "depfile", "q", "quiet", "cache", "no-cache", "threads", "strict"]

kiln_scene = rule(
    implementation = _kiln_scene_impl,
    doc = "Compiles `scene` (with the files it refers to in `srcs`) into `<name>.kiln`.",
    attrs = {
        "scene": attr.label(
            allow_single_file = [".gltf", ".glb", ".obj"],
            mandatory = True,
            doc = "The scene file: glTF (.gltf, .glb) or OBJ.",
        ),
        "srcs": attr.label_list(
            allow_files = True,
            doc = "Every file the scene refers to: buffers, images, MTL libraries. " +
                  "`kiln compile SCENE --depfile x.d` once lists them.",
        ),
        "config": attr.label(
            allow_single_file = [".toml"],
            doc = "The sidecar (camera, lights, sky, [bake] settings); docs/sidecar.md.",
        ),
        "bake": attr.string_dict(
            doc = "Bake settings as `kiln compile` spells them without the dashes, " +
                  "e.g. {\"voxel-res\": \"64\", \"shaft-variants\": \"none\"}.",
        ),
        "strict": attr.bool(
            default = False,
            doc = "Fail on any warning (`--strict`), e.g. a texture the scene names but srcs lacks.",
        ),
        "threads": attr.int(
            default = 0,
            doc = "Worker threads (0: all cores). The output is the same whatever it says.",
        ),
        "out": attr.string(doc = "Output file name (default `<name>.kiln`)."),
        "kiln": attr.label(
            default = "@kiln_tool//:kiln",
            executable = True,
            cfg = "exec",
            allow_single_file = True,
            doc = "The kiln binary; by default `@kiln_tool//:kiln`, which the workspace defines.",
        ),
    },
)
