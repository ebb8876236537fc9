//! The requirement rule, and the macros that apply it in a test.

/// Something a test needs from the machine, with the variable that makes its absence a failure
/// instead of a skip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// A Vulkan device (`KILN_REQUIRE_VULKAN`).
    Vulkan,
    /// `xvfb-run`, for the window test; required with Vulkan (`KILN_REQUIRE_VULKAN`), which is
    /// what that test exercises.
    Xvfb,
    /// `glslc`, to recompile the committed shaders (`KILN_REQUIRE_GLSLC`).
    Glslc,
    /// A Python with Mitsuba 3 or flip-evaluator, `.venv-mitsuba` or `KILN_MITSUBA_PYTHON`
    /// (`KILN_REQUIRE_MITSUBA`).
    Mitsuba,
    /// Headless Chromium, for screenshots of the benchmark pages (`KILN_REQUIRE_CHROMIUM`).
    Chromium,
    /// `ninja`, for the build-system test (`KILN_REQUIRE_NINJA`).
    Ninja,
    /// Bazel, PostgreSQL's server and BuildGrid (`.venv-buildgrid` or `KILN_BGD`), for the
    /// build-engine test (`KILN_REQUIRE_BAZEL`).
    Bazel,
}

impl Need {
    /// The environment variable that, set to any value, makes this need's absence fail a test.
    pub fn variable(self) -> &'static str {
        match self {
            Need::Vulkan | Need::Xvfb => "KILN_REQUIRE_VULKAN",
            Need::Glslc => "KILN_REQUIRE_GLSLC",
            Need::Mitsuba => "KILN_REQUIRE_MITSUBA",
            Need::Chromium => "KILN_REQUIRE_CHROMIUM",
            Need::Ninja => "KILN_REQUIRE_NINJA",
            Need::Bazel => "KILN_REQUIRE_BAZEL",
        }
    }

    /// What to install for it (the packages `.ci/run` installs).
    pub fn install(self) -> &'static str {
        match self {
            Need::Vulkan => {
                "a Vulkan driver, or Mesa's CPU driver lavapipe with the validation layer (Debian: \
                 libvulkan1 mesa-vulkan-drivers vulkan-validationlayers)"
            }
            Need::Xvfb => "a virtual X server (Debian: xvfb xauth)",
            Need::Glslc => "glslc (Debian: glslc)",
            Need::Mitsuba => {
                "Mitsuba 3 and flip-evaluator: run .ci/run, or python3 -m venv .venv-mitsuba && \
                 .venv-mitsuba/bin/pip install mitsuba flip-evaluator numpy (or name a Python that \
                 has them in KILN_MITSUBA_PYTHON)"
            }
            Need::Chromium => "Chromium (Debian: chromium fonts-dejavu-core)",
            Need::Ninja => "ninja (Debian: ninja-build)",
            Need::Bazel => {
                "Bazel, PostgreSQL and BuildGrid: run .ci/run, or apt-get install bazel-bootstrap \
                 postgresql && python3 -m venv .venv-buildgrid && .venv-buildgrid/bin/pip install \
                 buildgrid==0.4.4 psycopg2-binary==2.9.13 (or name its bgd in KILN_BGD)"
            }
        }
    }

    /// Whether this need's variable is set, so that its absence must fail the test.
    pub fn required(self) -> bool {
        std::env::var_os(self.variable()).is_some()
    }

    /// The rule: what `probe` found, or `None` after saying why (`Err`'s text) the test does
    /// not run and what to install; panics with that message instead where [`Need::required`].
    pub fn check<T>(self, probe: Result<T, String>) -> Option<T> {
        match probe {
            Ok(found) => Some(found),
            Err(why) => {
                assert!(
                    !self.required(),
                    "{why}, but {} is set: install {}",
                    self.variable(),
                    self.install()
                );
                eprintln!("skipping: {why}; to run this test, install {}", self.install());
                None
            }
        }
    }
}

/// What a finder returns: `true` or `Some` where the need is present. [`require!`](crate::require!) takes either.
pub trait Found {
    /// What the test gets: `()` for a `bool`, the value for an `Option`.
    type Value;
    /// `Some` where the need is present.
    fn found(self) -> Option<Self::Value>;
}

impl Found for bool {
    type Value = ();
    fn found(self) -> Option<()> {
        self.then_some(())
    }
}

impl<T> Found for Option<T> {
    type Value = T;
    fn found(self) -> Option<T> {
        self
    }
}

/// `require!(finder())`: what the finder found (a `bool` finder gives `()`), or returns from the
/// test, which then passes (the finder has said why, or panicked under `KILN_REQUIRE_<X>`).
#[macro_export]
macro_rules! require {
    ($finder:expr) => {
        match $crate::Found::found($finder) {
            ::std::option::Option::Some(found) => found,
            ::std::option::Option::None => return,
        }
    };
}

/// `let dir = gpu_test!();` at the top of a test that renders: a Vulkan device by the rule
/// ([`vulkan`]: otherwise the test says why and returns, or fails under `KILN_REQUIRE_VULKAN`),
/// then a fresh temporary folder for the test's files ([`temp_dir`]). A test that needs no
/// folder writes `require!(vulkan())`.
#[cfg(feature = "vulkan")]
#[macro_export]
macro_rules! gpu_test {
    () => {{
        $crate::require!($crate::vulkan());
        $crate::temp_dir()
    }};
}

/// Whether a Vulkan device is here, as the player lists them (`kiln_player::gpu::list_devices`),
/// by the rule ([`Need::check`]).
#[cfg(feature = "vulkan")]
pub fn vulkan() -> bool {
    let devices = match kiln_player::gpu::list_devices() {
        Ok(d) if !d.is_empty() => Ok(()),
        Ok(_) => Err("no Vulkan device".to_string()),
        Err(e) => Err(format!("no Vulkan device ({e})")),
    };
    Need::Vulkan.check(devices).is_some()
}

/// A fresh temporary folder, removed when dropped.
pub fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary folder")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_present_need_runs_and_a_missing_one_skips_or_fails_as_its_variable_says() {
        for need in [Need::Vulkan, Need::Xvfb, Need::Glslc, Need::Mitsuba, Need::Chromium, Need::Ninja] {
            assert_eq!(need.check(Ok(7)), Some(7));
            let missing = std::panic::catch_unwind(|| need.check::<()>(Err("not here".into())));
            match missing {
                Ok(found) => {
                    assert!(!need.required(), "{need:?} skipped though {} is set", need.variable());
                    assert_eq!(found, None);
                }
                Err(panic) => {
                    assert!(need.required(), "{need:?} failed though {} is not set", need.variable());
                    let message = panic.downcast_ref::<String>().expect("a formatted message");
                    assert!(
                        message.contains(need.variable()) && message.contains(need.install()),
                        "{message}"
                    );
                }
            }
        }
    }

    #[test]
    fn require_hands_over_what_was_found_or_returns() {
        fn run(found: Option<u32>, present: bool, got: &mut Option<u32>) {
            require!(present);
            *got = Some(require!(found));
        }
        let mut got = None;
        run(Some(5), true, &mut got);
        assert_eq!(got, Some(5));
        for (found, present) in [(None, true), (Some(5), false)] {
            let mut got = None;
            run(found, present, &mut got);
            assert_eq!(got, None, "{found:?} {present}");
        }
    }
}
