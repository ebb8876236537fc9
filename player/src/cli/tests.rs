//! The command line's unit tests: flags, presets, budgets and refusals against what they choose.

use super::*;
use crate::render::techniques::ao::{self, Radius};
use crate::render::techniques::reflections::rt::ReflectionRes;
use crate::render::techniques::{Effect, catalogue};
use crate::render::techniques::{aa, gi, reflections, shadows};
use crate::render::{Aa, Ao, GBuffer, Gi, Reflections, ScreenFraction, Shadows};

fn parse(args: &[&str]) -> Result<Args, clap::Error> {
    match parse_from(std::iter::once("kiln-play").chain(args.iter().copied()))? {
        Invocation::Play(a) => Ok(*a),
        other => panic!("{args:?} is not a session: {other:?}"),
    }
}

fn techniques(args: &[&str]) -> Techniques {
    parse(args).unwrap().techniques(std::path::Path::new("missing.kiln")).unwrap()
}

/// The message of a refused command line, whether clap or the techniques refuse it; usage
/// errors either way.
fn refusal(args: &[&str]) -> String {
    match parse(args) {
        Err(e) => {
            assert_eq!(e.exit_code(), 2, "{args:?}: {e}");
            e.to_string()
        }
        Ok(a) => {
            let e = a.techniques(std::path::Path::new("missing.kiln")).expect_err("refused");
            assert_eq!(e.exit, Exit::Usage);
            e.message
        }
    }
}

const AO_RT: Ao = Ao::Rt(ao::rt::Rt { radius: Radius { radius: None, reach: 0.1 } });

#[test]
fn flags_set_technique_values_with_their_knobs() {
    let t = techniques(&[
        "f.kiln",
        "--gbuffer",
        "visibility",
        "--shadows",
        "rt",
        "--light-radius",
        "1",
        "--sun-angle",
        "0.53",
        "--ao",
        "rt",
        "--ao-radius",
        "0.5",
        "--reflections",
        "rt",
        "--reflection-res",
        "half",
        "--reflection-max-roughness",
        "0.4",
        "--gi",
        "rt",
        "--gi-bounces",
        "2",
        "--no-accumulate",
    ]);
    assert_eq!(t.gbuffer, GBuffer::Visibility(crate::render::techniques::gbuffer::visibility::Visibility));
    assert_eq!(t.shadows, Shadows::Rt(shadows::rt::Rt { light_radius: 1.0, sun_degrees: 0.53 }));
    assert_eq!(t.ao, Ao::Rt(ao::rt::Rt { radius: Radius { radius: Some(0.5), reach: 0.1 } }));
    assert_eq!(
        t.reflections,
        Reflections::Rt(reflections::rt::Rt { resolution: ReflectionRes::Half, max_roughness: 0.4 })
    );
    assert_eq!(t.gi, Gi::Rt(gi::rt::Rt { bounces: 2, regularize: 0.5 }));
    assert_eq!(t.aa, Aa::Off(aa::none::Off));
    let e = refusal(&["f.kiln", "--gi", "rt", "--gi-bounces", "9"]);
    assert!(e.contains("gi-bounces"), "{e}");
    let d = techniques(&["f.kiln"]);
    assert_eq!(d, Techniques::default());
    assert_eq!(d.name_of(Effect::Shadows), "shadowmap");
}

#[test]
fn aa_flags_choose_taa_with_its_knobs() {
    let t = techniques(&["f.kiln", "--aa", "taa", "--taa-frames", "8", "--taa-weights", "luma"]);
    assert_eq!(t.aa, Aa::Taa(aa::taa::Taa { frames: 8, luma_weights: true }));
    assert_eq!(
        techniques(&["f.kiln", "--aa", "taa"]).aa,
        Aa::Taa(aa::taa::Taa { frames: 16, luma_weights: false })
    );
    assert_eq!(techniques(&["f.kiln", "--aa", "none"]).aa, Aa::Off(aa::none::Off));
    let t = techniques(&["f.kiln", "--aa", "reproject", "--history-frames", "8"]);
    assert_eq!(t.aa, Aa::Reproject(aa::reproject::Reproject { frames: 8 }));
    assert_eq!(t.aa.reprojected(), Some(8));
    let e = refusal(&["f.kiln", "--aa", "taa", "--taa-frames", "0"]);
    assert!(e.contains("--taa-frames"), "{e}");
    let e = parse(&["f.kiln", "--aa", "taa", "--no-accumulate"]).unwrap_err().to_string();
    assert!(e.contains("--no-accumulate") && e.contains("--aa"), "{e}");
}

#[test]
fn ssr_flags_set_its_knobs_with_their_defaults() {
    assert_eq!(
        techniques(&["f.kiln", "--reflections", "ssr"]).reflections,
        Reflections::Ssr(reflections::ssr::Ssr { steps: 48, max_roughness: 0.6 })
    );
    let t =
        techniques(&["f.kiln", "--reflections", "ssr", "--ssr-steps", "96", "--ssr-max-roughness", "0.3"]);
    assert_eq!(t.reflections, Reflections::Ssr(reflections::ssr::Ssr { steps: 96, max_roughness: 0.3 }));
    for bad in [&["--ssr-steps", "0"][..], &["--ssr-max-roughness", "1.5"], &["--ssr-steps", "1.5"]] {
        let args: Vec<&str> =
            ["f.kiln", "--reflections", "ssr"].into_iter().chain(bad.iter().copied()).collect();
        let e = refusal(&args);
        assert!(e.contains(bad[0]), "{bad:?}: {e}");
    }
}

#[test]
fn the_last_flag_wins() {
    assert_eq!(
        techniques(&["f.kiln", "--shadows", "rt", "--shadows", "none"]).name_of(Effect::Shadows),
        "none"
    );
    let t = techniques(&["f.kiln", "--ao", "rt", "--ao-radius", "2", "--ao-radius", "3"]);
    assert_eq!(t.ao, Ao::Rt(ao::rt::Rt { radius: Radius { radius: Some(3.0), reach: 0.1 } }));
}

#[test]
fn screen_space_ao_flags_set_their_knobs_with_the_techniques_defaults() {
    let sao = techniques(&["f.kiln", "--ao", "sao"]);
    let sao_default = ao::sao::Sao {
        radius: Radius { radius: None, reach: 0.05 },
        samples: 16,
        turns: 7.0,
        resolution: ScreenFraction::Half,
    };
    assert_eq!(sao.ao, Ao::Sao(sao_default));
    let t = techniques(&[
        "f.kiln",
        "--ao",
        "sao",
        "--ao-radius",
        "1.8",
        "--ao-samples",
        "8",
        "--ao-turns",
        "5",
        "--ao-res",
        "full",
    ]);
    assert_eq!(
        t.ao,
        Ao::Sao(ao::sao::Sao {
            radius: Radius { radius: Some(1.8), reach: 0.05 },
            samples: 8,
            turns: 5.0,
            resolution: ScreenFraction::Full
        })
    );
    let gtao = |reach, slices, steps| {
        Ao::Gtao(ao::gtao::Gtao { radius: Radius { radius: None, reach }, slices, steps })
    };
    assert_eq!(techniques(&["f.kiln", "--ao", "gtao"]).ao, gtao(0.05, 3, 3));
    let t =
        techniques(&["f.kiln", "--ao", "gtao", "--ao-slices", "9", "--ao-steps", "4", "--ao-reach", "0.2"]);
    assert_eq!(t.ao, gtao(0.2, 9, 4));
    // --ao-reach keeps each technique's own default when not given.
    assert_eq!(techniques(&["f.kiln", "--ao", "rt"]).ao, AO_RT);
    // Out of range, fractional or unknown values name the flag.
    for bad in [
        &["--ao", "sao", "--ao-samples", "0"][..],
        &["--ao", "sao", "--ao-samples", "65"],
        &["--ao", "gtao", "--ao-slices", "33"],
        &["--ao", "gtao", "--ao-steps", "0"],
        &["--ao", "sao", "--ao-turns=-1"],
        &["--ao", "sao", "--ao-reach", "0"],
    ] {
        let args: Vec<&str> = std::iter::once("f.kiln").chain(bad.iter().copied()).collect();
        let e = refusal(&args);
        let flag = bad[2].split('=').next().unwrap();
        assert!(e.contains(flag), "{bad:?}: {e}");
    }
    let e = parse(&["f.kiln", "--ao", "sao", "--ao-res", "quarter"]).unwrap_err().to_string();
    assert!(e.contains("full") && e.contains("half"), "{e}");
}

#[test]
fn contradictory_modes_are_refused_naming_both_flags() {
    for (a, b) in [("--reference", "--bench"), ("--bench", "--bench-rays"), ("--reference", "--bench-rays")] {
        let e = parse(&["f.kiln", a, b]).unwrap_err().to_string();
        assert!(e.contains(a) && e.contains(b), "{a} {b}: {e}");
    }
    let e = parse(&["f.kiln", "--bench", "-o", "x.png"]).unwrap_err().to_string();
    assert!(e.contains("--bench") && e.contains("--output"), "{e}");
}

#[test]
fn bad_values_are_usage_errors_naming_the_flag() {
    // A knob is checked whether or not its technique is chosen.
    let e = refusal(&["f.kiln", "--light-radius=-1"]);
    assert!(e.contains("--light-radius"), "{e}");
    let e = parse(&["f.kiln", "--shadows", "raytraced"]).unwrap_err().to_string();
    assert!(e.contains("shadowmap") && e.contains("rt"), "{e}");
}

/// The long help states each knob's default as the catalogue has it (the flags used to
/// repeat the defaults by hand and disagreed: `--taa-weights` said luma, the catalogue
/// linear), and each effect's default technique.
#[test]
fn help_states_the_catalogues_defaults() {
    let help = command().render_long_help().to_string();
    // Undo clap's wrapping: one flag's text per block (a flag's line is indented less than
    // its description's).
    let mut blocks: Vec<String> = Vec::new();
    for line in help.lines() {
        let indent = line.len() - line.trim_start().len();
        if line.trim_start().starts_with('-') && indent < 8 {
            blocks.push(line.trim().to_string());
        } else if let Some(b) = blocks.last_mut() {
            b.push(' ');
            b.push_str(line.trim());
        }
    }
    let flat = blocks.join(" ");
    for info in catalogue() {
        for k in info.knobs {
            let start = format!("--{} <", k.name);
            let block = blocks
                .iter()
                .find(|b| b.starts_with(&start))
                .unwrap_or_else(|| panic!("--{} missing", k.name));
            let default = k.default_text();
            assert!(
                block.contains(&format!("[default: {default}]"))
                    || block.contains(&format!("{} {default}", info.name)),
                "--{} of {} {}: default {default} not in: {block}",
                k.name,
                info.effect,
                info.name
            );
        }
    }
    assert!(flat.contains("--taa-weights <luma|linear>"), "{flat}");
    for e in Effect::ALL {
        assert!(help.contains(e.title()), "heading {e}");
        let default = Techniques::default().name_of(e);
        assert!(flat.contains(&format!("technique [default: {default}]")), "{e}");
    }
    // The short help names the effects and leaves the knobs to --help.
    let short = command().render_help().to_string();
    assert!(short.contains("--ao <TECHNIQUE>") && !short.contains("--ao-samples <N>"), "{short}");
    assert!(short.contains("kiln-play --help"), "{short}");
}

/// Completions and the man page name every flag the catalogue makes.
#[test]
fn completions_and_man_page_cover_the_catalogue() {
    let mut bash = Vec::new();
    write_generated(&Invocation::Completions(clap_complete::Shell::Bash), &mut bash).unwrap();
    let mut man = Vec::new();
    write_generated(&Invocation::Man, &mut man).unwrap();
    let (bash, man) = (String::from_utf8(bash).unwrap(), String::from_utf8(man).unwrap());
    for info in catalogue() {
        for k in info.knobs {
            assert!(bash.contains(&format!("--{}", k.name)), "bash: --{}", k.name);
            // roff escapes '-' as '\-'.
            assert!(man.contains(&format!("\\-\\-{}", k.name.replace('-', "\\-"))), "man: --{}", k.name);
        }
    }
    assert!(matches!(parse_from(["kiln-play", "completions", "zsh"]), Ok(Invocation::Completions(_))));
    assert!(matches!(parse_from(["kiln-play", "man"]), Ok(Invocation::Man)));
    assert!(parse_from(["kiln-play", "completions", "cmd.exe"]).is_err());
}

/// Every `kiln-play` line in the README and the docs parses and chooses valid techniques
/// (a flag renamed or dropped breaks a documented command line).
#[test]
fn documented_command_lines_parse() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = vec![root.join("README.md")];
    if let Ok(dir) = std::fs::read_dir(root.join("docs")) {
        files.extend(
            dir.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "md")),
        );
    }
    let mut checked = 0;
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        // Join continued lines, then take each command from `kiln-play` to a comment, a
        // pipe or the end of its code span.
        let text = text.replace("\\\n", " ");
        for line in text.lines() {
            let Some(at) = line.find("kiln-play ") else { continue };
            let rest = &line[at + "kiln-play ".len()..];
            let end = rest.find(['#', '`', '|', ';', '&', '>', ')']).unwrap_or(rest.len());
            let words: Vec<&str> = rest[..end].split_whitespace().collect();
            // Prose ("kiln-play renders ...") and placeholders ("kiln-play FILE [OPTIONS]").
            let runs = words.iter().any(|w| w.ends_with(".kiln"));
            if !runs || line.contains("...") || rest[..end].contains('[') {
                continue;
            }
            let mut args = vec!["kiln-play"];
            args.extend(words.iter().copied());
            let parsed = parse_from(args.iter().copied());
            match parsed {
                Ok(Invocation::Play(a)) => {
                    a.techniques(std::path::Path::new("missing.kiln"))
                        .unwrap_or_else(|e| panic!("{}: {line}: {e}", file.display()));
                }
                Ok(_) => {}
                Err(e) => panic!("{}: `{}` is refused: {e}", file.display(), args.join(" ")),
            }
            checked += 1;
        }
    }
    assert!(checked >= 10, "only {checked} documented command lines found");
}

/// `--preset` sets its techniques and knobs; flags beside it override a technique or a knob
/// and keep the rest of the preset.
#[test]
fn a_preset_sets_techniques_and_flags_override_it() {
    let t = techniques(&["f.kiln", "--preset", "rt-2"]);
    assert_eq!(t.gi, Gi::Rt(gi::rt::Rt { bounces: 2, regularize: 0.5 }));
    assert_eq!((t.name_of(Effect::Shadows), t.name_of(Effect::Denoise)), ("rt", "svgf"));
    let t = techniques(&["f.kiln", "--preset", "rt-2", "--gi-bounces", "3", "--denoise", "none"]);
    assert_eq!(t.gi, Gi::Rt(gi::rt::Rt { bounces: 3, regularize: 0.5 }));
    assert_eq!((t.name_of(Effect::Shadows), t.name_of(Effect::Denoise)), ("rt", "none"));
    let t = techniques(&["f.kiln", "--preset", "rt-4-taa", "--gi", "ssgi", "--no-accumulate"]);
    assert_eq!((t.name_of(Effect::Gi), t.name_of(Effect::Aa)), ("ssgi", "none"));
    assert!(refusal(&["f.kiln", "--preset", "fast"]).contains("rt-taa"));
}

/// A budget that is not a positive number of milliseconds is refused with the reason.
#[test]
fn a_budget_must_be_positive_milliseconds() {
    for bad in ["-2", "0", "nan", "inf"] {
        assert!(
            refusal(&["f.kiln", "--budget-ms", bad]).contains("positive number of milliseconds"),
            "{bad}"
        );
    }
}
