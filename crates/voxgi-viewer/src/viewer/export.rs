//! Export: the current view rendered offscreen at a chosen size through the window's own
//! renderer, as `voxgi render` renders a still (the voxels settled, then `frames` frames
//! accumulated), and written as a PNG (tone-mapped) or an EXR (linear radiance). The work is
//! spread over the window's frames, one renderer frame each, so the window keeps answering and
//! can cancel it; the view meanwhile shows its last image.

use super::Viewer;
use crate::jobs::Job;
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxgi::{FrameParams, Target, wgpu};

/// The format the exported frame is drawn in: `voxgi render`'s, so a PNG is byte for byte
/// what the command line writes.
const FORMAT: wgpu::TextureFormat = voxgi::headless::OUTPUT_FORMAT;

/// Frames a settling build may take before the export gives up: progressive bounces converge
/// within a few dozen.
const MAX_SETTLE_FRAMES: u32 = 256;

/// The dialog's fields, kept between openings.
pub(super) struct ExportDialog {
    pub(super) open: bool,
    /// The file field takes the keyboard in the next frame (the dialog was opened by key):
    /// Enter there exports.
    pub(super) focus_file: bool,
    width: u32,
    height: u32,
    exr: bool,
    frames: u32,
    path: String,
}

impl ExportDialog {
    pub(super) fn new(cpu: bool, scene: &str) -> Self {
        let (width, height) = if cpu { (960, 540) } else { (1920, 1080) };
        ExportDialog {
            open: false,
            focus_file: false,
            width,
            height,
            exr: false,
            // A CPU driver takes seconds a frame at these sizes.
            frames: if cpu {
                16
            } else {
                voxgi::headless::DEFAULT_ACCUMULATE
            },
            path: default_path(scene, false),
        }
    }
}

/// `voxgi_<scene>.png` (or `.exr`), the scene's name kept to letters, digits, `-` and `_`.
fn default_path(scene: &str, exr: bool) -> String {
    let name: String = scene
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("voxgi_{name}.{}", if exr { "exr" } else { "png" })
}

/// `path` with the extension of the chosen format.
fn with_format(path: &str, exr: bool) -> PathBuf {
    Path::new(path.trim()).with_extension(if exr { "exr" } else { "png" })
}

/// An export under way.
pub(super) struct Export {
    path: PathBuf,
    texture: wgpu::Texture,
    params: FrameParams,
    /// Frames to accumulate once the voxels settled (1 without temporal accumulation).
    frames: u32,
    /// Frames drawn while the voxels settle, then frames accumulated.
    settling: u32,
    accumulated: Option<u32>,
    started: Instant,
}

impl Export {
    fn progress(&self) -> (f32, String) {
        let (w, h) = (self.texture.width(), self.texture.height());
        match self.accumulated {
            None => (0.0, format!("exporting {w}x{h}: settling the voxels")),
            Some(n) => (
                n as f32 / self.frames as f32,
                format!("exporting {w}x{h}: frame {n} of {}", self.frames),
            ),
        }
    }
}

impl Viewer {
    /// Starts exporting the view as the dialog asks.
    fn start_export(&mut self) -> Result<()> {
        let d = &self.export_dialog;
        let max = self.device.limits().max_texture_dimension_2d;
        if !(16..=max).contains(&d.width) || !(16..=max).contains(&d.height) {
            bail!(
                "{}x{}: width and height must be 16..={max} on this GPU",
                d.width,
                d.height
            );
        }
        if d.path.trim().is_empty() {
            bail!("no file name to export to");
        }
        let path = with_format(&d.path, d.exr);
        let path = std::path::absolute(&path).unwrap_or(path);
        if let Some(dir) = path.parent()
            && !dir.is_dir()
        {
            bail!("{}: no such folder", dir.display());
        }
        let (w, h) = (d.width, d.height);
        let texture = self.image_texture("export", FORMAT, w, h);
        let frames = if self.options.temporal { d.frames } else { 1 };
        if self.playing {
            self.playing = false;
            self.toasts.info("paused for the export");
        }
        self.export = Some(Export {
            path,
            texture,
            params: self.params.clone(),
            frames,
            settling: 0,
            accumulated: None,
            started: Instant::now(),
        });
        Ok(())
    }

    /// Records this frame's export frame, when an export runs.
    pub(super) fn export_frame(&mut self, encoder: &mut wgpu::CommandEncoder) -> Result<()> {
        let Some(e) = &mut self.export else {
            return Ok(());
        };
        self.renderer.receive_feedback()?;
        if e.accumulated.is_none()
            && e.settling > 0
            && self.renderer.voxels_settled()
            && !self.renderer.feedback_in_flight()
        {
            self.renderer.reset_history();
            e.accumulated = Some(0);
        }
        if e.accumulated.is_none() && e.settling >= MAX_SETTLE_FRAMES {
            self.export = None;
            bail!("export: the voxels did not settle within {MAX_SETTLE_FRAMES} frames");
        }
        let view = e.texture.create_view(&Default::default());
        let target = Target::new(&view, FORMAT, e.texture.width(), e.texture.height());
        self.renderer.render(encoder, &target, &e.params)?;
        match &mut e.accumulated {
            Some(n) => *n += 1,
            None => e.settling += 1,
        }
        Ok(())
    }

    /// Once the export's last frame is submitted: reads it back and writes the file in the
    /// background; the view is drawn again at its own size.
    pub(super) fn export_done(&mut self) -> Result<()> {
        let finished = self
            .export
            .as_ref()
            .is_some_and(|e| e.accumulated.is_some_and(|n| n >= e.frames));
        if !finished {
            return Ok(());
        }
        let e = self.export.take().expect("checked above");
        self.export_ended();
        let hdr = self
            .renderer
            .hdr_texture()
            .ok_or_else(|| anyhow::anyhow!("export: the renderer has no HDR image"))?;
        let (device, queue) = (&self.device, &self.queue);
        let output = voxgi::RenderOutput {
            width: e.texture.width(),
            height: e.texture.height(),
            hdr: bytemuck::cast_slice(&voxgi::gpu::readback::read_texture(device, queue, hdr)?)
                .to_vec(),
            ldr: voxgi::gpu::readback::read_texture(device, queue, &e.texture)?,
        };
        let (path, frames, started) = (e.path, e.frames, e.started);
        let what = format!("writing {}", path.display());
        self.saving = Some(Job::spawn(what, move || {
            output.save(&path)?;
            Ok(format!(
                "exported {} ({}x{}, {frames} frame{} accumulated) in {:.1} s",
                path.display(),
                output.width,
                output.height,
                if frames == 1 { "" } else { "s" },
                started.elapsed().as_secs_f32()
            ))
        }));
        Ok(())
    }

    /// The view takes the renderer back: drawn afresh at its own size, with a history of its
    /// own.
    fn export_ended(&mut self) {
        if let Some(images) = &mut self.images {
            images.shows = None;
        }
        self.renderer.reset_history();
    }

    /// What the export is doing, for the window's indicator.
    pub(super) fn export_label(&self) -> Option<String> {
        self.export.as_ref().map(|e| e.progress().1)
    }

    /// The export dialog, when open.
    pub(super) fn export_ui(&mut self, ctx: &egui::Context) {
        if !self.export_dialog.open {
            return;
        }
        let mut open = true;
        let mut start = false;
        let mut cancel = false;
        let (x0, vw) = self.view_columns();
        let vh = self.config.height;
        let left = x0 as f32 / ctx.pixels_per_point();
        let max = self.device.limits().max_texture_dimension_2d;
        let temporal = self.options.temporal;
        let running = self.export.as_ref().map(Export::progress);
        let d = &mut self.export_dialog;
        egui::Window::new("Export the view")
            .default_pos(egui::pos2(left + 16.0, 16.0))
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .show(ctx, |ui| {
                ui.add_enabled_ui(running.is_none(), |ui| {
                    ui.horizontal(|ui| {
                        ui.label("size");
                        ui.add(egui::DragValue::new(&mut d.width).range(16..=max));
                        ui.label("x");
                        ui.add(egui::DragValue::new(&mut d.height).range(16..=max));
                    });
                    ui.horizontal(|ui| {
                        for (label, (w, h)) in [
                            ("the view's", (vw, vh)),
                            ("1080p", (1920, 1080)),
                            ("4K", (3840, 2160)),
                        ] {
                            if ui.button(label).clicked() {
                                (d.width, d.height) = (w.min(max), h.min(max));
                            }
                        }
                    });
                    ui.horizontal(|ui| {
                        let was = d.exr;
                        ui.radio_value(&mut d.exr, false, "PNG (tone-mapped)");
                        ui.radio_value(&mut d.exr, true, "EXR (linear radiance)");
                        if d.exr != was {
                            d.path = with_format(&d.path, d.exr).display().to_string();
                        }
                    });
                    ui.add_enabled_ui(temporal, |ui| {
                        ui.horizontal(|ui| {
                            ui.add(
                                egui::DragValue::new(&mut d.frames)
                                    .range(1..=voxgi::TEMPORAL_STILL_FRAMES),
                            );
                            ui.label(if temporal {
                                "frames accumulated (anti-aliasing, soft shadows)"
                            } else {
                                "frame (temporal accumulation is off)"
                            });
                        });
                    });
                    ui.horizontal(|ui| {
                        ui.label("file");
                        let edit =
                            ui.add(egui::TextEdit::singleline(&mut d.path).desired_width(260.0));
                        if std::mem::take(&mut d.focus_file) {
                            edit.request_focus();
                        }
                        start |= edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                    });
                });
                match &running {
                    None => start |= ui.button("Export").clicked(),
                    Some((done, what)) => {
                        ui.add(egui::ProgressBar::new(*done).text(what.as_str()));
                        cancel = ui.button("Cancel").clicked();
                    }
                }
            });
        self.export_dialog.open = open;
        if start && let Err(e) = self.start_export() {
            self.toasts.error(format!("{e:#}"));
        }
        if cancel || (!open && self.export.is_some()) {
            self.export = None;
            self.export_ended();
            self.toasts.info("export cancelled");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_name_follows_the_scene_and_the_format() {
        assert_eq!(
            default_path("cornell box/2", false),
            "voxgi_cornell_box_2.png"
        );
        assert_eq!(
            with_format("out/shot.png", true),
            PathBuf::from("out/shot.exr")
        );
        assert_eq!(with_format(" shot ", false), PathBuf::from("shot.png"));
    }
}
