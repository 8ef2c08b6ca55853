//! voxgi-web: voxgi in a browser page through WebGPU. The page (web/index.html, built by
//! web/build.sh) holds a canvas, status lines and a panel; this crate opens the WebGPU device,
//! renders a scene into the canvas every animation frame (cone tracing, the path tracer, or
//! both split), moves the viewer's orbit and fly cameras, opens built-in scenes and files
//! picked or dropped (open.rs), builds the settings panel from voxgi's one settings table
//! (panel.rs), and lowers the voxel resolution where the device's limits refuse it.
//!
//! The query string chooses the scene (`?builtin=two-rooms`) and any setting by its key, as a
//! scene file's `[settings]` would (`?voxel_resolution=64&bounces=1`).
//!
//! Only `wasm32` builds have code; elsewhere the crate is empty but for its browser test.
#![cfg(target_arch = "wasm32")]

// The viewer's camera controllers, shared as they are (the viewer is a binary crate).
#[path = "../../voxgi-viewer/src/camera.rs"]
#[allow(dead_code)]
mod camera;
mod open;
mod page;
mod panel;
mod traced;

use anyhow::{Context, Result, anyhow};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::{Arc, Mutex};
use voxgi::wgpu;
use voxgi::{FrameParams, Renderer, RendererOptions, SceneSettings};
use wasm_bindgen::prelude::*;

/// The page's entry point: runs when the module is instantiated.
#[wasm_bindgen(start)]
pub fn start() {
    // A panic is a bug: its message goes to the console (with the stack) and onto the page,
    // which cannot go on (the module's state is then undefined).
    std::panic::set_hook(Box::new(|info| {
        console_error_panic_hook::hook(info);
        page::show_error(&format!("voxgi stopped (a bug; please report it): {info}"));
    }));
    page::init_logging();
    wasm_bindgen_futures::spawn_local(async {
        if let Err(e) = run().await {
            page::show_error(&format!("{e:#}"));
        }
    });
}

/// Everything a frame needs, shared by the animation-frame loop and the event handlers.
pub(crate) struct App {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    canvas: web_sys::HtmlCanvasElement,
    pub(crate) renderer: Renderer,
    pub(crate) options: RendererOptions,
    pub(crate) params: FrameParams,
    /// The scene shown, kept for the path tracer (made when first shown).
    scene: voxgi::scene::Scene,
    /// Cone tracing, the path tracer, or both split.
    pub(crate) display: traced::Display,
    traced: Option<traced::Traced>,
    /// The path tracer's samples a pixel, when it is shown.
    traced_samples: Option<u32>,
    /// The adapter is a CPU (SwiftShader): smaller defaults.
    cpu: bool,
    /// Orbit or fly (F toggles), as the viewer's.
    controller: Controller,
    /// Follow the scene's camera flight, if it has one: on until the view is moved by hand,
    /// on again when a double click goes back to the scene's camera.
    fly_along: bool,
    /// The camera the flight last set, to tell when the view was moved by hand since.
    flown: Option<voxgi::scene::Camera>,
    /// How long the fly keys were held since the last frame.
    held: camera::HeldKeys,
    scene_radius: f32,
    /// The last pointer position of a drag, and whether it pans (right button or shift).
    drag: Option<(f32, f32, bool)>,
    /// The scene's animation: its length (0: none), the time shown, playing or not.
    duration: f32,
    time: f32,
    playing: bool,
    last_frame: Option<f64>,
    /// Frames the GPU finished, and the time the last one finished (ms since the page began).
    done: Arc<Mutex<Done>>,
    /// When the renderer's choices were last shown (ms since the page began).
    choices_at: Option<f64>,
    /// What the page changed to fit the device (the voxel resolution), said under the view.
    notice: Option<String>,
    /// The voxel resolution asked for (the query, a scene file, the panel), which `options`
    /// may hold lowered to fit the device.
    requested_resolution: u32,
    /// Whether the device was lost (the page cannot go on then).
    watch: voxgi::gpu::lost::DeviceWatch,
    /// Frames submitted.
    submitted: u32,
    /// An error stopped the loop (it is on the page).
    stopped: bool,
}

/// The least voxel resolution the page lowers to when the device's limits refuse a larger.
const MIN_FITTED_RESOLUTION: u32 = 16;

/// The options a renderer was made with, and what was lowered to make it fit.
struct Fitted {
    options: RendererOptions,
    notice: Option<String>,
}

fn lowered(from: u32, to: u32, reason: &str) -> String {
    format!("lowered from {from}³ to {to}³ to fit this device ({reason})")
}

/// A renderer for `scene` with `options`, the voxel resolution halved while the device's
/// limits refuse it (`Error::TooLarge`), down to `MIN_FITTED_RESOLUTION`.
fn fitting_renderer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &voxgi::scene::Scene,
    options: &RendererOptions,
) -> Result<(Renderer, Fitted)> {
    let mut o = options.clone();
    let mut first_refusal = None;
    loop {
        match Renderer::new(device, queue, scene, &o) {
            Ok(r) => {
                let notice = first_refusal.map(|reason: String| {
                    lowered(options.voxel_resolution, o.voxel_resolution, &reason)
                });
                return Ok((r, Fitted { options: o, notice }));
            }
            Err(voxgi::Error::TooLarge(reason)) if o.voxel_resolution > MIN_FITTED_RESOLUTION => {
                first_refusal.get_or_insert(reason);
                o.voxel_resolution /= 2;
            }
            Err(e) => return Err(e.into()),
        }
    }
}

/// How the camera moves.
enum Controller {
    Orbit(camera::Orbit),
    Fly(camera::Fly),
}

impl Controller {
    fn camera(&self) -> voxgi::scene::Camera {
        match self {
            Controller::Orbit(o) => o.camera(),
            Controller::Fly(f) => f.camera(),
        }
    }
}

/// What the GPU finished: counted by `Queue::on_submitted_work_done`.
#[derive(Default)]
struct Done {
    frames: u32,
    first_ms: Option<f64>,
    /// Milliseconds between the last finished frames, smoothed.
    frame_ms: Option<f64>,
    last_ms: Option<f64>,
}

async fn run() -> Result<()> {
    let query = page::query();
    let builtin = query
        .iter()
        .find(|(k, _)| k == "builtin")
        .map_or("cornell-box".to_string(), |(_, v)| v.clone());
    let scene = voxgi::scene::builtin::by_name(&builtin)?;

    // Every other key of the query is a setting, checked as a scene file's would be.
    // `webgpu_limits=default` asks only for WebGPU's default limits (128 MiB storage
    // buffers), as a browser that offers no more would give: the page then shows how it fits.
    let default_limits = query
        .iter()
        .any(|(k, v)| k == "webgpu_limits" && v == "default");
    let pairs: Vec<(&str, &str)> = query
        .iter()
        .filter(|(k, _)| k != "builtin" && k != "webgpu_limits")
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    let settings =
        SceneSettings::from_pairs(pairs.iter().copied()).context("the page's query string")?;

    page::status("asking the browser for a WebGPU adapter…");
    let canvas: web_sys::HtmlCanvasElement = page::element("voxgi")?;
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
    let instance = wgpu::Instance::new(descriptor);
    let surface = instance
        .create_surface(wgpu::SurfaceTarget::Canvas(canvas.clone()))
        .map_err(|e| anyhow!("the canvas cannot show WebGPU: {e}"))?;
    let adapter = instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            apply_limit_buckets: false,
        })
        .await
        .map_err(|e| anyhow!("this browser offers no WebGPU adapter ({e}); voxgi needs WebGPU"))?;
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("voxgi-web"),
            required_features: voxgi::required_features(&adapter),
            required_limits: if default_limits {
                voxgi::minimum_limits()
            } else {
                voxgi::required_limits(&adapter)
            },
            ..Default::default()
        })
        .await
        .context("cannot open the WebGPU device")?;
    device.on_uncaptured_error(Arc::new(|e: wgpu::Error| {
        page::show_error(&format!("WebGPU: {e}"));
    }));
    let watch = voxgi::gpu::lost::DeviceWatch::new(&device);

    // As the viewer's: a CPU adapter (SwiftShader) stays usable at 64³ and half resolution.
    let cpu = adapter.get_info().device_type == wgpu::DeviceType::Cpu;
    let mut options = RendererOptions::interactive(cpu);
    let mut scene = scene;
    scene.set_time(0.0);
    let mut params = FrameParams::new(scene.default_camera());
    settings.apply(&mut options, &mut params)?;
    page::status("uploading the scene and building the pipelines…");
    let requested_resolution = options.voxel_resolution;
    let (renderer, fitted) = fitting_renderer(&device, &queue, &scene, &options)?;
    let options = fitted.options;
    let bounds = scene.bounds();
    let scene_radius = (bounds.size().length() * 0.5).max(1e-3);
    let orbit = camera::Orbit::from_camera(renderer.default_camera(), scene_radius * 2.0);
    params.camera = orbit.camera();
    let controller = Controller::Orbit(orbit);

    let caps = surface.get_capabilities(&adapter);
    let format = voxgi::surface_format(&caps.formats)
        .ok_or_else(|| anyhow!("the canvas offers no format"))?;
    let (width, height) = page::canvas_size(&canvas, device.limits().max_texture_dimension_2d);
    let mut config = surface
        .get_default_config(&adapter, width, height)
        .ok_or_else(|| anyhow!("the adapter cannot draw into the canvas"))?;
    config.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    config.format = format;
    config.present_mode = wgpu::PresentMode::Fifo;
    surface.configure(&device, &config);

    let info = adapter.get_info();
    let limits = device.limits();
    page::set_scene(&builtin);
    page::set_adapter(&format!(
        "{} · storage buffers up to {} MiB · 3D textures up to {}³ · {}",
        adapter_name(&info),
        limits.max_storage_buffer_binding_size >> 20,
        limits.max_texture_dimension_3d,
        if device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            "GPU timestamps"
        } else {
            "no GPU timestamps"
        },
    ));

    let duration = scene.duration();
    let app = Rc::new(RefCell::new(App {
        device,
        queue,
        surface,
        config,
        canvas,
        renderer,
        options,
        params,
        controller,
        fly_along: true,
        flown: None,
        held: camera::HeldKeys::default(),
        scene,
        display: traced::Display::Cones,
        traced: None,
        traced_samples: None,
        cpu,
        scene_radius,
        drag: None,
        duration,
        time: 0.0,
        playing: duration > 0.0,
        last_frame: None,
        done: Arc::new(Mutex::new(Done::default())),
        submitted: 0,
        watch,
        choices_at: None,
        notice: fitted.notice,
        requested_resolution,
        stopped: false,
    }));
    open::build(&app, &builtin)?;
    panel::build(&app)?;
    page::listen_input(&app)?;
    page::dismissable_errors()?;
    page::animation_loop(app);
    Ok(())
}

/// The adapter as the browser describes it (WebGPU gives a vendor and an architecture, and
/// sometimes no name).
fn adapter_name(info: &wgpu::AdapterInfo) -> String {
    let parts: Vec<&str> = [
        info.name.as_str(),
        info.driver.as_str(),
        info.driver_info.as_str(),
    ]
    .into_iter()
    .filter(|s| !s.is_empty())
    .collect();
    let kind = format!("{:?}", info.device_type).to_lowercase();
    if parts.is_empty() {
        format!("WebGPU adapter ({kind}, vendor {:#x})", info.vendor)
    } else {
        format!("{} ({kind})", parts.join(", "))
    }
}

impl App {
    /// Renders one frame into the canvas (called once per animation frame).
    pub(crate) fn frame(&mut self, now_ms: f64) {
        if self.stopped {
            return;
        }
        // The browser asks for frames at the display's rate whatever the GPU's pace: with two
        // frames still on the GPU, this one is skipped, so input is answered by the next frame
        // rather than after a queue of stale ones.
        let finished = self.done.lock().map_or(0, |d| d.frames);
        if self.submitted > finished + 1 {
            return;
        }
        if let Err(e) = self.try_frame(now_ms) {
            // Pools grow from a frame's counts: one past the device's limits arrives here.
            let too_large = matches!(
                e.downcast_ref::<voxgi::Error>(),
                Some(voxgi::Error::TooLarge(_))
            );
            if too_large && self.lower_resolution(&e.to_string()) {
                return;
            }
            self.stopped = true;
            page::show_error(&format!("{e:#}"));
        }
    }

    fn try_frame(&mut self, now_ms: f64) -> Result<()> {
        if let Some(why) = self.watch.lost() {
            anyhow::bail!("the GPU device was lost ({why}); reload the page");
        }
        let (w, h) = page::canvas_size(&self.canvas, self.device.limits().max_texture_dimension_2d);
        if (w, h) != (self.config.width, self.config.height) {
            self.config.width = w;
            self.config.height = h;
            self.surface.configure(&self.device, &self.config);
        }
        // Slow frames do not make the animation jump.
        let dt = self
            .last_frame
            .map_or(0.0, |t| ((now_ms - t) / 1000.0).min(0.25) as f32);
        self.last_frame = Some(now_ms);
        if self.playing && self.duration > 0.0 {
            self.time = (self.time + dt) % self.duration.max(1e-3);
        }
        self.renderer.set_time(self.time)?;
        self.renderer.receive_feedback()?;
        if let Controller::Fly(f) = &mut self.controller {
            let (m, secs) = self.held.take(web_time::Instant::now());
            f.step(m, secs);
        }
        self.params.camera = self.flown_camera();

        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            other => return Err(anyhow!("the canvas's surface: {other:?}")),
        };
        let view = frame.texture.create_view(&Default::default());
        let target = voxgi::Target::new(&view, self.config.format, w, h);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        // The path tracer alone needs no cone-traced image under it.
        if self.display != traced::Display::Traced {
            self.renderer.render(&mut encoder, &target, &self.params)?;
        }
        self.traced_samples = match self.display.traced_columns(w) {
            Some(columns) => match self.record_traced(&mut encoder, &target, columns) {
                Ok(samples) => Some(samples),
                Err(e) => {
                    // The cone tracer goes on; the path tracer's failure is shown.
                    self.display = traced::Display::Cones;
                    self.traced = None;
                    panel::show_display(self.display);
                    page::show_error(&format!("the path tracer: {e:#}"));
                    None
                }
            },
            None => None,
        };
        if self.choices_at.is_none_or(|t| now_ms - t > 1000.0) {
            self.choices_at = Some(now_ms);
            page::set_choices(&self.choices());
        }
        self.queue.submit([encoder.finish()]);
        self.submitted += 1;
        let done = self.done.clone();
        self.queue.on_submitted_work_done(move || {
            let now = page::now_ms();
            // A poisoned lock only means an earlier callback panicked: its counts still hold.
            let mut d = done.lock().unwrap_or_else(|p| p.into_inner());
            d.frames += 1;
            d.first_ms.get_or_insert(now);
            if let Some(last) = d.last_ms {
                let ms = now - last;
                d.frame_ms = Some(d.frame_ms.map_or(ms, |m| 0.8 * m + 0.2 * ms));
            }
            d.last_ms = Some(now);
            page::frames_done(d.frames, d.first_ms, d.frame_ms);
        });
        self.queue.present(frame);
        Ok(())
    }

    /// What the renderer chose and holds: the structure, its resolution, GPU memory, and what
    /// the page lowered to fit the device.
    fn choices(&self) -> String {
        let mut text = self.holds();
        if let Some(n) = self.traced_samples {
            text.push_str(&format!(
                " · {}: the path tracer at {n} samples a pixel",
                self.display.name()
            ));
        }
        if let Some(n) = &self.notice {
            text.push_str(" · ");
            text.push_str(n);
        }
        text
    }

    fn holds(&self) -> String {
        let o = self.renderer.options();
        let bytes: u64 = self.renderer.memory().iter().map(|(_, b)| b).sum();
        format!(
            "{} volume of {}³ voxels · {} at {}×{} · {:.0} MiB of GPU memory",
            o.voxels.name(),
            o.voxel_resolution,
            if o.half_resolution {
                "half-resolution gather"
            } else {
                "full-resolution gather"
            },
            self.config.width,
            self.config.height,
            bytes as f64 / (1u64 << 20) as f64
        )
    }

    /// One band of the path tracer over `columns`, made (its BVH built) at the scene's time
    /// shown when first needed and again when that time changed: its image is of one instant.
    fn record_traced(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &voxgi::Target,
        columns: std::ops::Range<u32>,
    ) -> Result<u32> {
        if self.traced.as_ref().is_none_or(|t| t.time != self.time) {
            let mut scene = self.scene.clone();
            scene.set_time(self.time);
            self.traced = Some(traced::Traced::new(
                &self.device,
                &self.queue,
                &scene,
                &self.options,
                self.cpu,
                self.time,
            )?);
        }
        let t = self.traced.as_mut().expect("made above");
        t.record(encoder, target, &self.params, self.options.bounces, columns)
    }

    /// Shows cone tracing, the path tracer or both. Showing the path tracer pauses the
    /// animation: its image accumulates over one instant.
    pub(crate) fn set_display(&mut self, display: traced::Display) {
        self.display = display;
        if display != traced::Display::Cones && self.playing {
            self.playing = false;
            panel::show_playing(self.duration, self.playing);
        }
    }

    /// Halves the voxel resolution after `reason` (the device's limits), saying so; false
    /// at the least resolution or when the renderer refuses.
    fn lower_resolution(&mut self, reason: &str) -> bool {
        let from = self.options.voxel_resolution;
        if from <= MIN_FITTED_RESOLUTION {
            return false;
        }
        let options = RendererOptions {
            voxel_resolution: from / 2,
            ..self.options.clone()
        };
        if self.renderer.set_options(&options).is_err() {
            return false;
        }
        self.options = options;
        self.notice = Some(lowered(self.requested_resolution, from / 2, reason));
        log::warn!("{}", self.notice.as_deref().unwrap_or_default());
        panel::refresh(self);
        true
    }

    /// Applies a change of the options (from the panel): only what depends on it is redone.
    pub(crate) fn set_options(&mut self, options: RendererOptions) -> voxgi::Result<()> {
        self.renderer.set_options(&options)?;
        if options.voxel_resolution != self.options.voxel_resolution {
            // Asked for: what was lowered before no longer holds.
            self.requested_resolution = options.voxel_resolution;
            self.notice = None;
        }
        self.options = options;
        Ok(())
    }

    /// Shows `scene` (opened as `name`) instead, with its file's `[settings]` applied over
    /// the options in use. On an error the scene shown stays.
    pub(crate) fn replace_scene(
        &mut self,
        scene: &voxgi::scene::Scene,
        settings: Option<&SceneSettings>,
        name: &str,
    ) -> Result<()> {
        // The resolution asked for, not one lowered to fit the last scene.
        let mut options = RendererOptions {
            voxel_resolution: self.requested_resolution,
            ..self.options.clone()
        };
        let mut params = self.params.clone();
        if let Some(s) = settings {
            s.apply(&mut options, &mut params)?;
        }
        let requested = options.voxel_resolution;
        let mut scene = scene.clone();
        scene.set_time(0.0);
        let scene = &scene;
        let (renderer, fitted) = fitting_renderer(&self.device, &self.queue, scene, &options)
            .with_context(|| format!("cannot show {name}"))?;
        self.renderer = renderer;
        self.options = fitted.options;
        self.notice = fitted.notice;
        self.scene = scene.clone();
        self.traced = None;
        self.requested_resolution = requested;
        // A new scene starts afresh, after an error too.
        self.stopped = false;
        self.params = params;
        self.scene_radius = (scene.bounds().size().length() * 0.5).max(1e-3);
        self.duration = scene.duration();
        self.time = 0.0;
        self.playing = self.duration > 0.0;
        self.frame_scene();
        panel::refresh(self);
        page::set_scene(name);
        Ok(())
    }

    /// Back to the scene's own camera (orbiting).
    pub(crate) fn frame_scene(&mut self) {
        self.controller = Controller::Orbit(camera::Orbit::from_camera(
            self.renderer.default_camera(),
            self.scene_radius * 2.0,
        ));
        self.held = camera::HeldKeys::default();
        self.fly_along = true;
        self.flown = None;
        page::set_controller(false);
        // A cut to another view: nothing of the last view's history belongs in it.
        self.renderer.reset_history();
    }

    /// This frame's camera: the scene's flight at the time shown while it has one and the view
    /// was not moved by hand since it was followed (a drag, the wheel or a fly key stops it), the
    /// orbit or fly camera otherwise. Following, the controller is kept on the flight, so that
    /// leaving it starts from where the flight was.
    fn flown_camera(&mut self) -> voxgi::scene::Camera {
        if self
            .flown
            .as_ref()
            .is_some_and(|c| *c != self.controller.camera())
        {
            self.fly_along = false;
        }
        let flight = if self.fly_along && self.scene.camera_is_animated(0) {
            self.scene.camera_at(0, self.time)
        } else {
            None
        };
        let Some(cam) = flight else {
            self.flown = None;
            return self.controller.camera();
        };
        self.controller = match &self.controller {
            Controller::Orbit(_) => {
                Controller::Orbit(camera::Orbit::from_camera(&cam, self.scene_radius))
            }
            Controller::Fly(f) => Controller::Fly(camera::Fly::from_camera(&cam, f.speed)),
        };
        self.flown = Some(self.controller.camera());
        cam
    }

    /// The page lost the keyboard's focus: no key is held any more.
    pub(crate) fn release_keys(&mut self) {
        self.held = camera::HeldKeys::default();
    }

    /// Orbit to fly or back, keeping the view.
    pub(crate) fn toggle_fly(&mut self) {
        let camera = self.controller.camera();
        self.controller = match self.controller {
            Controller::Orbit(_) => {
                Controller::Fly(camera::Fly::from_camera(&camera, self.scene_radius * 0.5))
            }
            Controller::Fly(_) => {
                Controller::Orbit(camera::Orbit::from_camera(&camera, self.scene_radius))
            }
        };
        self.held = camera::HeldKeys::default();
        // Switching is not moving: a flight followed goes on.
        if self.flown.is_some() {
            self.flown = Some(self.controller.camera());
        }
        page::set_controller(matches!(self.controller, Controller::Fly(_)));
    }

    /// A fly key (axis 0 right, 1 up, 2 forward; which way) went down or up.
    pub(crate) fn fly_key(&mut self, axis: usize, positive: bool, down: bool) {
        let now = web_time::Instant::now();
        if down {
            self.held.press(axis, positive, now);
        } else {
            self.held.release(axis, positive, now);
        }
    }

    /// A drag or a wheel step on the canvas: orbiting, they turn, pan and zoom; flying, a drag
    /// looks around and the wheel sets the speed.
    pub(crate) fn pointer(&mut self, event: page::Pointer) {
        match event {
            page::Pointer::Down { x, y, pan } => self.drag = Some((x, y, pan)),
            page::Pointer::Move { x, y } => {
                if let Some((x0, y0, pan)) = self.drag {
                    let (dx, dy) = (x - x0, y - y0);
                    match &mut self.controller {
                        Controller::Orbit(o) if pan => o.pan(dx, dy, self.config.height as f32),
                        Controller::Orbit(o) => o.rotate(dx, dy),
                        Controller::Fly(f) => f.look(dx, dy),
                    }
                    self.drag = Some((x, y, pan));
                }
            }
            page::Pointer::Up => self.drag = None,
            page::Pointer::Wheel { steps } => match &mut self.controller {
                Controller::Orbit(o) => o.zoom(steps),
                Controller::Fly(f) => f.speed = (f.speed * 1.2f32.powf(steps)).max(1e-3),
            },
        }
    }

    /// Plays or pauses the scene's animation; false when it has none.
    pub(crate) fn toggle_play(&mut self) -> bool {
        if self.duration > 0.0 {
            self.playing = !self.playing;
        }
        self.playing
    }
}
