//! Light gizmos over the 3D view: a marker per light in its colour (a sun's where its light
//! comes from, with a line towards the scene), an area light's outline and a spot light's aim.
//! A click selects a light (its panel entry is marked, H frames it); a drag moves it in the
//! view's plane, at its depth, through `Renderer::set_light` (an area light's visible surface
//! follows); a sun's drag turns its direction.

use super::Viewer;
use super::input::Controller;
use crate::camera::{Orbit, metres_per_pixel, project, view_axes};
use glam::Vec3;
use voxgi::scene::{AreaShape, Camera, Light, LightKind};

/// The marker's radius, points: small enough not to hide the scene, big enough to grab.
const MARKER: f32 = 7.0;

/// What the gizmos draw in: the 3D view's rectangle (points) and its camera.
struct View {
    rect: egui::Rect,
    camera: Camera,
}

impl View {
    /// Where world point `p` shows, in points; `None` behind the camera.
    fn at(&self, p: Vec3) -> Option<egui::Pos2> {
        let size = [self.rect.width(), self.rect.height()];
        project(&self.camera, size, p).map(|[x, y]| self.rect.min + egui::vec2(x, y))
    }

    /// The world move of a drag of `d` points at world point `p`.
    fn drag(&self, p: Vec3, d: egui::Vec2) -> Vec3 {
        let (right, up) = view_axes(&self.camera);
        (right * d.x - up * d.y) * metres_per_pixel(&self.camera, self.rect.height(), p)
    }
}

/// Where a light's marker is: its position, or for a sun where its light comes from, the
/// scene's radius out from its centre.
pub(super) fn anchor(light: &Light, center: Vec3, radius: f32) -> Vec3 {
    match light.kind {
        LightKind::Directional => center - light.direction.normalize_or(Vec3::NEG_Y) * radius,
        _ => light.position,
    }
}

/// `light` with its marker dragged by `by` (world metres): moved, or a sun turned so its
/// light comes from the marker's new place.
pub(super) fn dragged(light: &Light, by: Vec3, center: Vec3, radius: f32) -> Light {
    let mut l = light.clone();
    match light.kind {
        LightKind::Directional => {
            let from = anchor(light, center, radius) + by;
            l.direction = (center - from).normalize_or(light.direction);
        }
        _ => l.position += by,
    }
    l
}

/// A light's colour as the marker's fill, at full brightness.
fn colour(light: &Light) -> egui::Color32 {
    let c = light.color;
    let max = c.iter().fold(1e-6f32, |a, &b| a.max(b));
    let u = |v: f32| ((v / max).clamp(0.0, 1.0) * 255.0) as u8;
    egui::Color32::from_rgb(u(c[0]), u(c[1]), u(c[2]))
}

impl Viewer {
    /// Draws the light gizmos and takes their clicks and drags.
    pub(super) fn gizmos_ui(&mut self, ctx: &egui::Context) {
        if !self.show_gizmos {
            return;
        }
        let ppp = ctx.pixels_per_point();
        let (x0, width) = self.view_columns();
        let view = View {
            rect: egui::Rect::from_min_size(
                egui::pos2(x0 as f32 / ppp, 0.0),
                egui::vec2(width as f32, self.config.height as f32) / ppp,
            ),
            camera: self.params.camera.clone(),
        };
        // Under windows and toasts (the export dialog drew the markers over itself).
        let painter = ctx.layer_painter(egui::LayerId::new(
            egui::Order::Background,
            egui::Id::unique("light gizmos"),
        ));
        let (center, radius) = (self.scene_center, self.scene_radius);
        let lights = self.renderer.lights().to_vec();
        let mut edit = None;
        for (i, light) in lights.iter().enumerate() {
            let p = anchor(light, center, radius);
            let Some(at) = view.at(p) else {
                continue;
            };
            if !view.rect.shrink(MARKER).contains(at) {
                continue;
            }
            let selected = self.selected_light == Some(i);
            let line = egui::Stroke::new(
                if selected { 2.0 } else { 1.0 },
                if selected {
                    egui::Color32::YELLOW
                } else {
                    egui::Color32::from_white_alpha(170)
                },
            );
            self.light_shape(&painter, &view, light, p, line);
            let response = egui::Area::new(egui::Id::unique(("light gizmo", i)))
                .order(egui::Order::Background)
                .movable(false)
                .fixed_pos(at - egui::Vec2::splat(MARKER))
                .show(ctx, |ui| {
                    let (_, r) = ui.allocate_exact_size(
                        egui::Vec2::splat(2.0 * MARKER),
                        egui::Sense::click_and_drag(),
                    );
                    r
                })
                .inner;
            if response.clicked() || response.drag_started() {
                self.selected_light = Some(i);
            }
            let d = response.drag_delta();
            if response.dragged() && d != egui::Vec2::ZERO {
                edit = Some((i, dragged(light, view.drag(p, d), center, radius)));
            }
            painter.circle(at, MARKER, colour(light), line);
            if selected || response.hovered() {
                // On a dark box: the name is often over the light's own bright surface.
                let galley = painter.layout_no_wrap(
                    light.name.clone(),
                    egui::FontId::proportional(13.0),
                    egui::Color32::WHITE,
                );
                let min = at + egui::vec2(MARKER + 6.0, -galley.size().y * 0.5);
                let rect = egui::Rect::from_min_size(min, galley.size()).expand(3.0);
                painter.rect_filled(rect, 3.0, egui::Color32::from_black_alpha(190));
                painter.galley(min, galley, egui::Color32::WHITE);
                response.on_hover_cursor(egui::CursorIcon::Grab);
            }
        }
        if let Some((i, l)) = edit {
            self.set_light(i, &l);
        }
    }

    /// The lines that show a light's shape: an area light's outline, a spot light's aim, a
    /// sun's direction towards the scene.
    fn light_shape(
        &self,
        painter: &egui::Painter,
        view: &View,
        light: &Light,
        p: Vec3,
        line: egui::Stroke,
    ) {
        let dir = light.direction.normalize_or(Vec3::NEG_Y);
        let polyline = |points: Vec<Vec3>, closed: bool| {
            let shown: Option<Vec<egui::Pos2>> = points.iter().map(|q| view.at(*q)).collect();
            if let Some(shown) = shown {
                let shape = if closed {
                    egui::Shape::closed_line(shown, line)
                } else {
                    egui::Shape::line(shown, line)
                };
                painter.add(shape);
            }
        };
        match light.kind {
            LightKind::Area {
                shape: AreaShape::Rect { u, v },
            } => polyline(vec![p - u - v, p + u - v, p + u + v, p - u + v], true),
            LightKind::Area {
                shape: AreaShape::Disc { radius },
            } => {
                let (t, b) = dir.any_orthonormal_pair();
                let ring = (0..24)
                    .map(|k| {
                        let a = k as f32 / 24.0 * std::f32::consts::TAU;
                        p + (t * a.cos() + b * a.sin()) * radius
                    })
                    .collect();
                polyline(ring, true);
            }
            LightKind::Spot { .. } => {
                polyline(vec![p, p + dir * self.scene_radius * 0.15], false);
            }
            LightKind::Directional => {
                polyline(vec![p, p + dir * self.scene_radius * 0.3], false);
            }
            LightKind::Point => {}
        }
    }

    /// Changes light `i` to `l` in the renderer (the path tracer follows).
    pub(super) fn set_light(&mut self, i: usize, l: &Light) {
        match self.renderer.set_light(i, l) {
            Ok(()) => self.ground.scene_changed(),
            Err(e) => self.toasts.error(format!("{e}")),
        }
    }

    /// H: the orbit turns about the selected light, or frames the scene with none selected.
    pub(super) fn frame_selection(&mut self) {
        let Some(light) = self
            .selected_light
            .and_then(|i| self.renderer.lights().get(i))
        else {
            return self.frame_scene();
        };
        // Along the line the camera sees it on, closer.
        let p = anchor(light, self.scene_center, self.scene_radius);
        let cam = &self.params.camera;
        let to = p - cam.position;
        let d = to
            .length()
            .clamp(self.scene_radius * 0.2, self.scene_radius * 0.6);
        let dir = to.normalize_or(cam.forward);
        let mut at = cam.clone();
        at.position = p - dir * d;
        at.forward = dir;
        at.up = if dir.cross(Vec3::Y).length_squared() > 1e-6 {
            dir.cross(Vec3::Y).cross(dir).normalize()
        } else {
            cam.up
        };
        self.controller = Controller::Orbit(Orbit::from_camera(&at, d));
        self.renderer.reset_history();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point light moves by the drag; a sun's marker stays on the sphere about the scene and
    /// the sun then shines from where the marker went.
    #[test]
    fn a_dragged_marker_moves_a_light_or_turns_a_sun() {
        let center = Vec3::new(1.0, 0.0, 0.0);
        let mut point = voxgi::scene::Scene::default_sun();
        point.kind = LightKind::Point;
        point.position = Vec3::new(0.0, 2.0, 0.0);
        let by = Vec3::new(0.5, 0.0, -0.25);
        assert_eq!(
            dragged(&point, by, center, 3.0).position,
            point.position + by
        );

        let sun = voxgi::scene::Scene::default_sun();
        let turned = dragged(&sun, Vec3::new(0.7, 0.0, 0.0), center, 3.0);
        let from = anchor(&sun, center, 3.0) + Vec3::new(0.7, 0.0, 0.0);
        let want = (center - from).normalize();
        assert!(
            (turned.direction - want).length() < 1e-5,
            "{:?}",
            turned.direction
        );
        assert!((anchor(&turned, center, 3.0) - center).length() - 3.0 < 1e-4);
        assert_eq!(turned.position, sun.position, "a sun has no place to move");
    }
}
