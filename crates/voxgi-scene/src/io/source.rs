//! Where the loaders read files: the file system, or, inside `load_from_memory`, a set of
//! files held in memory (a browser page's dropped or picked files, which have no paths). Every
//! loader reads through here, so a scene's side files (an OBJ's material library and
//! textures, a glTF's buffers and images, a scene file's includes) are found among the files
//! given with it. A point sequence's frames are not: the player reads them from the disk while
//! the scene plays, after the load.

use crate::{Result, Scene, SceneError};
use std::cell::RefCell;
use std::collections::HashMap;
use std::io;
use std::path::{Component, Path, PathBuf};

thread_local! {
    /// The files `load_from_memory` installed on this thread, while it runs.
    static MEMORY: RefCell<Option<HashMap<PathBuf, Vec<u8>>>> = const { RefCell::new(None) };
}

/// Loads `main`, one of `files` (name and contents), as `io::load` loads a file, with every
/// file it refers to read from `files` instead of the disk (`with_files`).
pub fn load_from_memory(files: Vec<(String, Vec<u8>)>, main: &str) -> Result<Scene> {
    if !files.iter().any(|(name, _)| name == main) {
        return Err(SceneError::load(
            Path::new(main),
            "not among the given files",
        ));
    }
    with_files(files, || super::load(Path::new(main)))
}

/// Runs `f` (a loader's call) with every file read from `files` (name and contents) instead
/// of the disk. A reference is found by its path relative to the file that makes it, or
/// failing that by its file name alone (files picked in a browser come without their
/// folders). Nothing is read from the disk meanwhile, on this thread.
pub fn with_files<T>(files: Vec<(String, Vec<u8>)>, f: impl FnOnce() -> T) -> T {
    let map = files
        .into_iter()
        .map(|(name, bytes)| (normal(Path::new(&name)), bytes))
        .collect();
    let previous = MEMORY.with(|m| m.replace(Some(map)));
    struct Restore(Option<HashMap<PathBuf, Vec<u8>>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            MEMORY.with(|m| *m.borrow_mut() = previous);
        }
    }
    let _restore = Restore(previous);
    f()
}

/// `path` without `.` components, `..` taken against what precedes it.
fn normal(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            // `..` takes back a name, never another `..` (nor the root).
            Component::ParentDir => {
                if matches!(out.components().next_back(), Some(Component::Normal(_))) {
                    out.pop();
                } else {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}

/// In memory: the key `path` names, exactly or by its file name alone when that is unique.
fn find(files: &HashMap<PathBuf, Vec<u8>>, path: &Path) -> Option<PathBuf> {
    let p = normal(path);
    if files.contains_key(&p) {
        return Some(p);
    }
    let name = p.file_name()?;
    let mut same = files.keys().filter(|k| k.file_name() == Some(name));
    match (same.next(), same.next()) {
        (Some(k), None) => Some(k.clone()),
        _ => None,
    }
}

fn in_memory<T>(f: impl FnOnce(&HashMap<PathBuf, Vec<u8>>) -> T) -> Option<T> {
    MEMORY.with(|m| m.borrow().as_ref().map(f))
}

/// The file's bytes.
pub(crate) fn read(path: &Path) -> io::Result<Vec<u8>> {
    in_memory(|files| {
        find(files, path)
            .and_then(|k| files.get(&k).cloned())
            .ok_or_else(|| {
                io::Error::new(
                    io::ErrorKind::NotFound,
                    "not among the files given (pick or drop it together with the scene)",
                )
            })
    })
    .unwrap_or_else(|| std::fs::read(path))
}

/// The file's text (UTF-8).
pub(crate) fn read_to_string(path: &Path) -> io::Result<String> {
    String::from_utf8(read(path)?).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

/// Whether `path` names a file.
pub(crate) fn is_file(path: &Path) -> bool {
    in_memory(|files| find(files, path).is_some()).unwrap_or_else(|| path.is_file())
}

/// Whether `path` names a folder (never, in memory).
pub(crate) fn is_dir(path: &Path) -> bool {
    in_memory(|_| false).unwrap_or_else(|| path.is_dir())
}

/// Whether `path` names anything.
pub(crate) fn exists(path: &Path) -> bool {
    in_memory(|files| find(files, path).is_some()).unwrap_or_else(|| path.exists())
}

/// One name per file, for telling two references to the same file apart from two files.
pub(crate) fn canonicalize(path: &Path) -> io::Result<PathBuf> {
    in_memory(|files| {
        find(files, path)
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "not among the files given"))
    })
    .unwrap_or_else(|| path.canonicalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    const OBJ: &str = "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    const MTL: &str = "newmtl red\nKd 0.8 0.1 0.1\n";

    #[test]
    fn an_obj_finds_its_material_library_among_the_files_given() {
        let files = vec![
            ("room.obj".to_string(), OBJ.as_bytes().to_vec()),
            ("room.mtl".to_string(), MTL.as_bytes().to_vec()),
        ];
        let scene = load_from_memory(files, "room.obj").expect("loads from memory");
        assert_eq!(scene.materials.len(), 1);
        // The library's red, not the default grey: the .mtl was read from memory.
        assert_eq!(scene.materials[0].base_color[..3], [0.8, 0.1, 0.1]);
        // Nothing stays installed after the load.
        assert!(!is_file(Path::new("room.obj")));
    }

    #[test]
    fn a_missing_side_file_or_main_file_is_named() {
        let files = vec![("room.obj".to_string(), OBJ.as_bytes().to_vec())];
        // Without its library the OBJ loads with default materials (a warning, as on disk).
        let scene = load_from_memory(files.clone(), "room.obj").expect("loads");
        assert!(
            scene
                .materials
                .iter()
                .all(|m| m.base_color[..3] != [0.8, 0.1, 0.1])
        );
        let e = load_from_memory(files, "other.glb")
            .unwrap_err()
            .to_string();
        assert!(e.contains("other.glb") && e.contains("not among"), "{e}");
    }

    #[test]
    fn references_are_found_by_relative_path_or_by_name() {
        let mut files = HashMap::new();
        files.insert(PathBuf::from("a/b.bin"), vec![1u8]);
        files.insert(PathBuf::from("tex.png"), vec![2u8]);
        assert_eq!(
            find(&files, Path::new("./a/x/../b.bin")),
            Some(PathBuf::from("a/b.bin"))
        );
        assert_eq!(
            find(&files, Path::new("textures/tex.png")),
            Some(PathBuf::from("tex.png"))
        );
        assert_eq!(find(&files, Path::new("c.bin")), None);
        assert_eq!(normal(Path::new("../../x")), PathBuf::from("../../x"));
        assert_eq!(normal(Path::new("a/../../x")), PathBuf::from("../x"));
    }
}
