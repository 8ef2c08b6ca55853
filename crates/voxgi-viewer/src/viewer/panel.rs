//! The egui panel: the settings panel's sections (the scene and how to open another, the view,
//! the scene's cameras, the path tracer, the lights, the renderer's options, the animation, the
//! stats section from `stats`), what its buttons ask for, and the overlays over the image (the
//! background work running, the split view's divider and captions). The settings widgets
//! themselves are in `crate::settings`.

use super::Viewer;
use super::input::Controller;
use crate::camera::{Orbit, render_flags};
use crate::ground_truth::Display;
use crate::settings::{PanelActions, frame_ui, options_ui};
use std::path::PathBuf;

/// The settings panel's width, points, in a window wide enough for it.
pub(super) const PANEL_WIDTH: f32 = 370.0;

/// The panel's width in a window `window` points wide: `PANEL_WIDTH`, or 40 % of a window
/// too narrow to leave the picture 60 % beside it (at least 240 points, where the sliders
/// still fit).
pub(super) fn panel_width(window: f32) -> f32 {
    PANEL_WIDTH.min(0.4 * window).max(240.0)
}

impl Viewer {
    pub(super) fn ui(&mut self, ui: &mut egui::Ui) -> PanelActions {
        let mut actions = PanelActions::default();
        self.overlays_ui(ui);
        if !self.show_panel {
            self.panel_px = 0;
            return actions;
        }
        // Its edge drags it wider or narrower; it starts narrower in a narrow window (370
        // points of a 560-point window left 190 for the picture). Its content scrolls both
        // ways: a panel that followed its content's width would resize the 3D view (and
        // restart the path tracer) whenever a label grew, and could not be made narrower.
        let window = ui.ctx().content_rect().width();
        let panel = egui::Panel::left("settings")
            .resizable(true)
            .default_size(panel_width(window))
            .size_range(240.0f32.min(window)..=(0.7 * window).max(240.0f32.min(window)))
            .show(ui, |ui| {
                egui::ScrollArea::both().auto_shrink([false, false]).show(ui, |ui| {
                    ui.heading(&self.scene_name);
                    ui.label(format!(
                        "{} ({:?})",
                        self.adapter.name, self.adapter.backend
                    ));
                    ui.label(
                        "drag: orbit · right-drag: pan · wheel: zoom · F: fly (WASD/QE, drag \
                         to look) · H: frame (the selected light) · 1/3/7: front/right/top · 5: orthographic · \
                         G: path tracer / split · Space: play · P: screenshot · O: frame \
                         time · L: light gizmos · X: export · B: bookmark · Tab: panel",
                    );
                    ui.horizontal(|ui| {
                        if ui.button("Open…").clicked() {
                            actions.open_dialog = true;
                        }
                        if ui.button("Export…").clicked() {
                            self.export_dialog.open = true;
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
                    ui.separator();
                    egui::CollapsingHeader::new("view")
                        .default_open(true)
                        .show(ui, |ui| {
                            frame_ui(ui, &mut self.params, self.options.voxel_levels());
                            ui.horizontal(|ui| {
                                for (i, (name, _)) in crate::camera::PRESETS.iter().enumerate() {
                                    let key = ["1", "3", "7"][i];
                                    if ui
                                        .button(*name)
                                        .on_hover_text(format!("key {key}"))
                                        .clicked()
                                    {
                                        self.view_preset(i);
                                    }
                                }
                                let ortho =
                                    matches!(&self.controller, Controller::Orbit(o) if o.ortho);
                                if ui
                                    .selectable_label(ortho, "orthographic")
                                    .on_hover_text("key 5")
                                    .clicked()
                                {
                                    self.toggle_ortho();
                                }
                                ui.checkbox(&mut self.show_grid, "grid")
                                    .on_hover_text("the ground grid under the scene (key K)");
                            });
                            let flags = render_flags(&self.params.camera);
                            ui.horizontal(|ui| {
                                if ui.button("copy view as voxgi render flags").clicked() {
                                    ui.ctx().copy_text(flags.clone());
                                }
                            });
                            ui.label(egui::RichText::new(flags).monospace().small());
                        });
                    self.cameras_ui(ui);
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
                            if self.scene.camera_is_animated(0) {
                                ui.checkbox(&mut self.fly_along, "fly with the scene's camera")
                                    .on_hover_text(
                                        "the view follows the scene's camera animation; \
                                         moving the view ends it",
                                    );
                            }
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
        self.toasts.ui(&ctx);
        let left = self.panel_px as f32 / ctx.pixels_per_point();
        self.axes_ui(&ctx, left);
        self.gizmos_ui(&ctx);
        self.export_ui(&ctx);
        let mut top = 8.0;
        if self.frame_overlay {
            let n = self.stats.frame_ms.len().max(1) as f32;
            let ms = self.stats.frame_ms.iter().sum::<f32>() / n;
            let what = if self.reused {
                "the last image again"
            } else {
                self.ground.display.name()
            };
            egui::Area::new(egui::Id::unique("frame time"))
                .anchor(egui::Align2::LEFT_TOP, [left + 8.0, top])
                .show(&ctx, |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        ui.add(
                            egui::Label::new(
                                egui::RichText::new(format!(
                                    "{ms:.1} ms · {:.1} fps · {what}",
                                    1e3 / ms.max(1e-3)
                                ))
                                .monospace(),
                            )
                            .extend(),
                        )
                    });
                });
            top += 30.0;
        }
        if let Controller::Fly(f) = &self.controller {
            egui::Area::new(egui::Id::unique("fly"))
                .anchor(egui::Align2::LEFT_TOP, [left + 8.0, top])
                .show(&ctx, |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        ui.label(format!(
                            "flying at {:.2} m/s · WASD or arrows, Q/E down/up · wheel: speed                              · drag: look · F: orbit",
                            f.speed
                        ))
                    });
                });
        }
        let running = self.running();
        if !running.is_empty() {
            // A fixed width: anchored by its right edge, a box whose width changed with its text
            // was drawn where the last frame's width put it, partly off the window.
            let width = (ctx.content_rect().width() * 0.3).clamp(200.0, 340.0);
            egui::Area::new(egui::Id::unique("jobs"))
                .anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0])
                .show(&ctx, |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        ui.set_width(width);
                        for r in &running {
                            ui.horizontal(|ui| {
                                ui.spinner();
                                ui.add(egui::Label::new(r).wrap());
                            });
                        }
                    });
                });
        }
        let screen = ctx.content_rect();
        let caption = |ui: &mut egui::Ui, text: String| {
            // One line: a caption wrapped onto three hid the image under it.
            egui::Frame::popup(ui.style()).show(ui, |ui| ui.add(egui::Label::new(text).extend()));
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

    /// The scene's cameras and the bookmarks (wrapped onto as many rows as they need), a
    /// button to bookmark the view, and one to save the view into the scene file.
    fn cameras_ui(&mut self, ui: &mut egui::Ui) {
        let mut pick = None;
        let mut forget = None;
        ui.horizontal_wrapped(|ui| {
            ui.label("cameras:");
            for (i, c) in self.cameras.iter().enumerate() {
                let name = if c.name.is_empty() {
                    format!("{i}")
                } else {
                    c.name.clone()
                };
                let b = ui.button(name);
                if b.clicked() {
                    pick = Some(c.clone());
                }
                if i >= self.first_bookmark {
                    b.context_menu(|ui| {
                        if ui.button("forget this view").clicked() {
                            forget = Some(i);
                        }
                    });
                }
            }
            if ui
                .button("+ bookmark")
                .on_hover_text("the view as a named camera (key B); right-click one to forget it")
                .clicked()
            {
                self.bookmark();
            }
        });
        if let Some(c) = pick {
            self.controller = Controller::Orbit(Orbit::from_camera(&c, self.scene_radius));
            self.renderer.reset_history();
        }
        if let Some(i) = forget {
            self.cameras.remove(i);
        }
        if let Some(target) = self.source.as_ref().map(|s| s.target()) {
            let name = target.file_name().map_or_else(
                || target.display().to_string(),
                |n| n.to_string_lossy().into(),
            );
            if ui
                .button(format!("save the view into {name}"))
                .on_hover_text(
                    "the camera, the bookmarks, the settings changed here and the scene \
                     file's own lights as edited; comments and the rest stay",
                )
                .clicked()
            {
                self.save_view();
            }
        }
    }

    /// The world's axes as the camera sees them, in the view's lower left corner (X red, Y
    /// green, Z blue, as Blender and three.js draw them).
    fn axes_ui(&self, ctx: &egui::Context, left: f32) {
        let screen = ctx.content_rect();
        let centre = egui::pos2(screen.left() + left + 40.0, screen.bottom() - 40.0);
        let painter = ctx.layer_painter(egui::LayerId::new(
            egui::Order::Foreground,
            egui::Id::unique("axes"),
        ));
        let colours = [
            egui::Color32::from_rgb(230, 70, 70),
            egui::Color32::from_rgb(110, 200, 80),
            egui::Color32::from_rgb(80, 140, 240),
        ];
        for (i, a) in crate::camera::screen_axes(&self.params.camera)
            .iter()
            .enumerate()
        {
            let d = egui::vec2(a[0], a[1]);
            painter.line_segment(
                [centre, centre + d * 26.0],
                egui::Stroke::new(2.0, colours[i]),
            );
            painter.text(
                centre + d * 34.0,
                egui::Align2::CENTER_CENTER,
                ["X", "Y", "Z"][i],
                egui::FontId::proportional(12.0),
                colours[i],
            );
        }
    }

    /// Each light's colour, intensity and placement; a change goes to `Renderer::set_light`,
    /// which re-renders its shadow views and re-lights the voxels.
    fn lights_ui(&mut self, ui: &mut egui::Ui) {
        ui.checkbox(
            &mut self.show_gizmos,
            "gizmos over the view (L): click one to select, drag to move",
        );
        let lights: Vec<voxgi::scene::Light> = self.renderer.lights().to_vec();
        for (i, light) in lights.iter().enumerate() {
            let mut l = light.clone();
            let kind = match l.kind {
                voxgi::scene::LightKind::Directional => "directional",
                voxgi::scene::LightKind::Point => "point",
                voxgi::scene::LightKind::Spot { .. } => "spot",
                voxgi::scene::LightKind::Area { .. } => "area",
            };
            let selected = self.selected_light == Some(i);
            let name = egui::RichText::new(format!("{} ({kind})", l.name)).strong();
            if ui.selectable_label(selected, name).clicked() {
                self.selected_light = (!selected).then_some(i);
            }
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
                    for (c, axis) in ["x ", "y ", "z "].into_iter().enumerate() {
                        changed |= ui
                            .add(
                                egui::DragValue::new(&mut l.direction[c])
                                    .speed(0.01)
                                    .prefix(axis),
                            )
                            .changed();
                    }
                });
            } else {
                ui.horizontal(|ui| {
                    ui.label("position");
                    for (c, axis) in ["x ", "y ", "z "].into_iter().enumerate() {
                        changed |= ui
                            .add(
                                egui::DragValue::new(&mut l.position[c])
                                    .speed(step)
                                    .prefix(axis),
                            )
                            .changed();
                    }
                });
            }
            if changed && l != *light {
                if l.direction.length_squared() < 1e-8 {
                    l.direction = light.direction;
                }
                // The path tracer takes the edit from `renderer.lights()` in its next update.
                self.set_light(i, &l);
            }
        }
    }

    /// Does what the panel's buttons asked for this frame.
    pub(super) fn act(&mut self, mut actions: PanelActions) {
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
    }
}
