//! The settings panel, made from voxgi's one settings table (`voxgi::settings::SETTINGS`): a
//! widget per setting (a checkbox, a list of choices or a text field), its help as the
//! tooltip. A change is parsed and checked as a scene file's value would be, and applied as
//! the viewer applies it: per-frame parameters at once, options through
//! `Renderer::set_options` (which redoes only what depends on them). A value the renderer
//! refuses is marked and its reason shown; the renderer keeps what it had.

use crate::App;
use crate::page::{self, document};
use anyhow::{Result, anyhow};
use std::cell::RefCell;
use std::rc::Rc;
use voxgi::settings::{Changes, Domain, SETTINGS, Setting, Value};
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

/// Fills the page's `panel` element.
pub(crate) fn build(app: &Rc<RefCell<App>>) -> Result<()> {
    let panel: web_sys::HtmlElement = page::element("panel")?;
    let doc = document();
    let make = |tag: &str| {
        doc.create_element(tag)
            .map_err(|_| anyhow!("cannot make a <{tag}>"))
    };
    // Plays or pauses the scene's animation (disabled for a still scene).
    let play = make("button")?;
    play.set_id("play");
    let a = app.clone();
    listen(&play, "click", move || {
        let mut a = a.borrow_mut();
        a.toggle_play();
        show_playing(a.duration, a.playing);
    })?;
    append(&panel, &play)?;
    {
        let a = app.borrow();
        show_playing(a.duration, a.playing);
    }
    // What the view shows: cone tracing, the path tracer, or both split.
    let display: web_sys::HtmlSelectElement = make("select")?.unchecked_into();
    display.set_id("display");
    display.set_title("cone tracing, voxgi's path tracer (the ground truth), or both split");
    for (_, name) in crate::traced::Display::ALL {
        let option = make("option")?;
        option.set_text_content(Some(name));
        option.set_attribute("value", name).ok();
        append(&display, &option)?;
    }
    let a = app.clone();
    let list = display.clone();
    listen(&display, "change", move || {
        let chosen = list.value();
        let _ = list.blur();
        if let Some((d, _)) = crate::traced::Display::ALL
            .iter()
            .find(|(_, n)| *n == chosen)
        {
            a.borrow_mut().set_display(*d);
        }
    })?;
    append(&panel, &display)?;
    for setting in SETTINGS.iter() {
        let row = make("label")?;
        row.set_class_name("setting");
        row.set_attribute(
            "title",
            &format!("{} ({})", setting.help, setting.describe()),
        )
        .ok();
        let name = make("span")?;
        name.set_text_content(Some(setting.label));
        append(&row, &name)?;
        let value = {
            let a = app.borrow();
            setting.value(&a.options, &a.params)
        };
        let input = widget(setting, value)?;
        input.set_id(&format!("setting-{}", setting.key));
        // Those shape the uploaded scene: the query string sets them when the page opens.
        if setting.changes == Changes::Scene {
            input.set_attribute("disabled", "").ok();
        }
        let a = app.clone();
        let field = input.clone();
        // A text field applies when it is left or Enter is pressed.
        listen(&input, "change", move || {
            let text = read(&field);
            // Keys go back to the view once a value is in (a widget with the focus takes the
            // arrows and Space).
            if let Some(f) = field.dyn_ref::<web_sys::HtmlElement>() {
                let _ = f.blur();
            }
            let outcome = apply(&a, setting, &text);
            let classes = field.class_list();
            match outcome {
                Ok(()) => {
                    let _ = classes.remove_1("refused");
                    field.remove_attribute("title").ok();
                }
                Err(e) => {
                    let _ = classes.add_1("refused");
                    field.set_attribute("title", &e.to_string()).ok();
                    page::show_error(&format!("{}: {e}", setting.label));
                }
            }
        })?;
        append(&row, &input)?;
        append(&panel, &row)?;
    }
    Ok(())
}

/// Shows the options and parameters in use in the widgets (after a scene file's settings).
pub(crate) fn refresh(app: &App) {
    for setting in SETTINGS.iter() {
        let Some(field) = document().get_element_by_id(&format!("setting-{}", setting.key)) else {
            continue;
        };
        let value = setting.value(&app.options, &app.params);
        if let Some(input) = field.dyn_ref::<web_sys::HtmlInputElement>() {
            if input.type_() == "checkbox" {
                input.set_checked(value == Value::Bool(true));
            } else {
                input.set_value(&value.to_string());
            }
        } else if let Some(select) = field.dyn_ref::<web_sys::HtmlSelectElement>() {
            select.set_value(&value.to_string());
        }
        let _ = field.class_list().remove_1("refused");
    }
    show_playing(app.duration, app.playing);
}

/// The display list's choice (after the page changed it).
pub(crate) fn show_display(display: crate::traced::Display) {
    if let Some(list) = document()
        .get_element_by_id("display")
        .and_then(|e| e.dyn_into::<web_sys::HtmlSelectElement>().ok())
    {
        list.set_value(display.name());
    }
}

/// The play button's state: what pressing it does, or disabled for a still scene.
pub(crate) fn show_playing(duration: f32, playing: bool) {
    let Some(button) = document().get_element_by_id("play") else {
        return;
    };
    let text = match (duration > 0.0, playing) {
        (false, _) => "still scene",
        (true, true) => "pause the animation",
        (true, false) => "play the animation",
    };
    button.set_text_content(Some(text));
    if duration > 0.0 {
        button.remove_attribute("disabled").ok();
    } else {
        button.set_attribute("disabled", "").ok();
    }
}

/// The widget for `setting`, showing `value`.
fn widget(setting: &Setting, value: Value) -> Result<web_sys::Element> {
    let doc = document();
    let make = |tag: &str| {
        doc.create_element(tag)
            .map_err(|_| anyhow!("cannot make a <{tag}>"))
    };
    match setting.domain {
        Domain::Bool => {
            let input: web_sys::HtmlInputElement = make("input")?.unchecked_into();
            input.set_type("checkbox");
            input.set_checked(value == Value::Bool(true));
            Ok(input.into())
        }
        Domain::Choice(_) => {
            let select: web_sys::HtmlSelectElement = make("select")?.unchecked_into();
            for choice in setting.choices() {
                let option = make("option")?;
                option.set_text_content(Some(choice));
                option.set_attribute("value", choice).ok();
                append(&select, &option)?;
            }
            select.set_value(&value.to_string());
            Ok(select.into())
        }
        _ => {
            let input: web_sys::HtmlInputElement = make("input")?.unchecked_into();
            input.set_type("text");
            input.set_value(&value.to_string());
            Ok(input.into())
        }
    }
}

/// The widget's value as text, as a flag's argument would be written.
fn read(field: &web_sys::Element) -> String {
    if let Some(input) = field.dyn_ref::<web_sys::HtmlInputElement>() {
        if input.type_() == "checkbox" {
            return input.checked().to_string();
        }
        return input.value();
    }
    if let Some(select) = field.dyn_ref::<web_sys::HtmlSelectElement>() {
        return select.value();
    }
    String::new()
}

/// Parses, checks and applies `text` as `setting`'s new value.
fn apply(app: &Rc<RefCell<App>>, setting: &Setting, text: &str) -> voxgi::Result<()> {
    let value = setting.parse(text)?;
    let mut a = app.borrow_mut();
    setting.check(value, a.options.voxels)?;
    let mut options = a.options.clone();
    let mut params = a.params.clone();
    setting.set(&mut options, &mut params, value);
    if setting.per_frame() {
        params.validate(options.voxel_levels())?;
        a.params = params;
        Ok(())
    } else {
        a.set_options(options)
    }
}

fn append(parent: &web_sys::Node, child: &web_sys::Node) -> Result<()> {
    parent
        .append_child(child)
        .map(|_| ())
        .map_err(|_| anyhow!("cannot build the panel"))
}

/// Calls `handler` on each `event` of `element` for the page's lifetime.
fn listen(
    element: &web_sys::Element,
    event: &str,
    mut handler: impl FnMut() + 'static,
) -> Result<()> {
    let closure = Closure::<dyn FnMut()>::new(move || handler());
    element
        .add_event_listener_with_callback(event, closure.as_ref().unchecked_ref())
        .map_err(|_| anyhow!("cannot listen to {event}"))?;
    closure.forget();
    Ok(())
}
