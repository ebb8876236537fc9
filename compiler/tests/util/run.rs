//! Runs `kiln` in a test's directory and checks the outcome (included by the CLI test files as
//! `mod run`).

use std::path::Path;
use std::process::Command;

/// The outcome of one `kiln` run.
#[derive(Debug)]
pub struct Run {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    /// Asserts the exit code and that nothing panicked.
    pub fn expect(&self, code: i32) -> &Self {
        assert!(!self.stderr.contains("panicked") && self.code != 70, "kiln panicked: {self:#?}");
        assert_eq!(
            self.code, code,
            "unexpected exit code\n--- stdout:\n{}\n--- stderr:\n{}",
            self.stdout, self.stderr
        );
        self
    }
    /// Asserts that stderr mentions `text`.
    // scenes.rs, which also includes this file, checks exit codes and stdout only.
    #[allow(dead_code)]
    pub fn says(&self, text: &str) -> &Self {
        assert!(self.stderr.contains(text), "stderr lacks {text:?}: {self:#?}");
        self
    }
}

/// Runs `kiln` with `args` in `dir`.
pub fn kiln(dir: &Path, args: &[&str]) -> Run {
    let out =
        Command::new(env!("CARGO_BIN_EXE_kiln")).args(args).current_dir(dir).output().expect("kiln runs");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}
