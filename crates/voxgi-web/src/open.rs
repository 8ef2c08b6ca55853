//! Opening scenes on the page: a built-in scene from the panel's list, or files picked with
//! the file button or dropped onto the view. Picked and dropped files are read in the
//! browser and loaded together (`voxgi::scene::io::with_files`), so a scene's side files (an
//! OBJ's .mtl and textures, a glTF's .bin and images, a scene file's includes) come with it.
//! A file that fails to load shows its error on the page; the scene shown stays.

use crate::App;
use crate::page::{self, document};
use anyhow::{Context, Result, anyhow, bail};
use std::cell::RefCell;
use std::path::Path;
use std::rc::Rc;
use voxgi::scene::{Scene, builtin, io};
use wasm_bindgen::JsCast;
use wasm_bindgen_futures::JsFuture;

/// Scene files by preference when several are given: a scene file (which includes the
/// others), then models, then point clouds.
const MAIN_ORDER: &[&str] = &["toml", "glb", "gltf", "obj", "ply", "pcd", "cloud"];

/// Adds the scene list and the file button to the panel, and dropping onto the view.
pub(crate) fn build(app: &Rc<RefCell<App>>, shown: &str) -> Result<()> {
    let panel: web_sys::HtmlElement = page::element("panel")?;
    let doc = document();
    let make = |tag: &str| {
        doc.create_element(tag)
            .map_err(|_| anyhow!("cannot make a <{tag}>"))
    };
    let row = make("div")?;
    row.set_class_name("open");
    let select: web_sys::HtmlSelectElement = make("select")?.unchecked_into();
    select.set_id("scene");
    select.set_title("a built-in scene");
    for (name, help) in builtin::BUILTINS {
        let option = make("option")?;
        option.set_text_content(Some(name));
        option.set_attribute("value", name).ok();
        option.set_attribute("title", help).ok();
        select.append_child(&option).ok();
    }
    select.set_value(shown);
    let a = app.clone();
    let list = select.clone();
    page::on(select.as_ref(), "change", move |_: web_sys::Event| {
        let name = list.value();
        // Keys go back to the view (a list with the focus takes the arrows).
        let _ = list.blur();
        let a = a.clone();
        wasm_bindgen_futures::spawn_local(async move {
            page::message(&format!("opening {name}…"));
            page::next_paint().await;
            let opened = builtin::by_name(&name)
                .map_err(anyhow::Error::from)
                .and_then(|scene| a.borrow_mut().replace_scene(&scene, None, &name));
            report(opened, &name);
        });
    })?;
    row.append_child(&select).ok();

    let input: web_sys::HtmlInputElement = make("input")?.unchecked_into();
    input.set_type("file");
    input.set_id("file");
    input.set_multiple(true);
    input.set_title(&format!(
        "a scene ({}) with the files it refers to; or drop them onto the view",
        io::EXTENSIONS.join(", ")
    ));
    let a = app.clone();
    let picker = input.clone();
    page::on(input.as_ref(), "change", move |_: web_sys::Event| {
        if let Some(files) = picker.files() {
            open_files(a.clone(), files);
        }
        // The same file picked again is a change too.
        picker.set_value("");
        // Keys go back to the view (Space on the button would open the dialog again).
        let _ = picker.blur();
    })?;
    row.append_child(&input).ok();
    panel.append_child(&row).ok();

    let view: web_sys::HtmlElement = page::element("view")?;
    page::on(view.as_ref(), "dragover", |e: web_sys::DragEvent| {
        e.prevent_default();
    })?;
    let a = app.clone();
    page::on(view.as_ref(), "drop", move |e: web_sys::DragEvent| {
        e.prevent_default();
        if let Some(files) = e.data_transfer().and_then(|d| d.files()) {
            open_files(a.clone(), files);
        }
    })?;
    Ok(())
}

/// Reads `files` in the browser and opens the scene among them.
fn open_files(app: Rc<RefCell<App>>, files: web_sys::FileList) {
    let files: Vec<web_sys::File> = (0..files.length()).filter_map(|i| files.get(i)).collect();
    wasm_bindgen_futures::spawn_local(async move {
        let label = files
            .iter()
            .map(|f| f.name())
            .collect::<Vec<_>>()
            .join(", ");
        page::message(&format!("reading {label}…"));
        let opened = async {
            let mut read = Vec::with_capacity(files.len());
            for f in &files {
                let buffer = JsFuture::from(f.array_buffer())
                    .await
                    .map_err(|_| anyhow!("{}: the browser could not read it", f.name()))?;
                read.push((f.name(), js_sys::Uint8Array::new(&buffer).to_vec()));
            }
            let main = main_file(&read)?;
            page::message(&format!("opening {main}…"));
            page::next_paint().await;
            let (scene, settings) = load(read, &main)?;
            app.borrow_mut()
                .replace_scene(&scene, settings.as_ref(), &main)?;
            Ok::<String, anyhow::Error>(main)
        }
        .await;
        match opened {
            Ok(main) => report(Ok(()), &main),
            Err(e) => report(Err(e), &label),
        }
    });
}

fn report(opened: Result<()>, name: &str) {
    match opened {
        Ok(()) => page::message(&format!("opened {name}")),
        Err(e) => {
            page::message(&format!("{name} did not open; the scene shown stays"));
            page::show_error(&format!("{e:#}"));
        }
    }
}

/// The file to open among `files`: the first scene file by `MAIN_ORDER`.
fn main_file(files: &[(String, Vec<u8>)]) -> Result<String> {
    let ext = |name: &str| {
        Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
    };
    for wanted in MAIN_ORDER {
        if let Some((name, _)) = files
            .iter()
            .find(|(n, _)| ext(n).as_deref() == Some(*wanted))
        {
            return Ok(name.clone());
        }
    }
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    bail!(
        "none of {} is a scene voxgi reads ({})",
        names.join(", "),
        io::EXTENSIONS.join(", ")
    )
}

/// The scene in `main` (and a scene file's `[settings]`), its references read from `files`.
fn load(
    files: Vec<(String, Vec<u8>)>,
    main: &str,
) -> Result<(Scene, Option<voxgi::SceneSettings>)> {
    let path = Path::new(main);
    io::with_files(files, || {
        if main.to_ascii_lowercase().ends_with(".toml") {
            let (scene, table) = io::scene_file::load_with_settings(path)?;
            scene.validate().map_err(|e| e.in_file(path))?;
            let settings = table
                .as_ref()
                .map(voxgi::SceneSettings::from_table)
                .transpose()
                .with_context(|| main.to_string())?;
            Ok((scene, settings))
        } else {
            Ok((io::load(path)?, None))
        }
    })
}
