//! The window: the winit application (`App`), and the `Viewer` it hands events to, with its
//! fields and its creation. The viewer's work is spread over the child modules by job:
//! `surface` (the device, the surface's configuration, resizing), `input` (keys and mouse to the
//! camera controllers), `frame` (a frame's steps, the scene and the split view drawn into the
//! window), `screenshot`, `panel` (the egui panel and the overlays), `toasts` (messages over the
//! view), `stats` (frame and per-pass
//! times) and `open` (opening scenes, applying options, and the background work for both).

mod budget;
mod export;
mod frame;
mod gizmos;
mod grid;
mod input;
mod open;
mod panel;
mod pieces;
mod save;
mod screenshot;
mod starting;
mod stats;
mod surface;
mod toasts;
mod upscale;

use crate::Args;
use crate::camera::Orbit;
use crate::ground_truth::{Display, GroundTruth};
use crate::jobs::Job;
use anyhow::Result;
use input::{Controller, Input};
use open::{Handover, Opened};
use pieces::{Pieces, Step};
use starting::Starting;
use stats::Stats;
use std::path::PathBuf;
use std::sync::Arc;
use voxgi::scene::Scene;
use voxgi::{FrameParams, Renderer, RendererOptions, SceneSettings, wgpu};
use winit::application::ApplicationHandler;
use winit::event::StartCause;
use winit::event::{DeviceEvent, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow};
use winit::window::{Window, WindowId};

/// The winit application: opens the window on `resumed`, then hands events to the `Viewer`.
pub struct App {
    args: Args,
    scene: Option<(Scene, Option<SceneSettings>)>,
    /// The window while its first renderer is made.
    starting: Option<Starting>,
    viewer: Option<Viewer>,
    error: Option<anyhow::Error>,
}

impl App {
    pub fn new(args: Args, scene: (Scene, Option<SceneSettings>)) -> Self {
        App {
            args,
            scene: Some(scene),
            starting: None,
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

    /// An event while the renderer is made: the progress frame, a resize, closing; the viewer
    /// once the renderer is there.
    fn starting_event(&mut self, event_loop: &ActiveEventLoop, event: WindowEvent) {
        let Some(s) = self.starting.as_mut() else {
            return;
        };
        let _ = s.egui_state.on_window_event(&s.gpu.window, &event);
        match event {
            WindowEvent::KeyboardInput { .. } => s.keys.push(event),
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => s.resize(size),
            WindowEvent::RedrawRequested => {
                if s.pieces.is_none()
                    && let Some(made) = s.job.poll()
                {
                    match made.and_then(|mut r| {
                        let pieces = Pieces::new(&mut r, &s.params)?;
                        Ok((r, pieces))
                    }) {
                        Ok(p) => s.pieces = Some(p),
                        Err(e) => return self.fail(event_loop, e),
                    }
                }
                let name = scene_label(&s.scene);
                let label = match &mut s.pieces {
                    None => s.job.label(),
                    Some((renderer, pieces)) => {
                        match pieces.step(renderer, &s.gpu.queue, &s.params) {
                            Ok(Step::Done) => return self.take_over(event_loop),
                            Ok(Step::Submitted | Step::Waiting) => {}
                            Err(e) => return self.fail(event_loop, e.into()),
                        }
                        let compiling = if s.gpu.cpu {
                            " (the CPU driver compiles each shader as it first runs, once per \
                             machine)"
                        } else {
                            ""
                        };
                        format!(
                            "voxelizing the scene and lighting the voxels: {}{compiling} …",
                            pieces.progress()
                        )
                    }
                };
                if let Err(e) = s.redraw(&name, &label) {
                    self.fail(event_loop, e);
                }
            }
            _ => {}
        }
    }
}

impl App {
    /// The renderer made and its first voxel work submitted: the viewer takes the window.
    fn take_over(&mut self, event_loop: &ActiveEventLoop) {
        let Some(mut s) = self.starting.take() else {
            return;
        };
        let Some((renderer, _)) = s.pieces.take() else {
            return;
        };
        let keys = std::mem::take(&mut s.keys);
        match Viewer::new(&self.args, s, renderer).and_then(|mut v| {
            for k in keys {
                v.window_event(event_loop, k)?;
            }
            Ok(v)
        }) {
            Ok(v) => {
                v.window.request_redraw();
                self.viewer = Some(v);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.viewer.is_some() || self.starting.is_some() {
            return;
        }
        let Some(scene) = self.scene.take() else {
            return;
        };
        match Viewer::start(event_loop, &self.args, scene) {
            Ok(s) => self.starting = Some(s),
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn new_events(&mut self, _: &ActiveEventLoop, cause: StartCause) {
        // While the renderer is made, a progress frame ten times a second (`about_to_wait`).
        if let Some(s) = &self.starting
            && matches!(
                cause,
                StartCause::ResumeTimeReached { .. } | StartCause::Init
            )
        {
            s.gpu.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        if self.starting.is_some() {
            return self.starting_event(event_loop, event);
        }
        let Some(v) = self.viewer.as_mut() else {
            return;
        };
        // A lost device fails whatever comes next in ways that do not say so: name the loss.
        let result = match v.watch.check() {
            Ok(()) => v.window_event(event_loop, event),
            Err(lost) => Err(lost.into()),
        };
        match result {
            Ok(()) => {}
            Err(e) => {
                let e = match v.watch.check() {
                    Err(lost) => anyhow::Error::from(lost),
                    Ok(()) => e,
                };
                self.fail(event_loop, e)
            }
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: winit::event::DeviceId, event: DeviceEvent) {
        if let (Some(v), DeviceEvent::MouseMotion { delta }) = (self.viewer.as_mut(), event) {
            v.mouse_motion(delta.0 as f32, delta.1 as f32);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(s) = &self.starting {
            if s.pieces.is_some() {
                // The voxel work's passes, one a frame, as fast as the GPU takes them.
                event_loop.set_control_flow(ControlFlow::Wait);
                s.gpu.window.request_redraw();
            } else {
                // Not every loop: the thread making the renderer needs the CPU more.
                event_loop.set_control_flow(ControlFlow::WaitUntil(
                    std::time::Instant::now() + std::time::Duration::from_millis(100),
                ));
            }
        } else if let Some(v) = &self.viewer {
            event_loop.set_control_flow(ControlFlow::Wait);
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

struct Viewer {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: wgpu::AdapterInfo,
    timestamps: bool,
    /// Whether the device was lost: the window then closes with `Error::DeviceLost`.
    watch: voxgi::gpu::lost::DeviceWatch,
    renderer: Renderer,
    /// The scene as loaded (at time 0): what new options and the path tracer build from.
    scene: Arc<Scene>,
    /// Counts changes of the scene's state (time, lights): the path tracer follows it.
    version: u64,
    last_time: f32,
    ground: GroundTruth,
    // Background work, each shown in the window while it runs.
    rebuild: Option<Job<(Renderer, RendererOptions)>>,
    /// Counts the scenes opened: a renderer made for new options of an earlier scene is not
    /// taken when it arrives (`rebuild_scene`, the scene it was made for).
    scene_generation: u64,
    rebuild_scene: u64,
    opening: Option<Job<Opened>>,
    handover: Option<Handover>,
    /// A file being written (an export): the message to show when it is done.
    saving: Option<Job<String>>,
    export_dialog: export::ExportDialog,
    export: Option<export::Export>,
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
    /// The centre of the scene's bounds (with every pose of its animations).
    scene_center: glam::Vec3,
    /// The light the gizmos selected (H frames it).
    selected_light: Option<usize>,
    /// Whether the light gizmos are drawn.
    show_gizmos: bool,
    /// The grid's height (`grid::height`).
    scene_floor: f32,
    grid: grid::GridPass,
    /// The moving view's resolution, and the pass that stretches it over the view.
    scale: budget::Scale,
    upscale: upscale::UpscalePass,
    /// The last frame drew a view that moved (the camera, the scene).
    moving: bool,
    /// Frames cone tracing accumulated of the view as it is now (0 after any change), and
    /// how many it accumulates before it holds the image (`still_cap`).
    still_frames: u32,
    still_cap: u32,
    /// The frame parameters and scene state the last frame drew.
    last_view: Option<(FrameParams, u64)>,
    show_grid: bool,
    /// The scene's own cameras, to pick from, and the bookmarks from `first_bookmark` on
    /// (the scene file's `[[view]]`s and those added).
    cameras: Vec<voxgi::scene::Camera>,
    first_bookmark: usize,
    /// Where the view is saved.
    source: Option<save::Source>,
    /// The settings when the scene was opened: saving writes those changed since.
    opened_options: (RendererOptions, FrameParams),
    options: RendererOptions,
    draft: RendererOptions,
    params: FrameParams,
    controller: Controller,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    input: Input,
    // Animation.
    duration: f32,
    time: f32,
    playing: bool,
    /// The view follows the scene's animated camera (until the user moves the view).
    fly_along: bool,
    /// The controller's camera as following set it last frame: another one means the user
    /// moved the view.
    flown: Option<voxgi::scene::Camera>,
    // Stats.
    stats: Stats,
    frames: u32,
    /// Frames drawn with nothing in the background (the path tracer built): what
    /// `--after-frames` counts, so a screenshot does not race a build.
    ready_frames: u32,
    /// Messages over the 3D view.
    toasts: toasts::Toasts,
    /// The frame time shown over the 3D view.
    frame_overlay: bool,
    show_panel: bool,
    // Screenshots.
    screenshot: Option<(PathBuf, u32)>,
    screenshot_ui: bool,
    screenshot_key: bool,
    /// When the window opened, until the first frame is shown.
    opened: Option<std::time::Instant>,
}

impl Viewer {
    /// Opens the window and starts making the renderer for `scene` on a thread.
    fn start(
        event_loop: &ActiveEventLoop,
        args: &Args,
        (scene, settings): (Scene, Option<SceneSettings>),
    ) -> Result<Starting> {
        let gpu = surface::open_window(event_loop, args, &scene_label(&scene))?;
        let opened = std::time::Instant::now();
        let cpu = gpu.cpu;
        let mut options = RendererOptions::interactive(cpu);
        let mut scene = scene;
        scene.set_time(0.0);
        let mut params = FrameParams::new(scene.default_camera());
        if let Some(s) = &settings {
            s.apply(&mut options, &mut params)?;
        }
        let scene = Arc::new(scene);
        let job = {
            let (device, queue) = (gpu.device.clone(), gpu.queue.clone());
            let (scene, options) = (scene.clone(), options.clone());
            Job::spawn(
                "uploading the scene and building the pipelines",
                move || Ok(Renderer::new(&device, &queue, &scene, &options)?),
            )
        };
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &gpu.window,
            Some(gpu.window.scale_factor() as f32),
            None,
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(
            &gpu.device,
            gpu.config.format,
            egui_wgpu::RendererOptions::default(),
        );
        Ok(Starting {
            gpu,
            scene,
            options,
            params,
            job,
            pieces: None,
            stats: Stats::new(),
            egui_ctx,
            egui_state,
            egui_renderer,
            opened,
            keys: Vec::new(),
        })
    }

    /// The viewer over `renderer`, made for what `start` opened.
    fn new(args: &Args, start: Starting, mut renderer: Renderer) -> Result<Self> {
        let Starting {
            gpu,
            scene,
            options,
            params,
            egui_ctx,
            egui_state,
            egui_renderer,
            opened,
            stats,
            ..
        } = start;
        log::info!(
            "renderer made and its first voxel work submitted {:.2} s after the window opened",
            opened.elapsed().as_secs_f32()
        );
        let surface::Gpu {
            window,
            surface,
            config,
            device,
            queue,
            info,
            cpu,
            timestamps,
            keeps_image,
            watch,
        } = gpu;
        let default_camera = scene.default_camera();
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
        let duration = scene.duration();
        let panel_px = if args.screenshot.is_none() || args.with_ui {
            let scale = window.scale_factor() as f32;
            let points = window.inner_size().width as f32 / scale;
            ((panel::panel_width(points) * scale).round() as u32).min(window.inner_size().width)
        } else {
            0
        };
        let orbit_distance = (bounds.center() - default_camera.position)
            .length()
            .max(radius * 0.1);
        let export_dialog = export::ExportDialog::new(cpu, &scene_label(&scene));
        let grid = grid::GridPass::new(&device, config.format);
        let upscale = upscale::UpscalePass::new(&device, config.format);
        Ok(Viewer {
            window,
            surface,
            config,
            device,
            queue,
            adapter: info,
            timestamps,
            watch,
            scene_name: scene_label(&scene),
            scene_radius: radius,
            scene_center: bounds.center(),
            selected_light: None,
            show_gizmos: true,
            scene_floor: grid::height(&scene),
            grid,
            // A screenshot is of the view at full resolution, frame after frame.
            scale: budget::Scale::new(cpu, args.screenshot.is_none()),
            upscale,
            moving: false,
            still_frames: 0,
            still_cap: still_cap(cpu, args.screenshot.is_some()),
            last_view: None,
            // Like the panel: in the window and in screenshots of it, not in those of the scene.
            show_grid: args.screenshot.is_none() || args.with_ui || args.grid,
            cameras: scene.cameras.clone(),
            first_bookmark: scene.cameras.len() - save::views_in(args.scene.as_deref()),
            source: save::source(args.scene.as_deref(), args.builtin.as_deref()),
            opened_options: (options.clone(), params.clone()),
            // The path tracer shows a still scene: play with G's cone tracing.
            playing: duration > 0.0 && args.display == Display::ConeTraced,
            fly_along: scene.camera_is_animated(0),
            flown: None,
            draft: options.clone(),
            options,
            controller: Controller::Orbit(Orbit::from_camera(&default_camera, orbit_distance)),
            params,
            renderer,
            scene,
            version: 0,
            last_time: 0.0,
            ground,
            rebuild: None,
            scene_generation: 0,
            rebuild_scene: 0,
            opening: None,
            handover: None,
            saving: None,
            export_dialog,
            export: None,
            dialog: None,
            open_path: String::new(),
            vsync: !args.no_vsync,
            images: keeps_image.then_some(ViewImages {
                cone: None,
                view: None,
                shows: None,
            }),
            // Its width is fixed: known before the first frame lays it out, so that input
            // arriving earlier (a wheel over where it will be) is the panel's too.
            panel_px,
            reused: false,
            turntable: args.turntable,
            cpu,
            egui_ctx,
            egui_state,
            egui_renderer,
            input: Input::default(),
            duration,
            time: 0.0,
            stats,
            frames: 0,
            ready_frames: 0,
            toasts: Default::default(),
            frame_overlay: false,
            // A screenshot without the UI is of the whole window.
            show_panel: args.screenshot.is_none() || args.with_ui,
            screenshot: args
                .screenshot
                .clone()
                .map(|p| (p, args.after_frames.max(1))),
            screenshot_ui: args.with_ui,
            screenshot_key: false,
            opened: Some(opened),
        })
    }
}

fn scene_label(scene: &Scene) -> String {
    if scene.name.is_empty() {
        "scene".into()
    } else {
        scene.name.clone()
    }
}

/// Frames a still view accumulates before the image is held. On a CPU driver each is half a
/// second of Sponza, and input waits for the one in flight: 64 (the anti-aliasing and the
/// area lights' sampled shadows have mostly converged by then) keep that to half a minute
/// after each change instead of two; a GPU, and a screenshot that asks for its frames,
/// accumulate as many as the renderer does.
fn still_cap(cpu: bool, screenshot: bool) -> u32 {
    if cpu && !screenshot {
        64
    } else {
        voxgi::TEMPORAL_STILL_FRAMES
    }
}
