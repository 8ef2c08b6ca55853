use crate::{Result, Scene, SceneError};
use std::path::Path;

pub fn load(path: &Path) -> Result<Scene> {
    Err(SceneError::load(path, "ply loader not written yet"))
}
