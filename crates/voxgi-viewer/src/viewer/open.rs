//! Opening scenes and the background work: a file loaded and its renderer built off the
//! window's thread, new options applied (or a renderer rebuilt for them), the file dialog, and
//! taking what finished; framing the scene's camera.

use super::input::Controller;
use super::pieces::{Pieces, Step};
use super::{Viewer, scene_label};
use crate::camera::Orbit;
use crate::ground_truth::Display;
use crate::jobs::{Job, take};
use crate::load;
use anyhow::Context;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use voxgi::scene::Scene;
use voxgi::{FrameParams, Renderer, RendererOptions};

/// A renderer made in the background, taking over once its first voxel work is done: that
/// work is submitted a pass a frame (`Pieces`) while the current renderer goes on drawing.
pub(super) struct Handover {
    taking: Taking,
    pieces: Pieces,
}

enum Taking {
    Rebuilt(Box<(Renderer, RendererOptions)>),
    Opened(Box<Opened>),
}

impl Handover {
    /// Whether it brings a newly opened scene.
    fn opens(&self) -> bool {
        matches!(self.taking, Taking::Opened(..))
    }

    pub(super) fn label(&self) -> String {
        let what = match self.taking {
            Taking::Rebuilt(..) => "the voxels for the new options",
            Taking::Opened(..) => "the new scene's voxels",
        };
        format!("building {what}: {}", self.pieces.progress())
    }
}

/// A file loaded and its renderer built, off the window's thread.
pub(super) struct Opened {
    path: PathBuf,
    scene: Scene,
    settings_params: FrameParams,
    options: RendererOptions,
    renderer: Renderer,
}

impl Viewer {
    /// Back to the scene's own camera (or the view of its bounds).
    pub(super) fn frame_scene(&mut self) {
        let cam = self.renderer.default_camera().clone();
        self.controller = Controller::Orbit(Orbit::from_camera(&cam, self.scene_radius * 2.0));
        // A cut to another view: nothing of the last view's history belongs in it.
        self.renderer.reset_history();
    }

    /// Starts loading the file at `path` (and building its renderer) in the background; when it
    /// is done it replaces the scene. On failure the error shows and the scene stays.
    pub(super) fn open(&mut self, path: &Path) {
        let path = path.to_path_buf();
        let (device, queue) = (self.device.clone(), self.queue.clone());
        let (options, camera) = (self.options.clone(), self.params.camera.clone());
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        self.opening = Some(Job::spawn(format!("opening {name}"), move || {
            let (mut scene, settings) = load(Some(&path), None)?;
            scene.set_time(0.0);
            let mut options = options;
            let mut params = FrameParams::new(camera);
            if let Some(s) = &settings {
                s.apply(&mut options, &mut params)?;
            }
            let renderer = Renderer::new(&device, &queue, &scene, &options)
                .with_context(|| path.display().to_string())?;
            Ok(Opened {
                path,
                scene,
                settings_params: params,
                options,
                renderer,
            })
        }));
    }

    /// The loaded file replaces the scene.
    fn opened(&mut self, o: Opened) {
        self.scene_generation += 1;
        let mut renderer = o.renderer;
        renderer.enable_timing(self.timestamps);
        self.renderer = renderer;
        self.draft = o.options.clone();
        self.options = o.options;
        // The file's view settings (exposure, tone curve, view mode); the camera is framed below.
        self.params = o.settings_params;
        let bounds = o.scene.swept_bounds();
        self.scene_radius = (bounds.size().length() * 0.5).max(1e-3);
        self.scene_center = bounds.center();
        self.scene_floor = super::grid::height(&o.scene);
        self.selected_light = None;
        self.duration = o.scene.duration();
        self.time = 0.0;
        self.playing = self.duration > 0.0 && self.ground.display == Display::ConeTraced;
        self.fly_along = o.scene.camera_is_animated(0);
        self.flown = None;
        self.scene_name = scene_label(&o.scene);
        self.cameras = o.scene.cameras.clone();
        self.first_bookmark = self.cameras.len() - super::save::views_in(Some(&o.path));
        self.source = super::save::source(Some(&o.path), None);
        self.opened_options = (self.options.clone(), self.params.clone());
        self.window
            .set_title(&format!("voxgi — {}", self.scene_name));
        self.scene = Arc::new(o.scene);
        self.version += 1;
        self.ground.clear();
        self.stats.clear_passes();
        self.frame_scene();
        self.toasts.info(format!("opened {}", o.path.display()));
    }

    /// Applies the draft options: through `Renderer::set_options`, which rebuilds only what the
    /// changed settings feed (a lighting change relights the voxels it has), or, for a setting
    /// that shapes the uploaded scene, by building a new renderer in the background while the
    /// current one draws.
    pub(super) fn apply(&mut self) {
        if self.opening.is_some() || self.handover.as_ref().is_some_and(Handover::opens) {
            self.toasts
                .info("a scene is being opened: apply the options once it shows");
            return;
        }
        if !crate::settings::needs_new_renderer(&self.options, &self.draft) {
            match self.renderer.set_options(&self.draft) {
                Ok(()) => {
                    self.options = self.draft.clone();
                    self.stats.clear_passes();
                    self.version += 1;
                    self.toasts.info("options applied");
                }
                Err(e) => self.toasts.error(format!("the new options failed: {e:#}")),
            }
            return;
        }
        let (device, queue) = (self.device.clone(), self.queue.clone());
        let (scene, options) = (self.scene.clone(), self.draft.clone());
        self.rebuild_scene = self.scene_generation;
        self.rebuild = Some(Job::spawn("rebuilding for the new options", move || {
            Ok((Renderer::new(&device, &queue, &scene, &options)?, options))
        }));
    }

    /// Gives `renderer` (made for new options) the scene's time and the lights as edited in
    /// the current one.
    fn adopt_state(&self, renderer: &mut Renderer) {
        if let Err(e) = renderer.set_time(self.time) {
            log::warn!("the new renderer's scene time: {e}");
        }
        let lights = self.renderer.lights();
        if renderer.lights().len() == lights.len() {
            for (i, l) in lights.iter().enumerate() {
                // Only what differs: an unchanged light would relight the voxels.
                if renderer.lights()[i] != *l {
                    // A light whose kind differs (the default sun switched) keeps the new one's.
                    let _ = renderer.set_light(i, l);
                }
            }
        }
    }

    /// The new options' renderer takes over, with the scene's time and the lights as edited.
    fn rebuilt(&mut self, mut renderer: Renderer, options: RendererOptions) {
        renderer.enable_timing(self.timestamps);
        // Lights edited while its voxels were built (relit in its first frame).
        self.adopt_state(&mut renderer);
        self.renderer = renderer;
        // The path tracer sees the scene's lights, and the default sun when there are none.
        if options.default_light != self.options.default_light {
            self.ground.clear();
        }
        self.options = options;
        self.stats.clear_passes();
        self.version += 1;
        self.toasts.info("options applied");
    }

    /// Opens the system's file dialog on its own thread.
    pub(super) fn open_dialog(&mut self) {
        self.dialog = Some(Job::spawn("waiting for the file dialog", || {
            Ok(rfd::FileDialog::new()
                .set_title("Open a scene")
                .add_filter("scenes", voxgi::scene::io::EXTENSIONS)
                .pick_file())
        }));
    }

    /// Takes the results of finished background work: a renderer made in the background
    /// submits its first voxel work a pass a frame, then takes over (`Handover`).
    pub(super) fn poll_jobs(&mut self) {
        if let Some(h) = &mut self.handover {
            let (renderer, params) = match &mut h.taking {
                Taking::Rebuilt(b) => (&mut b.0, &self.params),
                Taking::Opened(o) => (&mut o.renderer, &o.settings_params),
            };
            match h.pieces.step(renderer, &self.queue, params) {
                Ok(Step::Submitted | Step::Waiting) => {}
                Ok(Step::Done) => match self.handover.take().map(|h| h.taking) {
                    Some(Taking::Rebuilt(b)) => self.rebuilt(b.0, b.1),
                    Some(Taking::Opened(o)) => self.opened(*o),
                    None => {}
                },
                Err(e) => {
                    self.handover = None;
                    self.toasts
                        .error(format!("building the voxels failed: {e:#}"));
                }
            }
        }
        match take(&mut self.rebuild) {
            Some(Ok(_))
                if self.rebuild_scene != self.scene_generation
                    || self.handover.as_ref().is_some_and(Handover::opens) =>
            {
                self.toasts
                    .info("the new options were for the scene open before: apply them again");
            }
            Some(Ok((mut renderer, options))) => {
                self.adopt_state(&mut renderer);
                match Pieces::new(&mut renderer, &self.params) {
                    Ok(pieces) => {
                        self.handover = Some(Handover {
                            taking: Taking::Rebuilt(Box::new((renderer, options))),
                            pieces,
                        })
                    }
                    Err(e) => self.toasts.error(format!("the new options failed: {e:#}")),
                }
            }
            Some(Err(e)) => self.toasts.error(format!("the new options failed: {e:#}")),
            None => {}
        }
        match take(&mut self.opening) {
            Some(Ok(mut o)) => match Pieces::new(&mut o.renderer, &o.settings_params) {
                Ok(pieces) => {
                    self.handover = Some(Handover {
                        taking: Taking::Opened(Box::new(o)),
                        pieces,
                    })
                }
                Err(e) => self.toasts.error(format!("{}: {e:#}", o.path.display())),
            },
            Some(Err(e)) => self.toasts.error(format!("{e:#}")),
            None => {}
        }
        match take(&mut self.saving) {
            Some(Ok(done)) => self.toasts.info(done),
            Some(Err(e)) => self.toasts.error(format!("{e:#}")),
            None => {}
        }
        match take(&mut self.dialog) {
            Some(Ok(Some(path))) => self.open(&path),
            Some(Ok(None)) => self.toasts.info(
                "no file chosen (the dialog needs xdg-desktop-portal or zenity; a file \
                     dropped onto the window or a path typed in the panel opens too)",
            ),
            Some(Err(e)) => self.toasts.error(format!("{e:#}")),
            None => {}
        }
    }
}
