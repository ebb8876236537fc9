//! What `docs/contributing.md` ("Adding a technique") promises, read from the tree as text: a
//! technique is its module (`player/src/render/techniques/<effect>/<technique>.rs`, with its
//! pass, if it has one of its own, in that module or beside it), its shader folder and one
//! registration line in its effect's `mod.rs`. Nothing else in the player's code names it, no
//! pass file names any technique, and no shader outside a folder includes from it, so adding,
//! removing or restoring a technique touches only those.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn files(dir: &Path, ext: &str, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(&path, ext, found);
        } else if path.extension().is_some_and(|e| e == ext) {
            found.push(path);
        }
    }
}

/// A Rust file's code without its unit tests (a test may name any technique it tests) and
/// without comments (a comment may name one as an example).
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.split("#[cfg(test)]").next().unwrap_or_default();
    text.lines()
        .map(|l| match l.find("//") {
            Some(at) => &l[..at],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// (effect folder, technique module) of every technique module on disk.
fn technique_modules() -> Vec<(String, String)> {
    let dir = root().join("player/src/render/techniques");
    let mut found = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if !path.is_dir() {
            continue;
        }
        let effect = path.file_name().unwrap().to_str().unwrap().to_owned();
        for module in std::fs::read_dir(&path).unwrap() {
            let module = module.unwrap().path();
            let name = module.file_stem().unwrap().to_str().unwrap().to_owned();
            if module.extension().is_some_and(|e| e == "rs") && name != "mod" {
                found.push((effect.clone(), name));
            }
        }
    }
    found.sort();
    found
}

/// The `techniques! { ... }` list of an effect's `mod.rs`.
fn registrations(effect: &str) -> String {
    let list = code(&root().join(format!("player/src/render/techniques/{effect}/mod.rs")));
    let start =
        list.find("techniques! {").unwrap_or_else(|| panic!("{effect}/mod.rs has no techniques! list"));
    let end = list[start..].find("\n}").map_or(list.len(), |e| start + e);
    list[start..end].to_owned()
}

/// Whether `code` names the module `effect::module` (`ao::gtao::`, `ao::gtao;`, an alias of the
/// effect such as `ao_techniques::gtao::`).
fn names_module(code: &str, effect: &str, module: &str) -> bool {
    code.match_indices(&format!("::{module}")).any(|(at, _)| {
        let before = &code[..at];
        let after = &code[at + module.len() + 2..];
        let word = before.rsplit(|c: char| !(c.is_alphanumeric() || c == '_')).next().unwrap_or("");
        let effect_named = word == effect || word.starts_with(&format!("{effect}_"));
        let module_ends = !after.starts_with(|c: char| c.is_alphanumeric() || c == '_');
        effect_named && module_ends
    })
}

#[test]
fn each_technique_module_is_registered_by_one_line_of_its_effect() {
    let modules = technique_modules();
    assert!(modules.len() >= 26, "only {} technique modules", modules.len());
    for (effect, module) in &modules {
        let list = registrations(effect);
        let lines: Vec<&str> =
            list.lines().filter(|l| l.trim_start().starts_with(&format!("{module} =>"))).collect();
        assert_eq!(lines.len(), 1, "{effect}/mod.rs must register {module} in one line `{module} => Type,`");
    }
    // And every registration has its module.
    for effect in modules.iter().map(|(e, _)| e).collect::<BTreeSet<_>>() {
        let list = registrations(effect);
        for line in list.lines().map(str::trim).filter(|l| l.contains(" => ") && l.ends_with(',')) {
            let module = line.split(" =>").next().unwrap();
            assert!(
                modules.contains(&(effect.to_string(), module.to_owned())),
                "{effect}: {module} has no module"
            );
        }
    }
}

#[test]
fn nothing_outside_a_technique_module_names_it() {
    let techniques = root().join("player/src/render/techniques");
    let mut sources = Vec::new();
    files(&root().join("player/src"), "rs", &mut sources);
    let modules = technique_modules();
    let mut named = Vec::new();
    for path in &sources {
        let rel = path.strip_prefix(root()).unwrap().display().to_string();
        if rel.ends_with("render/techniques/tests.rs") {
            continue;
        }
        let text = code(path);
        for (effect, module) in &modules {
            // The effect's own folder may: its list, its shared helpers, the sibling modules.
            if path.starts_with(techniques.join(effect)) {
                continue;
            }
            if names_module(&text, effect, module) {
                named.push(format!("{rel} names {effect}::{module}"));
            }
        }
        // Passes are built by techniques and know none of them.
        let effects: BTreeSet<&str> = modules.iter().map(|(e, _)| e.as_str()).collect();
        if rel.contains("render/passes/")
            && effects.iter().any(|e| text.contains(&format!("techniques::{e}")))
        {
            named.push(format!("{rel} names the technique modules"));
        }
    }
    assert!(named.is_empty(), "technique modules named outside their effect's folder: {named:#?}");
}

#[test]
fn no_shader_includes_from_another_pass_folder() {
    let shaders = root().join("shaders");
    let mut sources = Vec::new();
    for ext in ["glsl", "comp", "vert", "frag", "rgen", "rmiss", "rchit"] {
        files(&shaders, ext, &mut sources);
    }
    let mut crossing = Vec::new();
    for path in &sources {
        let folder = path.parent().unwrap().file_name().unwrap().to_str().unwrap();
        for line in
            std::fs::read_to_string(path).unwrap().lines().filter(|l| l.trim_start().starts_with("#include"))
        {
            let target = line.split('"').nth(1).unwrap_or_default();
            // Shared code lives in common/; a folder includes its own files.
            let from = match target.strip_prefix("../") {
                Some(rest) => rest.split('/').next().unwrap_or_default(),
                None => folder,
            };
            if from != "common" && from != folder {
                crossing.push(format!("{}: {line}", path.strip_prefix(&shaders).unwrap().display()));
            }
        }
    }
    assert!(
        crossing.is_empty(),
        "includes across pass folders (move the shared code to common/): {crossing:#?}"
    );
}

/// The check itself finds a technique named outside its folder, and lets the effect's own
/// folder and comments pass.
#[test]
fn the_name_check_sees_a_planted_reference() {
    assert!(names_module("let p = crate::render::techniques::ao::gtao::Gtao { };", "ao", "gtao"));
    assert!(names_module(
        "use super::techniques::{ao as ao_techniques}; ao_techniques::gtao::pass",
        "ao",
        "gtao"
    ));
    assert!(names_module("use crate::render::techniques::ao::gtao;", "ao", "gtao"));
    assert!(!names_module("shaders/gtao/gtao.comp", "ao", "gtao"));
    assert!(!names_module("ao::gtao_like::X", "ao", "gtao"));
    assert!(!names_module("gi::rt::Rt", "ao", "rt"));
}

/// The compiler names the player's techniques only through kiln-format's readers table (which
/// the player's catalogue checks), never as its own list of flags.
#[test]
fn the_compiler_names_techniques_only_through_the_readers_table() {
    let mut sources = Vec::new();
    for dir in ["compiler/src", "format/src", "gpubake/src"] {
        files(&root().join(dir), "rs", &mut sources);
    }
    let flags: Vec<String> = technique_modules().iter().map(|(e, m)| format!("--{e} {m}")).collect();
    let mut named = Vec::new();
    for path in sources.iter().filter(|p| !p.ends_with("format/src/readers.rs")) {
        let text = code(path);
        for flag in flags.iter().filter(|f| text.contains(f.as_str())) {
            named.push(format!("{} names {flag}", path.strip_prefix(root()).unwrap().display()));
        }
    }
    assert!(named.is_empty(), "{named:#?}");
}
