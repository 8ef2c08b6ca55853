//! Saving the view into the scene file: the camera as its `[camera]`, the bookmarks as its
//! `[[view]]`s, the settings changed in the window into `[settings]`, and the file's own
//! `[[light]]`s as edited. The file is edited in place (its comments, its order and what the
//! window does not change are kept); a scene opened from another format, or a built-in one,
//! gets a scene file of its own that includes it.

use super::Viewer;
use anyhow::{Context, Result, bail};
use glam::Vec3;
use std::path::{Path, PathBuf};
use toml_edit::{ArrayOfTables, DocumentMut, Item, Table, value};
use voxgi::scene::{Camera, Light, LightKind, Projection};
use voxgi::settings::SETTINGS;
use voxgi::{FrameParams, RendererOptions};

/// Where the scene came from: what the view is saved into.
#[derive(Clone, Debug)]
pub(super) enum Source {
    /// A scene file: saved into it.
    SceneFile(PathBuf),
    /// A model in another format: saved into `<model>.toml` beside it, which includes it.
    Model(PathBuf),
    /// A built-in scene: saved into `voxgi_<name>.toml` here, which includes it.
    Builtin(String),
}

impl Source {
    /// The scene file the view goes into.
    pub(super) fn target(&self) -> PathBuf {
        match self {
            Source::SceneFile(p) => p.clone(),
            Source::Model(p) => p.with_extension("toml"),
            Source::Builtin(name) => PathBuf::from(format!("voxgi_{name}.toml")),
        }
    }

    /// The `[[include]]` a new scene file gets.
    fn include(&self) -> Option<Table> {
        let mut t = Table::new();
        match self {
            Source::SceneFile(_) => return None,
            Source::Model(p) => {
                let name = p.file_name()?.to_string_lossy().into_owned();
                t["file"] = value(name);
            }
            Source::Builtin(name) => t["builtin"] = value(name.as_str()),
        }
        Some(t)
    }
}

/// What is saved.
pub(super) struct Saved<'a> {
    /// The camera, and the point it turns about (the orbit's target).
    pub(super) camera: &'a Camera,
    pub(super) target: Vec3,
    /// The bookmarks.
    pub(super) views: &'a [Camera],
    /// The settings as they are, and as they were when the scene was opened: only the changed
    /// ones are written (the viewer's own defaults, a CPU driver's smaller volume, stay out).
    pub(super) now: (&'a RendererOptions, &'a FrameParams),
    pub(super) opened: (&'a RendererOptions, &'a FrameParams),
    /// The scene's lights as edited, and how many the scene had when loaded (the file's own
    /// `[[light]]`s are the last of those).
    pub(super) lights: &'a [Light],
    pub(super) loaded_lights: usize,
}

/// What `save_into` wrote, for the message.
#[derive(Debug, PartialEq)]
pub(super) struct Written {
    pub(super) views: usize,
    pub(super) settings: usize,
    pub(super) lights: usize,
    /// Lights of included files: theirs, not the scene file's.
    pub(super) other_lights: usize,
}

fn vec3(v: Vec3) -> toml_edit::Value {
    let short = |x: f32| x.to_string().parse::<f64>().unwrap_or(x.into());
    let mut a = toml_edit::Array::new();
    for x in v.to_array() {
        a.push(short(x));
    }
    toml_edit::Value::Array(a)
}

/// A camera's `position`, `target` and `fov` into `t`.
fn camera_into(t: &mut Table, camera: &Camera, target: Vec3) {
    t["position"] = value(vec3(camera.position));
    t["target"] = value(vec3(target));
    let fov = match camera.projection {
        Projection::Perspective { yfov } => yfov.to_degrees(),
        // Scene files have perspective cameras only: an orthographic view keeps the orbit's.
        Projection::Orthographic { .. } => 45.0,
    };
    t["fov"] = value((fov as f64 * 100.0).round() / 100.0);
}

/// A TOML value of the `toml` crate as `toml_edit`'s.
fn edit_value(v: &toml::Value) -> Result<toml_edit::Value> {
    v.to_string()
        .parse()
        .with_context(|| format!("{v} as a TOML value"))
}

/// `text` (a scene file, or `None` for a new one including `include`) with `s` saved into it.
pub(super) fn save_into(
    text: Option<&str>,
    include: Option<Table>,
    s: &Saved,
) -> Result<(String, Written)> {
    let mut doc: DocumentMut = match text {
        Some(t) => t.parse().context("the scene file is not valid TOML")?,
        None => DocumentMut::new(),
    };
    if text.is_none() {
        let mut includes = ArrayOfTables::new();
        includes.push(include.context("a new scene file needs the scene to include")?);
        doc["include"] = Item::ArrayOfTables(includes);
    }

    let mut camera = Table::new();
    camera_into(&mut camera, s.camera, s.target);
    doc["camera"] = Item::Table(camera);

    if s.views.is_empty() {
        doc.remove("view");
    } else {
        let mut views = ArrayOfTables::new();
        for v in s.views {
            let mut t = Table::new();
            t["name"] = value(v.name.as_str());
            camera_into(&mut t, v, v.position + v.forward.normalize_or(Vec3::NEG_Z));
            views.push(t);
        }
        doc["view"] = Item::ArrayOfTables(views);
    }

    let mut settings = 0;
    for setting in SETTINGS {
        let (now, was) = (
            setting.value(s.now.0, s.now.1),
            setting.value(s.opened.0, s.opened.1),
        );
        if now == was {
            continue;
        }
        if !doc.contains_table("settings") {
            doc["settings"] = toml_edit::table();
        }
        doc["settings"][setting.key] = value(edit_value(&setting.to_toml(now))?);
        settings += 1;
    }

    // The file's own lights are the last `count` of the scene's as loaded, in its order.
    let count = doc
        .get("light")
        .and_then(Item::as_array_of_tables)
        .map_or(0, |a| a.len());
    let first = s.loaded_lights.checked_sub(count);
    let mut lights = 0;
    if let (Some(first), Some(tables)) = (
        first,
        doc.get_mut("light").and_then(Item::as_array_of_tables_mut),
    ) {
        for (k, t) in tables.iter_mut().enumerate() {
            let Some(l) = s.lights.get(first + k) else {
                break;
            };
            let name = t
                .get("name")
                .and_then(|n| n.as_str())
                .map_or_else(|| format!("light {}", k + 1), str::to_owned);
            if name != l.name {
                bail!(
                    "the scene file's light {} is '{name}', the scene's is '{}': the file changed \
                     since it was opened",
                    k + 1,
                    l.name
                );
            }
            t["color"] = value(vec3(Vec3::from(l.color)));
            t["intensity"] = value(l.intensity.to_string().parse::<f64>()?);
            if l.kind != LightKind::Directional || t.contains_key("position") {
                t["position"] = value(vec3(l.position));
            }
            t.remove("target");
            t["direction"] = value(vec3(l.direction));
            lights += 1;
        }
    }
    let written = Written {
        views: s.views.len(),
        settings,
        lights,
        other_lights: s.lights.len().min(s.loaded_lights) - lights,
    };
    Ok((doc.to_string(), written))
}

impl Viewer {
    /// Saves the view into the scene's file (`Source::target`), and says what it wrote.
    pub(super) fn save_view(&mut self) {
        match self.try_save_view() {
            Ok(message) => self.toasts.info(message),
            Err(e) => self.toasts.error(format!("saving the view: {e:#}")),
        }
    }

    fn try_save_view(&mut self) -> Result<String> {
        let Some(source) = self.source.clone() else {
            bail!(
                "the scene came from nowhere a file can say (a dropped file's scene is saved once opened from its path)"
            );
        };
        let path = source.target();
        let existing = match std::fs::read_to_string(&path) {
            Ok(t) => Some(t),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(e).with_context(|| path.display().to_string()),
        };
        let target = match &self.controller {
            super::input::Controller::Orbit(o) => o.target,
            super::input::Controller::Fly(_) => {
                self.params.camera.position + self.params.camera.forward * self.scene_radius
            }
        };
        let saved = Saved {
            camera: &self.params.camera,
            target,
            views: &self.cameras[self.first_bookmark.min(self.cameras.len())..],
            now: (&self.options, &self.params),
            opened: (&self.opened_options.0, &self.opened_options.1),
            lights: self.renderer.lights(),
            loaded_lights: self.scene.lights.len(),
        };
        let (text, w) = save_into(existing.as_deref(), source.include(), &saved)
            .with_context(|| path.display().to_string())?;
        voxgi::scene::io::atomic::replace_with(&path, |f| {
            use std::io::Write;
            f.write_all(text.as_bytes())
        })
        .with_context(|| path.display().to_string())?;
        let path = std::path::absolute(&path).unwrap_or(path);
        let mut message = format!(
            "saved the camera, {} view{}, {} changed setting{} and {} light{} into {}",
            w.views,
            if w.views == 1 { "" } else { "s" },
            w.settings,
            if w.settings == 1 { "" } else { "s" },
            w.lights,
            if w.lights == 1 { "" } else { "s" },
            path.display()
        );
        if w.other_lights > 0 {
            message += &format!(
                " ({} light{} of included files not saved: they are theirs)",
                w.other_lights,
                if w.other_lights == 1 { "" } else { "s" }
            );
        }
        if matches!(source, Source::Model(_) | Source::Builtin(_)) {
            // From now on the view goes into the file it made.
            self.source = Some(Source::SceneFile(path));
        }
        Ok(message)
    }

    /// Adds the current view to the bookmarks, named "view N".
    pub(super) fn bookmark(&mut self) {
        let n = self.cameras.len().saturating_sub(self.first_bookmark) + 1;
        let mut c = self.params.camera.clone();
        c.name = format!("view {n}");
        self.toasts
            .info(format!("bookmarked the view as '{}'", c.name));
        self.cameras.push(c);
    }
}

/// How many `[[view]]`s the scene file at `path` has (0 for other files): the last cameras of
/// its scene.
pub(super) fn views_in(path: Option<&Path>) -> usize {
    let Some(p) = path.filter(|p| {
        p.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    }) else {
        return 0;
    };
    std::fs::read_to_string(p)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .and_then(|t| t.get("view").and_then(|v| v.as_array()).map(Vec::len))
        .unwrap_or(0)
}

/// The source of a scene opened from `path` (`None`: a built-in scene named `builtin`).
pub(super) fn source(path: Option<&Path>, builtin: Option<&str>) -> Option<Source> {
    match path {
        Some(p)
            if p.extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml")) =>
        {
            Some(Source::SceneFile(p.to_path_buf()))
        }
        Some(p) => Some(Source::Model(p.to_path_buf())),
        None => Some(Source::Builtin(builtin.unwrap_or("cornell-box").to_owned())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene file with a comment, an include, a light and settings: the camera, a view, a
    /// changed setting and the moved light are written; the comment, the include and the
    /// setting nobody changed stay; the result loads as a scene with those.
    #[test]
    fn the_view_goes_into_the_scene_file_and_loads_back() {
        let text = r#"# my room
[[include]]
builtin = "cornell-box"

[[light]]
type = "point"
name = "bulb"
intensity = 2.0
position = [0.2, 0.4, 0.2]

[settings]
voxel_resolution = 32  # small
"#;
        let dir = std::env::temp_dir().join(format!("voxgi_save_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("room.toml");
        std::fs::write(&path, text).unwrap();
        let scene = voxgi::scene::io::load(&path).unwrap();
        let opened = (
            RendererOptions::default(),
            FrameParams::new(scene.default_camera()),
        );
        let mut now = opened.clone();
        now.0.bounces = 3;
        now.1.exposure = 1.5;
        let mut lights = scene.lights.clone();
        let bulb = lights.len() - 1;
        lights[bulb].position = Vec3::new(0.3, 0.45, 0.1);
        lights[bulb].intensity = 3.5;
        let camera = Camera::look_at(Vec3::new(0.3, 0.3, -0.5), Vec3::new(0.28, 0.27, 0.28), 40.0);
        let mut view = Camera::look_at(Vec3::new(0.1, 0.5, 0.1), Vec3::new(0.3, 0.0, 0.3), 50.0);
        view.name = "from the corner".into();
        let saved = Saved {
            camera: &camera,
            target: Vec3::new(0.28, 0.27, 0.28),
            views: std::slice::from_ref(&view),
            now: (&now.0, &now.1),
            opened: (&opened.0, &opened.1),
            lights: &lights,
            loaded_lights: scene.lights.len(),
        };
        let (out, w) = save_into(Some(text), None, &saved).unwrap();
        assert_eq!(
            w,
            Written {
                views: 1,
                settings: 2,
                lights: 1,
                other_lights: scene.lights.len() - 1,
            }
        );
        assert!(out.starts_with("# my room"), "{out}");
        assert!(out.contains("voxel_resolution = 32  # small"), "{out}");
        std::fs::write(&path, &out).unwrap();
        let back = voxgi::scene::io::load(&path).unwrap();
        let cam = &back.cameras[0];
        assert!(cam.position.distance(camera.position) < 1e-5);
        assert!(cam.forward.dot(camera.forward) > 1.0 - 1e-5);
        let v = back.cameras.last().unwrap();
        assert_eq!(v.name, "from the corner");
        assert!(v.forward.dot(view.forward) > 1.0 - 1e-5);
        let l = back.lights.last().unwrap();
        assert!(l.position.distance(lights[bulb].position) < 1e-6 && l.intensity == 3.5);
        let table: toml::Table = toml::from_str(&out).unwrap();
        let settings =
            voxgi::SceneSettings::from_table(table["settings"].as_table().unwrap()).unwrap();
        let (mut o, mut f) = opened.clone();
        settings.apply(&mut o, &mut f).unwrap();
        assert_eq!((o.bounces, o.voxel_resolution, f.exposure), (3, 32, 1.5));
    }

    /// A built-in scene gets a scene file of its own that includes it.
    #[test]
    fn a_builtin_scene_gets_a_file_that_includes_it() {
        let source = source(None, Some("two-rooms")).unwrap();
        assert_eq!(source.target(), PathBuf::from("voxgi_two-rooms.toml"));
        let scene = voxgi::scene::builtin::by_name("two-rooms").unwrap();
        let o = (
            RendererOptions::default(),
            FrameParams::new(scene.default_camera()),
        );
        let camera = scene.default_camera();
        let saved = Saved {
            camera: &camera,
            target: camera.position + camera.forward,
            views: &[],
            now: (&o.0, &o.1),
            opened: (&o.0, &o.1),
            lights: &scene.lights,
            loaded_lights: scene.lights.len(),
        };
        let (out, w) = save_into(None, source.include(), &saved).unwrap();
        assert!(out.contains("builtin = \"two-rooms\""), "{out}");
        assert_eq!((w.settings, w.lights), (0, 0));
        let dir = std::env::temp_dir().join(format!("voxgi_save_b_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("two.toml");
        std::fs::write(&path, &out).unwrap();
        let back = voxgi::scene::io::load(&path).unwrap();
        assert_eq!(back.triangle_count(), scene.triangle_count());
    }
}
