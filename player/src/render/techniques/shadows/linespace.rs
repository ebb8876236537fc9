//! `--shadows linespace`: the ray-traced estimator with its shadow feelers through the binary
//! line space (seed 004; `passes/rt_shadows.rs`, `shaders/rt/shadows_linespace*.comp`).


use super::{LIGHT_RADIUS, SUN_ANGLE};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_shadows::RtShadowsPass;
use crate::render::spirv;
use crate::render::techniques::knobs::choice;
use crate::render::techniques::{Knob, Knobs, Needs, Registered, Technique};
use crate::scene::linespace::LsArrays;

/// Soft shadows with the rays through the binary line space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSpace {
    /// As for [`super::rt::Rt`].
    pub light_radius: f32,
    /// As for [`super::rt::Rt`].
    pub sun_degrees: f32,
    /// How a filled shaft is decided.
    pub test: LsShadowTest,
}

/// How line-space shadow feelers decide a filled shaft.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LsShadowTest {
    /// Exact triangle tests in the cells holding the ray's ends, a filled shaft elsewhere counts
    /// as occluded: conservative (never a missed occluder), the cheapest.
    Ends,
    /// Exact triangle tests wherever the shaft is filled: the exact answer, the bits skipping
    /// empty shafts.
    Filled,
}

impl Registered for LineSpace {
    const NAME: &'static str = "linespace";
    const HELP: &'static str = "the ray-traced estimator with its shadow feelers through the binary line space \
                                (seed 004; the emissive surfaces' shadow rays too; needs a file compiled with line \
                                space, see --ls-shadow-test)";
    const KNOBS: &'static [Knob] = &[
        LIGHT_RADIUS,
        SUN_ANGLE,
        choice(
            "ls-shadow-test",
            "ends: exact triangle tests in the cells holding the ray's ends, a filled shaft \
             elsewhere occludes (conservative, cheapest); filled: exact tests wherever the \
             shaft is filled (exact)",
            &["ends", "filled"],
            0,
        ),
    ];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<LineSpace, String> {
        Ok(LineSpace {
            light_radius: k.number("light-radius"),
            sun_degrees: k.number("sun-angle"),
            test: if k.choice("ls-shadow-test") == "filled" { LsShadowTest::Filled } else { LsShadowTest::Ends },
        })
    }
}

impl Technique for LineSpace {
    super::traced_shadows!();

    fn line_space_visibility(&self) -> Option<bool> {
        Some(self.test == LsShadowTest::Filled)
    }

    fn needs(&self) -> Needs {
        Needs { line_space: LsArrays::BINARY_QUERY, ..Needs::TRACED_SURFACES }
    }



    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, lights, decode) = (frame.gpu, frame.scene.lights, frame.decode);
        let code = match self.test {
            LsShadowTest::Ends => spirv::shader!("rt/shadows_linespace.comp"),
            LsShadowTest::Filled => spirv::shader!("rt/shadows_linespace_exact.comp"),
        };
        frame.add(Stage::Shadows, move || RtShadowsPass::new(gpu, code, true, lights, decode));
    }
}
