//! Progress display when stderr is a terminal, nothing otherwise (build logs stay clean): a
//! spinner naming the current stage, and for long stages (line space, shadow maps) a bar with a
//! count of the work done. Counting is one atomic add in indicatif's position; the bar is redrawn
//! at most 20 times a second, so no item takes a lock.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// Stage progress for one compile.
#[derive(Debug)]
pub struct Progress {
    bar: Option<ProgressBar>,
}

fn spinner_style() -> ProgressStyle {
    ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}")
        .unwrap_or_else(|_| ProgressStyle::default_spinner())
}

fn bar_style() -> ProgressStyle {
    ProgressStyle::with_template("{spinner} {elapsed:>4} {msg} [{bar:30}] {human_pos}/{human_len} ({eta})")
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar())
}

impl Progress {
    /// A spinner if stderr is a terminal and `enabled`, else nothing.
    pub fn new(enabled: bool) -> Progress {
        let bar = (enabled && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new_spinner();
            bar.set_style(spinner_style());
            bar.enable_steady_tick(Duration::from_millis(100));
            bar
        });
        Progress { bar }
    }

    /// A progress display that shows nothing.
    pub fn hidden() -> Progress {
        Progress { bar: None }
    }

    /// Whether anything is shown.
    pub fn is_shown(&self) -> bool {
        self.bar.is_some()
    }

    /// Announces the stage now running (a spinner).
    pub fn stage(&self, name: &str) {
        if let Some(b) = &self.bar {
            b.set_style(spinner_style());
            b.set_message(name.to_string());
        }
    }

    /// Announces a stage of `total` counted items (`what`: e.g. "line space: cells"), shown as a
    /// bar advanced by [`Progress::inc`].
    pub fn count(&self, what: &str, total: u64) {
        if let Some(b) = &self.bar {
            b.set_length(total);
            b.set_position(0);
            b.set_style(bar_style());
            b.set_message(what.to_string());
        }
    }

    /// Counts `n` more items done (any thread).
    pub fn inc(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
        }
    }

    /// Removes the display.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
