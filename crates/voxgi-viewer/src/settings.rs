//! The settings panel: per-frame parameters edited in place (they apply at once), creation-time
//! options edited as a draft that "Apply" hands to `Renderer::set_options`. The widgets' own
//! values (a resolution as a power of two, bounces as a count or unlimited) map to the options
//! and back without loss.

use voxgi::{
    ConeSet, DIRECTIONS, FrameParams, RendererOptions, Tonemap, UNLIMITED_BOUNCES, ViewMode,
};

/// Voxel resolutions the panel offers: 16..=512.
pub const RESOLUTIONS: [u32; 6] = [16, 32, 64, 128, 256, 512];
pub const CONE_SETS: [ConeSet; 3] = [ConeSet::Six60, ConeSet::Seven45, ConeSet::Nine45];

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

/// The panel's creation-time options section: widgets over the draft.
pub fn options_ui(ui: &mut egui::Ui, draft: &mut RendererOptions, dirty: bool) -> PanelActions {
    let mut actions = PanelActions::default();
    egui::ComboBox::from_label("voxel structure")
        .selected_text(draft.voxels.name())
        .show_ui(ui, |ui| {
            for &k in voxgi::VoxelKind::ALL {
                ui.selectable_value(&mut draft.voxels, k, k.name());
            }
        });
    egui::ComboBox::from_label("voxels per side")
        .selected_text(draft.voxel_resolution.to_string())
        .show_ui(ui, |ui| {
            for r in RESOLUTIONS {
                ui.selectable_value(&mut draft.voxel_resolution, r, format!("{r}³"));
            }
        });
    egui::ComboBox::from_label("diffuse cones")
        .selected_text(draft.cones.name())
        .show_ui(ui, |ui| {
            for c in CONE_SETS {
                ui.selectable_value(&mut draft.cones, c, c.name());
            }
        });
    let mut b = BounceWidget::from_option(draft.bounces);
    ui.horizontal(|ui| {
        ui.add_enabled(
            !b.unlimited,
            egui::Slider::new(&mut b.count, 0..=8).text("bounces"),
        );
        ui.checkbox(&mut b.unlimited, "unlimited");
    });
    draft.bounces = b.to_option();
    ui.add_enabled(
        b.unlimited,
        egui::Checkbox::new(&mut draft.progressive, "progressive (one bounce per frame)"),
    );
    if !b.unlimited {
        draft.progressive = false;
    }
    ui.checkbox(&mut draft.anisotropic, "anisotropic voxels");
    ui.add_enabled(
        draft.anisotropic,
        egui::Checkbox::new(&mut draft.ndf_mips, "leaves weighed by their normals (NDF)"),
    );
    if !draft.anisotropic {
        draft.ndf_mips = false;
    }
    egui::ComboBox::from_label("diffuse indirect")
        .selected_text(match draft.indirect {
            voxgi::IndirectShading::Cones => "cones per pixel",
            voxgi::IndirectShading::Leaves => "leaves' irradiance (fast)",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(
                &mut draft.indirect,
                voxgi::IndirectShading::Cones,
                "cones per pixel",
            );
            ui.selectable_value(
                &mut draft.indirect,
                voxgi::IndirectShading::Leaves,
                "leaves' irradiance (fast)",
            );
        });
    ui.checkbox(&mut draft.half_resolution, "half-resolution gather");
    ui.checkbox(&mut draft.cone_shadows, "cone-traced area-light shadows");
    egui::ComboBox::from_label("point, spot and sun shadows")
        .selected_text(draft.shadow_filter.name())
        .show_ui(ui, |ui| {
            for f in voxgi::ShadowFilter::ALL {
                ui.selectable_value(&mut draft.shadow_filter, f, f.name());
            }
        });
    ui.add(
        egui::Slider::new(&mut draft.voxel_update_interval, 1..=16)
            .text("voxel update every k frames"),
    );
    ui.horizontal(|ui| {
        if ui.add_enabled(dirty, egui::Button::new("Apply")).clicked() {
            actions.apply = true;
        }
        if ui.add_enabled(dirty, egui::Button::new("Revert")).clicked() {
            actions.revert = true;
        }
    });
    if dirty {
        ui.label("Apply builds a new renderer; the window goes on meanwhile.");
    }
    actions
}

/// The panel's per-frame section: edits `params` in place.
pub fn frame_ui(ui: &mut egui::Ui, params: &mut FrameParams, levels: u32) {
    egui::ComboBox::from_label("view")
        .selected_text(params.view.name())
        .show_ui(ui, |ui| {
            for v in ViewMode::ALL {
                ui.selectable_value(&mut params.view, v, v.name());
            }
        });
    if params.view.is_voxel() {
        ui.add(
            egui::Slider::new(&mut params.debug_level, 0..=levels.saturating_sub(1))
                .text("voxel level"),
        );
        egui::ComboBox::from_label("voxel direction")
            .selected_text(DIRECTIONS[params.debug_direction.min(5) as usize])
            .show_ui(ui, |ui| {
                for (i, d) in DIRECTIONS.iter().enumerate() {
                    ui.selectable_value(&mut params.debug_direction, i as u32, *d);
                }
            });
    }
    ui.add(egui::Slider::new(&mut params.exposure, -8.0..=8.0).text("exposure (EV)"));
    egui::ComboBox::from_label("tone map")
        .selected_text(params.tonemap.name())
        .show_ui(ui, |ui| {
            for t in Tonemap::ALL {
                ui.selectable_value(&mut params.tonemap, t, t.name());
            }
        });
    ui.add(
        egui::Slider::new(&mut params.shadow_softness, 0.0..=16.0).text("shadow softness (texels)"),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounce_widget_round_trips_every_setting() {
        for b in (0..=8).chain([UNLIMITED_BOUNCES]) {
            assert_eq!(BounceWidget::from_option(b).to_option(), b);
        }
    }

    #[test]
    fn the_panel_offers_every_valid_resolution_and_cone_set() {
        for r in RESOLUTIONS {
            let o = RendererOptions {
                voxel_resolution: r,
                ..RendererOptions::default()
            };
            assert!(o.validate().is_ok(), "{r}");
        }
        // Powers of two 16..=512 are exactly what the options accept.
        let accepted: Vec<u32> = (4..=10)
            .map(|k| 1u32 << k)
            .filter(|&r| {
                RendererOptions {
                    voxel_resolution: r,
                    ..RendererOptions::default()
                }
                .validate()
                .is_ok()
            })
            .collect();
        assert_eq!(accepted, RESOLUTIONS);
        for c in CONE_SETS {
            assert_eq!(ConeSet::parse(c.name()), Some(c));
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
