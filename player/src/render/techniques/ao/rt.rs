//! `--ao rt`: one cosine-weighted ray per pixel per frame through the BVH; a hit at t weighs
//! (t/R)² (`passes/rt_ao.rs`, `shaders/rt/ao.comp`).


use super::{AO_RADIUS, Radius, ao_reach};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::ao;
use crate::render::passes::rt_ao::RtAoPass;
use crate::render::passes::rt_history::{Accumulated, Kind};
use crate::render::techniques::{Knob, Knobs, Registered, Technique};

/// Ray-traced ambient occlusion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rt {
    /// The ray length R.
    pub radius: Radius,
}

impl Registered for Rt {
    const NAME: &'static str = "rt";
    const HELP: &'static str =
        "ray-traced: one cosine-weighted ray per pixel per frame within --ao-radius (or --ao-reach)";
    const KNOBS: &'static [Knob] = &[AO_RADIUS, ao_reach(0.1, &[0.03, 0.1, 0.3, 100.0])];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<Rt, String> {
        Ok(Rt { radius: Radius::of(k) })
    }
}

impl Technique for Rt {
    super::ao_image!();

    fn ray_traced(&self) -> bool {
        true
    }

    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, decode) = (frame.gpu, frame.decode);
        frame.add(Stage::Ao, move || RtAoPass::new(gpu, decode));
    }


    fn accumulated(&self, _: usize) -> Option<Accumulated> {
        let histories = ["rt ao history a", "rt ao history b"];
        Some(Accumulated::new(ao::AO, histories, Kind::One, 1, 1))
    }
}
