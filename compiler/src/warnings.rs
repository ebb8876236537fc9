//! What a compile does with each class of warning: print it, ignore it, or fail on it.
//! `--strict` fails on data loss only (a missing camera or light is not data loss: a sidecar
//! supplies them); `-W CLASS=LEVEL` sets any class, the last setting of a class winning.

use crate::ir::{Warning, WarningClass};

/// What happens to a warning of some class.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WarningLevel {
    /// The compile fails (after printing every warning).
    Error,
    /// Printed (unless `-q`) and in the report.
    Warn,
    /// Not printed; still in the report.
    Ignore,
}

/// `CLASS=LEVEL`, as `-W` takes it.
pub fn parse_setting(s: &str) -> Result<(WarningClass, WarningLevel), String> {
    let classes: Vec<&str> = WarningClass::ALL.iter().map(|c| c.name()).collect();
    let (class, level) = s.split_once('=').ok_or_else(|| {
        format!("'{s}' is not CLASS=LEVEL (e.g. data-loss=error; classes: {})", classes.join(", "))
    })?;
    let class = WarningClass::ALL
        .into_iter()
        .find(|c| c.name() == class)
        .ok_or_else(|| format!("no warning class '{class}' (one of: {})", classes.join(", ")))?;
    let level = match level {
        "error" => WarningLevel::Error,
        "warn" => WarningLevel::Warn,
        "ignore" => WarningLevel::Ignore,
        other => return Err(format!("no level '{other}' (one of: error, warn, ignore)")),
    };
    Ok((class, level))
}

/// The level of every class for one compile.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WarningPolicy {
    levels: Vec<(WarningClass, WarningLevel)>,
}

impl Default for WarningPolicy {
    /// Every class a warning.
    fn default() -> Self {
        WarningPolicy { levels: WarningClass::ALL.iter().map(|&c| (c, WarningLevel::Warn)).collect() }
    }
}

impl WarningPolicy {
    /// `--strict` (data loss fails) then each `-W` setting in order.
    pub fn new(strict: bool, settings: &[(WarningClass, WarningLevel)]) -> WarningPolicy {
        let mut p = WarningPolicy::default();
        if strict {
            p.set(WarningClass::DataLoss, WarningLevel::Error);
        }
        for &(class, level) in settings {
            p.set(class, level);
        }
        p
    }

    fn set(&mut self, class: WarningClass, level: WarningLevel) {
        for entry in &mut self.levels {
            if entry.0 == class {
                entry.1 = level;
            }
        }
    }

    /// The level of `class`.
    pub fn level(&self, class: WarningClass) -> WarningLevel {
        self.levels.iter().find(|e| e.0 == class).map_or(WarningLevel::Warn, |e| e.1)
    }

    /// The warnings that fail the compile.
    pub fn failing<'a>(&self, warnings: &'a [Warning]) -> Vec<&'a Warning> {
        warnings.iter().filter(|w| self.level(w.class) == WarningLevel::Error).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(class: WarningClass) -> Warning {
        Warning { class, message: "m".into() }
    }

    #[test]
    fn strict_fails_on_data_loss_only_and_w_settings_win_in_order() {
        let all = [w(WarningClass::DataLoss), w(WarningClass::MissingSetup), w(WarningClass::Performance)];
        assert!(WarningPolicy::default().failing(&all).is_empty());
        let strict = WarningPolicy::new(true, &[]);
        assert_eq!(strict.failing(&all), [&all[0]]);
        let both = WarningPolicy::new(true, &[parse_setting("missing-setup=error").unwrap()]);
        assert_eq!(both.failing(&all).len(), 2);
        let perf = WarningPolicy::new(false, &[parse_setting("performance=error").unwrap()]);
        assert_eq!(perf.failing(&all), [&all[2]]);
        let relaxed = WarningPolicy::new(
            true,
            &[parse_setting("data-loss=ignore").unwrap(), parse_setting("data-loss=warn").unwrap()],
        );
        assert!(relaxed.failing(&all).is_empty());
        assert_eq!(relaxed.level(WarningClass::DataLoss), WarningLevel::Warn);
        assert!(parse_setting("data-loss").unwrap_err().contains("CLASS=LEVEL"));
        assert!(parse_setting("perf=error").unwrap_err().contains("data-loss, missing-setup, performance"));
        assert!(parse_setting("data-loss=fatal").unwrap_err().contains("error, warn, ignore"));
    }
}
