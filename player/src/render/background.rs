//! A [`Frame`] built on a thread of its own while the session renders with another one (the
//! ray-traced passes' pipelines take seconds to compile on a cold driver cache).
//!
//! Creating pipelines, layouts and images are device-level calls that Vulkan allows from any
//! thread; the pipeline cache is internally synchronized (it is not created with
//! `EXTERNALLY_SYNCHRONIZED`), and the allocator is behind a mutex. The queue stays with the
//! thread that records and submits. Nothing built here is used by the GPU before
//! [`FrameBuild::join`] hands it over.

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

use super::frame::{Frame, SceneTraits};
use super::techniques::Techniques;
use super::texels::TexelDecode;
use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::Gpu;

/// A frame that is being built on another thread. Dropping it waits for the thread and drops
/// what it made (nothing of it was used by the GPU), so that no path leaks it and the thread's
/// hold on the device ends before the session's.
#[derive(Debug)]
pub struct FrameBuild {
    thread: Option<JoinHandle<PlayResult<Built>>>,
}

/// What the thread made.
#[derive(Debug)]
pub struct Built {
    /// The passes and their images.
    pub frame: Frame,
    /// Milliseconds the thread took.
    pub ms: f64,
    /// When it finished.
    pub done: Instant,
}

impl FrameBuild {
    /// Starts building the passes of `techniques` and their images at `width` × `height`, as
    /// [`Frame::new`] does.
    pub fn spawn(
        gpu: &Arc<Gpu>,
        techniques: Techniques,
        scene: SceneTraits,
        decode: TexelDecode,
        width: u32,
        height: u32,
    ) -> PlayResult<FrameBuild> {
        let device = Arc::clone(gpu);
        let thread = std::thread::Builder::new()
            .name("kiln-pipelines".into())
            .spawn(move || {
                let t = Instant::now();
                let frame = Frame::new(&device, &techniques, scene, decode, width, height)?;
                Ok(Built { frame, ms: t.elapsed().as_secs_f64() * 1e3, done: Instant::now() })
            })
            .map_err(|e| PlayError::new(Exit::Gpu, format!("cannot start the pipeline thread: {e}")))?;
        Ok(FrameBuild { thread: Some(thread) })
    }

    /// Whether the thread has finished (a [`FrameBuild::join`] would not wait).
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }

    /// Waits for the thread and takes what it built.
    pub fn join(mut self) -> PlayResult<Built> {
        let thread = self.thread.take().expect("joined once: join takes the build");
        thread.join().unwrap_or_else(|_| Err(PlayError::new(Exit::Gpu, "pipeline creation panicked")))
    }
}

impl Drop for FrameBuild {
    fn drop(&mut self) {
        if let Some(thread) = self.thread.take() {
            // The frame it built, if any, is dropped with the result.
            let _ = thread.join();
        }
    }
}
