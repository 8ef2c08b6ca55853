//! The page around the canvas: its elements (web/index.html names them), the status line and
//! errors, the console logger, pointer input and the animation-frame loop.

use crate::App;
use anyhow::{Result, anyhow};
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

pub(crate) fn window() -> web_sys::Window {
    web_sys::window().expect("a page has a window")
}

pub(crate) fn document() -> web_sys::Document {
    window().document().expect("a page has a document")
}

/// The element with id `id`, as the type the page gives it.
pub(crate) fn element<T: JsCast>(id: &str) -> Result<T> {
    document()
        .get_element_by_id(id)
        .ok_or_else(|| anyhow!("the page has no element '{id}'"))?
        .dyn_into::<T>()
        .map_err(|_| anyhow!("the page's element '{id}' is not of the expected kind"))
}

/// The query string's pairs, decoded, in order.
pub(crate) fn query() -> Vec<(String, String)> {
    let search = window().location().search().unwrap_or_default();
    let Ok(params) = web_sys::UrlSearchParams::new_with_str(&search) else {
        return Vec::new();
    };
    let mut pairs = Vec::new();
    for entry in js_sys::try_iter(&params)
        .ok()
        .flatten()
        .into_iter()
        .flatten()
    {
        let Ok(entry) = entry else { continue };
        let pair: js_sys::Array = entry.unchecked_into();
        if let (Some(k), Some(v)) = (pair.get(0).as_string(), pair.get(1).as_string()) {
            pairs.push((k, v));
        }
    }
    pairs
}

/// Milliseconds since the page began loading.
pub(crate) fn now_ms() -> f64 {
    window().performance().map_or(0.0, |p| p.now())
}

fn set_text(id: &str, text: &str) {
    if let Some(e) = document().get_element_by_id(id) {
        e.set_text_content(Some(text));
    }
}

/// The status line under the canvas.
pub(crate) fn status(text: &str) {
    set_text("status", text);
}

/// What the last thing asked for did (a scene opened or not): its own line, which the frame
/// count does not overwrite.
pub(crate) fn message(text: &str) {
    set_text("message", text);
}

/// What the adapter and its limits are.
pub(crate) fn set_adapter(text: &str) {
    set_text("adapter", text);
}

/// The scene shown, in the page's title and its `data-scene` (for scripts).
pub(crate) fn set_scene(name: &str) {
    let doc = document();
    doc.set_title(&format!("voxgi — {name}"));
    if let Some(body) = doc.body() {
        let _ = body.set_attribute("data-scene", name);
    }
}

/// What the renderer chose for this device (structure, resolution, memory).
pub(crate) fn set_choices(text: &str) {
    set_text("choices", text);
}

/// Shows an error on the page (and in the console): the page stays, the loop may stop.
pub(crate) fn show_error(text: &str) {
    web_sys::console::error_1(&JsValue::from_str(text));
    if let Some(e) = document().get_element_by_id("error") {
        let old = e.text_content().unwrap_or_default();
        // The first error is the cause; a few more are worth seeing, not a flood.
        if old.lines().count() < 4 {
            let joined = if old.is_empty() {
                text.to_string()
            } else {
                format!("{old}\n{text}")
            };
            e.set_text_content(Some(&joined));
        }
        let _ = e.class_list().remove_1("hidden");
    }
}

/// A click on the error box dismisses it.
pub(crate) fn dismissable_errors() -> Result<()> {
    let e: web_sys::HtmlElement = element("error")?;
    let target = e.clone();
    on(e.as_ref(), "click", move |_: web_sys::MouseEvent| {
        target.set_text_content(None);
        let _ = target.class_list().add_1("hidden");
    })
}

/// Records the frames the GPU finished on the page (`data-frames` on the body, for tests and
/// scripts) and the status line: the time to the first frame and the smoothed frame time.
pub(crate) fn frames_done(frames: u32, first_ms: Option<f64>, frame_ms: Option<f64>) {
    if let Some(body) = document().body() {
        let _ = body.set_attribute("data-frames", &frames.to_string());
        if let Some(f) = first_ms {
            let _ = body.set_attribute("data-first-frame-ms", &format!("{f:.0}"));
        }
        if let Some(ms) = frame_ms {
            let _ = body.set_attribute("data-frame-ms", &format!("{ms:.1}"));
        }
    }
    let first = first_ms.map_or(String::new(), |f| {
        format!("first frame after {:.1} s", f / 1000.0)
    });
    let each = frame_ms.map_or(String::new(), |ms| format!(" · {ms:.0} ms a frame"));
    status(&format!("{frames} frames · {first}{each}"));
}

/// The canvas's drawing size: its size on the page in CSS pixels (at least 64, at most the
/// device's largest texture), written back to the canvas when it changed.
pub(crate) fn canvas_size(canvas: &web_sys::HtmlCanvasElement, max: u32) -> (u32, u32) {
    let fit = |v: i32| (v.max(64) as u32).min(max);
    let (w, h) = (fit(canvas.client_width()), fit(canvas.client_height()));
    if canvas.width() != w {
        canvas.set_width(w);
    }
    if canvas.height() != h {
        canvas.set_height(h);
    }
    (w, h)
}

/// Logs warnings and errors to the browser's console.
pub(crate) fn init_logging() {
    struct Console;
    impl log::Log for Console {
        fn enabled(&self, m: &log::Metadata) -> bool {
            m.level() <= log::Level::Warn
        }
        fn log(&self, r: &log::Record) {
            if !self.enabled(r.metadata()) {
                return;
            }
            let text = JsValue::from_str(&format!("{}: {}", r.target(), r.args()));
            match r.level() {
                log::Level::Error => web_sys::console::error_1(&text),
                _ => web_sys::console::warn_1(&text),
            }
        }
        fn flush(&self) {}
    }
    static CONSOLE: Console = Console;
    if log::set_logger(&CONSOLE).is_ok() {
        log::set_max_level(log::LevelFilter::Warn);
    }
}

/// A pointer event on the canvas, in CSS pixels.
pub(crate) enum Pointer {
    Down { x: f32, y: f32, pan: bool },
    Move { x: f32, y: f32 },
    Up,
    Wheel { steps: f32 },
}

/// Adds `handler` for `event` on `target` for the page's lifetime.
pub(crate) fn on<E: JsCast + 'static>(
    target: &web_sys::EventTarget,
    event: &str,
    mut handler: impl FnMut(E) + 'static,
) -> Result<()> {
    let closure = Closure::<dyn FnMut(web_sys::Event)>::new(move |e: web_sys::Event| {
        if let Ok(e) = e.dyn_into::<E>() {
            handler(e);
        }
    });
    target
        .add_event_listener_with_callback(event, closure.as_ref().unchecked_ref())
        .map_err(|_| anyhow!("cannot listen to {event}"))?;
    // The page keeps its listeners until it closes.
    closure.forget();
    Ok(())
}

/// Drags turn the orbit (the right button or shift pans), the wheel zooms, a double click or H
/// goes back to the scene's camera, F flies (WASD/arrows, Q/E), space plays or pauses an
/// animation.
pub(crate) fn listen_input(app: &Rc<RefCell<App>>) -> Result<()> {
    let canvas: web_sys::HtmlCanvasElement = element("voxgi")?;
    let target: &web_sys::EventTarget = canvas.as_ref();
    let a = app.clone();
    let c = canvas.clone();
    on(target, "pointerdown", move |e: web_sys::PointerEvent| {
        let _ = c.set_pointer_capture(e.pointer_id());
        let pan = e.button() == 2 || e.shift_key();
        a.borrow_mut().pointer(Pointer::Down {
            x: e.offset_x() as f32,
            y: e.offset_y() as f32,
            pan,
        });
    })?;
    let a = app.clone();
    on(target, "pointermove", move |e: web_sys::PointerEvent| {
        a.borrow_mut().pointer(Pointer::Move {
            x: e.offset_x() as f32,
            y: e.offset_y() as f32,
        });
    })?;
    for up in ["pointerup", "pointercancel"] {
        let a = app.clone();
        on(target, up, move |_: web_sys::PointerEvent| {
            a.borrow_mut().pointer(Pointer::Up)
        })?;
    }
    let a = app.clone();
    on(target, "wheel", move |e: web_sys::WheelEvent| {
        e.prevent_default();
        // A wheel notch is about 100 pixels of delta in every browser's default mode.
        let steps = (-e.delta_y() / 100.0) as f32;
        a.borrow_mut().pointer(Pointer::Wheel { steps });
    })?;
    on(target, "contextmenu", |e: web_sys::MouseEvent| {
        e.prevent_default()
    })?;
    let a = app.clone();
    on(target, "dblclick", move |_: web_sys::MouseEvent| {
        a.borrow_mut().frame_scene()
    })?;
    // Keys reach the view unless a panel field has the focus (typing a value).
    let typing = |e: &web_sys::KeyboardEvent| {
        e.target()
            .and_then(|t| t.dyn_into::<web_sys::Element>().ok())
            .is_some_and(|el| matches!(el.tag_name().as_str(), "INPUT" | "SELECT" | "TEXTAREA"))
    };
    let page: web_sys::EventTarget = window().into();
    let a = app.clone();
    on(&page, "keydown", move |e: web_sys::KeyboardEvent| {
        if typing(&e) || e.ctrl_key() || e.meta_key() || e.alt_key() {
            return;
        }
        let code = e.code();
        if let Some((axis, positive)) = fly_key(&code) {
            e.prevent_default();
            if !e.repeat() {
                a.borrow_mut().fly_key(axis, positive, true);
            }
            return;
        }
        match code.as_str() {
            "KeyF" => a.borrow_mut().toggle_fly(),
            "KeyH" => a.borrow_mut().frame_scene(),
            "Space" => {
                e.prevent_default();
                let mut a = a.borrow_mut();
                a.toggle_play();
                crate::panel::show_playing(a.duration, a.playing);
            }
            _ => {}
        }
    })?;
    let a = app.clone();
    on(&page, "keyup", move |e: web_sys::KeyboardEvent| {
        if let Some((axis, positive)) = fly_key(&e.code()) {
            a.borrow_mut().fly_key(axis, positive, false);
        }
    })?;
    // A key released while the page had no focus never comes up here.
    let a = app.clone();
    on(&page, "blur", move |_: web_sys::Event| {
        a.borrow_mut().release_keys()
    })?;
    Ok(())
}

/// The fly keys, as the viewer's: the axis each pushes along (0 right, 1 up, 2 forward) and
/// which way.
fn fly_key(code: &str) -> Option<(usize, bool)> {
    Some(match code {
        "KeyD" | "ArrowRight" => (0, true),
        "KeyA" | "ArrowLeft" => (0, false),
        "KeyE" => (1, true),
        "KeyQ" => (1, false),
        "KeyW" | "ArrowUp" => (2, true),
        "KeyS" | "ArrowDown" => (2, false),
        _ => return None,
    })
}

/// Says on the page whether the camera flies (and how) or orbits.
pub(crate) fn set_controller(flying: bool) {
    set_text(
        "controller",
        if flying {
            "flying: WASD or the arrows move, Q/E down and up, drag to look, wheel for speed; F orbits"
        } else {
            "orbiting: F flies"
        },
    );
    if let Some(body) = document().body() {
        let _ = body.set_attribute("data-camera", if flying { "fly" } else { "orbit" });
    }
}

/// Renders a frame on every animation frame the browser gives, for the page's lifetime.
pub(crate) fn animation_loop(app: Rc<RefCell<App>>) {
    type Tick = Closure<dyn FnMut(f64)>;
    let tick: Rc<RefCell<Option<Tick>>> = Rc::new(RefCell::new(None));
    let next = tick.clone();
    *tick.borrow_mut() = Some(Closure::new(move |now_ms: f64| {
        app.borrow_mut().frame(now_ms);
        if let Some(t) = next.borrow().as_ref() {
            let _ = window().request_animation_frame(t.as_ref().unchecked_ref());
        }
    }));
    if let Some(t) = tick.borrow().as_ref() {
        let _ = window().request_animation_frame(t.as_ref().unchecked_ref());
    }
}

/// Resolves after the browser painted once more: work that blocks the page (opening a
/// scene) lets the status line say so first.
pub(crate) async fn next_paint() {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        let after_paint = Closure::once_into_js(move || {
            let _ = window().set_timeout_with_callback(resolve.unchecked_ref());
        });
        let _ = window().request_animation_frame(after_paint.unchecked_ref());
    });
    let _ = wasm_bindgen_futures::JsFuture::from(promise).await;
}
