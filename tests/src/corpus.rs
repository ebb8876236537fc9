//! The public corpus: every model of `tests/corpus/models.toml` compiled, verified and rendered
//! at 64×48 as a user would run `kiln compile`, `kiln verify` and `kiln-play --headless` (the
//! same command lines, in process), and a table of what happened. Models committed under
//! `tests/corpus/` always run; the shared scenes run where `../shared/scenes` is; models a
//! developer fetched into `tests/corpus/fetched/` (or `KILN_CORPUS_DIR`) run where present, the
//! others are listed as absent with where to get them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Deserialize;

/// `tests/corpus/models.toml`.
#[derive(Debug, Deserialize)]
struct List {
    model: Vec<Entry>,
}

/// One model of the list.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    /// Name in the table.
    pub name: String,
    /// Where the folder it sits in is: `committed` (`tests/corpus/`), `shared`
    /// (`../shared/scenes/`) or `fetched` (`tests/corpus/fetched/` or `KILN_CORPUS_DIR`).
    pub root: String,
    /// Main file, relative to the root.
    pub path: String,
    /// A sidecar, relative to the repository (`tests/scenes/…`), when the model needs one.
    pub sidecar: Option<String>,
    /// Licence.
    pub licence: String,
    /// Where a copy is (for fetched models: where to get it).
    pub source: String,
}

/// What happened to one model.
#[derive(Debug, Clone)]
pub struct Row {
    /// The list's entry.
    pub entry: Entry,
    /// `None`: the model is not here (with why in `skipped`).
    pub skipped: Option<String>,
    /// Triangles compiled.
    pub triangles: u64,
    /// Warnings by class.
    pub warnings: BTreeMap<String, u64>,
    /// Compile wall time, ms.
    pub compile_ms: f64,
    /// File size, bytes.
    pub bytes: u64,
    /// Compile outcome (`Err`: the message).
    pub compile: Result<(), String>,
    /// Verify outcome.
    pub verify: Result<(), String>,
    /// Render outcome: the mean of the 64×48 PNG's sRGB codes (0 to 255), or why not; `None`
    /// when not asked for (no Vulkan).
    pub render: Option<Result<f64, String>>,
}

impl Row {
    /// Whether the model compiled, verified and rendered (or is absent).
    pub fn passed(&self) -> bool {
        self.skipped.is_some()
            || (self.compile.is_ok() && self.verify.is_ok() && self.render.as_ref().is_none_or(Result::is_ok))
    }
}

/// The repository's root.
pub fn repository() -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    root.canonicalize().unwrap_or(root)
}

/// The models of `tests/corpus/models.toml`.
pub fn entries() -> Result<Vec<Entry>, String> {
    let path = repository().join("tests/corpus/models.toml");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let list: List = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(list.model)
}

/// Where a root's models are, or why not.
fn root_dir(root: &str) -> Result<PathBuf, String> {
    match root {
        "committed" => Ok(repository().join("tests/corpus")),
        "shared" => {
            let d = repository().join("../shared/scenes");
            d.is_dir().then_some(d).ok_or_else(|| "../shared/scenes is not here".to_string())
        }
        "fetched" => Ok(std::env::var_os("KILN_CORPUS_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| repository().join("tests/corpus/fetched"))),
        other => Err(format!("unknown root '{other}' (committed, shared or fetched)")),
    }
}

/// Compiles, verifies and renders `entry` in `work` (its files named after it); `render` false
/// leaves the render out (no Vulkan), `extra` are more `kiln compile` flags.
pub fn run(entry: &Entry, work: &Path, render: bool, extra: &[String]) -> Row {
    let mut row = Row {
        entry: entry.clone(),
        skipped: None,
        triangles: 0,
        warnings: BTreeMap::new(),
        compile_ms: 0.0,
        bytes: 0,
        compile: Err("not run".into()),
        verify: Err("not run".into()),
        render: None,
    };
    let input = match root_dir(&entry.root) {
        Ok(d) => d.join(&entry.path),
        Err(why) => {
            row.skipped = Some(why);
            return row;
        }
    };
    if !input.is_file() {
        row.skipped = Some(format!("{} is not here (get it from {})", input.display(), entry.source));
        return row;
    }
    let stem: String = entry.name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    let out = work.join(format!("{stem}.kiln"));
    let report = work.join(format!("{stem}.json"));
    let mut args: Vec<String> = ["kiln", "compile"].map(String::from).to_vec();
    args.push(input.display().to_string());
    args.extend([
        "-o".into(),
        out.display().to_string(),
        "--report".into(),
        report.display().to_string(),
        "-q".into(),
    ]);
    if let Some(s) = &entry.sidecar {
        args.extend(["-c".into(), repository().join(s).display().to_string()]);
    }
    args.extend(extra.iter().cloned());
    let start = Instant::now();
    row.compile = kiln(&args);
    row.compile_ms = start.elapsed().as_secs_f64() * 1e3;
    if row.compile.is_err() {
        return row;
    }
    let report =
        std::fs::read(&report).ok().and_then(|t| serde_json::from_slice::<serde_json::Value>(&t).ok());
    if let Some(r) = report {
        row.triangles = r["counts"]["triangles"].as_u64().unwrap_or(0);
        row.bytes = r["bytes"].as_u64().unwrap_or(0);
        for w in r["warnings"].as_array().into_iter().flatten() {
            *row.warnings.entry(w["class"].as_str().unwrap_or("?").to_string()).or_default() += 1;
        }
    }
    row.verify = kiln(&["kiln".into(), "verify".into(), out.display().to_string()]);
    row.render = render.then(|| render_png(&out, &work.join(format!("{stem}.png"))));
    row
}

/// `kiln ARGS…` in process.
fn kiln(args: &[String]) -> Result<(), String> {
    let cli = kiln_compiler::cli::parse_from(args).map_err(|e| e.to_string())?;
    kiln_compiler::commands::run(cli).map_err(|e| e.message)
}

/// `kiln-play FILE --headless --size 64x48 -o PNG`, in process; the PNG's mean sRGB code.
fn render_png(file: &Path, png: &Path) -> Result<f64, String> {
    let args = [
        "kiln-play",
        &file.display().to_string(),
        "--headless",
        "--size",
        "64x48",
        "-o",
        &png.display().to_string(),
    ];
    let kiln_player::cli::Invocation::Play(args) =
        kiln_player::cli::parse_from(args).map_err(|e| e.to_string())?
    else {
        return Err("not a play command".into());
    };
    kiln_player::cli::run(*args, Instant::now()).map_err(|e| e.to_string())?;
    let img = image::open(png).map_err(|e| format!("{}: {e}", png.display()))?.to_rgb8();
    let sum: u64 = img.as_raw().iter().map(|&c| u64::from(c)).sum();
    Ok(sum as f64 / img.as_raw().len().max(1) as f64)
}

/// The table (Markdown), one row per model.
pub fn table(rows: &[Row]) -> String {
    let mut t = String::from(
        "| model | licence | triangles | warnings (data-loss / missing-setup / performance) | compile ms | file | verify | render (mean sRGB) |\n\
         |---|---|---:|---|---:|---:|---|---|\n",
    );
    let cell = |r: &Result<(), String>| match r {
        Ok(()) => "ok".to_string(),
        Err(e) => format!("**failed**: {}", e.replace('|', "\\|").replace('\n', " ")),
    };
    for r in rows {
        if let Some(why) = &r.skipped {
            t += &format!(
                "| {} | {} | | | | | absent: {} | |\n",
                r.entry.name,
                r.entry.licence,
                why.replace('|', "\\|")
            );
            continue;
        }
        let w = |c: &str| r.warnings.get(c).copied().unwrap_or(0);
        let render = match &r.render {
            None => "not run".to_string(),
            Some(Ok(m)) if *m < 1.0 => format!("ok, black ({m:.1})"),
            Some(Ok(m)) => format!("ok ({m:.0})"),
            Some(Err(e)) => format!("**failed**: {}", e.replace('|', "\\|")),
        };
        let compiled = r.compile.is_ok();
        t += &format!(
            "| {} | {} | {} | {} | {:.0} | {} | {} | {} |\n",
            r.entry.name,
            r.entry.licence,
            if compiled { r.triangles.to_string() } else { String::new() },
            if compiled {
                format!("{} / {} / {}", w("data-loss"), w("missing-setup"), w("performance"))
            } else {
                cell(&r.compile)
            },
            r.compile_ms,
            if compiled { format!("{:.1} MiB", r.bytes as f64 / (1 << 20) as f64) } else { String::new() },
            if compiled { cell(&r.verify) } else { String::new() },
            if compiled { render } else { String::new() },
        );
    }
    t
}
