//! What kiln's tests share, whatever crate they test: the rule for what a test needs from the
//! machine, the finders of those tools, and the image files the tests read and write. A
//! dev-dependency only, never published.
//!
//! # The requirement rule
//!
//! A test that needs something a machine may lack (a Vulkan device, `glslc`, a Python with
//! Mitsuba or flip-evaluator, Chromium, ninja, `xvfb-run`) asks for it through a finder of this
//! crate, which applies [`Need::check`]: where it is present the test runs; where it is missing
//! the test prints why and what to install, and passes, unless the need's variable
//! `KILN_REQUIRE_<X>` is set (to any value; `.ci/run` sets them all to 1), when it fails with that
//! message. So nothing skips in CI, and a developer without Chromium can still run the rest.
//!
//! [`require!`] returns from the test where a finder found nothing; `gpu_test!` (feature
//! `vulkan`) asks for a Vulkan device and hands the test a fresh temporary folder:
//!
//! ```no_run
//! use kiln_test_support::{glslc, require, temp_dir};
//!
//! fn embedded_spirv_is_what_glslc_makes() {
//!     require!(glslc()); // or say why and return; fail instead under KILN_REQUIRE_GLSLC
//!     let dir = temp_dir();
//!     // ... run glslc into dir and compare ...
//! }
//! ```

#![deny(missing_docs)]

mod images;
mod need;
mod tools;

pub use images::{mse, read_exr, read_npy, write_npy, write_npy_rgba8};
#[cfg(feature = "vulkan")]
pub use need::vulkan;
pub use need::{Found, Need, temp_dir};
pub use tools::{
    bazel_and_buildgrid, chromium, flip_python, glslc, mitsuba_python, ninja, screenshot, workspace, xvfb_run,
};
