//! What the loaders' tests share: the warnings a load logs about its file.

use std::path::Path;
use voxgi_scene::{Scene, io};

// A logger that keeps warnings, so tests can check what the loader said about their file.
struct Capture;
static WARNINGS: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if self.enabled(r.metadata()) {
            WARNINGS.lock().unwrap().push(r.args().to_string());
        }
    }
    fn flush(&self) {}
}

/// Loads `path` and returns the scene with the warnings that name its file.
pub fn load_warned(path: &Path) -> (voxgi_scene::Result<Scene>, Vec<String>) {
    static CAPTURE: Capture = Capture;
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // Tests run in parallel in one process: one logger for all, filtered by file name.
        let _ = log::set_logger(&CAPTURE);
        log::set_max_level(log::LevelFilter::Warn);
    });
    let scene = io::load(path);
    let name = path.display().to_string();
    let w = WARNINGS
        .lock()
        .unwrap()
        .iter()
        .filter(|w| w.contains(&name))
        .cloned()
        .collect();
    (scene, w)
}
