//! Vulkan is fenced off: `unsafe` and raw `ash` live only under `player/src/gpu/`. Every other
//! source file of the player is scanned (comments and string literals skipped) for the keyword
//! `unsafe`, any `ash::` path (Vulkan types come through `crate::gpu::vk`, so nothing outside
//! `gpu/` depends on ash directly), and the raw handles of a `Gpu` (`gpu.device`, `gpu.instance`,
//! `gpu.entry`). Every Vulkan command in ash is an `unsafe fn`, so the first rule alone keeps
//! calls inside `gpu/`; the others catch loaders built and handles passed out around it.

use std::path::{Path, PathBuf};

/// The source with comments and the contents of string and character literals blanked (line
/// breaks kept, so positions keep their line numbers).
fn code_only(source: &str) -> String {
    let chars: Vec<char> = source.chars().collect();
    let mut out = String::with_capacity(source.len());
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < chars.len() {
                if chars[i] == '/' && chars.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if chars[i] == '*' && chars.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(chars[i]));
                    i += 1;
                }
            }
        } else if c == '"' {
            out.push(' ');
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < chars.len() {
                    out.push(blank(chars[i]));
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if (c == 'r' || ((c == 'b' || c == 'c') && next == Some('r')))
            && (i == 0 || !ident(chars[i - 1]))
            && {
                let mut j = i + if c == 'r' { 1 } else { 2 };
                while chars.get(j) == Some(&'#') {
                    j += 1;
                }
                chars.get(j) == Some(&'"')
            }
        {
            // A raw string: r"…", r#"…"#, br"…", cr"…".
            let mut j = i + if c == 'r' { 1 } else { 2 };
            let mut hashes = 0;
            while chars[j] == '#' {
                hashes += 1;
                j += 1;
            }
            j += 1;
            let end: Vec<char> = std::iter::once('"').chain(std::iter::repeat_n('#', hashes)).collect();
            while j < chars.len() && !chars[j..].starts_with(&end) {
                j += 1;
            }
            j = (j + end.len()).min(chars.len());
            out.extend(chars[i..j].iter().map(|&c| blank(c)));
            i = j;
        } else if c == '\'' && (next == Some('\\') || chars.get(i + 2) == Some(&'\'')) {
            // A character literal (a lifetime has no closing quote after one character).
            out.push(' ');
            i += 1;
            if chars.get(i) == Some(&'\\') {
                // The backslash and the escaped character (which may be a quote).
                out.push_str("  ");
                i += 2;
            }
            while i < chars.len() && chars[i] != '\'' {
                out.push(' ');
                i += 1;
            }
            out.push(' ');
            i += 1;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// Tokens of code (identifiers and single punctuation characters) with their line numbers.
fn tokens(code: &str) -> Vec<(String, usize)> {
    let mut tokens = Vec::new();
    for (n, line) in code.lines().enumerate() {
        let mut word = String::new();
        for c in line.chars().chain(std::iter::once(' ')) {
            if c.is_alphanumeric() || c == '_' {
                word.push(c);
                continue;
            }
            if !word.is_empty() {
                tokens.push((std::mem::take(&mut word), n + 1));
            }
            if !c.is_whitespace() {
                tokens.push((c.to_string(), n + 1));
            }
        }
    }
    tokens
}

/// The fence's violations in one file's source: (line, what).
fn violations(source: &str) -> Vec<(usize, String)> {
    let t = tokens(&code_only(source));
    let at = |i: usize| t.get(i).map_or("", |(s, _)| s.as_str());
    let mut found = Vec::new();
    for (i, (token, line)) in t.iter().enumerate() {
        if token == "unsafe" {
            found.push((*line, "`unsafe`".to_string()));
        }
        if token == "ash" && at(i + 1) == ":" && at(i + 2) == ":" {
            found.push((*line, format!("`ash::{}` (Vulkan types come through `crate::gpu::vk`)", at(i + 3))));
        }
        if token == "gpu" && at(i + 1) == "." && matches!(at(i + 2), "device" | "instance" | "entry") {
            found.push((*line, format!("`gpu.{}` (a raw ash handle)", at(i + 2))));
        }
    }
    found
}

fn rust_files(dir: &Path, skip: &Path, files: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    for path in entries {
        if path == skip {
            continue;
        }
        if path.is_dir() {
            rust_files(&path, skip, files);
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
}

#[test]
fn no_unsafe_or_raw_ash_outside_gpu() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let gpu = src.join("gpu");
    assert!(gpu.join("mod.rs").is_file(), "the gpu module moved: update the fence");
    let mut files = Vec::new();
    rust_files(&src, &gpu, &mut files);
    assert!(files.len() > 10, "too few sources found under {}", src.display());
    let mut report = Vec::new();
    for file in &files {
        let source = std::fs::read_to_string(file).unwrap();
        for (line, what) in violations(&source) {
            report.push(format!("{}:{line}: {what}", file.strip_prefix(&src).unwrap().display()));
        }
    }
    assert!(
        report.is_empty(),
        "raw Vulkan outside player/src/gpu/ (move it behind a safe helper in gpu/):\n{}",
        report.join("\n")
    );
}

#[test]
fn the_scan_finds_code_and_skips_prose() {
    let lines = |s: &str| violations(s).into_iter().map(|(l, _)| l).collect::<Vec<_>>();
    assert_eq!(lines("fn f() {\n    unsafe { g() };\n}\n"), [2]);
    assert_eq!(lines("unsafe fn f() {}"), [1]);
    assert_eq!(lines("let l = ash::khr::ray_tracing_pipeline::Device::new(&i, &d);"), [1]);
    assert_eq!(lines("use ash::{vk, khr};"), [1]);
    assert_eq!(lines("let w = ash::util::read_spv(&mut c);"), [1]);
    assert_eq!(lines("let d = self.gpu.device.clone();"), [1]);
    assert_eq!(lines("let i = &gpu\n    .instance;"), [1]);
    // Even plain Vulkan types come through the fence (`crate::gpu::vk`).
    assert_eq!(lines("use ash::vk;\nfn f(e: ash::vk::Result) {}"), [1, 2]);
    assert_eq!(lines("use crate::gpu::vk;\nfn f(e: vk::Result) {}"), [] as [usize; 0]);
    // Prose, strings, characters, lifetimes and other fields named alike.
    let prose = r##"
//! Every call here is unsafe in ash:: terms.
/// Calls gpu.device.destroy_buffer (unsafe) for you.
/* unsafe { ash::khr } /* nested unsafe */ gpu.device */
fn f<'a>(s: &'a S) -> &'a str {
    let _ = s.entry.kind; // a section entry, not ash::Entry
    let _ = self.device.clone(); // a device name
    let _ = ('"', '\'', 'u');
    let _ = "unsafe \" ash::khr gpu.device";
    let _ = r#"unsafe "ash::khr" gpu.device"#;
    let _ = br"unsafe";
    #[allow(unsafe_code)]
    "unsafe"
}
"##;
    let found = violations(prose);
    assert!(found.is_empty(), "{found:?}");
}
