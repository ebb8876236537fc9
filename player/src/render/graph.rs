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

use ash::vk;

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

/// The images of one frame size and their states.
#[derive(Debug)]
pub struct FrameImages {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    slots: Vec<Slot>,
}

impl FrameImages {
    /// Makes the `made` images, and 1 × 1 placeholders of the `bound` declarations no entry of
    /// `made` covers. On failure the images already made are released.
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
        let mut images = FrameImages { width, height, slots: Vec::with_capacity(wanted.len()) };
        for (decl, desc) in wanted {
            match Image::new(gpu, decl.name, desc) {
                Ok(image) => images.slots.push(Slot { decl, image, state: None }),
                Err(e) => {
                    images.destroy(gpu);
                    return Err(e);
                }
            }
        }
        Ok(images)
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
            let to = access.target_use();
            let from = match (self.slots[i].state, access) {
                (None, _) | (_, Access::Write(_)) => Some(Use::DISCARD),
                (Some(s), _) if s.layout != to.layout || s.wrote || access.writes() => {
                    Some(Use { layout: s.layout, stage: s.stage, access: s.access })
                }
                _ => None,
            };
            let state = &mut self.slots[i].state;
            match (from, *state) {
                (None, Some(s)) => {
                    // Another read in the same layout: a later write must wait for it too.
                    *state = Some(State { stage: s.stage | to.stage, access: s.access | to.access, ..s });
                }
                _ => {
                    *state = Some(State {
                        layout: to.layout,
                        stage: to.stage,
                        access: to.access,
                        wrote: access.writes(),
                    })
                }
            }
            if let Some(from) = from {
                barriers.push((i, from, to));
            }
        }
        let list: Vec<(&Image, Use, Use)> =
            barriers.iter().map(|&(i, from, to)| (&self.slots[i].image, from, to)).collect();
        rec.transitions(&list);
    }

    /// Releases the images.
    pub fn destroy(&mut self, gpu: &Gpu) {
        for s in &mut self.slots {
            s.image.destroy(gpu);
        }
        self.slots.clear();
    }
}
