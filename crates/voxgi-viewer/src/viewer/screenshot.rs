//! Screenshots: the images the view is drawn into and read back from, the frame drawn again
//! with the panel for `--with-ui`, writing PNGs, and the screenshots a frame asks for (P's, and
//! `--screenshot`'s, after which the viewer closes).

use super::Viewer;
use super::frame::{UiFrame, egui_pass};
use crate::ground_truth::Display;
use anyhow::Result;
use std::path::PathBuf;
use voxgi::{Target, wgpu};

impl Viewer {
    /// An image the view is drawn into, copied from, sampled (upscaled) and read back
    /// (screenshots, the view's cone-traced and composed images).
    pub(super) fn image_texture(
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
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::TEXTURE_BINDING,
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

    /// A screenshot with the panel: the same frame drawn again into an image, when
    /// `--screenshot --with-ui` takes it after this frame; recorded and submitted on its own,
    /// after the frame's work.
    pub(super) fn capture_with_ui(&mut self, ui: &UiFrame) -> Result<Option<wgpu::Texture>> {
        let capture_ui = self.screenshot_ui
            && self
                .screenshot
                .as_ref()
                .is_some_and(|(_, after)| self.ready_frames + 1 >= *after);
        if !capture_ui {
            return Ok(None);
        }
        let texture = self.capture_texture(self.config.format);
        let v = texture.create_view(&Default::default());
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.draw_frame(&mut encoder, &texture, false)?;
        egui_pass(&self.egui_renderer, &mut encoder, &v, &ui.jobs, &ui.screen);
        self.queue.submit([encoder.finish()]);
        Ok(Some(texture))
    }

    /// Writes the screenshots this frame asks for: P's (F12's), and `--screenshot`'s once
    /// `--after-frames` frames are ready (`ui_capture` is the frame with the panel, for
    /// `--with-ui`). Returns true when the viewer should close (`--screenshot` was taken).
    pub(super) fn take_screenshots(&mut self, ui_capture: Option<wgpu::Texture>) -> Result<bool> {
        if self.screenshot_key {
            self.screenshot_key = false;
            let name = PathBuf::from(format!("voxgi_{:05}.png", self.frames));
            // The whole path: the working directory is not on screen.
            let path = std::path::absolute(&name).unwrap_or(name);
            match self.save_screenshot(&path) {
                Ok(()) => self.toasts.info(format!("wrote {}", path.display())),
                Err(e) => self.toasts.error(format!("screenshot: {e:#}")),
            }
        }
        if let Some((path, after)) = &self.screenshot
            && self.ready_frames >= *after
        {
            let path = path.clone();
            match ui_capture {
                Some(t) => self.save_texture(&t, &path)?,
                None => self.save_screenshot(&path)?,
            }
            let timing = match self.stats.steady_frame_ms() {
                Some((mean, frames)) => format!(
                    "{mean:.1} ms per frame, {:.1} fps, over the last {frames}",
                    1e3 / mean.max(1e-3)
                ),
                None => "too few frames to time: the first two build the voxels".into(),
            };
            // The animation's time, to render the same instant again (`voxgi render --time`).
            let time = if self.duration > 0.0 {
                format!(", scene time {:.6} s", self.time)
            } else {
                String::new()
            };
            eprintln!(
                "wrote {} after {} frames ({timing}{time})",
                path.display(),
                self.frames
            );
            if self.ground.display != Display::ConeTraced {
                eprintln!("{}", self.ground.label());
            }
            return Ok(true);
        }
        Ok(false)
    }
}

fn bytemuck_f32(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}
