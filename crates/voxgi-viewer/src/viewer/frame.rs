//! A frame and the split view: the frame's steps (`redraw`), the scene drawn into the window
//! right of the panel (cone tracing, with the path tracer over its columns, or the last image
//! again when nothing changed), the UI laid out and drawn over it, and presenting.

use super::Viewer;
use super::input::Controller;
use crate::camera::{Fly, Orbit};
use crate::ground_truth::Display;
use crate::settings::PanelActions;
use anyhow::Result;
use voxgi::{Target, wgpu};

/// The frame's UI, laid out and its textures and buffers uploaded: what the egui passes draw,
/// and what is left to hand over once they are recorded.
pub(super) struct UiFrame {
    pub(super) jobs: Vec<egui::ClippedPrimitive>,
    pub(super) screen: egui_wgpu::ScreenDescriptor,
    /// Command buffers from egui's `update_buffers`, submitted before the frame's encoder.
    extra: Vec<wgpu::CommandBuffer>,
    /// The frame's texture changes: the new ones uploaded, the ones egui is done with freed
    /// after the passes are recorded.
    textures: egui::TexturesDelta,
}

impl Viewer {
    /// Draws one frame; returns true when the viewer should close (a screenshot was taken).
    pub(super) fn redraw(&mut self) -> Result<bool> {
        self.poll_jobs();
        let dt = self.time_frame();
        self.move_camera();
        self.update_scene(dt)?;

        let Some(frame) = self.surface_texture()? else {
            return Ok(false);
        };
        let view = frame.texture.create_view(&Default::default());
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.draw_frame(&mut encoder, &frame.texture, true)?;
        if let Err(e) = self.export_frame(&mut encoder) {
            self.toasts.error(format!("{e:#}"));
        }

        // The UI, drawn over the image.
        let (ui, actions) = self.run_ui(&mut encoder);
        egui_pass(
            &self.egui_renderer,
            &mut encoder,
            &view,
            &ui.jobs,
            &ui.screen,
        );
        let mut ui = ui;
        let extra = std::mem::take(&mut ui.extra);
        self.present(encoder, extra, frame);
        let busy = self.running().join(", ");
        self.stats.presented(&busy);
        if let Err(e) = self.export_done() {
            self.toasts.error(format!("{e:#}"));
        }
        // After the frame's submission: a second drawing in the frame's own encoder ended the
        // renderer's GPU timer frame before its queries were submitted, and wgpu panicked.
        let ui_capture = self.capture_with_ui(&ui)?;
        for id in &ui.textures.free {
            self.egui_renderer.free_texture(id);
        }
        if let Some(t) = self.opened.take() {
            log::info!(
                "first frame shown {:.2} s after the window opened",
                t.elapsed().as_secs_f32()
            );
        }
        self.record_pass_times()?;
        self.count_frame();

        self.act(actions);
        self.follow_vsync();
        self.take_screenshots(ui_capture)
    }

    /// Times the frame (for the stats and the path tracer's budget); returns the time step
    /// for the camera and the animation.
    fn time_frame(&mut self) -> f32 {
        let elapsed = self.stats.frame_started();
        self.scale.frame(elapsed * 1e3, self.moving);
        let tracing_only = self.reused || !self.ground.needs_cone_tracing();
        self.ground.frame_time(elapsed * 1e3, tracing_only);
        // Slow frames do not make the animation or the fly camera jump.
        elapsed.min(0.25)
    }

    /// The scene's state for this frame: the animation played `dt` seconds on, the renderer
    /// at its time, the controller's camera, and the path tracer following them.
    fn update_scene(&mut self, dt: f32) -> Result<()> {
        if self.playing && self.duration > 0.0 {
            self.time = (self.time + dt) % self.duration.max(1e-3);
        }
        self.renderer.set_time(self.time)?;
        if self.time != self.last_time {
            self.last_time = self.time;
            self.version += 1;
            self.ground.scene_changed();
        }
        self.params.camera = self.flown_camera();
        self.ground.update(
            &self.device,
            &self.queue,
            &self.scene,
            self.time,
            self.renderer.lights(),
            &self.options,
            self.version,
        );
        Ok(())
    }

    /// The frame's camera: the scene's animated camera at this time while the view follows
    /// it, else the controller's. Following keeps the controller at the animated camera, so
    /// that moving the view (a drag, a key, a preset) starts from where the flight was, and
    /// ends following.
    fn flown_camera(&mut self) -> voxgi::scene::Camera {
        let animated = self.scene.camera_is_animated(0);
        if self
            .flown
            .as_ref()
            .is_some_and(|c| *c != self.controller_camera())
        {
            self.fly_along = false;
        }
        let cam = self
            .scene
            .camera_at(0, self.time)
            .filter(|_| animated && self.fly_along);
        let Some(cam) = cam else {
            self.flown = None;
            return self.controller_camera();
        };
        self.controller = match &self.controller {
            Controller::Orbit(_) => Controller::Orbit(Orbit::from_camera(&cam, self.scene_radius)),
            Controller::Fly(f) => Controller::Fly(Fly::from_camera(&cam, f.speed)),
        };
        self.flown = Some(self.controller_camera());
        cam
    }

    /// Runs the panel for this frame's input and uploads what egui needs to draw it (texture
    /// updates, and buffers recorded into `encoder`); returns that and what the panel asked for.
    fn run_ui(&mut self, encoder: &mut wgpu::CommandEncoder) -> (UiFrame, PanelActions) {
        let (w, h) = (self.config.width, self.config.height);
        let mut raw = self.egui_state.take_egui_input(&self.window);
        self.input.batch_taken();
        // At a GPU's frame rate egui's easing of the wheel is smooth; at a CPU driver's it
        // drags on for seconds.
        if self.stats.frame_ms.back().is_some_and(|&ms| ms > 50.0) {
            let line = self.egui_ctx.options(|o| o.input_options.line_scroll_speed);
            let page = h as f32 / self.egui_ctx.pixels_per_point();
            super::input::wheel_at_once(&mut raw.events, line, page);
        }
        log::trace!("egui input at {:?}: {:?}", raw.time, raw.events);
        let ctx = self.egui_ctx.clone();
        let mut actions = PanelActions::default();
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
        let extra =
            self.egui_renderer
                .update_buffers(&self.device, &self.queue, encoder, &jobs, &screen);
        let ui = UiFrame {
            jobs,
            screen,
            extra,
            textures: full.textures_delta,
        };
        (ui, actions)
    }

    /// Submits the frame's work (egui's buffer updates first) and presents it.
    fn present(
        &mut self,
        encoder: wgpu::CommandEncoder,
        extra: Vec<wgpu::CommandBuffer>,
        frame: wgpu::SurfaceTexture,
    ) {
        self.queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        self.window.pre_present_notify();
        self.queue.present(frame);
    }

    /// What runs in the background, for the window's indicator and the frame-gap log.
    pub(super) fn running(&self) -> Vec<String> {
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
        if let Some(h) = &self.handover {
            running.push(h.label());
        }
        running.extend(self.export_label());
        if let Some(job) = &self.saving {
            running.push(job.label());
        }
        if self.ground.display != Display::ConeTraced
            && let Some(l) = self.ground.job_label()
        {
            running.push(l);
        }
        running
    }

    /// Counts the frame, and as ready when nothing ran in the background.
    fn count_frame(&mut self) {
        self.frames += 1;
        let busy = self.rebuild.is_some()
            || self.opening.is_some()
            || self.handover.is_some()
            || self.export.is_some()
            || self.saving.is_some()
            || (self.ground.display != Display::ConeTraced && self.ground.building());
        if !busy {
            self.ready_frames += 1;
        }
    }

    pub(super) fn set_display(&mut self, display: Display) {
        if display != Display::ConeTraced && self.playing {
            self.playing = false;
            self.toasts
                .info("paused: the path tracer shows a still scene");
        }
        if display != self.ground.display {
            log::info!("display: {display:?}");
        }
        self.ground.display = display;
    }

    /// The 3D view's columns of the window: right of the panel, or all of the window when the
    /// panel is hidden, leaves less than a quarter, or the view cannot be copied beside it.
    pub(super) fn view_columns(&self) -> (u32, u32) {
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
    pub(super) fn draw_frame(
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
            if self.export.is_some() {
                // The export has the renderer; nothing holds the last image to show.
                return Ok(());
            }
            self.draw_scene(
                encoder,
                &Target::new(&surface_view, format, w, h),
                accumulate,
            )?;
            if self.show_grid && self.ground.needs_cone_tracing() {
                self.draw_grid(encoder, &surface_view, (w, h), (w, h));
            }
            return Ok(());
        }
        let (x0, vw) = self.view_columns();
        // Cone tracing draws at the moving view's fraction of the view (`budget`).
        let (cw, ch) = super::budget::scaled(vw, h, self.scale.value());
        let images = self.images.as_ref().expect("checked above");
        let size = |t: &Option<wgpu::Texture>| t.as_ref().map(|t| (t.width(), t.height()));
        let view_stale = size(&images.view) != Some((vw, h));
        let cone_stale = size(&images.cone) != Some((cw, ch));
        let view_image = view_stale.then(|| self.image_texture("view", format, vw, h));
        let cone_image = cone_stale.then(|| self.image_texture("cone-traced view", format, cw, ch));
        if view_stale || cone_stale {
            log::debug!("view images: {vw}x{h} at column {x0}, cone traced at {cw}x{ch}");
        }
        let images = self.images.as_mut().expect("checked above");
        if let Some(view) = view_image {
            images.view = Some(view);
            images.shows = None;
        }
        if let Some(cone) = cone_image {
            images.cone = Some(cone);
            images.shows = None;
        }
        let cone = images.cone.clone().expect("made above");
        let view = images.view.clone().expect("made above");
        let view_v = view.create_view(&Default::default());
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
            // While an export has the renderer, the view shows its last image.
            let exporting = self.export.is_some() && images.shows.is_some();
            if accumulate {
                // Against the last frame's view, not the image's (a new size forgets that).
                let last = self.last_view.replace(shows.clone().expect("set above"));
                self.moving = last.is_some_and(|l| Some(l) != shows);
            }
            let still = images.shows == shows;
            // A light edited or a rebuild coming: the image changes and accumulates afresh.
            let settled = self.renderer.voxels_settled();
            if !still || !settled {
                self.still_frames = 0;
            }
            // A still view whose voxels are settled stops accumulating while a new renderer's
            // voxel work runs (it is about to be replaced, and its frames would come between
            // that work's passes), after `still_cap` frames, and, on a CPU driver, for a frame
            // that answers input (the panel's answer then comes in a frame of its own, not
            // after another accumulation of half a second).
            let hold = self.renderer.is_idle()
                || (settled
                    && (self.handover.is_some()
                        || self.still_frames >= self.still_cap
                        || (self.cpu && self.stats.input_waiting())));
            if exporting || (still && hold) {
                self.reused |= accumulate;
            } else {
                if still && accumulate {
                    self.still_frames += 1;
                }
                let v = cone.create_view(&Default::default());
                let target = Target::new(&v, format, cw, ch);
                if accumulate {
                    self.renderer.render(encoder, &target, &self.params)?;
                } else {
                    // The frame shown, again: another would accumulate into the history.
                    self.renderer.redraw(encoder, &target, &self.params)?;
                }
                images.shows = shows;
            }
            if (cw, ch) == (vw, h) {
                encoder.copy_texture_to_texture(cone.as_image_copy(), view.as_image_copy(), extent);
            } else {
                self.upscale.draw(&self.device, encoder, &cone, &view_v);
            }
            if self.show_grid && self.export.is_none() {
                self.draw_grid(encoder, &view_v, (vw, h), (cw, ch));
            }
        }
        let r = self.ground.record(
            encoder,
            &Target::new(&view_v, format, vw, h),
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
    pub(super) fn draw_scene(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        accumulate: bool,
    ) -> Result<()> {
        if self.ground.needs_cone_tracing() {
            if accumulate {
                self.renderer.render(encoder, target, &self.params)?;
            } else {
                // The frame shown, again: another would accumulate into the history.
                self.renderer.redraw(encoder, target, &self.params)?;
            }
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
}

/// Draws the UI over what `view` holds.
pub(super) fn egui_pass(
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
pub(super) fn color_pass<'e>(
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
