//! The window front end: winit, a swapchain the display image is blitted to, and a fly camera
//! (WASD/QE to move, drag with a mouse button to look, Shift for speed, Esc to quit).

use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

use crate::gpu::vk;
use glam::DVec3;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::error::{Exit, PlayError, PlayResult};
use crate::gpu::{SemaphoreOp, Swapchain, Use, surface_extensions};
use crate::render::Readable;
use crate::session::{Session, SessionOptions};

/// A playing window. Dropped in field order after `drop` waited for the GPU: the swapchain
/// (while the window it presents to is still open), then the session, then the window.
struct Running {
    swapchain: Swapchain,
    session: Session,
    window: Arc<Window>,
    resized: bool,
    /// The session's notes printed so far.
    notes_shown: usize,
}

impl Drop for Running {
    fn drop(&mut self) {
        // The swapchain's images and semaphores may be in use until the GPU is idle.
        let _ = self.session.gpu.wait_idle();
    }
}

struct App {
    options: SessionOptions,
    start: Instant,
    running: Option<Running>,
    error: Option<PlayError>,
    keys: HashSet<KeyCode>,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    last: Instant,
    title_at: Instant,
    frame_ms: f64,
    speed: f64,
    frames_left: Option<u32>,
}

/// Opens the window and plays until it is closed, or for `frames` frames.
pub fn run(options: SessionOptions, frames: Option<u32>, start: Instant) -> PlayResult {
    let event_loop = EventLoop::new().map_err(|e| {
        PlayError::new(
            Exit::Unsupported,
            format!("cannot open a window ({e}); without a display server use --headless -o OUT.png"),
        )
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        options,
        start,
        running: None,
        error: None,
        keys: HashSet::new(),
        dragging: false,
        cursor: None,
        last: Instant::now(),
        title_at: Instant::now(),
        frame_ms: 0.0,
        speed: 1.0,
        frames_left: frames,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| PlayError::new(Exit::Gpu, format!("window event loop failed: {e}")))?;
    let counts = app.running.as_ref().map(|r| r.session.gpu.validation.clone());
    drop(app.running.take());
    let errors = counts.map_or(0, |c| c.errors.load(std::sync::atomic::Ordering::Relaxed));
    if let Some(e) = app.error {
        return Err(e);
    }
    if errors > 0 {
        return Err(PlayError::new(Exit::Gpu, format!("the validation layer reported {errors} error(s)")));
    }
    Ok(())
}

impl App {
    fn start_session(&mut self, event_loop: &ActiveEventLoop) -> PlayResult<Running> {
        let attributes = Window::default_attributes()
            .with_title(format!("kiln-play — {}", self.options.file.display()))
            .with_inner_size(PhysicalSize::new(self.options.width, self.options.height));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| PlayError::new(Exit::Unsupported, format!("cannot create a window: {e}")))?,
        );
        let display = event_loop
            .display_handle()
            .map_err(|e| PlayError::new(Exit::Unsupported, format!("no display handle: {e}")))?
            .as_raw();
        let handle = window
            .window_handle()
            .map_err(|e| PlayError::new(Exit::Unsupported, format!("no window handle: {e}")))?
            .as_raw();
        let mut options = self.options.clone();
        options.gpu.surface_extensions = surface_extensions(display)?;
        let size = window.inner_size();
        options.width = size.width.max(1);
        options.height = size.height.max(1);
        let session = Session::open(&options, self.start)?;
        let swapchain = Swapchain::new(&session.gpu, display, handle, options.width, options.height)?;
        for w in &session.warnings {
            eprintln!("warning: {w}");
        }
        for n in &session.notes {
            eprintln!("note: {n}");
        }
        let notes_shown = session.notes.len();
        let b = &session.scene.manifest.bounds;
        let diagonal = DVec3::from_array(b.max.map(f64::from)) - DVec3::from_array(b.min.map(f64::from));
        self.speed = if diagonal.is_finite() { (diagonal.length() * 0.2).max(1e-3) } else { 1.0 };
        Ok(Running { swapchain, session, window, resized: false, notes_shown })
    }

    fn draw(&mut self) -> PlayResult {
        let dt = self.last.elapsed().as_secs_f64().min(0.1);
        self.last = Instant::now();
        let Some(r) = self.running.as_mut() else { return Ok(()) };
        let mut local = DVec3::ZERO;
        for (key, v) in [
            (KeyCode::KeyW, DVec3::Z),
            (KeyCode::KeyS, DVec3::NEG_Z),
            (KeyCode::KeyD, DVec3::X),
            (KeyCode::KeyA, DVec3::NEG_X),
            (KeyCode::KeyE, DVec3::Y),
            (KeyCode::KeyQ, DVec3::NEG_Y),
        ] {
            if self.keys.contains(&key) {
                local += v;
            }
        }
        let fast = if self.keys.contains(&KeyCode::ShiftLeft) || self.keys.contains(&KeyCode::ShiftRight) {
            4.0
        } else {
            1.0
        };
        r.session.camera.fly(local, self.speed * fast * dt);

        let size = r.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        if r.resized {
            r.session.resize(size.width, size.height)?;
            r.swapchain.recreate(&r.session.gpu, size.width, size.height)?;
            r.resized = false;
        }
        // The previous frame's fence guards the acquire semaphore's reuse.
        r.session.wait()?;
        let Some(index) = r.swapchain.acquire()? else {
            r.resized = true;
            return Ok(());
        };
        let image = r.swapchain.images[index as usize];
        let extent = r.swapchain.extent;
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        let t = Instant::now();
        r.session.record_and_submit(
            |rec, renderer| {
                let display = renderer.copy_source(rec, Readable::Display);
                rec.transition_raw(image, range, Use::DISCARD, Use::TRANSFER_DST);
                rec.blit(display, image, extent.width, extent.height);
                rec.transition_raw(image, range, Use::TRANSFER_DST, Use::PRESENT);
            },
            &[SemaphoreOp::binary(r.swapchain.acquired.raw, vk::PipelineStageFlags2::ALL_COMMANDS)],
            &[SemaphoreOp::binary(
                r.swapchain.rendered[index as usize].raw,
                vk::PipelineStageFlags2::ALL_COMMANDS,
            )],
        )?;
        if !r.swapchain.present(&r.session.gpu, index)? {
            r.resized = true;
        }
        // What the first frame did not wait for uploads after it.
        r.session.upload_rest()?;
        // The switch from the fallback to the chosen techniques says so.
        for n in &r.session.notes[r.notes_shown..] {
            eprintln!("note: {n}");
        }
        r.notes_shown = r.session.notes.len();
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * t.elapsed().as_secs_f64() * 1e3;
        if self.title_at.elapsed().as_secs_f64() > 0.5 {
            self.title_at = Instant::now();
            if let Ok(p) = r.session.pass_times() {
                // Passes that ran (more than a microsecond), by name.
                let passes: Vec<String> = p.iter().map(|(name, ms)| format!("{name} {ms:.2}")).collect();
                r.window.set_title(&format!(
                    "kiln-play — {} — GPU {:.2} ms ({})",
                    r.session.scene.manifest.scene_name,
                    p.iter().map(|(_, ms)| ms).sum::<f64>(),
                    passes.join(", ")
                ));
            }
        }
        Ok(())
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: PlayError) {
        self.error = Some(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start_session(event_loop) {
            Ok(r) => self.running = Some(r),
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                if let Some(r) = self.running.as_mut() {
                    r.resized = true;
                }
            }
            WindowEvent::KeyboardInput {
                event: KeyEvent { physical_key: PhysicalKey::Code(code), state, .. },
                ..
            } => {
                if code == KeyCode::Escape {
                    event_loop.exit();
                } else if state == ElementState::Pressed {
                    self.keys.insert(code);
                } else {
                    self.keys.remove(&code);
                }
            }
            WindowEvent::MouseInput { state, .. } => {
                self.dragging = state == ElementState::Pressed;
                self.cursor = None;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if self.dragging
                    && let (Some((x, y)), Some(r)) = (self.cursor, self.running.as_mut())
                {
                    r.session.camera.turn((position.x - x) * 0.004, -(position.y - y) * 0.004);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.draw() {
                    self.fail(event_loop, e);
                }
                if let Some(n) = &mut self.frames_left {
                    *n = n.saturating_sub(1);
                    if *n == 0 {
                        event_loop.exit();
                    }
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(r) = &self.running {
            r.window.request_redraw();
        }
    }
}
