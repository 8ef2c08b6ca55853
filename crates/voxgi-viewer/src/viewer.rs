//! The window: device and surface, the voxgi renderer drawing into the surface texture, egui on
//! top, input to the camera controllers, animation playback, screenshots.

use crate::camera::{Fly, Movement, Orbit, render_flags};
use crate::ground_truth::{Display, GroundTruth};
use crate::jobs::{Job, take};
use crate::settings::{frame_ui, options_ui};
use crate::{Args, load};
use anyhow::{Context, Result, anyhow};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
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

/// The 3D view's images, the size of the part of the window right of the panel: what cone
/// tracing drew last (kept to show again while nothing changes) and the frame's view (cone
/// tracing with the path tracer over its columns), copied into the window beside the panel.
struct ViewImages {
    cone: Option<wgpu::Texture>,
    view: Option<wgpu::Texture>,
    /// The frame parameters and scene state (`Viewer::version`) `cone` shows.
    shows: Option<(FrameParams, u64)>,
}

/// A file loaded and its renderer built, off the window's thread.
struct Opened {
    path: PathBuf,
    scene: Scene,
    settings_params: FrameParams,
    options: RendererOptions,
    renderer: Renderer,
}

enum Controller {
    Orbit(Orbit),
    Fly(Fly),
}

/// The settings panel's width, points.
const PANEL_WIDTH: f32 = 370.0;

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
    /// The scene as loaded (at time 0): what new options and the path tracer build from.
    scene: Arc<Scene>,
    /// Counts changes of the scene's state (time, lights): the path tracer follows it.
    version: u64,
    last_time: f32,
    ground: GroundTruth,
    // Background work, each shown in the window while it runs.
    rebuild: Option<Job<(Renderer, RendererOptions)>>,
    opening: Option<Job<Opened>>,
    dialog: Option<Job<Option<PathBuf>>>,
    open_path: String,
    vsync: bool,
    /// The view's images; `None` when the surface cannot be copied into (then every frame
    /// draws the whole window, under the panel too).
    images: Option<ViewImages>,
    /// Where the panel ends, physical pixels from the window's left (0 without the panel):
    /// the 3D view starts there.
    panel_px: u32,
    /// Whether this frame showed the last image again instead of drawing.
    reused: bool,
    /// Degrees the orbit turns each frame (`--turntable`).
    turntable: f32,
    /// The adapter is a CPU driver (lavapipe, WARP): smaller defaults.
    cpu: bool,
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
    /// Frames drawn with nothing in the background (the path tracer built): what
    /// `--after-frames` counts, so a screenshot does not race a build.
    ready_frames: u32,
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
            .unwrap_or(if cpu { (960, 480) } else { (1280, 720) });
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
        // A still view is drawn once into an image and copied into each frame after that.
        let keeps_image = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
        if keeps_image {
            config.usage |= wgpu::TextureUsages::COPY_DST;
        }
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
        let default_camera = scene.default_camera();
        let mut params = FrameParams::new(default_camera.clone());
        if let Some(s) = &settings {
            s.apply(&mut options, &mut params)?;
        }
        let mut renderer = Renderer::new(&device, &queue, &scene, &options)?;
        renderer.enable_timing(timestamps);
        let mut ground = GroundTruth::new(args.display, cpu, timestamps);
        ground.divider = args.divider;
        if let Some(n) = args.paths_per_frame {
            ground.paths_per_frame = n;
            ground.frame_target_ms = None;
        }
        let bounds = scene.swept_bounds();
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
            // The path tracer shows a still scene: play with G's cone tracing.
            playing: duration > 0.0 && args.display == Display::ConeTraced,
            draft: options.clone(),
            options,
            controller: Controller::Orbit(Orbit::from_camera(&default_camera, orbit_distance)),
            params,
            renderer,
            scene: Arc::new(scene),
            version: 0,
            last_time: 0.0,
            ground,
            rebuild: None,
            opening: None,
            dialog: None,
            open_path: String::new(),
            vsync: !args.no_vsync,
            images: keeps_image.then_some(ViewImages {
                cone: None,
                view: None,
                shows: None,
            }),
            panel_px: 0,
            reused: false,
            turntable: args.turntable,
            cpu,
            egui_ctx,
            egui_state,
            egui_renderer,
            keys: HashSet::new(),
            left_down: false,
            right_down: false,
            cursor: None,
            duration,
            time: 0.0,
            last_frame: Instant::now(),
            frame_ms: Default::default(),
            pass_ms: Vec::new(),
            frames: 0,
            ready_frames: 0,
            status: String::new(),
            // A screenshot without the UI is of the whole window.
            show_panel: args.screenshot.is_none() || args.with_ui,
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
            // A release always ends a drag or a held key, even over the panel: swallowed, it
            // would leave the camera turning or flying.
            WindowEvent::MouseInput {
                state: ElementState::Released,
                button,
                ..
            } => match button {
                MouseButton::Left => self.left_down = false,
                MouseButton::Right | MouseButton::Middle => self.right_down = false,
                _ => {}
            },
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Released => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    self.keys.remove(&code);
                }
            }
            _ if response.consumed => {}
            // Presses only: releases were taken above.
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    if !event.repeat {
                        self.key_pressed(code);
                    }
                    self.keys.insert(code);
                }
            }
            WindowEvent::MouseInput { button, .. } => match button {
                MouseButton::Left => self.left_down = true,
                MouseButton::Right | MouseButton::Middle => self.right_down = true,
                _ => {}
            },
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
            KeyCode::KeyG => {
                let i = Display::ALL.iter().position(|d| *d == self.ground.display);
                self.set_display(Display::ALL[(i.unwrap_or(0) + 1) % Display::ALL.len()]);
            }
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

    /// Starts loading the file at `path` (and building its renderer) in the background; when it
    /// is done it replaces the scene. On failure the error shows and the scene stays.
    fn open(&mut self, path: &Path) {
        let path = path.to_path_buf();
        let (device, queue) = (self.device.clone(), self.queue.clone());
        let (options, camera) = (self.options.clone(), self.params.camera.clone());
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        self.opening = Some(Job::spawn(format!("opening {name}"), move || {
            let (mut scene, settings) = load(Some(&path), None)?;
            scene.set_time(0.0);
            let mut options = options;
            let mut params = FrameParams::new(camera);
            if let Some(s) = &settings {
                s.apply(&mut options, &mut params)?;
            }
            let renderer = Renderer::new(&device, &queue, &scene, &options)
                .with_context(|| path.display().to_string())?;
            Ok(Opened {
                path,
                scene,
                settings_params: params,
                options,
                renderer,
            })
        }));
    }

    /// The loaded file replaces the scene.
    fn opened(&mut self, o: Opened) {
        let mut renderer = o.renderer;
        renderer.enable_timing(self.timestamps);
        self.renderer = renderer;
        self.draft = o.options.clone();
        self.options = o.options;
        // The file's view settings (exposure, tone curve, view mode); the camera is framed below.
        self.params = o.settings_params;
        let bounds = o.scene.swept_bounds();
        self.scene_radius = (bounds.size().length() * 0.5).max(1e-3);
        self.duration = o
            .scene
            .animations
            .iter()
            .map(|a| a.duration())
            .fold(0.0f32, f32::max);
        self.time = 0.0;
        self.playing = self.duration > 0.0 && self.ground.display == Display::ConeTraced;
        self.scene_name = scene_label(&o.scene);
        self.cameras = o.scene.cameras.clone();
        self.window
            .set_title(&format!("voxgi — {}", self.scene_name));
        self.scene = Arc::new(o.scene);
        self.version += 1;
        self.ground.clear();
        self.pass_ms.clear();
        self.frame_scene();
        self.status = format!("opened {}", o.path.display());
    }

    /// Applies the draft options: through `Renderer::set_options`, which rebuilds only what the
    /// changed settings feed (a lighting change relights the voxels it has), or, for a setting
    /// that shapes the uploaded scene, by building a new renderer in the background while the
    /// current one draws.
    fn apply(&mut self) {
        if !crate::settings::needs_new_renderer(&self.options, &self.draft) {
            match self.renderer.set_options(&self.draft) {
                Ok(()) => {
                    self.options = self.draft.clone();
                    self.pass_ms.clear();
                    self.version += 1;
                    self.status = "options applied".into();
                }
                Err(e) => self.status = format!("the new options failed: {e:#}"),
            }
            return;
        }
        let (device, queue) = (self.device.clone(), self.queue.clone());
        let (scene, options) = (self.scene.clone(), self.draft.clone());
        self.rebuild = Some(Job::spawn("rebuilding for the new options", move || {
            Ok((Renderer::new(&device, &queue, &scene, &options)?, options))
        }));
    }

    /// The new options' renderer takes over, with the scene's time and the lights as edited.
    fn rebuilt(&mut self, mut renderer: Renderer, options: RendererOptions) {
        renderer.enable_timing(self.timestamps);
        let lights = self.renderer.lights().to_vec();
        if renderer.lights().len() == lights.len() {
            for (i, l) in lights.iter().enumerate() {
                // A light whose kind differs (the default sun switched) keeps the new one's.
                let _ = renderer.set_light(i, l);
            }
        }
        self.renderer = renderer;
        // The path tracer sees the scene's lights, and the default sun when there are none.
        if options.default_light != self.options.default_light {
            self.ground.clear();
        }
        self.options = options;
        self.pass_ms.clear();
        self.version += 1;
        self.status = "options applied".into();
    }

    /// Opens the system's file dialog on its own thread.
    fn open_dialog(&mut self) {
        self.dialog = Some(Job::spawn("waiting for the file dialog", || {
            Ok(rfd::FileDialog::new()
                .set_title("Open a scene")
                .add_filter("scenes", voxgi::scene::io::EXTENSIONS)
                .pick_file())
        }));
    }

    /// Takes the results of finished background work.
    fn poll_jobs(&mut self) {
        match take(&mut self.rebuild) {
            Some(Ok((r, options))) => self.rebuilt(r, options),
            Some(Err(e)) => self.status = format!("the new options failed: {e:#}"),
            None => {}
        }
        match take(&mut self.opening) {
            Some(Ok(o)) => self.opened(o),
            Some(Err(e)) => self.status = format!("{e:#}"),
            None => {}
        }
        match take(&mut self.dialog) {
            Some(Ok(Some(path))) => self.open(&path),
            Some(Ok(None)) => {
                self.status = "no file chosen (the dialog needs xdg-desktop-portal or zenity; \
                               a file dropped onto the window or a path typed above opens too)"
                    .into()
            }
            Some(Err(e)) => self.status = format!("{e:#}"),
            None => {}
        }
    }

    fn set_display(&mut self, display: Display) {
        if display != Display::ConeTraced && self.playing {
            self.playing = false;
            self.status = "paused: the path tracer shows a still scene".into();
        }
        self.ground.display = display;
    }

    /// The 3D view's columns of the window: right of the panel, or all of the window when the
    /// panel is hidden, leaves less than a quarter, or the view cannot be copied beside it.
    fn view_columns(&self) -> (u32, u32) {
        let w = self.config.width;
        let x0 = if self.images.is_some() && self.panel_px * 4 <= w * 3 {
            self.panel_px
        } else {
            0
        };
        (x0, w - x0)
    }

    /// The frame's scene into `surface` (the window's texture, or a capture of it) right of
    /// the panel: cone tracing, with the path tracer over its columns. A cone-traced image that
    /// would come out as the last one (same parameters, same scene, the renderer idle) is
    /// copied from the last instead of drawn, so a still view costs next to nothing. With
    /// `accumulate` false the path tracer only shows what it has (the frame drawn again).
    fn draw_frame(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        surface: &wgpu::Texture,
        accumulate: bool,
    ) -> Result<()> {
        let (w, h, format) = (self.config.width, self.config.height, self.config.format);
        let surface_view = surface.create_view(&Default::default());
        if accumulate {
            self.reused = false;
        }
        if self.images.is_none() {
            return self.draw_scene(
                encoder,
                &Target::new(&surface_view, format, w, h),
                accumulate,
            );
        }
        let (x0, vw) = self.view_columns();
        let stale = self
            .images
            .as_ref()
            .and_then(|i| i.view.as_ref())
            .is_none_or(|t| (t.width(), t.height()) != (vw, h));
        let fresh = stale.then(|| {
            (
                self.image_texture("cone-traced view", format, vw, h),
                self.image_texture("view", format, vw, h),
            )
        });
        if stale {
            log::debug!("view images: {vw}x{h} at column {x0}");
        }
        let images = self.images.as_mut().expect("checked above");
        if let Some((cone, view)) = fresh {
            images.cone = Some(cone);
            images.view = Some(view);
            images.shows = None;
        }
        let cone = images.cone.clone().expect("made above");
        let view = images.view.clone().expect("made above");
        let extent = wgpu::Extent3d {
            width: vw,
            height: h,
            depth_or_array_layers: 1,
        };
        if self.ground.needs_cone_tracing() {
            // Counters that came back may ask for a rebuild: then the renderer is not idle.
            self.renderer.receive_feedback()?;
            let shows = Some((self.params.clone(), self.version));
            let images = self.images.as_mut().expect("checked above");
            if images.shows == shows && self.renderer.is_idle() {
                self.reused |= accumulate;
            } else {
                let v = cone.create_view(&Default::default());
                self.renderer
                    .render(encoder, &Target::new(&v, format, vw, h), &self.params)?;
                images.shows = shows;
            }
            encoder.copy_texture_to_texture(cone.as_image_copy(), view.as_image_copy(), extent);
        }
        let v = view.create_view(&Default::default());
        let r = self.ground.record(
            encoder,
            &Target::new(&v, format, vw, h),
            &self.params,
            self.options.bounces,
            accumulate,
        );
        if let Err(e) = r {
            self.ground.error = Some(format!("{e:#}"));
        }
        if x0 > 0 {
            // Under the panel: black, not whatever the surface held.
            color_pass(
                encoder,
                "clear",
                &surface_view,
                wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            );
        }
        encoder.copy_texture_to_texture(
            view.as_image_copy(),
            wgpu::TexelCopyTextureInfo {
                texture: surface,
                mip_level: 0,
                origin: wgpu::Origin3d { x: x0, y: 0, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            extent,
        );
        Ok(())
    }

    /// The scene into `target`: cone tracing, then the path tracer over its columns. With
    /// `accumulate` false the path tracer only shows what it has (a second drawing of the same
    /// frame, for a screenshot).
    fn draw_scene(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        accumulate: bool,
    ) -> Result<()> {
        if self.ground.needs_cone_tracing() {
            self.renderer.render(encoder, target, &self.params)?;
        }
        let r = self.ground.record(
            encoder,
            target,
            &self.params,
            self.options.bounces,
            accumulate,
        );
        if let Err(e) = r {
            self.ground.error = Some(format!("{e:#}"));
        }
        Ok(())
    }

    /// Draws one frame; returns true when the viewer should close (a screenshot was taken).
    fn redraw(&mut self) -> Result<bool> {
        self.poll_jobs();
        let now = Instant::now();
        let elapsed = (now - self.last_frame).as_secs_f32();
        self.last_frame = now;
        push(&mut self.frame_ms, elapsed * 1e3);
        let tracing_only = self.reused || !self.ground.needs_cone_tracing();
        self.ground.frame_time(elapsed * 1e3, tracing_only);
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
        if let Controller::Orbit(o) = &mut self.controller
            && self.turntable != 0.0
        {
            o.turn(self.turntable.to_radians());
        }
        if self.playing && self.duration > 0.0 {
            self.time = (self.time + dt) % self.duration.max(1e-3);
        }
        self.renderer.set_time(self.time)?;
        if self.time != self.last_time {
            self.last_time = self.time;
            self.version += 1;
            self.ground.scene_changed();
        }
        self.params.camera = match &self.controller {
            Controller::Orbit(o) => o.camera(),
            Controller::Fly(f) => f.camera(),
        };
        self.ground.update(
            &self.device,
            &self.queue,
            &self.scene,
            self.time,
            self.renderer.lights(),
            &self.options,
            self.version,
        );

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
        self.draw_frame(&mut encoder, &frame.texture, true)?;

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
                .is_some_and(|(_, after)| self.ready_frames + 1 >= *after);
        let ui_capture = if capture_ui {
            let texture = self.capture_texture(self.config.format);
            let v = texture.create_view(&Default::default());
            self.draw_frame(&mut encoder, &texture, false)?;
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
        let reference = self.ground.frame_done();
        if self.timestamps {
            let times: Vec<_> = self
                .renderer
                .pass_times()?
                .into_iter()
                .chain(reference)
                .collect();
            for (name, _) in &times {
                if !self.pass_ms.iter().any(|(n, _)| n == name) {
                    self.pass_ms.push((name, Default::default()));
                }
            }
            // A pass that did not run this frame (the voxel passes of a still scene) took 0 ms
            // of it: the means are per frame, not per run.
            for (name, v) in &mut self.pass_ms {
                let ms = times
                    .iter()
                    .find(|(n, _)| n == name)
                    .map_or(0.0, |(_, ms)| *ms);
                push(v, ms as f32);
            }
        }
        self.frames += 1;
        let busy = self.rebuild.is_some()
            || self.opening.is_some()
            || (self.ground.display != Display::ConeTraced && self.ground.building());
        if !busy {
            self.ready_frames += 1;
        }

        if actions.revert {
            self.draft = self.options.clone();
        }
        if actions.apply {
            self.apply();
        }
        if actions.open_dialog {
            self.open_dialog();
        }
        if let Some(path) = actions.open.take() {
            self.open(&path);
        }
        if let Some(d) = actions.display {
            self.set_display(d);
        }
        let present_mode = if self.vsync {
            wgpu::PresentMode::AutoVsync
        } else {
            wgpu::PresentMode::AutoNoVsync
        };
        if present_mode != self.config.present_mode {
            self.config.present_mode = present_mode;
            self.surface.configure(&self.device, &self.config);
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
            && self.ready_frames >= *after
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
            if self.ground.display != Display::ConeTraced {
                eprintln!("{}", self.ground.label());
            }
            return Ok(true);
        }
        Ok(false)
    }
    /// An image the view is drawn into, copied from and read back (screenshots, the view's
    /// cone-traced and composed images).
    fn image_texture(
        &self,
        label: &str,
        format: wgpu::TextureFormat,
        w: u32,
        h: u32,
    ) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    }

    /// An image the size of the window to capture a frame into.
    fn capture_texture(&self, format: wgpu::TextureFormat) -> wgpu::Texture {
        self.image_texture("screenshot", format, self.config.width, self.config.height)
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
        // The frame as shown right of the panel.
        if let Some(view) = self.images.as_ref().and_then(|i| i.view.clone()) {
            return self.save_texture(&view, path);
        }
        let (w, h) = (self.config.width, self.config.height);
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let texture = self.capture_texture(format);
        let view = texture.create_view(&Default::default());
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.draw_scene(&mut encoder, &Target::new(&view, format, w, h), false)?;
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
        self.overlays_ui(ui);
        if !self.show_panel {
            self.panel_px = 0;
            return actions;
        }
        // A fixed width: a panel that followed its content would resize the 3D view (and
        // restart the path tracer) whenever a label grew.
        let panel = egui::Panel::left("settings")
            .exact_size(PANEL_WIDTH)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    ui.heading(&self.scene_name);
                    ui.label(format!(
                        "{} ({:?})",
                        self.adapter.name, self.adapter.backend
                    ));
                    ui.label(
                        "drag: orbit · right-drag: pan · wheel: zoom · F: fly (WASD/QE, drag \
                         to look) · H: frame · G: path tracer / split · Space: play · \
                         P: screenshot · Tab: panel",
                    );
                    ui.horizontal(|ui| {
                        if ui.button("Open…").clicked() {
                            actions.open_dialog = true;
                        }
                        let edit = ui.add(
                            egui::TextEdit::singleline(&mut self.open_path)
                                .hint_text("or a path, then Enter")
                                .desired_width(150.0),
                        );
                        let enter =
                            edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                        if enter && !self.open_path.trim().is_empty() {
                            actions.open = Some(PathBuf::from(self.open_path.trim()));
                        }
                    });
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
                    egui::CollapsingHeader::new("ground truth")
                        .default_open(true)
                        .show(ui, |ui| {
                            if let Some(d) = self.ground_ui(ui) {
                                actions.display = Some(d);
                            }
                        });
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
        let ppp = ui.ctx().pixels_per_point();
        let right = panel.response.rect.right() - ui.ctx().content_rect().left();
        self.panel_px = ((right * ppp).round().max(0.0) as u32).min(self.config.width);
        actions
    }

    /// The path tracer's controls: what the window shows, the divider, samples per frame.
    fn ground_ui(&mut self, ui: &mut egui::Ui) -> Option<Display> {
        let mut pick = None;
        ui.horizontal(|ui| {
            for d in Display::ALL {
                if ui
                    .selectable_label(self.ground.display == d, d.name())
                    .clicked()
                {
                    pick = Some(d);
                }
            }
        });
        if self.ground.display == Display::Split {
            ui.add(egui::Slider::new(&mut self.ground.divider, 0.0..=1.0).text("divider"));
        }
        ui.add(
            egui::Slider::new(&mut self.ground.samples_per_frame, 1..=64)
                .logarithmic(true)
                .text("samples per frame"),
        );
        let mut auto = self.ground.frame_target_ms.is_some();
        ui.horizontal(|ui| {
            ui.add_enabled(
                !auto,
                egui::Slider::new(&mut self.ground.paths_per_frame, 1 << 10..=1 << 26)
                    .logarithmic(true)
                    .text("paths a frame"),
            );
            ui.checkbox(&mut auto, "auto");
        });
        match (auto, self.ground.frame_target_ms) {
            (true, None) => {
                self.ground.frame_target_ms = Some(crate::ground_truth::default_target_ms(self.cpu))
            }
            (false, Some(_)) => self.ground.frame_target_ms = None,
            _ => {}
        }
        if let Some(t) = &mut self.ground.frame_target_ms {
            ui.add(
                egui::Slider::new(t, 1.0..=2000.0)
                    .logarithmic(true)
                    .text("ms of tracing a frame"),
            );
        }
        ui.add(
            egui::Slider::new(&mut self.ground.max_samples, 16..=65536)
                .logarithmic(true)
                .text("stop at spp"),
        );
        if self.ground.display != Display::ConeTraced {
            ui.label(self.ground.label());
            if self.params.view != voxgi::ViewMode::Final {
                ui.label("(the path tracer shows the final image in every view mode)");
            }
        }
        pick
    }

    /// Over the image: what runs in the background, the split view's divider and the names of
    /// its sides.
    fn overlays_ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let mut running: Vec<String> = Vec::new();
        if let Some(job) = &self.rebuild {
            running.push(job.label());
        }
        if let Some(job) = &self.opening {
            running.push(job.label());
        }
        if let Some(job) = &self.dialog {
            running.push(job.label());
        }
        if self.ground.display != Display::ConeTraced
            && let Some(l) = self.ground.job_label()
        {
            running.push(l);
        }
        if !running.is_empty() {
            egui::Area::new(egui::Id::unique("jobs"))
                .anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0])
                .show(&ctx, |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        for r in &running {
                            ui.horizontal(|ui| {
                                ui.spinner();
                                ui.label(r);
                            });
                        }
                    });
                });
        }
        let screen = ctx.content_rect();
        let caption = |ui: &mut egui::Ui, text: String| {
            egui::Frame::popup(ui.style()).show(ui, |ui| ui.label(text));
        };
        match self.ground.display {
            Display::ConeTraced => {}
            Display::PathTraced => {
                let text = self.ground.label();
                egui::Area::new(egui::Id::unique("path traced"))
                    .anchor(egui::Align2::RIGHT_BOTTOM, [-8.0, -8.0])
                    .show(&ctx, |ui| caption(ui, text));
            }
            Display::Split => {
                let ppp = ctx.pixels_per_point();
                let (x0, vw) = self.view_columns();
                let (left, width) = (screen.left() + x0 as f32 / ppp, vw as f32 / ppp);
                let x = left + width * self.ground.divider;
                let text = self.ground.label();
                egui::Area::new(egui::Id::unique("path traced"))
                    .anchor(egui::Align2::RIGHT_BOTTOM, [-8.0, -8.0])
                    .show(&ctx, |ui| caption(ui, text));
                egui::Area::new(egui::Id::unique("cone traced"))
                    .pivot(egui::Align2::RIGHT_BOTTOM)
                    .fixed_pos(egui::pos2(x - 12.0, screen.bottom() - 8.0))
                    .show(&ctx, |ui| caption(ui, "cone traced".into()));
                // The divider: a line with a handle, dragged sideways.
                let response = egui::Area::new(egui::Id::unique("divider"))
                    .fixed_pos(egui::pos2(x - 6.0, screen.top()))
                    .movable(false)
                    .show(&ctx, |ui| {
                        let (rect, response) = ui.allocate_exact_size(
                            egui::vec2(12.0, screen.height()),
                            egui::Sense::drag(),
                        );
                        let painter = ui.painter();
                        let stroke = egui::Stroke::new(2.0, egui::Color32::WHITE);
                        painter.line_segment([rect.center_top(), rect.center_bottom()], stroke);
                        painter.circle(rect.center(), 7.0, egui::Color32::from_gray(40), stroke);
                        response.on_hover_cursor(egui::CursorIcon::ResizeHorizontal)
                    })
                    .inner;
                if response.dragged() {
                    let moved = response.drag_delta().x / width.max(1.0);
                    self.ground.divider = (self.ground.divider + moved).clamp(0.0, 1.0);
                }
            }
        }
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
            // Only what the user changed counts: the colour button rounds its value through
            // HSV when first shown, which is not an edit.
            let mut changed = false;
            ui.horizontal(|ui| {
                changed |= ui.color_edit_button_rgb(&mut l.color).changed();
                changed |= ui
                    .add(
                        egui::DragValue::new(&mut l.intensity)
                            .speed(speed)
                            .range(0.0..=1e6)
                            .prefix("intensity "),
                    )
                    .changed();
            });
            let step = self.scene_radius * 0.005;
            if l.kind == voxgi::scene::LightKind::Directional {
                ui.horizontal(|ui| {
                    ui.label("direction");
                    for c in 0..3 {
                        changed |= ui
                            .add(egui::DragValue::new(&mut l.direction[c]).speed(0.01))
                            .changed();
                    }
                });
            } else {
                ui.horizontal(|ui| {
                    ui.label("position");
                    for c in 0..3 {
                        changed |= ui
                            .add(egui::DragValue::new(&mut l.position[c]).speed(step))
                            .changed();
                    }
                });
            }
            if changed && l != *light {
                if l.direction.length_squared() < 1e-8 {
                    l.direction = light.direction;
                }
                // The path tracer takes the edit from `renderer.lights()` in its next update.
                match self.renderer.set_light(i, &l) {
                    Ok(()) => self.ground.scene_changed(),
                    Err(e) => self.status = format!("{e}"),
                }
            }
        }
    }

    fn stats_ui(&mut self, ui: &mut egui::Ui) {
        let mean =
            |v: &std::collections::VecDeque<f32>| v.iter().sum::<f32>() / v.len().max(1) as f32;
        let frame = mean(&self.frame_ms);
        ui.label(format!(
            "frame {frame:.1} ms ({:.1} fps)",
            1e3 / frame.max(1e-3)
        ));
        if self.reused {
            ui.label("cone tracing: nothing changed, the last image is shown again");
        }
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
        ui.checkbox(&mut self.vsync, "vsync");
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
    let pass = color_pass(encoder, "egui", view, wgpu::LoadOp::Load);
    renderer.render(&mut pass.forget_lifetime(), jobs, screen);
}

/// A render pass into `view` alone, loading or clearing it.
fn color_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
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
