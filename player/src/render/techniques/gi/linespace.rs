//! `--gi linespace`: the path-traced GI estimator with its rays through the line space (seed
//! 004): bounce rays through the chosen structure, shadow rays through the binary line space;
//! specular bounces and emissive hits through the BVH (`passes/rt_gi.rs`,
//! `shaders/rt/gi_linespace*.comp`).


use super::{GI_BOUNCES, GI_REGULARIZE};
use crate::render::frame::{FrameBuild, Stage};
use crate::render::passes::rt_gi::RtGiPass;
use crate::render::spirv;
use crate::render::techniques::knobs::choice;
use crate::render::techniques::{Knob, Knobs, Needs, Registered, Technique};
use crate::scene::linespace::LsArrays;

/// Path-traced diffuse GI through the line space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSpace {
    /// As for [`super::rt::Rt`].
    pub bounces: u32,
    /// What answers the bounce rays.
    pub structure: GiStructure,
    /// As for [`super::rt::Rt`].
    pub regularize: f32,
}

/// What answers the bounce rays of `--gi linespace` (shadow rays: the binary line space).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GiStructure {
    /// The shaft's PNMT record: an approximate hit without triangle tests.
    Pnmt,
    /// The candidate lists: the exact hit.
    Candidates,
    /// The record's pre-illuminated radiance: one lookup, no shading, one bounce.
    Preillum,
}

impl Registered for LineSpace {
    const NAME: &'static str = "linespace";
    const HELP: &'static str = "the path-traced GI estimator with its rays through the line space (seed 004): bounce \
                                rays through --gi-structure, shadow rays through the binary line space; specular \
                                bounces and emissive hits through the BVH (needs a file compiled with line space)";
    const KNOBS: &'static [Knob] = &[
        GI_BOUNCES,
        GI_REGULARIZE,
        choice(
            "gi-structure",
            "pnmt: the shaft's stored hit, no triangle test (approximate); candidates: the \
             shaft's triangle list (exact); preillum: the stored hit's baked radiance, one \
             bounce, no shading",
            &["pnmt", "candidates", "preillum"],
            0,
        ),
    ];
    const STOCHASTIC: bool = true;

    fn new(k: &Knobs) -> Result<LineSpace, String> {
        let structure = match k.choice("gi-structure") {
            "candidates" => GiStructure::Candidates,
            "preillum" => GiStructure::Preillum,
            _ => GiStructure::Pnmt,
        };
        Ok(LineSpace { bounces: k.whole("gi-bounces")?, structure, regularize: k.number("gi-regularize") })
    }
}

impl Technique for LineSpace {
    super::traced_gi!();

    fn needs(&self) -> Needs {
        let line_space = match self.structure {
            GiStructure::Pnmt => LsArrays::PNMT_QUERY | LsArrays::BINARY_QUERY,
            GiStructure::Candidates => LsArrays::CANDIDATE_QUERY | LsArrays::BINARY_QUERY,
            GiStructure::Preillum => LsArrays::PNMT_QUERY | LsArrays::PREILLUM,
        };
        Needs { line_space, ..Needs::TRACED_SURFACES }
    }


    fn passes<'a>(&'a self, frame: &mut FrameBuild<'a>) {
        let (gpu, decode) = (frame.gpu, frame.decode);
        let code = match self.structure {
            GiStructure::Pnmt => spirv::shader!("rt/gi_linespace_pnmt.comp"),
            GiStructure::Candidates => spirv::shader!("rt/gi_linespace_candidates.comp"),
            GiStructure::Preillum => spirv::shader!("rt/gi_linespace_preillum.comp"),
        };
        frame.add(Stage::Gi, move || RtGiPass::with_line_space(gpu, code, decode));
    }
}
