//! The catalogue against the technique modules: every entry builds its technique by name,
//! knobs are checked and read by name, and what the techniques read and fall back to.

use super::ao::{Radius, gtao::Gtao, rt::Rt as AoRt, sao::Sao};
use super::gi::{linespace::GiStructure, linespace::LineSpace as GiLineSpace, rt::Rt as GiRt, ssgi::Ssgi};
use super::media::{march::March, mitchell::Mitchell, sousa::Sousa, toth::Phase, toth::Toth};
use super::reflections::{rt::ReflectionRes, rt::Rt as ReflRt, ssr::Ssr};
use super::shadows::linespace::{LineSpace as ShadowLineSpace, LsShadowTest};
use super::shadows::rt::Rt as ShadowRt;
use super::*;

/// The defaults with nothing read but the frame's own sections: the raster G-buffer, and no
/// emissive surfaces' direct light (`--direct restir`, which a session drops for a file whose
/// materials emit nothing).
fn baked() -> Techniques {
    let mut t = Techniques::default();
    t.set(Effect::Direct, "none", &[]).unwrap();
    t.set(Effect::GBuffer, "raster", &[]).unwrap();
    t
}

#[test]
fn the_default_lights_with_emissive_surfaces_by_restir_which_is_ray_traced() {
    let d = Techniques::default();
    assert_eq!(d.name_of(Effect::Direct), "restir");
    // The visibility buffer, which resolves materials from the scene's buffers.
    assert_eq!(d.name_of(Effect::GBuffer), "visibility");
    assert!(d.ray_traced() && d.needs().bvh && d.needs().scene_buffers);
    assert_eq!(d.flags(), kiln_format::gpu::FrameFlags::RT_DIRECT);
    // While its pipelines compile, frames show no emitters' light; without a BVH it is off.
    let mut unlit = d;
    unlit.set(Effect::Direct, "none", &[]).unwrap();
    assert_eq!(d.fallback(true).unwrap(), unlit);
    assert_eq!(d.without_rays(), unlit);
}

#[test]
fn every_catalogue_entry_builds_its_technique() {
    for info in catalogue() {
        let mut t = Techniques::default();
        t.set(info.effect, info.name, &[]).unwrap();
        assert_eq!(t.name_of(info.effect), info.name, "{} {}", info.effect, info.name);
        for k in info.knobs {
            k.check(k.default).unwrap();
        }
    }
    for e in Effect::ALL {
        assert!(techniques_of(e).count() >= 1, "{e} has no technique");
        assert!(
            techniques_of(e).any(|t| t.name == "none") || matches!(e, Effect::GBuffer),
            "{e} has no 'none'"
        );
    }
}

/// Knobs are read by name: building a technique with every knob set to a value other than its
/// default gives exactly those values in its fields, whatever the order the module lists them
/// in (the catalogue used to be read by position).
#[test]
fn knobs_reach_the_fields_they_name() {
    let mut t = baked();
    t.set(
        Effect::Ao,
        "sao",
        &[
            ("ao-res", KnobValue::Choice(0)),
            ("ao-turns", KnobValue::Number(5.0)),
            ("ao-samples", KnobValue::Number(8.0)),
            ("ao-reach", KnobValue::Number(0.2)),
            ("ao-radius", KnobValue::Number(1.5)),
        ],
    )
    .unwrap();
    assert_eq!(
        t.ao,
        Ao::Sao(Sao {
            radius: Radius { radius: Some(1.5), reach: 0.2 },
            samples: 8,
            turns: 5.0,
            resolution: ScreenFraction::Full
        })
    );
    t.set(
        Effect::Gi,
        "ssgi",
        &[
            ("ssgi-rotation", KnobValue::Choice(0)),
            ("ssgi-frames", KnobValue::Number(7.0)),
            ("ssgi-falloff", KnobValue::Choice(1)),
            ("ssgi-mip", KnobValue::Choice(0)),
            ("ssgi-radius", KnobValue::Number(20.0)),
            ("ssgi-res", KnobValue::Choice(2)),
            ("ssgi-samples", KnobValue::Number(9.0)),
        ],
    )
    .unwrap();
    assert_eq!(
        t.gi,
        Gi::Ssgi(Ssgi {
            samples: 9,
            resolution: ScreenFraction::Quarter,
            radius: 20,
            voting: false,
            falloff: true,
            frames: 7,
            tiled: false
        })
    );
    t.set(
        Effect::Media,
        "mitchell",
        &[
            ("media-exposure", KnobValue::Number(3.0)),
            ("media-res", KnobValue::Choice(1)),
            ("media-samples", KnobValue::Number(12.0)),
        ],
    )
    .unwrap();
    assert_eq!(
        t.media,
        Media::Mitchell(Mitchell { samples: 12, resolution: ScreenFraction::Half, exposure: 3.0 })
    );
    t.set(
        Effect::Media,
        "sousa",
        &[("media-brightness", KnobValue::Number(0.5)), ("media-taps", KnobValue::Number(3.0))],
    )
    .unwrap();
    assert_eq!(
        t.media,
        Media::Sousa(Sousa { taps: 3, resolution: ScreenFraction::Quarter, brightness: 0.5 })
    );
    t.set(
        Effect::Shadows,
        "linespace",
        &[("ls-shadow-test", KnobValue::Choice(1)), ("sun-angle", KnobValue::Number(2.0))],
    )
    .unwrap();
    assert_eq!(
        t.shadows,
        Shadows::LineSpace(ShadowLineSpace {
            light_radius: 0.0,
            sun_degrees: 2.0,
            test: LsShadowTest::Filled
        })
    );
    t.set(
        Effect::Gi,
        "linespace",
        &[("gi-structure", KnobValue::Choice(2)), ("gi-bounces", KnobValue::Number(3.0))],
    )
    .unwrap();
    assert_eq!(
        t.gi,
        Gi::LineSpace(GiLineSpace { bounces: 3, structure: GiStructure::Preillum, regularize: 0.5 })
    );
    t.set(
        Effect::Aa,
        "taa",
        &[("taa-weights", KnobValue::Choice(0)), ("taa-frames", KnobValue::Number(4.0))],
    )
    .unwrap();
    assert_eq!(t.aa, Aa::Taa(super::aa::taa::Taa { frames: 4, luma_weights: true }));
}

#[test]
fn knobs_are_checked_and_named_in_errors() {
    let mut t = baked();
    let e = t.set(Effect::Shadows, "rt", &[("light-radius", KnobValue::Number(-1.0))]).unwrap_err();
    assert!(e.contains("light-radius"), "{e}");
    let e = t.set(Effect::Shadows, "rt", &[("radius", KnobValue::Number(1.0))]).unwrap_err();
    assert!(e.contains("light-radius, sun-angle"), "{e}");
    let e = t.set(Effect::Ao, "ssao", &[]).unwrap_err();
    assert!(e.contains("none, rt, sao, gtao"), "{e}");
    let e = t.set(Effect::Ao, "gtao", &[("ao-slices", KnobValue::Number(2.5))]).unwrap_err();
    assert!(e.contains("ao-slices") && e.contains("whole"), "{e}");
    t.set(Effect::Reflections, "rt", &[("reflection-res", KnobValue::Choice(1))]).unwrap();
    assert_eq!(
        t.reflections,
        Reflections::Rt(ReflRt {
            resolution: ReflectionRes::Half,
            max_roughness: 1.0,
            metal_bounce: super::reflections::rt::METAL_BOUNCE
        })
    );
}

/// Knobs of one name in several techniques are one command-line flag: they must agree on what
/// values are valid.
#[test]
fn knobs_sharing_a_name_share_their_range() {
    for a in catalogue().iter().flat_map(|t| t.knobs) {
        for b in catalogue().iter().flat_map(|t| t.knobs).filter(|b| b.name == a.name) {
            let strip = |r: KnobRange| match r {
                KnobRange::Number { min, max, whole, .. } => {
                    KnobRange::Number { min, max, whole, sweep: &[] }
                }
                c => c,
            };
            assert_eq!(strip(a.range), strip(b.range), "{}", a.name);
        }
    }
}

#[test]
fn needs_follow_the_techniques() {
    let d = baked();
    assert_eq!(d.needs(), Needs { shadow_maps: true, ..Needs::FRAME });
    let rt_ao = Ao::Rt(AoRt { radius: Radius { radius: None, reach: 0.1 } });
    let rt = Techniques { ao: rt_ao, shadows: Shadows::Off(super::shadows::none::Off), ..d };
    assert!(rt.needs().bvh && rt.needs().scene_buffers && !rt.needs().shadow_maps);
    let vis = Techniques { gbuffer: GBuffer::Visibility(super::gbuffer::visibility::Visibility), ..d };
    assert!(vis.needs().scene_buffers && !vis.needs().bvh);
    let gi = Techniques { gi: Gi::Rt(GiRt { bounces: 1, regularize: 0.5 }), ..d };
    assert!(gi.ray_traced() && gi.needs().bvh && gi.needs().scene_buffers);
    assert_eq!(gi.without_rays().gi, Gi::default());
    // The screen-space AO techniques read the G-buffer only, and survive a file without a BVH.
    for ao in [
        Ao::Sao(Sao {
            radius: Radius { radius: None, reach: 0.05 },
            samples: 16,
            turns: 7.0,
            resolution: ScreenFraction::Half,
        }),
        Ao::Gtao(Gtao { radius: Radius { radius: Some(2.0), reach: 0.05 }, slices: 3, steps: 3 }),
    ] {
        let t = Techniques { ao, ..d };
        assert_eq!(t.needs(), d.needs(), "{ao:?}");
        assert!(!t.ray_traced());
        assert_eq!(t.without_rays().ao, ao);
    }
    assert_eq!(Radius { radius: Some(2.0), reach: 0.05 }.world(10.0), 2.0);
    assert_eq!(Radius { radius: None, reach: 0.1 }.world(10.0), 1.0);
}

#[test]
fn the_fallback_keeps_effects_from_baked_data_and_compiles_no_ray_traced_pass() {
    let d = baked();
    assert_eq!(d.fallback(true), None, "nothing ray traced: no fallback");
    let ssgi = Gi::Ssgi(Ssgi {
        samples: 8,
        resolution: ScreenFraction::Half,
        radius: 40,
        voting: true,
        falloff: false,
        frames: 16,
        tiled: true,
    });
    let gtao = Ao::Gtao(Gtao { radius: Radius { radius: None, reach: 0.05 }, slices: 3, steps: 3 });
    let taa = Aa::Taa(super::aa::taa::Taa { frames: 8, luma_weights: false });
    let all = Techniques {
        shadows: Shadows::Rt(ShadowRt { light_radius: 0.1, sun_degrees: 0.5 }),
        ao: Ao::Rt(AoRt { radius: Radius { radius: None, reach: 0.1 } }),
        reflections: Reflections::Rt(ReflRt {
            resolution: ReflectionRes::Half,
            max_roughness: 1.0,
            metal_bounce: super::reflections::rt::METAL_BOUNCE,
        }),
        gi: Gi::Rt(GiRt { bounces: 2, regularize: 0.5 }),
        aa: taa,
        ..d
    };
    let f = all.fallback(true).unwrap();
    assert!(!f.ray_traced() && f.reprojected_rays().is_none());
    assert_eq!(
        (f.shadows, f.ao, f.reflections, f.gi, f.aa),
        (Shadows::default(), Ao::default(), Reflections::default(), Gi::default(), all.aa)
    );
    assert_eq!(f.name_of(Effect::Shadows), "shadowmap");
    assert_eq!(all.fallback(false).unwrap().name_of(Effect::Shadows), "none", "no shadow maps in the file");
    assert_eq!(
        all.differences(&f),
        vec![
            (Effect::Shadows, "rt", "shadowmap"),
            (Effect::Ao, "rt", "none"),
            (Effect::Reflections, "rt", "none"),
            (Effect::Gi, "rt", "none")
        ]
    );
    // Techniques that are not ray traced are kept, screen-space ones included.
    let mixed = Techniques {
        shadows: Shadows::LineSpace(ShadowLineSpace {
            light_radius: 0.0,
            sun_degrees: 0.0,
            test: LsShadowTest::Ends,
        }),
        ao: gtao,
        reflections: Reflections::Ssr(Ssr { steps: 48, max_roughness: 0.6 }),
        gi: ssgi,
        ..d
    };
    let f = mixed.fallback(true).unwrap();
    assert_eq!((f.shadows, f.ao, f.reflections, f.gi), (Shadows::default(), gtao, mixed.reflections, ssgi));
    assert_eq!(mixed.differences(&f), vec![(Effect::Shadows, "linespace", "shadowmap")]);
    let gi = Techniques {
        gi: Gi::LineSpace(GiLineSpace { bounces: 1, structure: GiStructure::Pnmt, regularize: 0.5 }),
        ..d
    };
    assert_eq!(gi.fallback(true), Some(d));
    // What the fallback reads beyond the requested techniques: the shadow maps at most.
    for t in [all, mixed, gi] {
        let (n, f) = (t.needs(), t.fallback(true).unwrap().needs());
        assert_eq!(n.union(f), Needs { shadow_maps: true, ..n }, "{t:?}");
    }
}

#[test]
fn media_techniques_read_only_the_sections_they_use() {
    // What `kiln plan` says of the MVIS and SHDW stages: march reads the visibility volumes,
    // toth the shadow maps, the image-space blurs neither; all read the media table.
    let none = Techniques { shadows: Shadows::Off(super::shadows::none::Off), ..baked() };
    let with = |media| Techniques { media, ..none };
    let march = with(Media::March(March { steps: 8 }));
    assert!(march.needs().media && march.needs().media_volumes && !march.needs().shadow_maps);
    let toth = with(Media::Toth(Toth { samples: 16, block: 2, phase: Phase::Medium }));
    assert!(toth.needs().media && !toth.needs().media_volumes && toth.needs().shadow_maps);
    for blur in [
        Media::Mitchell(Mitchell { samples: 8, resolution: ScreenFraction::Half, exposure: 1.0 }),
        Media::Sousa(Sousa { taps: 6, resolution: ScreenFraction::Half, brightness: 0.19 }),
    ] {
        let t = with(blur);
        let n = t.needs();
        assert!(n.media && !n.media_volumes && !n.shadow_maps, "{blur:?}");
        assert!(!t.dims_surfaces(), "{blur:?}");
    }
    assert_eq!(with(Media::default()).needs(), Needs::FRAME);
    assert!(march.dims_surfaces() && toth.dims_surfaces());
    // Surfaces are lit with the shadow maps only when the shadows technique reads them.
    assert!(!toth.shadow_mapped_surfaces() && baked().shadow_mapped_surfaces());
    // The block splits the samples: block² of them at least.
    let mut t = baked();
    let e = t.set(Effect::Media, "toth", &[("media-samples", KnobValue::Number(8.0))]).unwrap_err();
    assert!(e.contains("media-block 4") && e.contains("16"), "{e}");
    t.set(Effect::Media, "toth", &[("media-phase", KnobValue::Choice(1))]).unwrap();
    assert_eq!(t.media, Media::Toth(Toth { samples: 60, block: 4, phase: Phase::Rayleigh }));
    // The readers the player names for a section it leaves out come from the same needs.
    assert_eq!(readers(|n| n.shadow_maps), ["--shadows shadowmap", "--media toth"]);
    assert_eq!(readers(|n| n.media_volumes), ["--media march"]);
}

#[test]
fn the_catalogue_builds_ssr_with_its_knobs_and_it_needs_no_rays() {
    let mut t = baked();
    t.set(Effect::Reflections, "ssr", &[]).unwrap();
    assert_eq!(t.reflections, Reflections::Ssr(Ssr { steps: 48, max_roughness: 0.6 }));
    assert_eq!(t.name_of(Effect::Reflections), "ssr");
    t.set(
        Effect::Reflections,
        "ssr",
        &[("ssr-steps", KnobValue::Number(16.0)), ("ssr-max-roughness", KnobValue::Number(0.3))],
    )
    .unwrap();
    assert_eq!(t.reflections, Reflections::Ssr(Ssr { steps: 16, max_roughness: 0.3 }));
    // Screen space: the G-buffer only, kept on a file without a BVH.
    assert!(!t.ray_traced() && t.reads_previous_frame());
    assert_eq!(t.needs(), Techniques { reflections: Reflections::default(), ..t }.needs());
    assert_eq!(t.without_rays().reflections, t.reflections);
    for (knob, bad) in [("ssr-steps", 1.5), ("ssr-steps", 0.0), ("ssr-max-roughness", 1.5)] {
        let e = t.set(Effect::Reflections, "ssr", &[(knob, KnobValue::Number(bad))]).unwrap_err();
        assert!(e.contains(knob), "{e}");
    }
}

#[test]
fn the_catalogue_builds_gi_rt_with_its_bounces() {
    let mut t = baked();
    t.set(Effect::Gi, "rt", &[]).unwrap();
    assert_eq!(t.gi, Gi::Rt(GiRt { bounces: 1, regularize: 0.5 }));
    assert_eq!(t.name_of(Effect::Gi), "rt");
    t.set(Effect::Gi, "rt", &[("gi-bounces", KnobValue::Number(3.0))]).unwrap();
    assert_eq!(t.gi, Gi::Rt(GiRt { bounces: 3, regularize: 0.5 }));
    assert_eq!(t.gi.bounces(), Some(3));
    for bad in [0.0, 9.0, 1.5] {
        let e = t.set(Effect::Gi, "rt", &[("gi-bounces", KnobValue::Number(bad))]).unwrap_err();
        assert!(e.contains("gi-bounces"), "{e}");
    }
    let info = techniques_of(Effect::Gi).find(|i| i.name == "rt").unwrap();
    assert!(info.stochastic);
    assert_eq!(info.knobs[0].role, KnobRole::Quality);
    assert_eq!(
        info.knobs[0].range,
        KnobRange::Number { min: 1.0, max: 8.0, sweep: &[1.0, 2.0], whole: true }
    );
    t.set(Effect::Gi, "none", &[]).unwrap();
    assert_eq!(t.gi, Gi::default());
}

/// The frame flags each technique raises, as the direct pass's specialisation needs them
/// (written out here from `FrameFlags`, not from the modules).
#[test]
fn flags_follow_the_techniques() {
    use kiln_format::gpu::FrameFlags as F;
    let flags = |e: Effect, name: &str, knobs: &[(&str, KnobValue)]| {
        let mut t = baked();
        t.set(e, name, knobs).unwrap();
        t.flags()
    };
    assert_eq!(baked().flags(), 0);
    assert_eq!(flags(Effect::Shadows, "rt", &[]), F::RT_SHADOWS);
    assert_eq!(flags(Effect::Shadows, "linespace", &[]), F::RT_SHADOWS);
    for ao in ["rt", "sao", "gtao"] {
        assert_eq!(flags(Effect::Ao, ao, &[]), F::RT_AO, "{ao}");
    }
    assert_eq!(flags(Effect::Reflections, "rt", &[]), F::RT_REFLECTIONS);
    assert_eq!(
        flags(Effect::Reflections, "rt", &[("reflection-res", KnobValue::Choice(1))]),
        F::RT_REFLECTIONS | F::REFLECTIONS_HALF
    );
    assert_eq!(flags(Effect::Reflections, "ssr", &[]), F::SCREEN_REFLECTIONS);
    assert_eq!(flags(Effect::Gi, "rt", &[]), F::RT_GI);
    assert_eq!(flags(Effect::Gi, "linespace", &[]), F::RT_GI);
    assert_eq!(flags(Effect::Gi, "ssgi", &[]), F::SCREEN_GI);
    for (e, name) in [(Effect::Media, "toth"), (Effect::Aa, "taa"), (Effect::GBuffer, "visibility")] {
        assert_eq!(flags(e, name, &[]), 0, "{e} {name}");
    }
}

/// `kiln plan` names the readers of the sections only some techniques read from kiln-format's
/// table (the compiler does not link the player); the catalogue's needs must say the same.
#[test]
fn the_format_names_the_readers_the_catalogue_has() {
    use kiln_format::readers;
    assert_eq!(readers(|n| n.shadow_maps), readers::SHADOW_MAPS);
    assert_eq!(readers(|n| n.media_volumes), readers::MEDIA_VISIBILITY);
    assert_eq!(readers(|n| n.line_space != 0), readers::LINE_SPACE);
    assert_eq!(readers(|n| n.probes), readers::PROBES);
    assert_eq!(readers::list(&["--a x", "--b y", "--c z"]), "--a x, --b y and --c z");
}
