//! The window while its first renderer is made: `Renderer::new` (the scene's upload, the
//! pipelines, the voxel pools) runs on a thread, and the window shows what is being built and
//! for how long, ten times a second, instead of staying black (7 s for Sponza on lavapipe, up
//! to 23 s on a busy machine). Then its first voxel work is submitted a pass a frame
//! (`Pieces`), the progress frame naming the pass, before the viewer takes over.

use super::surface::Gpu;
use crate::jobs::Job;
use anyhow::Result;
use std::sync::Arc;
use voxgi::scene::Scene;
use voxgi::{FrameParams, Renderer, RendererOptions, wgpu};

/// Everything `Viewer::new` takes, but the renderer still being made.
pub(super) struct Starting {
    pub(super) gpu: Gpu,
    pub(super) scene: Arc<Scene>,
    pub(super) options: RendererOptions,
    pub(super) params: FrameParams,
    pub(super) job: Job<Renderer>,
    /// The renderer once made, and its first voxel work being submitted a pass a frame.
    pub(super) pieces: Option<(Renderer, super::pieces::Pieces)>,
    pub(super) egui_ctx: egui::Context,
    pub(super) egui_state: egui_winit::State,
    pub(super) egui_renderer: egui_wgpu::Renderer,
    /// When the window opened.
    pub(super) opened: std::time::Instant,
    /// The waits between frames, from the window's first on (the viewer's then).
    pub(super) stats: super::stats::Stats,
    /// Keys pressed and released meanwhile, for the viewer once it is there (Tab, F, G ...).
    pub(super) keys: Vec<winit::event::WindowEvent>,
}

impl Starting {
    /// Draws the progress frame: the scene's name and `label` (what is being built, for how
    /// long).
    pub(super) fn redraw(&mut self, name: &str, label: &str) -> Result<()> {
        let g = &mut self.gpu;
        let frame = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                g.surface.configure(&g.device, &g.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let raw = self.egui_state.take_egui_input(&g.window);
        let full = self.egui_ctx.run_ui(raw, |ui| {
            egui::CentralPanel::default().show(ui, |ui| {
                ui.vertical_centered(|ui| {
                    ui.add_space(ui.available_height() * 0.4);
                    ui.heading(name);
                    ui.horizontal(|ui| {
                        ui.spinner();
                        ui.label(label);
                    });
                });
            });
        });
        self.egui_state
            .handle_platform_output(&g.window, full.platform_output);
        let jobs = self.egui_ctx.tessellate(full.shapes, full.pixels_per_point);
        for (id, deltas) in &full.textures_delta.set {
            for delta in deltas {
                self.egui_renderer
                    .update_texture(&g.device, &g.queue, *id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [g.config.width, g.config.height],
            pixels_per_point: full.pixels_per_point,
        };
        let mut encoder = g.device.create_command_encoder(&Default::default());
        let extra =
            self.egui_renderer
                .update_buffers(&g.device, &g.queue, &mut encoder, &jobs, &screen);
        let view = frame.texture.create_view(&Default::default());
        {
            let pass = super::frame::color_pass(
                &mut encoder,
                "starting",
                &view,
                wgpu::LoadOp::Clear(wgpu::Color::BLACK),
            );
            self.egui_renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in &full.textures_delta.free {
            self.egui_renderer.free_texture(id);
        }
        g.queue.submit(extra.into_iter().chain([encoder.finish()]));
        g.window.pre_present_notify();
        g.queue.present(frame);
        self.stats.presented(label);
        Ok(())
    }

    /// The window's new size.
    pub(super) fn resize(&mut self, size: winit::dpi::PhysicalSize<u32>) {
        let g = &mut self.gpu;
        g.config.width = size.width.max(1);
        g.config.height = size.height.max(1);
        g.surface.configure(&g.device, &g.config);
    }
}
