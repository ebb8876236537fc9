//! Outputs never replace inputs: `kiln compile scene.gltf -o scene.gltf` (or `--report` or
//! `--depfile` naming the MTL, a texture, the sidecar) would overwrite the asset and exit 0.
//! Paths are compared as files, not as spellings: `./a.gltf`, `/abs/a.gltf` and a hard link or
//! symbolic link to it are the same file.

use std::path::{Path, PathBuf};

use crate::exit::{CliError, CliResult};

/// Whether `a` and `b` name the same file. For an `a` that does not exist yet, its canonical
/// folder and name are compared with `b`'s canonical path.
pub fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
        #[cfg(not(unix))]
        {
            let _ = (ma, mb);
        }
    }
    match (canonical(a), canonical(b)) {
        (Some(a), Some(b)) => a == b,
        _ => false,
    }
}

/// `path` made absolute with symbolic links resolved; for a file that does not exist, its
/// folder's canonical path joined with its name.
fn canonical(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let name = path.file_name()?;
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Some(parent.canonicalize().ok()?.join(name))
}

/// A usage error when an output (`(option, path)`) names an input or another output.
pub fn refuse(outputs: &[(&str, &Path)], inputs: &[PathBuf]) -> CliResult {
    for (i, (option, out)) in outputs.iter().enumerate() {
        if let Some(input) = inputs.iter().find(|input| same_file(out, input)) {
            return Err(CliError::usage(format!(
                "{option} {} would overwrite the input {}: choose another output path",
                out.display(),
                input.display()
            )));
        }
        if let Some((other, _)) = outputs[..i].iter().find(|(_, o)| same_file(out, o)) {
            return Err(CliError::usage(format!(
                "{option} {} and {other} name the same file: give each output its own path",
                out.display()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_file_however_it_is_spelled() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.gltf");
        std::fs::write(&a, "{}").unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        assert!(same_file(&a, &sub.join("../a.gltf")));
        assert!(!same_file(&a, &dir.path().join("b.gltf")));
        // A file that does not exist yet is the input only if it has the input's path.
        assert!(!same_file(&dir.path().join("new.kiln"), &a));
        #[cfg(unix)]
        {
            let link = dir.path().join("link.gltf");
            std::os::unix::fs::symlink(&a, &link).unwrap();
            let hard = dir.path().join("hard.gltf");
            std::fs::hard_link(&a, &hard).unwrap();
            assert!(same_file(&link, &a) && same_file(&hard, &a));
        }
        let e = refuse(&[("-o", &a)], std::slice::from_ref(&a)).unwrap_err();
        assert!(e.to_string().contains("-o") && e.to_string().contains("overwrite"), "{e}");
        let out = dir.path().join("out.kiln");
        let e = refuse(&[("-o", &out), ("--report", &out)], &[]).unwrap_err();
        assert!(e.to_string().contains("--report") && e.to_string().contains("-o"), "{e}");
        refuse(&[("-o", &out), ("--report", &dir.path().join("r.json"))], std::slice::from_ref(&a)).unwrap();
    }
}
