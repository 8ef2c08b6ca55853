use crate::{Result, Scene, SceneError};
use std::path::Path;

pub fn load(path: &Path) -> Result<Scene> {
    Err(SceneError::load(path, "scene_file loader not written yet"))
}
