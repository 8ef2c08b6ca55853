//! Input: the window's events dispatched (keys, mouse buttons, cursor, wheel, dropped files),
//! raw mouse motion, the key bindings, and the camera controllers (orbit and fly) they drive.

use super::Viewer;
use crate::camera::{Fly, HeldKeys, Orbit};
use crate::ground_truth::Display;
use anyhow::Result;
use std::collections::{HashSet, VecDeque};
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
    /// Pointer events held for egui's next frame (`holds_for_next_frame`), in order.
    held: VecDeque<WindowEvent>,
    /// In the events egui's next frame gets: a button went down or up, the pointer moved,
    /// with a button down.
    batch_button: bool,
    batch_moved: bool,
    batch_moved_down: bool,
    /// A button is down as egui was told (`left_down` and `right_down` are the 3D view's).
    egui_down: bool,
}

/// What a pointer event does, for `Input::holds`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pointer {
    Moved,
    Pressed,
    Released,
    Wheel,
}

impl Input {
    /// egui took this frame's events: the next batch starts.
    pub(super) fn batch_taken(&mut self) {
        self.batch_button = false;
        self.batch_moved = false;
        self.batch_moved_down = false;
    }

    /// Whether a pointer event waits for egui's next frame (else it goes into this one's
    /// batch). egui sees a frame's events all at once: a click or a drag whose press and
    /// release fell in one slow frame (a few hundred milliseconds on a CPU driver) was lost (the
    /// time slider's quick click, a 0.75 s drag of the split view's divider), and egui picks
    /// what a press grabs by where the pointer is at the end of the press's frame. So a batch
    /// gets one button change at most; a press shares one neither with the moves before it
    /// (the frame's delta would count them as dragged) nor with those after it (the pointer
    /// would have left the widget); a release shares one neither with its press nor with a
    /// move while a button is down; and what comes after an event held back is held back too.
    /// `queued`: events are held already; `ui`: the pointer is over egui's widgets (else
    /// nothing is held: the 3D view's own drags need none of it).
    fn holds(&mut self, p: Pointer, queued: bool, ui: bool) -> bool {
        let hold = ui
            && match p {
                Pointer::Pressed => self.batch_button || self.batch_moved,
                Pointer::Released => self.batch_button || self.batch_moved_down,
                Pointer::Moved => self.batch_button && self.egui_down,
                Pointer::Wheel => false,
            };
        if hold || queued {
            return true;
        }
        match p {
            Pointer::Pressed | Pointer::Released => {
                self.batch_button = true;
                self.egui_down = p == Pointer::Pressed;
                self.batch_moved_down = self.egui_down;
            }
            Pointer::Moved => {
                self.batch_moved = true;
                self.batch_moved_down |= self.egui_down;
            }
            Pointer::Wheel => {}
        }
        false
    }
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
        if self.holds_for_next_frame(&event) {
            self.input.held.push_back(event);
            return Ok(());
        }
        let response = self.egui_state.on_window_event(&self.window, &event);
        match event {
            WindowEvent::RedrawRequested => {
                // What waited for this frame goes in first (in order; what is still too much
                // for it waits again).
                for held in std::mem::take(&mut self.input.held) {
                    self.window_event(event_loop, held)?;
                }
                if self.redraw()? {
                    event_loop.exit();
                }
            }
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size),
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
    /// Whether a pointer event waits for egui's next frame (`Input::holds`).
    fn holds_for_next_frame(&mut self, event: &WindowEvent) -> bool {
        let pointer = match event {
            WindowEvent::MouseInput { state, .. } => match state {
                ElementState::Pressed => Pointer::Pressed,
                ElementState::Released => Pointer::Released,
            },
            WindowEvent::CursorMoved { .. } => Pointer::Moved,
            WindowEvent::MouseWheel { .. } => Pointer::Wheel,
            _ => return false,
        };
        let queued = !self.input.held.is_empty();
        // Over the 3D view (no widget under the pointer, none dragged) nothing waits: an orbit
        // drag started two slow frames late.
        let ui = self.over_panel()
            || self.egui_ctx.is_pointer_over_egui()
            || self.egui_ctx.dragged_id().is_some();
        self.input.holds(pointer, queued, ui)
    }

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
                // Switching is not moving: a flight followed goes on.
                if self.flown.is_some() {
                    self.flown = Some(self.controller_camera());
                }
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

/// Below this many points a wheel step is not eased by egui (its "smooth" input).
const UNEASED_STEP: f32 = 7.5;

/// Makes this batch's wheel notches scroll in full in the frame they arrive. egui eases a
/// notch in over frames, each frame advancing the easing by at most 0.1 s (`stable_dt`
/// capped), whatever the frame's real length: at a CPU driver's two frames a second the panel
/// crept on for seconds after a scroll, moving under the pointer (a click right after it
/// missed the widget it aimed at). A notch is given instead as steps of points small enough
/// that egui applies them at once (`line` and `page`: points per line and per page).
pub(super) fn wheel_at_once(events: &mut Vec<egui::Event>, line: f32, page: f32) {
    let mut out = Vec::with_capacity(events.len());
    for e in events.drain(..) {
        let egui::Event::MouseWheel {
            unit,
            delta,
            modifiers,
            phase,
            source,
        } = e
        else {
            out.push(e);
            continue;
        };
        let points = match unit {
            egui::MouseWheelUnit::Point => delta,
            egui::MouseWheelUnit::Line => delta * line,
            egui::MouseWheelUnit::Page => delta * page,
        };
        if !points.is_finite() {
            continue;
        }
        // A notch of a few lines is a handful of steps; a page at most 64.
        let steps = (points.length() / UNEASED_STEP).ceil().clamp(1.0, 64.0);
        for _ in 0..steps as usize {
            out.push(egui::Event::MouseWheel {
                unit: egui::MouseWheelUnit::Point,
                delta: points / steps,
                modifiers,
                phase,
                source,
            });
        }
    }
    *events = out;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `events` as they arrive, `|` marking where egui takes a frame's batch; returns
    /// the batches egui gets (held events go in first at each frame, as `window_event` does).
    fn batches(events: &str) -> Vec<Vec<Pointer>> {
        let mut input = Input::default();
        let mut held: VecDeque<Pointer> = VecDeque::new();
        let mut batch = Vec::new();
        let mut out = Vec::new();
        let feed = |input: &mut Input, held: &mut VecDeque<Pointer>, p, batch: &mut Vec<_>| {
            let queued = !held.is_empty();
            if input.holds(p, queued, true) {
                held.push_back(p);
            } else {
                batch.push(p);
            }
        };
        let frame = |input: &mut Input, held: &mut VecDeque<Pointer>, batch: &mut Vec<Pointer>| {
            for p in std::mem::take(held) {
                let queued = !held.is_empty();
                if input.holds(p, queued, true) {
                    held.push_back(p);
                } else {
                    batch.push(p);
                }
            }
            input.batch_taken();
            std::mem::take(batch)
        };
        for c in events.chars() {
            match c {
                'm' => feed(&mut input, &mut held, Pointer::Moved, &mut batch),
                'p' => feed(&mut input, &mut held, Pointer::Pressed, &mut batch),
                'r' => feed(&mut input, &mut held, Pointer::Released, &mut batch),
                'w' => feed(&mut input, &mut held, Pointer::Wheel, &mut batch),
                '|' => out.push(frame(&mut input, &mut held, &mut batch)),
                _ => {}
            }
        }
        while !held.is_empty() || !batch.is_empty() {
            out.push(frame(&mut input, &mut held, &mut batch));
        }
        out
    }

    /// A drag within one slow frame (move onto the divider, press, three moves, release) comes
    /// out as egui needs it: the hover, the press alone, the moves with the button down, the
    /// release; a quick click as a press and a release a frame apart; moves and the wheel in a
    /// frame with nothing pressed are not held.
    #[test]
    fn a_drag_within_one_slow_frame_reaches_egui_over_four() {
        use Pointer::*;
        assert_eq!(
            batches("mpmmmr|"),
            vec![
                vec![Moved],
                vec![Pressed],
                vec![Moved, Moved, Moved],
                vec![Released]
            ]
        );
        assert_eq!(batches("|pr|"), vec![vec![], vec![Pressed], vec![Released]]);
        assert_eq!(
            batches("mmwm|mm|"),
            vec![vec![Moved, Moved, Wheel, Moved], vec![Moved, Moved]]
        );
        // Over the 3D view nothing waits: an orbit drag starts in its first frame.
        let mut input = Input::default();
        for p in [Moved, Pressed, Moved, Moved, Released] {
            assert!(!input.holds(p, false, false), "{p:?} held over the view");
        }
        // Moves while the button is down, frame after frame, are not held back.
        assert_eq!(
            batches("p|mm|mm|r|"),
            vec![
                vec![Pressed],
                vec![Moved, Moved],
                vec![Moved, Moved],
                vec![Released]
            ]
        );
    }

    /// A scroll area's offset in the frame of a notch of the wheel: its whole 3 lines with
    /// `wheel_at_once`, against the 90 % egui's easing gives a frame of 0.1 s or more (the
    /// rest over the next frames).
    #[test]
    fn a_wheel_notch_scrolls_in_full_in_its_frame() {
        let offset_after_notch = |at_once: bool| {
            let ctx = egui::Context::default();
            let run = |events: Vec<egui::Event>, time: f64| {
                let mut raw = egui::RawInput {
                    screen_rect: Some(egui::Rect::from_min_size(
                        egui::Pos2::ZERO,
                        egui::vec2(300.0, 200.0),
                    )),
                    time: Some(time),
                    predicted_dt: 0.5,
                    events,
                    ..Default::default()
                };
                if at_once {
                    let line = ctx.options(|o| o.input_options.line_scroll_speed);
                    wheel_at_once(&mut raw.events, line, 200.0);
                }
                let mut offset = 0.0;
                let _ = ctx.run_ui(raw, |ui| {
                    egui::CentralPanel::default().show(ui, |ui| {
                        let out = egui::ScrollArea::vertical().show(ui, |ui| {
                            for i in 0..200 {
                                ui.label(format!("row {i}"));
                            }
                        });
                        offset = out.state.unclamped_offset().y;
                    });
                });
                offset
            };
            run(vec![egui::Event::PointerMoved(egui::pos2(50.0, 50.0))], 0.0);
            run(vec![egui::Event::PointerMoved(egui::pos2(50.0, 50.0))], 0.5);
            let notch = egui::Event::MouseWheel {
                unit: egui::MouseWheelUnit::Line,
                delta: egui::vec2(0.0, -3.0),
                modifiers: Default::default(),
                phase: egui::TouchPhase::Move,
                source: egui::MouseWheelSource::Wheel,
            };
            run(vec![notch], 1.0)
        };
        let line = egui::Context::default().options(|o| o.input_options.line_scroll_speed);
        let (eased, at_once) = (offset_after_notch(false), offset_after_notch(true));
        eprintln!("3 lines of {line} points: eased {eased}, at once {at_once}");
        assert!((at_once - 3.0 * line).abs() < 0.5, "at once: {at_once}");
        assert!(eased < 0.95 * 3.0 * line, "eased: {eased}");
    }
}
