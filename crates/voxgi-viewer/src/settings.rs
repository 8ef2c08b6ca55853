//! The settings panel, drawn from the library's one table of settings
//! (`voxgi::settings::SETTINGS`): a widget per setting by its domain, with the table's label,
//! range, choices and help. Per-frame parameters are edited in place (they apply at once);
//! creation-time options are edited as a draft that "Apply" hands to `Renderer::set_options`.
//! The widgets' own values (a resolution as a power of two, bounces as a count or unlimited)
//! map to the settings and back without loss.

use voxgi::settings::{Changes, Domain, SETTINGS, Setting, Value};
use voxgi::{FrameParams, MAX_BOUNCES, RendererOptions, UNLIMITED_BOUNCES};

/// Bounces as the panel shows them: a count 0..=8 and an "unlimited" box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BounceWidget {
    pub count: u32,
    pub unlimited: bool,
}

impl BounceWidget {
    pub fn from_option(bounces: u32) -> Self {
        if bounces == UNLIMITED_BOUNCES {
            BounceWidget {
                count: 2,
                unlimited: true,
            }
        } else {
            BounceWidget {
                count: bounces,
                unlimited: false,
            }
        }
    }

    pub fn to_option(self) -> u32 {
        if self.unlimited {
            UNLIMITED_BOUNCES
        } else {
            self.count
        }
    }
}

/// What the panel asks of the viewer after a frame's UI.
#[derive(Default)]
pub struct PanelActions {
    /// Hand the draft options to the renderer.
    pub apply: bool,
    /// Put the draft back to the options in use.
    pub revert: bool,
    /// Open the system's file dialog.
    pub open_dialog: bool,
    /// Open this file.
    pub open: Option<std::path::PathBuf>,
    /// Show this instead.
    pub display: Option<crate::ground_truth::Display>,
}

/// One setting's widget over `o` and `f`; `levels` bounds the voxel views' level. Returns
/// whether the user changed it.
fn widget(
    ui: &mut egui::Ui,
    s: &'static Setting,
    o: &mut RendererOptions,
    f: &mut FrameParams,
    levels: u32,
) -> bool {
    let old = s.value(o, f);
    let mut v = old;
    match (s.domain, &mut v) {
        (Domain::Bool, Value::Bool(b)) => {
            ui.checkbox(b, s.label);
        }
        (Domain::Int { min, max }, Value::Int(n)) => {
            let max = if s.key == "voxel_level" {
                levels.saturating_sub(1)
            } else {
                max
            };
            ui.add(egui::Slider::new(n, min..=max.max(min)).text(s.label));
        }
        (Domain::Resolution { min }, Value::Int(n)) => {
            egui::ComboBox::from_label(s.label)
                .selected_text(format!("{n}³"))
                .show_ui(ui, |ui| {
                    for r in resolutions(min, o.voxels) {
                        ui.selectable_value(n, r, format!("{r}³"));
                    }
                });
        }
        (Domain::Float { min, max }, Value::Float(x)) => {
            ui.add(egui::Slider::new(x, min..=max).text(s.label));
        }
        (Domain::Auto, Value::Auto(x)) => {
            ui.horizontal(|ui| {
                let mut auto = x.is_none();
                ui.checkbox(&mut auto, format!("{}: auto", s.label));
                if auto {
                    *x = None;
                } else {
                    let mut m = x.unwrap_or(1.0);
                    ui.add(
                        egui::DragValue::new(&mut m)
                            .speed(0.01)
                            .range(0.001..=1.0e4),
                    );
                    *x = Some(m);
                }
            });
        }
        (Domain::Choice(names), Value::Name(n)) => {
            egui::ComboBox::from_label(s.label)
                .selected_text(*n)
                .show_ui(ui, |ui| {
                    for c in names() {
                        ui.selectable_value(n, c, c);
                    }
                });
        }
        (Domain::Bounces, Value::Int(n)) => {
            let mut b = BounceWidget::from_option(*n);
            ui.horizontal(|ui| {
                ui.add_enabled(
                    !b.unlimited,
                    egui::Slider::new(&mut b.count, 0..=MAX_BOUNCES).text(s.label),
                );
                ui.checkbox(&mut b.unlimited, "unlimited");
            });
            *n = b.to_option();
        }
        (Domain::Rgb, Value::Rgb(c)) => {
            ui.horizontal(|ui| {
                ui.color_edit_button_rgb(c);
                ui.label(s.label);
            });
        }
        (d, v) => unreachable!("{}: {d:?} holds {v:?}", s.key),
    }
    if v != old {
        s.set(o, f, v);
        true
    } else {
        false
    }
}

/// The resolutions the panel offers for structure `voxels`: every power of two the options
/// accept.
pub fn resolutions(min: u32, voxels: voxgi::VoxelKind) -> Vec<u32> {
    let top = voxels.info().max_resolution;
    (min.ilog2()..=top.ilog2()).map(|k| 1u32 << k).collect()
}

/// The panel's creation-time options section: a widget per option of the table over the draft.
pub fn options_ui(ui: &mut egui::Ui, draft: &mut RendererOptions, dirty: bool) -> PanelActions {
    let mut actions = PanelActions::default();
    // The frame parameters are not edited here; the widgets need somewhere to read them.
    let mut unused = FrameParams::new(voxgi::scene::Camera::look_at(
        glam::Vec3::Z,
        glam::Vec3::ZERO,
        45.0,
    ));
    for s in SETTINGS.iter().filter(|s| !s.per_frame()) {
        let enabled = match s.key {
            "ndf_mips" => draft.anisotropic,
            "progressive" => draft.bounces == UNLIMITED_BOUNCES,
            _ => true,
        };
        ui.add_enabled_ui(enabled, |ui| {
            widget(ui, s, draft, &mut unused, 0);
        })
        .response
        .on_hover_text(s.help);
    }
    // The options that need another: what the library would refuse, the panel turns off.
    if draft.bounces != UNLIMITED_BOUNCES {
        draft.progressive = false;
    }
    let top = draft.voxels.info().max_resolution;
    draft.voxel_resolution = draft.voxel_resolution.min(top);
    ui.horizontal(|ui| {
        if ui.add_enabled(dirty, egui::Button::new("Apply")).clicked() {
            actions.apply = true;
        }
        if ui.add_enabled(dirty, egui::Button::new("Revert")).clicked() {
            actions.revert = true;
        }
    });
    if dirty {
        ui.label(
            "Apply changes the renderer's options; the voxel structure, its resolution, the \
             shadow maps and the uploaded scene's settings rebuild it.",
        );
    }
    actions
}

/// Whether applying `draft` over `current` is done by a new renderer made in the background
/// while the current one draws, rather than by `Renderer::set_options` on the window's
/// thread: when a setting shapes the uploaded scene, and when the voxels or their light are
/// computed again (new pipelines, a structure counted before it is built, and seconds of voxel
/// work a CPU driver would do between two frames; the new renderer's is submitted a pass a
/// frame).
pub fn needs_new_renderer(current: &RendererOptions, draft: &RendererOptions) -> bool {
    matches!(
        voxgi::settings::changes_between(current, draft),
        Some(Changes::Scene | Changes::Voxels | Changes::Lighting)
    )
}

/// The panel's per-frame section: a widget per frame parameter of the table over `params`;
/// the voxel level and direction only for the voxel views. `levels` is the volume's mip count.
pub fn frame_ui(ui: &mut egui::Ui, params: &mut FrameParams, levels: u32) {
    let mut unused = RendererOptions::default();
    for s in SETTINGS.iter().filter(|s| s.per_frame()) {
        if matches!(s.key, "voxel_level" | "voxel_dir") && !params.view.is_voxel() {
            continue;
        }
        ui.scope(|ui| {
            widget(ui, s, &mut unused, params, levels);
        })
        .response
        .on_hover_text(s.help);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxgi::{ConeSet, Tonemap, ViewMode};

    #[test]
    fn bounce_widget_round_trips_every_setting() {
        for b in (0..=8).chain([UNLIMITED_BOUNCES]) {
            assert_eq!(BounceWidget::from_option(b).to_option(), b);
        }
    }

    #[test]
    fn the_panel_offers_every_valid_resolution() {
        // Per structure, the powers of two the panel offers are exactly what the options
        // accept (the octree's 1024 included).
        for &voxels in voxgi::VoxelKind::ALL {
            let accepted: Vec<u32> = (0..=12)
                .map(|k| 1u32 << k)
                .filter(|&r| {
                    RendererOptions {
                        voxels,
                        voxel_resolution: r,
                        ..RendererOptions::default()
                    }
                    .validate()
                    .is_ok()
                })
                .collect();
            assert_eq!(accepted, resolutions(16, voxels), "{voxels:?}");
        }
    }

    /// The panel edits `FrameParams` and the draft `RendererOptions` in place, so whatever a
    /// frame's UI leaves is exactly what reaches the renderer: a UI pass that touches nothing
    /// changes nothing (no widget rounds a value it shows).
    #[test]
    fn an_untouched_panel_changes_nothing() {
        let ctx = egui::Context::default();
        let mut options = RendererOptions {
            voxel_resolution: 64,
            bounces: UNLIMITED_BOUNCES,
            progressive: true,
            cones: ConeSet::Nine45,
            anisotropic: false,
            half_resolution: true,
            voxel_update_interval: 3,
            ..RendererOptions::default()
        };
        let before = options.clone();
        let camera =
            voxgi::scene::Camera::look_at(glam::Vec3::new(0.0, 1.0, 3.0), glam::Vec3::ZERO, 45.0);
        let mut params = FrameParams {
            exposure: 1.25,
            tonemap: Tonemap::Neutral,
            view: ViewMode::VoxelRadiance,
            debug_level: 2,
            debug_direction: 3,
            shadow_softness: 2.5,
            ..FrameParams::new(camera)
        };
        let params_before = params.clone();
        let _ = ctx.run_ui(egui::RawInput::default(), |ui| {
            options_ui(ui, &mut options, false);
            frame_ui(ui, &mut params, 7);
        });
        assert_eq!(options, before);
        assert_eq!(params, params_before);
    }
}
