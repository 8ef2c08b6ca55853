//! Input: the window's events dispatched (keys, mouse buttons, cursor, wheel, dropped files),
//! raw mouse motion, the key bindings, and the camera controllers (orbit and fly) they drive.

use super::Viewer;
use crate::camera::{Fly, HeldKeys, Orbit};
use crate::ground_truth::Display;
use anyhow::Result;
use std::collections::HashSet;
use std::time::Instant;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};

/// The keys the viewer binds (`key_pressed`, and flying's held keys).
const VIEWER_KEYS: &[KeyCode] = &[
    KeyCode::KeyF,
    KeyCode::KeyH,
    KeyCode::KeyG,
    KeyCode::Space,
    KeyCode::Tab,
    KeyCode::F12,
    KeyCode::KeyP,
    KeyCode::KeyW,
    KeyCode::KeyA,
    KeyCode::KeyS,
    KeyCode::KeyD,
    KeyCode::KeyQ,
    KeyCode::KeyE,
    KeyCode::ArrowUp,
    KeyCode::ArrowDown,
    KeyCode::ArrowLeft,
    KeyCode::ArrowRight,
    KeyCode::Digit1,
    KeyCode::Digit3,
    KeyCode::Digit5,
    KeyCode::Digit7,
    KeyCode::Numpad1,
    KeyCode::Numpad3,
    KeyCode::Numpad5,
    KeyCode::Numpad7,
    KeyCode::KeyO,
    KeyCode::Escape,
    KeyCode::KeyL,
    KeyCode::KeyX,
    KeyCode::KeyK,
    KeyCode::KeyB,
];

/// The fly keys: the axis each pushes along (0 right, 1 up, 2 forward) and which way.
fn fly_key(code: KeyCode) -> Option<(usize, bool)> {
    Some(match code {
        KeyCode::KeyD | KeyCode::ArrowRight => (0, true),
        KeyCode::KeyA | KeyCode::ArrowLeft => (0, false),
        KeyCode::KeyE => (1, true),
        KeyCode::KeyQ => (1, false),
        KeyCode::KeyW | KeyCode::ArrowUp => (2, true),
        KeyCode::KeyS | KeyCode::ArrowDown => (2, false),
        _ => return None,
    })
}

pub(super) enum Controller {
    Orbit(Orbit),
    Fly(Fly),
}

/// What the keyboard and the mouse hold.
#[derive(Default)]
pub(super) struct Input {
    keys: HashSet<KeyCode>,
    /// How long the fly keys were held.
    fly: HeldKeys,
    left_down: bool,
    right_down: bool,
    cursor: Option<(f32, f32)>,
}

impl Viewer {
    pub(super) fn window_event(
        &mut self,
        event_loop: &ActiveEventLoop,
        event: WindowEvent,
    ) -> Result<()> {
        let shows_on_screen = match &event {
            WindowEvent::KeyboardInput { event, .. } => event.state == ElementState::Pressed,
            WindowEvent::MouseInput { .. } | WindowEvent::MouseWheel { .. } => true,
            WindowEvent::CursorMoved { .. } => self.input.left_down || self.input.right_down,
            _ => false,
        };
        if shows_on_screen {
            self.stats.input_arrived();
        }
        // The viewer's keys are its own unless a text field is being typed in: egui would take
        // Tab for moving the focus between widgets, and, once a button had the focus, every
        // key after it, until the view was clicked.
        if let WindowEvent::KeyboardInput { event: key, .. } = &event
            && let PhysicalKey::Code(code) = key.physical_key
            && VIEWER_KEYS.contains(&code)
            && !self.egui_ctx.text_edit_focused()
        {
            let now = Instant::now();
            if key.state == ElementState::Pressed {
                if !key.repeat {
                    self.key_pressed(code);
                }
                if let Some((axis, positive)) = fly_key(code) {
                    self.input.fly.press(axis, positive, now);
                }
                self.input.keys.insert(code);
                self.egui_ctx.memory_mut(|m| {
                    if let Some(id) = m.focused() {
                        m.surrender_focus(id);
                    }
                });
            } else {
                if let Some((axis, positive)) = fly_key(code) {
                    self.input.fly.release(axis, positive, now);
                }
                self.input.keys.remove(&code);
            }
            return Ok(());
        }
        let response = self.egui_state.on_window_event(&self.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size),
            WindowEvent::RedrawRequested if self.redraw()? => event_loop.exit(),
            WindowEvent::DroppedFile(path) => self.open(&path),
            // Keys released while another window had the keyboard never arrive here.
            WindowEvent::Focused(false) => {
                let now = Instant::now();
                for code in std::mem::take(&mut self.input.keys) {
                    if let Some((axis, positive)) = fly_key(code) {
                        self.input.fly.release(axis, positive, now);
                    }
                }
            }
            // A release always ends a drag or a held key, even over the panel: swallowed, it
            // would leave the camera turning or flying.
            WindowEvent::MouseInput {
                state: ElementState::Released,
                button,
                ..
            } => match button {
                MouseButton::Left => self.input.left_down = false,
                MouseButton::Right | MouseButton::Middle => self.input.right_down = false,
                _ => {}
            },
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Released => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    self.input.keys.remove(&code);
                }
            }
            // Over the panel the wheel scrolls it and a press is the panel's, whatever egui
            // knew of the pointer at its last frame (a slow frame's was out of date, and the
            // wheel zoomed the camera).
            WindowEvent::MouseWheel { .. } | WindowEvent::MouseInput { .. }
                if self.over_panel() => {}
            _ if response.consumed => {}
            // Presses only: releases were taken above.
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    if !event.repeat {
                        self.key_pressed(code);
                    }
                    self.input.keys.insert(code);
                }
            }
            WindowEvent::MouseInput { button, .. } => match button {
                MouseButton::Left => self.input.left_down = true,
                MouseButton::Right | MouseButton::Middle => self.input.right_down = true,
                _ => {}
            },
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x as f32, position.y as f32);
                if let Some(last) = self.input.cursor
                    && let Controller::Orbit(o) = &mut self.controller
                {
                    let (dx, dy) = (p.0 - last.0, p.1 - last.1);
                    if self.input.left_down {
                        o.rotate(dx, dy);
                    } else if self.input.right_down {
                        o.pan(dx, dy, self.config.height as f32);
                    }
                }
                self.input.cursor = Some(p);
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

    /// The orbit (from the view as it is, when flying) looking along preset `i`
    /// (`camera::PRESETS`).
    pub(super) fn view_preset(&mut self, i: usize) {
        let mut o = self.orbit();
        o.view_along(crate::camera::PRESETS[i].1);
        self.controller = Controller::Orbit(o);
        // A cut to another view: nothing of the last view's history belongs in it.
        self.renderer.reset_history();
    }

    /// Switches between the perspective and the orthographic view (an orbit's).
    pub(super) fn toggle_ortho(&mut self) {
        let mut o = self.orbit();
        o.ortho = !o.ortho;
        self.controller = Controller::Orbit(o);
        self.renderer.reset_history();
    }

    /// The orbit, or one that sees what the fly camera sees.
    fn orbit(&self) -> Orbit {
        match &self.controller {
            Controller::Orbit(o) => o.clone(),
            Controller::Fly(f) => Orbit::from_camera(&f.camera(), self.scene_radius),
        }
    }

    /// Whether the cursor is over the settings panel.
    pub(super) fn over_panel(&self) -> bool {
        self.input
            .cursor
            .is_some_and(|(x, _)| x < self.panel_px as f32)
    }

    /// Raw mouse motion: mouse look while flying with the left button held.
    pub(super) fn mouse_motion(&mut self, dx: f32, dy: f32) {
        if let Controller::Fly(f) = &mut self.controller
            && self.input.left_down
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
            KeyCode::KeyH => self.frame_selection(),
            KeyCode::Escape => self.selected_light = None,
            KeyCode::KeyG => {
                let i = Display::ALL.iter().position(|d| *d == self.ground.display);
                self.set_display(Display::ALL[(i.unwrap_or(0) + 1) % Display::ALL.len()]);
            }
            KeyCode::Digit1 | KeyCode::Numpad1 => self.view_preset(0),
            KeyCode::Digit3 | KeyCode::Numpad3 => self.view_preset(1),
            KeyCode::Digit7 | KeyCode::Numpad7 => self.view_preset(2),
            KeyCode::Digit5 | KeyCode::Numpad5 => self.toggle_ortho(),
            KeyCode::KeyO => self.frame_overlay = !self.frame_overlay,
            KeyCode::KeyL => self.show_gizmos = !self.show_gizmos,
            KeyCode::KeyK => self.show_grid = !self.show_grid,
            KeyCode::KeyB => self.bookmark(),
            KeyCode::KeyX => {
                self.export_dialog.open = true;
                self.export_dialog.focus_file = true;
            }
            KeyCode::Space => self.playing = !self.playing,
            KeyCode::Tab => self.show_panel = !self.show_panel,
            KeyCode::F12 | KeyCode::KeyP => self.screenshot_key = true,
            _ => {}
        }
    }

    /// The frame's camera motion: flying for as long as the keys were held since the last
    /// frame, or the orbit's turntable turn.
    pub(super) fn move_camera(&mut self) {
        let (movement, secs) = self.input.fly.take(Instant::now());
        if let Controller::Fly(f) = &mut self.controller {
            f.step(movement, secs);
        }
        if let Controller::Orbit(o) = &mut self.controller
            && self.turntable != 0.0
        {
            o.turn(self.turntable.to_radians());
        }
    }

    /// The controller's camera.
    pub(super) fn controller_camera(&self) -> voxgi::scene::Camera {
        match &self.controller {
            Controller::Orbit(o) => o.camera(),
            Controller::Fly(f) => f.camera(),
        }
    }
}
