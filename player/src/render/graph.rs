//! The frame's images and the barriers between passes, derived from what each pass declares it
//! reads and writes: no pass writes a barrier by hand.
//!
//! A target is declared once, in the file of the pass that makes it ([`TargetDecl`]); passes
//! that only read a target name the same declaration. A target that no pass of the run makes
//! but some pass binds (e.g. the ray-traced shadow layers the direct pass reads when shadows are
//! shadow-mapped) becomes a 1 × 1 placeholder, so descriptor sets are always complete.
//!
//! Each image remembers how it was last used. Before a step, [`FrameImages::access`] compares
//! that with what the step needs and records the transitions, batched in one barrier:
//! a layout change, a read or write after a write, or a write after reads each need one;
//! reads after reads in the same layout do not. A write that discards the contents transitions
//! from `UNDEFINED` (and still waits for all earlier work, which orders it after the previous
//! frame's reads).

use crate::gpu::vk;

use crate::error::PlayResult;
use crate::gpu::{Gpu, Image, ImageDesc, Recorder, Use};

/// A frame image by role: name, format and usage; sized when made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TargetDecl {
    /// Name (debug name of the image, key of the registry).
    pub name: &'static str,
    /// Format.
    pub format: vk::Format,
    /// Usage.
    pub usage: vk::ImageUsageFlags,
    /// Viewed as a 2D array.
    pub array: bool,
}

impl TargetDecl {
    /// The image description at `width` × `height` with `layers` layers.
    pub fn sized(&self, width: u32, height: u32, layers: u32) -> ImageDesc {
        ImageDesc {
            format: self.format,
            width: width.max(1),
            height: height.max(1),
            mips: 1,
            layers: layers.max(1),
            cube: false,
            array: self.array,
            usage: self.usage,
            uploaded: false,
            components: vk::ComponentMapping::default(),
        }
    }
}

/// How a step uses an image.
#[derive(Debug, Clone, Copy)]
pub enum Access {
    /// Reads it.
    Read(Use),
    /// Reads and writes it (e.g. a running mean).
    ReadWrite(Use),
    /// Overwrites it: the previous contents are not needed.
    Write(Use),
}

impl Access {
    fn target_use(self) -> Use {
        match self {
            Access::Read(u) | Access::ReadWrite(u) | Access::Write(u) => u,
        }
    }

    fn writes(self) -> bool {
        !matches!(self, Access::Read(_))
    }
}

/// How an image was last used: the uses since the last barrier, merged.
#[derive(Debug, Clone, Copy)]
struct State {
    layout: vk::ImageLayout,
    stage: vk::PipelineStageFlags2,
    access: vk::AccessFlags2,
    wrote: bool,
}

#[derive(Debug)]
struct Slot {
    decl: TargetDecl,
    image: Image,
    /// `None`: never used since it was made (contents undefined).
    state: Option<State>,
}

/// What `access` needs after `state`: the use to transition from (`None`: no barrier) and the
/// state after it.
fn step(state: Option<State>, access: Access) -> (Option<Use>, State) {
    let to = access.target_use();
    let from = match (state, access) {
        (None, _) | (_, Access::Write(_)) => Some(Use::DISCARD),
        (Some(s), _) if s.layout != to.layout || s.wrote || access.writes() => {
            Some(Use { layout: s.layout, stage: s.stage, access: s.access })
        }
        _ => None,
    };
    let next = match (from, state) {
        // Another read in the same layout: a later write must wait for it too.
        (None, Some(s)) => State { stage: s.stage | to.stage, access: s.access | to.access, ..s },
        _ => State { layout: to.layout, stage: to.stage, access: to.access, wrote: access.writes() },
    };
    (from, next)
}

/// The images of one frame size and their states, released when dropped (the GPU must be done
/// with them). The default has no image.
#[derive(Debug, Default)]
pub struct FrameImages {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    slots: Vec<Slot>,
}

impl FrameImages {
    /// Makes the `made` images, and 1 × 1 placeholders of the `bound` declarations no entry of
    /// `made` covers. On failure the images already made are released (dropped).
    pub fn new(
        gpu: &Gpu,
        width: u32,
        height: u32,
        made: &[(TargetDecl, ImageDesc)],
        bound: &[TargetDecl],
    ) -> PlayResult<FrameImages> {
        let mut wanted: Vec<(TargetDecl, ImageDesc)> = Vec::new();
        for (decl, desc) in made {
            assert!(
                !wanted.iter().any(|(d, _)| d.name == decl.name),
                "two passes make the target '{}'",
                decl.name
            );
            wanted.push((*decl, *desc));
        }
        for decl in bound {
            if !wanted.iter().any(|(d, _)| d.name == decl.name) {
                wanted.push((*decl, decl.sized(1, 1, 1)));
            }
        }
        let slots = wanted
            .into_iter()
            .map(|(decl, desc)| Ok(Slot { decl, image: Image::new(gpu, decl.name, desc)?, state: None }))
            .collect::<PlayResult<Vec<Slot>>>()?;
        Ok(FrameImages { width, height, slots })
    }

    fn slot(&self, decl: &TargetDecl) -> usize {
        self.slots
            .iter()
            .position(|s| s.decl.name == decl.name)
            .unwrap_or_else(|| panic!("no pass made or bound the target '{}'", decl.name))
    }

    /// The image of a target (made or placeholder).
    pub fn get(&self, decl: &TargetDecl) -> &Image {
        &self.slots[self.slot(decl)].image
    }

    /// Records the barriers that make the targets ready for the given accesses.
    pub fn access(&mut self, rec: &Recorder, accesses: &[(TargetDecl, Access)]) {
        let mut barriers: Vec<(usize, Use, Use)> = Vec::new();
        for &(decl, access) in accesses {
            let i = self.slot(&decl);
            let (from, state) = step(self.slots[i].state, access);
            self.slots[i].state = Some(state);
            if let Some(from) = from {
                barriers.push((i, from, access.target_use()));
            }
        }
        let list: Vec<(&Image, Use, Use)> =
            barriers.iter().map(|&(i, from, to)| (&self.slots[i].image, from, to)).collect();
        rec.transitions(&list);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs accesses from a fresh image; returns the `from` layout of each barrier (None: none).
    fn run(accesses: &[Access]) -> Vec<Option<vk::ImageLayout>> {
        let mut state = None;
        accesses
            .iter()
            .map(|&a| {
                let (from, next) = step(state, a);
                state = Some(next);
                from.map(|u| u.layout)
            })
            .collect()
    }

    const GENERAL: vk::ImageLayout = vk::ImageLayout::GENERAL;
    const UNDEFINED: vk::ImageLayout = vk::ImageLayout::UNDEFINED;

    #[test]
    fn hazards_get_barriers_and_read_after_read_does_not() {
        use Access::*;
        let (s, sampled, color) = (Use::STORAGE, Use::SAMPLED, Use::COLOR);
        // First use and a discarding write come from UNDEFINED.
        assert_eq!(run(&[Read(s)]), vec![Some(UNDEFINED)]);
        assert_eq!(run(&[ReadWrite(s), Write(s)]), vec![Some(UNDEFINED), Some(UNDEFINED)]);
        // Read after write, write after write (running mean), write after read.
        assert_eq!(run(&[ReadWrite(s), Read(s)]), vec![Some(UNDEFINED), Some(GENERAL)]);
        assert_eq!(run(&[ReadWrite(s), ReadWrite(s)]), vec![Some(UNDEFINED), Some(GENERAL)]);
        assert_eq!(
            run(&[ReadWrite(s), Read(s), ReadWrite(s)]),
            vec![Some(UNDEFINED), Some(GENERAL), Some(GENERAL)]
        );
        // Reads after reads in one layout: one barrier, for the first.
        assert_eq!(
            run(&[Write(color), Read(sampled), Read(sampled), Read(sampled)]),
            vec![Some(UNDEFINED), Some(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL), None, None]
        );
        // A layout change after reads needs one.
        assert_eq!(
            run(&[Write(s), Read(s), Read(Use::TRANSFER_SRC)]),
            vec![Some(UNDEFINED), Some(GENERAL), Some(GENERAL)]
        );
    }

    #[test]
    fn a_write_after_several_reads_waits_for_all_of_them() {
        let reads = [Access::Write(Use::COLOR), Access::Read(Use::SAMPLED), Access::Read(Use::STORAGE)];
        let mut state = None;
        for a in reads {
            state = Some(step(state, a).1);
        }
        // SAMPLED and STORAGE reads in GENERAL vs SHADER_READ_ONLY differ in layout, so the
        // second read already had its own barrier; a write now waits on the last reads' stages.
        let (from, _) = step(state, Access::ReadWrite(Use::STORAGE));
        let from = from.expect("a write after reads needs a barrier");
        assert!(from.stage.contains(Use::STORAGE.stage));
        let mut s = Some(step(None, Access::Write(Use::STORAGE)).1);
        s = Some(step(s, Access::Read(Use::STORAGE)).1);
        s = Some(
            step(s, Access::Read(Use { stage: vk::PipelineStageFlags2::FRAGMENT_SHADER, ..Use::STORAGE })).1,
        );
        let (from, _) = step(s, Access::ReadWrite(Use::STORAGE));
        let from = from.expect("barrier");
        assert!(
            from.stage
                .contains(vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COMPUTE_SHADER)
        );
        assert!(from.access.contains(vk::AccessFlags2::SHADER_STORAGE_READ));
    }
}
