//! Loading arbitrary bytes as a file of a given type, for the fuzz targets (`fuzz/`) and the
//! mutation test that keeps them honest in CI: the loaders read paths (an OBJ's material
//! library, a glTF's buffers and a scene file's includes lie beside them), so the bytes go to
//! a file in a directory of this thread's own.

use crate::{Result, Scene};
use std::path::PathBuf;

/// Loads `data` as a file with extension `ext` (`io::load`, validation included).
pub fn load_as(ext: &str, data: &[u8]) -> Result<Scene> {
    let path = scratch_dir().join(format!("input.{ext}"));
    std::fs::write(&path, data).map_err(|e| crate::SceneError::load(&path, e))?;
    super::load(&path)
}

/// A directory for this process and thread, made once.
fn scratch_dir() -> PathBuf {
    thread_local! {
        static DIR: PathBuf = {
            let d = std::env::temp_dir().join(format!(
                "voxgi-fuzz-{}-{:?}",
                std::process::id(),
                std::thread::current().id()
            ).replace(['(', ')'], ""));
            let _ = std::fs::create_dir_all(&d);
            d
        };
    }
    DIR.with(|d| d.clone())
}
