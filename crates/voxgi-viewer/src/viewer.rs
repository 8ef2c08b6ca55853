//! The window: device and surface, the voxgi renderer drawing into the surface texture, egui on
//! top, input to the camera controllers, animation playback, screenshots.

use crate::camera::{Fly, Movement, Orbit, render_flags};
use crate::settings::{frame_ui, options_ui};
use crate::{Args, load};
use anyhow::{Context, Result, anyhow};
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use voxgi::scene::Scene;
use voxgi::{FrameParams, Renderer, RendererOptions, SceneSettings, Target, wgpu};
use winit::application::ApplicationHandler;
use winit::event::{DeviceEvent, ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// The winit application: opens the window on `resumed`, then hands events to the `Viewer`.
pub struct App {
    args: Args,
    scene: Option<(Scene, Option<SceneSettings>)>,
    viewer: Option<Viewer>,
    error: Option<anyhow::Error>,
}

impl App {
    pub fn new(args: Args, scene: (Scene, Option<SceneSettings>)) -> Self {
        App {
            args,
            scene: Some(scene),
            viewer: None,
            error: None,
        }
    }

    /// The error that closed the window, if one did.
    pub fn finish(self) -> Result<()> {
        match self.error {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.error = Some(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_some() {
            return;
        }
        let Some(scene) = self.scene.take() else {
            return;
        };
        match Viewer::new(event_loop, &self.args, scene) {
            Ok(v) => self.viewer = Some(v),
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(v) = self.viewer.as_mut() else {
            return;
        };
        match v.window_event(event_loop, event) {
            Ok(()) => {}
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: winit::event::DeviceId, event: DeviceEvent) {
        if let (Some(v), DeviceEvent::MouseMotion { delta }) = (self.viewer.as_mut(), event) {
            v.mouse_motion(delta.0 as f32, delta.1 as f32);
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(v) = &self.viewer {
            v.window.request_redraw();
        }
    }
}

enum Controller {
    Orbit(Orbit),
    Fly(Fly),
}

/// Per-pass GPU milliseconds of recent frames, for the rolling graph.
const HISTORY: usize = 120;

struct Viewer {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: wgpu::AdapterInfo,
    timestamps: bool,
    renderer: Renderer,
    scene_name: String,
    scene_radius: f32,
    /// The scene's own cameras, to pick from.
    cameras: Vec<voxgi::scene::Camera>,
    options: RendererOptions,
    draft: RendererOptions,
    params: FrameParams,
    controller: Controller,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    // Input.
    keys: HashSet<KeyCode>,
    left_down: bool,
    right_down: bool,
    cursor: Option<(f32, f32)>,
    // Animation.
    duration: f32,
    time: f32,
    playing: bool,
    // Stats.
    last_frame: Instant,
    frame_ms: std::collections::VecDeque<f32>,
    pass_ms: Vec<(&'static str, std::collections::VecDeque<f32>)>,
    frames: u32,
    status: String,
    show_panel: bool,
    // Screenshots.
    screenshot: Option<(PathBuf, u32)>,
    screenshot_ui: bool,
    screenshot_key: bool,
}

impl Viewer {
    fn new(
        event_loop: &ActiveEventLoop,
        args: &Args,
        (scene, settings): (Scene, Option<SceneSettings>),
    ) -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        // Open small first: the size depends on whether the adapter is a CPU.
        let attrs = Window::default_attributes()
            .with_title(format!("voxgi — {}", scene_label(&scene)))
            .with_inner_size(winit::dpi::PhysicalSize::new(640, 360));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .context("cannot open a window")?,
        );
        let surface = instance
            .create_surface(window.clone())
            .context("cannot draw into the window")?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            apply_limit_buckets: false,
        }))
        .map_err(|e| anyhow!("no GPU adapter can draw into this window: {e}"))?;
        let info = adapter.get_info();
        let cpu = info.device_type == wgpu::DeviceType::Cpu;
        let features = voxgi::required_features(&adapter);
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("voxgi-viewer"),
            required_features: features,
            required_limits: voxgi::required_limits(&adapter),
            ..Default::default()
        }))
        .with_context(|| format!("cannot open {}", info.name))?;
        let (w, h) = args
            .size
            .unwrap_or(if cpu { (640, 360) } else { (960, 540) });
        let _ = window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let size = window.inner_size();
        let caps = surface.get_capabilities(&adapter);
        // 8-bit without an sRGB view: voxgi applies the sRGB curve itself, and egui, which
        // blends in gamma space, wants exactly that.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| {
                matches!(
                    f,
                    wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
                )
            })
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| anyhow!("the window offers no surface format"))?;
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("{} cannot draw into this window", info.name))?;
        config.usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        config.format = format;
        config.present_mode = if args.no_vsync {
            wgpu::PresentMode::AutoNoVsync
        } else {
            wgpu::PresentMode::AutoVsync
        };
        surface.configure(&device, &config);

        let mut options = RendererOptions {
            // A CPU driver stays usable at half resolution.
            half_resolution: cpu,
            voxel_resolution: if cpu { 64 } else { 128 },
            ..RendererOptions::default()
        };
        let mut scene = scene;
        scene.set_time(0.0);
        let default_camera = scene
            .cameras
            .first()
            .cloned()
            .unwrap_or_else(|| voxgi::scene::Camera::viewing(voxgi::swept_bounds(&scene)));
        let mut params = FrameParams::new(default_camera.clone());
        if let Some(s) = &settings {
            s.apply(&mut options, &mut params)?;
        }
        let mut renderer = Renderer::new(&device, &queue, &scene, &options)?;
        renderer.enable_timing(timestamps);
        let bounds = voxgi::swept_bounds(&scene);
        let radius = if bounds.is_empty() {
            1.0
        } else {
            (bounds.size().length() * 0.5).max(1e-3)
        };
        let duration = scene
            .animations
            .iter()
            .map(|a| a.duration())
            .fold(0.0f32, f32::max);
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&device, format, egui_wgpu::RendererOptions::default());
        let orbit_distance = (bounds.center() - default_camera.position)
            .length()
            .max(radius * 0.1);
        Ok(Viewer {
            window,
            surface,
            config,
            device,
            queue,
            adapter: info,
            timestamps,
            scene_name: scene_label(&scene),
            scene_radius: radius,
            cameras: scene.cameras.clone(),
            draft: options.clone(),
            options,
            controller: Controller::Orbit(Orbit::from_camera(&default_camera, orbit_distance)),
            params,
            renderer,
            egui_ctx,
            egui_state,
            egui_renderer,
            keys: HashSet::new(),
            left_down: false,
            right_down: false,
            cursor: None,
            duration,
            time: 0.0,
            playing: duration > 0.0,
            last_frame: Instant::now(),
            frame_ms: Default::default(),
            pass_ms: Vec::new(),
            frames: 0,
            status: String::new(),
            show_panel: true,
            screenshot: args
                .screenshot
                .clone()
                .map(|p| (p, args.after_frames.max(1))),
            screenshot_ui: args.with_ui,
            screenshot_key: false,
        })
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, event: WindowEvent) -> Result<()> {
        let response = self.egui_state.on_window_event(&self.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                self.config.width = size.width.max(1);
                self.config.height = size.height.max(1);
                self.surface.configure(&self.device, &self.config);
            }
            WindowEvent::RedrawRequested if self.redraw()? => event_loop.exit(),
            WindowEvent::DroppedFile(path) => self.open(&path),
            _ if response.consumed => {}
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    match event.state {
                        ElementState::Pressed => {
                            if !event.repeat {
                                self.key_pressed(code);
                            }
                            self.keys.insert(code);
                        }
                        ElementState::Released => {
                            self.keys.remove(&code);
                        }
                    }
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.left_down = down,
                    MouseButton::Right | MouseButton::Middle => self.right_down = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x as f32, position.y as f32);
                if let Some(last) = self.cursor
                    && let Controller::Orbit(o) = &mut self.controller
                {
                    let (dx, dy) = (p.0 - last.0, p.1 - last.1);
                    if self.left_down {
                        o.rotate(dx, dy);
                    } else if self.right_down {
                        o.pan(dx, dy, self.config.height as f32);
                    }
                }
                self.cursor = Some(p);
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                match &mut self.controller {
                    Controller::Orbit(o) => o.zoom(steps),
                    Controller::Fly(f) => f.speed = (f.speed * 1.2f32.powf(steps)).max(1e-3),
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Raw mouse motion: mouse look while flying with the left button held.
    fn mouse_motion(&mut self, dx: f32, dy: f32) {
        if let Controller::Fly(f) = &mut self.controller
            && self.left_down
        {
            f.look(dx, dy);
        }
    }

    fn key_pressed(&mut self, code: KeyCode) {
        match code {
            KeyCode::KeyF => {
                let cam = self.params.camera.clone();
                self.controller = match &self.controller {
                    Controller::Orbit(_) => {
                        Controller::Fly(Fly::from_camera(&cam, self.scene_radius * 0.5))
                    }
                    Controller::Fly(_) => {
                        Controller::Orbit(Orbit::from_camera(&cam, self.scene_radius))
                    }
                };
            }
            KeyCode::KeyH => self.frame_scene(),
            KeyCode::Space => self.playing = !self.playing,
            KeyCode::Tab => self.show_panel = !self.show_panel,
            KeyCode::F12 | KeyCode::KeyP => self.screenshot_key = true,
            _ => {}
        }
    }

    /// Back to the scene's own camera (or the view of its bounds).
    fn frame_scene(&mut self) {
        let cam = self.renderer.default_camera().clone();
        self.controller = Controller::Orbit(Orbit::from_camera(&cam, self.scene_radius * 2.0));
    }

    /// Replaces the scene with the file at `path`; on failure the error shows and the scene
    /// stays.
    fn open(&mut self, path: &std::path::Path) {
        let result = (|| -> Result<()> {
            let (mut scene, settings) = load(Some(path), None)?;
            scene.set_time(0.0);
            let mut options = self.options.clone();
            let mut params = FrameParams::new(self.params.camera.clone());
            if let Some(s) = &settings {
                s.apply(&mut options, &mut params)?;
            }
            let mut renderer = Renderer::new(&self.device, &self.queue, &scene, &options)
                .with_context(|| path.display().to_string())?;
            renderer.enable_timing(self.timestamps);
            self.renderer = renderer;
            self.draft = options.clone();
            self.options = options;
            let bounds = voxgi::swept_bounds(&scene);
            self.scene_radius = (bounds.size().length() * 0.5).max(1e-3);
            self.duration = scene
                .animations
                .iter()
                .map(|a| a.duration())
                .fold(0.0f32, f32::max);
            self.time = 0.0;
            self.playing = self.duration > 0.0;
            self.scene_name = scene_label(&scene);
            self.window
                .set_title(&format!("voxgi — {}", self.scene_name));
            self.frame_scene();
            Ok(())
        })();
        self.status = match result {
            Ok(()) => format!("opened {}", path.display()),
            Err(e) => format!("{e:#}"),
        };
    }

    /// Draws one frame; returns true when the viewer should close (a screenshot was taken).
    fn redraw(&mut self) -> Result<bool> {
        let now = Instant::now();
        let elapsed = (now - self.last_frame).as_secs_f32();
        self.last_frame = now;
        push(&mut self.frame_ms, elapsed * 1e3);
        // Slow frames do not make the animation or the fly camera jump.
        let dt = elapsed.min(0.25);
        if let Controller::Fly(f) = &mut self.controller {
            let k = |c: KeyCode| self.keys.contains(&c) as i32 as f32;
            f.step(
                Movement {
                    right: k(KeyCode::KeyD) - k(KeyCode::KeyA),
                    up: k(KeyCode::KeyE) - k(KeyCode::KeyQ),
                    forward: k(KeyCode::KeyW) - k(KeyCode::KeyS),
                },
                dt,
            );
        }
        if self.playing && self.duration > 0.0 {
            self.time = (self.time + dt) % self.duration.max(1e-3);
        }
        self.renderer.set_time(self.time)?;
        self.params.camera = match &self.controller {
            Controller::Orbit(o) => o.camera(),
            Controller::Fly(f) => f.camera(),
        };

        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(false);
            }
            // Minimised or slow to hand out a frame: try again on the next redraw.
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(false);
            }
            other => return Err(anyhow!("the window's surface: {other:?}")),
        };
        let view = frame.texture.create_view(&Default::default());
        let (w, h) = (self.config.width, self.config.height);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.renderer.render(
            &mut encoder,
            &Target::new(&view, self.config.format, w, h),
            &self.params,
        )?;

        // The UI, drawn over the image.
        let raw = self.egui_state.take_egui_input(&self.window);
        let ctx = self.egui_ctx.clone();
        let mut actions = crate::settings::PanelActions::default();
        let full = ctx.run_ui(raw, |ui| actions = self.ui(ui));
        self.egui_state
            .handle_platform_output(&self.window, full.platform_output);
        let jobs = ctx.tessellate(full.shapes, full.pixels_per_point);
        for (id, deltas) in &full.textures_delta.set {
            for delta in deltas {
                self.egui_renderer
                    .update_texture(&self.device, &self.queue, *id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [w, h],
            pixels_per_point: full.pixels_per_point,
        };
        let extra = self.egui_renderer.update_buffers(
            &self.device,
            &self.queue,
            &mut encoder,
            &jobs,
            &screen,
        );
        egui_pass(&self.egui_renderer, &mut encoder, &view, &jobs, &screen);
        // A screenshot with the panel: the same frame drawn again into an image.
        let capture_ui = self.screenshot_ui
            && self
                .screenshot
                .as_ref()
                .is_some_and(|(_, after)| self.frames + 1 >= *after);
        let ui_capture = if capture_ui {
            let texture = self.capture_texture(self.config.format);
            let v = texture.create_view(&Default::default());
            self.renderer.render(
                &mut encoder,
                &Target::new(&v, self.config.format, w, h),
                &self.params,
            )?;
            egui_pass(&self.egui_renderer, &mut encoder, &v, &jobs, &screen);
            Some(texture)
        } else {
            None
        };
        for id in &full.textures_delta.free {
            self.egui_renderer.free_texture(id);
        }
        self.queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        self.window.pre_present_notify();
        self.queue.present(frame);
        if self.timestamps {
            for (name, ms) in self.renderer.pass_times()? {
                match self.pass_ms.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, v)) => push(v, ms as f32),
                    None => {
                        let mut v = std::collections::VecDeque::new();
                        push(&mut v, ms as f32);
                        self.pass_ms.push((name, v));
                    }
                }
            }
        }
        self.frames += 1;

        if actions.revert {
            self.draft = self.options.clone();
        }
        if actions.apply {
            // Rebuilds only what the changes feed; a failure leaves the renderer as it was.
            match self.renderer.set_options(&self.draft) {
                Ok(()) => {
                    self.options = self.draft.clone();
                    self.status = "options applied".into();
                }
                Err(e) => self.status = format!("{e}"),
            }
        }
        if self.screenshot_key {
            self.screenshot_key = false;
            let path = PathBuf::from(format!("voxgi_{:05}.png", self.frames));
            self.status = match self.save_screenshot(&path) {
                Ok(()) => format!("wrote {}", path.display()),
                Err(e) => format!("screenshot: {e:#}"),
            };
        }
        if let Some((path, after)) = &self.screenshot
            && self.frames >= *after
        {
            let path = path.clone();
            match ui_capture {
                Some(t) => self.save_texture(&t, &path)?,
                None => self.save_screenshot(&path)?,
            }
            // The steady state: the frames after the first, which builds the voxels.
            let recent: Vec<f32> = self.frame_ms.iter().skip(2).copied().collect();
            let mean = recent.iter().sum::<f32>() / recent.len().max(1) as f32;
            eprintln!(
                "wrote {} after {} frames ({:.1} ms per frame, {:.1} fps, over the last {})",
                path.display(),
                self.frames,
                mean,
                1e3 / mean.max(1e-3),
                recent.len()
            );
            return Ok(true);
        }
        Ok(false)
    }

    /// An image the size of the window to capture a frame into.
    fn capture_texture(&self, format: wgpu::TextureFormat) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: wgpu::Extent3d {
                width: self.config.width,
                height: self.config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    /// Writes an 8-bit capture (RGBA or BGRA) as a PNG.
    fn save_texture(&self, texture: &wgpu::Texture, path: &std::path::Path) -> Result<()> {
        let mut ldr = voxgi::gpu::readback::read_texture(&self.device, &self.queue, texture)?;
        if texture.format() == wgpu::TextureFormat::Bgra8Unorm {
            for px in ldr.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
        }
        let (w, h) = (texture.width(), texture.height());
        voxgi::RenderOutput {
            width: w,
            height: h,
            hdr: vec![0.0; (w * h * 4) as usize],
            ldr,
        }
        .save(path)?;
        Ok(())
    }

    /// Renders the current view (without the UI) into an image and writes it as a PNG.
    fn save_screenshot(&mut self, path: &std::path::Path) -> Result<()> {
        let (w, h) = (self.config.width, self.config.height);
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let texture = self.capture_texture(format);
        let view = texture.create_view(&Default::default());
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.renderer.render(
            &mut encoder,
            &Target::new(&view, format, w, h),
            &self.params,
        )?;
        self.queue.submit([encoder.finish()]);
        let ldr = voxgi::gpu::readback::read_texture(&self.device, &self.queue, &texture)?;
        let hdr = match self.renderer.hdr_texture() {
            Some(t) => bytemuck_f32(&voxgi::gpu::readback::read_texture(
                &self.device,
                &self.queue,
                t,
            )?),
            None => vec![0.0; (w * h * 4) as usize],
        };
        voxgi::RenderOutput {
            width: w,
            height: h,
            hdr,
            ldr,
        }
        .save(path)?;
        Ok(())
    }

    fn ui(&mut self, ui: &mut egui::Ui) -> crate::settings::PanelActions {
        let mut actions = crate::settings::PanelActions::default();
        if !self.show_panel {
            return actions;
        }
        egui::Panel::left("settings")
            .default_size(260.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    ui.heading(&self.scene_name);
                    ui.label(format!(
                        "{} ({:?})",
                        self.adapter.name, self.adapter.backend
                    ));
                    ui.label(
                        "drag: orbit · right-drag: pan · wheel: zoom · F: fly (WASD/QE, drag \
                         to look) · H: frame · Space: play · P: screenshot · Tab: panel",
                    );
                    if !self.status.is_empty() {
                        ui.colored_label(egui::Color32::YELLOW, &self.status);
                    }
                    ui.separator();
                    egui::CollapsingHeader::new("view")
                        .default_open(true)
                        .show(ui, |ui| {
                            frame_ui(ui, &mut self.params, self.options.voxel_levels());
                            let flags = render_flags(&self.params.camera);
                            ui.horizontal(|ui| {
                                if ui.button("copy view as voxgi render flags").clicked() {
                                    ui.ctx().copy_text(flags.clone());
                                }
                            });
                            ui.label(egui::RichText::new(flags).monospace().small());
                        });
                    if !self.cameras.is_empty() {
                        ui.horizontal(|ui| {
                            ui.label("scene camera:");
                            let mut pick = None;
                            for (i, c) in self.cameras.iter().enumerate() {
                                let name = if c.name.is_empty() {
                                    format!("{i}")
                                } else {
                                    c.name.clone()
                                };
                                if ui.button(name).clicked() {
                                    pick = Some(c.clone());
                                }
                            }
                            if let Some(c) = pick {
                                self.controller =
                                    Controller::Orbit(Orbit::from_camera(&c, self.scene_radius));
                            }
                        });
                    }
                    ui.collapsing("lights", |ui| self.lights_ui(ui));
                    ui.collapsing("renderer", |ui| {
                        let dirty = self.draft != self.options;
                        let a = options_ui(ui, &mut self.draft, dirty);
                        actions.apply |= a.apply;
                        actions.revert |= a.revert;
                    });
                    if self.duration > 0.0 {
                        ui.collapsing("animation", |ui| {
                            ui.horizontal(|ui| {
                                let label = if self.playing { "pause" } else { "play" };
                                if ui.button(label).clicked() {
                                    self.playing = !self.playing;
                                }
                                ui.add(
                                    egui::Slider::new(&mut self.time, 0.0..=self.duration)
                                        .text("s"),
                                );
                            });
                        });
                    }
                    egui::CollapsingHeader::new("stats")
                        .default_open(true)
                        .show(ui, |ui| self.stats_ui(ui));
                });
            });
        actions
    }

    /// Each light's colour, intensity and placement; a change goes to `Renderer::set_light`,
    /// which re-renders its shadow views and re-lights the voxels.
    fn lights_ui(&mut self, ui: &mut egui::Ui) {
        let lights: Vec<voxgi::scene::Light> = self.renderer.lights().to_vec();
        for (i, light) in lights.iter().enumerate() {
            let mut l = light.clone();
            let kind = match l.kind {
                voxgi::scene::LightKind::Directional => "directional",
                voxgi::scene::LightKind::Point => "point",
                voxgi::scene::LightKind::Spot { .. } => "spot",
                voxgi::scene::LightKind::Area { .. } => "area",
            };
            ui.label(egui::RichText::new(format!("{} ({kind})", l.name)).strong());
            let speed = 0.01 * l.intensity.max(0.1);
            ui.horizontal(|ui| {
                ui.color_edit_button_rgb(&mut l.color);
                ui.add(
                    egui::DragValue::new(&mut l.intensity)
                        .speed(speed)
                        .range(0.0..=1e6)
                        .prefix("intensity "),
                );
            });
            let step = self.scene_radius * 0.005;
            if l.kind == voxgi::scene::LightKind::Directional {
                ui.horizontal(|ui| {
                    ui.label("direction");
                    for c in 0..3 {
                        ui.add(egui::DragValue::new(&mut l.direction[c]).speed(0.01));
                    }
                });
            } else {
                ui.horizontal(|ui| {
                    ui.label("position");
                    for c in 0..3 {
                        ui.add(egui::DragValue::new(&mut l.position[c]).speed(step));
                    }
                });
            }
            if l != *light {
                if l.direction.length_squared() < 1e-8 {
                    l.direction = light.direction;
                }
                if let Err(e) = self.renderer.set_light(i, &l) {
                    self.status = format!("{e}");
                }
            }
        }
    }

    fn stats_ui(&self, ui: &mut egui::Ui) {
        let mean =
            |v: &std::collections::VecDeque<f32>| v.iter().sum::<f32>() / v.len().max(1) as f32;
        let frame = mean(&self.frame_ms);
        ui.label(format!(
            "frame {frame:.1} ms ({:.1} fps)",
            1e3 / frame.max(1e-3)
        ));
        if let Some(c) = self.renderer.last_voxel_counts() {
            ui.label(format!("{} fragments, {} voxels", c.fragments, c.occupied));
        }
        if self.pass_ms.is_empty() {
            ui.label("no GPU timestamps on this adapter");
        }
        // A bar per pass: the mean of the recent frames, and a sparkline of them.
        let max = self
            .pass_ms
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .fold(1e-3f32, f32::max);
        for (name, v) in &self.pass_ms {
            ui.horizontal(|ui| {
                ui.label(
                    egui::RichText::new(format!("{name:<12} {:>7.2} ms", mean(v))).monospace(),
                );
                let (rect, _) =
                    ui.allocate_exact_size(egui::vec2(120.0, 14.0), egui::Sense::hover());
                let painter = ui.painter_at(rect);
                let n = v.len().max(2) as f32;
                let points: Vec<egui::Pos2> = v
                    .iter()
                    .enumerate()
                    .map(|(i, ms)| {
                        egui::pos2(
                            rect.left() + rect.width() * i as f32 / (n - 1.0),
                            rect.bottom() - rect.height() * (ms / max).min(1.0),
                        )
                    })
                    .collect();
                painter.add(egui::Shape::line(
                    points,
                    egui::Stroke::new(1.0, egui::Color32::LIGHT_GREEN),
                ));
            });
        }
        ui.separator();
        let memory = self.renderer.memory();
        let total: u64 = memory.iter().map(|(_, b)| b).sum();
        ui.label(format!("GPU memory {:.1} MiB", total as f64 / 1048576.0));
        for (name, bytes) in memory.iter().filter(|(_, b)| *b >= 1 << 16) {
            ui.label(
                egui::RichText::new(format!(
                    "  {name:<28} {:>8.2} MiB",
                    *bytes as f64 / 1048576.0
                ))
                .monospace()
                .small(),
            );
        }
    }
}

/// Draws the UI over what `view` holds.
fn egui_pass(
    renderer: &egui_wgpu::Renderer,
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
) {
    let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("egui"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    renderer.render(&mut pass.forget_lifetime(), jobs, screen);
}

fn push(v: &mut std::collections::VecDeque<f32>, x: f32) {
    if v.len() == HISTORY {
        v.pop_front();
    }
    v.push_back(x);
}

fn bytemuck_f32(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

fn scene_label(scene: &Scene) -> String {
    if scene.name.is_empty() {
        "scene".into()
    } else {
        scene.name.clone()
    }
}
