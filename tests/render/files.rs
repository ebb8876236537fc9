//! Files the player must refuse or render bare: truncated, a flipped byte, not kiln at all,
//! empty and missing files fail with the exit code of their class; a file with no lights renders
//! its emission and sky as they are.

use std::time::Instant;

use kiln_compiler::import::demo::{cornell_box, lambert_material};
use kiln_format::manifest::Sky;
use kiln_player::error::Exit;
use kiln_player::headless;
use kiln_test_support::gpu_test;
use kiln_tests::{Options, compile, scene_of};

use crate::harness::{fast_settings, render, square};

#[test]
fn damaged_files_fail_cleanly_and_minimal_files_render() {
    let dir = gpu_test!();
    let good = compile(cornell_box(), fast_settings());
    let file = kiln_format::read::KilnFile::from_bytes(&good, Default::default()).unwrap();
    let vert = file.find(kiln_format::sections::VERTICES, 0).unwrap().entry;
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("truncated", good[..good.len() / 2].to_vec()),
        ("flipped vertex byte", {
            let mut b = good.clone();
            b[vert.offset as usize + 5] ^= 0x40;
            b
        }),
        ("not a kiln file", b"glTF binary, not kiln".repeat(10)),
        ("empty", Vec::new()),
    ];
    for (name, bytes) in cases {
        let path = dir.path().join(format!("{}.kiln", name.replace(' ', "-")));
        std::fs::write(&path, &bytes).unwrap();
        let err = headless::run(
            &Options::new(&path, 32, 32).build(),
            1,
            Some(&dir.path().join("x.png")),
            Instant::now(),
        )
        .unwrap_err();
        assert_eq!(err.exit, Exit::BadInput, "{name}: {}", err.message);
        assert!(
            err.message.contains(path.to_str().unwrap()) || err.message.contains("invalid"),
            "{name}: {}",
            err.message
        );
    }
    let missing = dir.path().join("missing.kiln");
    let err = headless::run(&Options::new(&missing, 32, 32).build(), 1, None, Instant::now()).unwrap_err();
    assert_eq!(err.exit, Exit::Io, "{}", err.message);

    // No lights: no shadow maps, no BRDF table, no textures. It renders emission and sky only.
    let mut scene = scene_of(&square(0.0, 1.0));
    scene.materials[0].gpu = lambert_material([0.0; 3]);
    scene.materials[0].gpu.emission = [0.5, 0.25, 0.125];
    scene.sky = Sky { radiance: [0.1, 0.2, 0.3] };
    let bytes = compile(scene, fast_settings());
    let (rgb, result) = render(dir.path(), "minimal", &bytes, |f| {
        Options::new(f, 32, 32).camera("0,3,0.01,0,0,0,90".parse().unwrap())
    });
    assert!(result.session.scene.shadow_maps.is_empty() && result.session.scene.brdf_lut.is_none());
    assert!(rgb.chunks_exact(3).any(|p| p == [0.5, 0.25, 0.125]), "emission is written as is");
    assert!(rgb.chunks_exact(3).any(|p| p == [0.1, 0.2, 0.3]), "the sky is written as is");
    let skipped: Vec<_> =
        result.session.scene.sections.iter().filter(|s| !s.uploaded).map(|s| s.section.clone()).collect();
    assert!(skipped.iter().any(|s| s == "bvh"), "the BVH is not uploaded: no pass traces rays ({skipped:?})");
}
