//! File loaders. [`load`] picks one by extension; each returns a validated [`Scene`].

pub mod atomic;
pub mod cloud;
pub mod emitters;
#[doc(hidden)]
pub mod fuzz;
pub mod gltf;
pub mod obj;
pub mod pcd;
pub mod ply;
pub mod scene_file;
pub mod source;
pub mod texture;

use crate::{Result, Scene, SceneError};
use std::path::Path;

pub use source::{load_from_memory, with_files};

/// File extensions `load` understands, for help texts and error messages.
pub const EXTENSIONS: &[&str] = &["gltf", "glb", "obj", "ply", "pcd", "cloud", "toml"];

/// Loads a scene file, choosing the loader by extension.
pub fn load(path: &Path) -> Result<Scene> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if !source::exists(path) {
        return Err(SceneError::load(path, "no such file"));
    }
    if source::is_dir(path) {
        return Err(SceneError::load(
            path,
            format!(
                "is a directory, not a scene file (voxgi reads {})",
                EXTENSIONS.join(", ")
            ),
        ));
    }
    let scene = match ext.as_str() {
        "gltf" | "glb" => gltf::load(path)?,
        "obj" => {
            let mut s = obj::load(path)?;
            emitters::promote_emissive_quads(&mut s);
            s
        }
        "ply" => {
            let mut s = ply::load(path)?;
            emitters::promote_emissive_quads(&mut s);
            emitters::promote_emissive_points(&mut s);
            s
        }
        "pcd" => pcd::load(path)?,
        "cloud" => cloud::load(path)?,
        "toml" => scene_file::load(path)?,
        _ => {
            let kind = if ext.is_empty() {
                "no file extension to tell its type by".to_string()
            } else {
                format!("unknown file type '.{ext}'")
            };
            return Err(SceneError::load(
                path,
                format!("{kind} (voxgi reads {})", EXTENSIONS.join(", ")),
            ));
        }
    };
    scene.validate().map_err(|e| e.in_file(path))?;
    Ok(scene)
}
