//! The path tracer in the window: voxgi's ground truth, accumulating a few samples a frame while
//! the view stands still, either in place of cone tracing or right of a draggable divider.
//!
//! The path tracer sees the scene as it was built (its BVH is of the instances' poses then), so
//! a change of time or of a light builds a new one, in the background, while the last image
//! stays up.

use crate::jobs::{Job, take};
use anyhow::Result;
use std::ops::Range;
use std::sync::Arc;
use voxgi::reference::{Accumulation, Region};
use voxgi::scene::{Light, Scene};
use voxgi::{
    Bounces, FrameParams, PathTracer, ReferenceMode, ReferenceOptions, RendererOptions, Target,
    wgpu,
};

/// What the window shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Display {
    /// Cone tracing only.
    #[value(name = "cone-traced")]
    ConeTraced,
    /// The path tracer only.
    #[value(name = "path-traced")]
    PathTraced,
    /// Cone tracing left of the divider, the path tracer right of it.
    Split,
}

impl Display {
    pub const ALL: [Display; 3] = [Display::ConeTraced, Display::PathTraced, Display::Split];

    pub fn name(self) -> &'static str {
        match self {
            Display::ConeTraced => "cone traced",
            Display::PathTraced => "path traced",
            Display::Split => "split",
        }
    }
}

/// A path tracer of one state of the scene, and its image.
struct Traced {
    tracer: PathTracer,
    accumulation: Option<Accumulation>,
    version: u64,
    /// The lights it has (as `Renderer::lights` numbers them): an edit is set in place.
    lights: Vec<Light>,
    /// Frames before the first traced one on a CPU driver (2, then 1 in the frame that shows
    /// why, then 0): such a driver compiles the path tracer's code at its first dispatch, inside
    /// the queue, stopping the window for seconds (once per machine: the driver's shader cache
    /// keeps the code), so a frame saying so is shown first.
    compile_notice: u8,
}

/// A path tracer and what it was built for: the scene state (`version`) and the lights.
type Built = (PathTracer, u64, Vec<Light>);

/// The window's ground truth.
pub struct GroundTruth {
    pub display: Display,
    /// Where the split view's divider is, as a fraction of the window's width.
    pub divider: f32,
    /// Samples per pixel each frame adds.
    pub samples_per_frame: u32,
    /// The image stops improving (and costs nothing) once it has this many.
    pub max_samples: u32,
    /// Paths traced a frame at most: fewer pixels than the image has are traced a band of rows
    /// at a time, so a slow GPU keeps the window responsive.
    pub paths_per_frame: u32,
    /// When set, `paths_per_frame` follows the path tracer's GPU time a frame towards this many
    /// milliseconds (on a GPU without timestamps it stays as it is).
    pub frame_target_ms: Option<f32>,
    /// Time the path tracer's passes on the GPU.
    timing: bool,
    /// The adapter is a CPU driver.
    cpu: bool,
    /// Adapt the paths a frame to the frame's wall time instead of the GPU's timestamps.
    wall_clock: bool,
    /// Whether the last frame traced paths (so its time says something about them).
    traced_last_frame: bool,
    /// The first row of the next band.
    next_row: u32,
    /// Rows a band has (the last one of a sweep may be cut short by the image's bottom).
    band_rows: u32,
    traced: Option<Traced>,
    /// A path tracer being built, with the scene state and the lights it is built for.
    building: Option<Job<Built>>,
    pub error: Option<String>,
}

impl GroundTruth {
    pub fn new(display: Display, cpu: bool, timing: bool) -> Self {
        GroundTruth {
            display,
            divider: 0.5,
            // A CPU driver traces a sample a frame and stays responsive; a GPU does more.
            samples_per_frame: if cpu { 1 } else { 4 },
            max_samples: 4096,
            paths_per_frame: if cpu { 1 << 14 } else { 1 << 22 },
            frame_target_ms: Some(default_target_ms(cpu)),
            timing,
            cpu,
            wall_clock: cpu || !timing,
            traced_last_frame: false,
            next_row: 0,
            band_rows: 0,
            traced: None,
            building: None,
            error: None,
        }
    }

    /// Forgets the path tracer (a new scene or new options): the next frame builds another.
    pub fn clear(&mut self) {
        self.traced = None;
        self.building = None;
        self.error = None;
    }

    /// The columns the path tracer draws in a `width`-wide window; `None` when it draws none.
    pub fn columns(&self, width: u32) -> Option<Range<u32>> {
        match self.display {
            Display::ConeTraced => None,
            Display::PathTraced => Some(0..width),
            Display::Split => {
                let x = ((self.divider.clamp(0.0, 1.0) * width as f32) as u32).min(width - 1);
                Some(x..width)
            }
        }
    }

    /// Whether the cone tracer's image is needed this frame: for its side of the split, or in
    /// place of a path tracer that is not built yet.
    pub fn needs_cone_tracing(&self) -> bool {
        self.display != Display::PathTraced
            || self.traced.as_ref().is_none_or(|t| t.compile_notice > 0)
    }

    /// Takes a finished build, and starts one when the scene (its `version`) moved on from the
    /// path tracer's; called once a frame while the path tracer is shown.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Arc<Scene>,
        time: f32,
        lights: &[Light],
        options: &RendererOptions,
        version: u64,
    ) {
        if self.display == Display::ConeTraced {
            return;
        }
        if let Some(result) = take(&mut self.building) {
            match result {
                Ok((mut tracer, built_for, built_lights)) => {
                    tracer.enable_timing(self.timing);
                    self.error = None;
                    self.traced = Some(Traced {
                        tracer,
                        accumulation: None,
                        version: built_for,
                        lights: built_lights,
                        compile_notice: if self.cpu { 2 } else { 0 },
                    })
                }
                Err(e) => self.error = Some(format!("{e:#}")),
            }
        }
        // Lights edited since: set in place (the triangles do not move), the image starts over.
        if let Some(t) = &mut self.traced
            && t.lights.len() == lights.len()
            && t.lights != lights
        {
            let mut failed = false;
            for (i, l) in lights.iter().enumerate() {
                if t.lights[i] != *l {
                    failed |= t.tracer.set_light(i, l).is_err();
                }
            }
            t.lights = lights.to_vec();
            if let Some(a) = &mut t.accumulation {
                a.reset();
            }
            if failed {
                // A light the path tracer cannot take in place: build it anew.
                t.version = u64::MAX;
            }
        }
        let current = self.traced.as_ref().is_some_and(|t| t.version == version);
        let failed_here = self.error.is_some();
        if current || self.building.is_some() || failed_here {
            return;
        }
        let (device, queue, scene) = (device.clone(), queue.clone(), scene.clone());
        let (lights, options) = (lights.to_vec(), options.clone());
        log::debug!("building a path tracer for scene state {version}");
        self.building = Some(Job::spawn(
            "building the path tracer",
            move || -> Result<Built> {
                let mut scene = (*scene).clone();
                scene.set_time(time);
                scene.load_frames_at(time)?;
                // The lights as the renderer has them now: animated, then edited in the window.
                if lights.len() == scene.lights.len() {
                    scene.lights = lights.clone();
                }
                let tracer = PathTracer::new(&device, &queue, &scene, &options)?;
                Ok((tracer, version, lights))
            },
        ));
    }

    /// The scene changed in a way that makes a built path tracer wrong now and again: a failed
    /// build is retried for the new state.
    pub fn scene_changed(&mut self) {
        self.error = None;
    }

    /// The path tracer's GPU milliseconds per pass in the frame just submitted (empty without
    /// timestamps); on a GPU clock, the paths a frame adapted to them when a target is set.
    pub fn frame_done(&mut self) -> Vec<(&'static str, f64)> {
        let Some(t) = &mut self.traced else {
            return Vec::new();
        };
        let times = t.tracer.pass_times().unwrap_or_default();
        let traced = times
            .iter()
            .find(|(n, _)| *n == "reference")
            .map(|(_, ms)| *ms as f32);
        log::debug!("path tracer: {times:?} for {} paths", self.paths_per_frame);
        if !self.wall_clock
            && let Some(ms) = traced
        {
            self.adapt(ms);
        }
        times
    }

    /// On the wall clock (a CPU driver, whose compute timestamps read about 0 ms, or no
    /// timestamps at all): the last frame's wall time, `frame_ms`, adapts the paths a frame
    /// when that frame did little else than trace (`tracing_only`: cone tracing showed its last
    /// image again, or was not drawn).
    pub fn frame_time(&mut self, frame_ms: f32, tracing_only: bool) {
        if self.wall_clock && tracing_only {
            self.adapt(frame_ms);
        } else if self.wall_clock {
            self.traced_last_frame = false;
        }
    }

    fn adapt(&mut self, ms: f32) {
        if let Some(target) = self.frame_target_ms
            && std::mem::take(&mut self.traced_last_frame)
        {
            self.paths_per_frame = next_budget(self.paths_per_frame, ms, target);
            log::debug!(
                "path tracer: {ms:.0} ms a frame, {} paths next",
                self.paths_per_frame
            );
        }
    }

    /// What the path tracer's build is doing, while one runs.
    pub fn job_label(&self) -> Option<String> {
        if self.traced.as_ref().is_some_and(|t| t.compile_notice == 1) {
            return Some(
                "the CPU driver compiles the path tracer at its first frame: seconds, once \
                 per machine …"
                    .into(),
            );
        }
        self.building.as_ref().map(Job::label)
    }

    /// Whether a path tracer is being built.
    pub fn building(&self) -> bool {
        self.building.is_some()
    }

    /// What the path tracer is doing, for the window: building, or how many samples it has.
    pub fn label(&self) -> String {
        if let Some(e) = &self.error {
            return format!("path tracer: {e}");
        }
        let samples = self
            .traced
            .as_ref()
            .and_then(|t| t.accumulation.as_ref())
            .map(|a| a.samples());
        let band = match self.traced.as_ref().and_then(|t| t.accumulation.as_ref()) {
            Some(a) if self.band_rows < a.height() => format!(", {} rows a frame", self.band_rows),
            _ => String::new(),
        };
        if self.traced.as_ref().is_some_and(|t| t.compile_notice == 1) {
            return "path tracer: compiling …".into();
        }
        match (&self.building, samples) {
            (Some(job), Some(n)) => {
                format!("path traced, {n} spp (the scene changed: {})", job.label())
            }
            (Some(job), None) => job.label(),
            (None, Some(n)) if n >= self.max_samples => format!("path traced, {n} spp (done)"),
            (None, Some(n)) => format!("path traced, {n} spp{band}"),
            (None, None) => "path tracer starting".into(),
        }
    }

    /// Records this frame's samples (with `accumulate`) and draws the image into its columns of
    /// `target` (over the cone-traced image in a split view).
    pub fn record(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        params: &FrameParams,
        bounces: u32,
        accumulate: bool,
    ) -> Result<()> {
        let Some(columns) = self.columns(target.width) else {
            return Ok(());
        };
        let Some(t) = &mut self.traced else {
            return Ok(());
        };
        if t.compile_notice > 0 && accumulate {
            t.compile_notice -= 1;
            if t.compile_notice == 1 {
                // This frame shows the label saying why the next one is late.
                return Ok(());
            }
        }
        let size = (target.width, target.height);
        if t.accumulation.as_ref().map(|a| (a.width(), a.height())) != Some(size) {
            t.accumulation = Some(t.tracer.accumulation(size.0, size.1)?);
        }
        let acc = t.accumulation.as_mut().expect("made above");
        let opts = ReferenceOptions {
            spp: self.samples_per_frame.max(1),
            bounces: Bounces::matching(bounces),
            mode: ReferenceMode::Radiance,
            seed: 0,
        };
        // Past the cap the image is left as it is, unless the view changed (which the
        // accumulation tells by restarting, so ask it with one more call).
        let moved = !t.tracer.shows(acc, params, &opts);
        if moved && accumulate {
            log::debug!("path tracer restarts: the view or the options changed");
        }
        if accumulate && (acc.samples() < self.max_samples || moved) {
            if moved {
                self.next_row = 0;
            }
            let h = target.height;
            let width = (columns.end - columns.start) as u64;
            let per_row = (width * opts.spp as u64).max(1);
            let rows = (self.paths_per_frame as u64 / per_row).clamp(1, h as u64) as u32;
            let start = if self.next_row >= h { 0 } else { self.next_row };
            let end = (start + rows).min(h);
            self.band_rows = rows;
            self.next_row = end % h;
            let region = Region {
                columns: columns.clone(),
                rows: start..end,
            };
            t.tracer.accumulate(encoder, acc, params, &opts, region)?;
            self.traced_last_frame = true;
        }
        t.tracer.display(encoder, acc, target, params, columns)?;
        Ok(())
    }
}

/// How long the path tracer may take a frame by default: on a CPU driver a whole frame's wall
/// time, short enough that input is answered about ten times a second (at 300 ms a click
/// waited up to two frames); a GPU stays interactive beside cone tracing.
pub fn default_target_ms(cpu: bool) -> f32 {
    if cpu { 100.0 } else { 10.0 }
}

/// The paths a frame for the next frame: scaled by how far the last frame's path tracing time
/// was from the target, by at most a factor of two down and a quarter up a frame, so a single slow frame
/// (a rebuild, a resize) does not throw it far, and within 1024 (some progress) to 2^26.
pub fn next_budget(paths: u32, frame_ms: f32, target_ms: f32) -> u32 {
    let ratio = (target_ms / frame_ms.max(1e-3)).clamp(0.5, 1.25);
    ((paths as f32 * ratio) as u32).clamp(1 << 10, 1 << 26)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tracing costs a fixed part plus a part per path; the budget settles where it takes the
    /// target time.
    #[test]
    fn the_budget_settles_at_the_target_frame_time() {
        for (fixed, per_path, start) in [(100.0, 0.02, 1u32 << 14), (5.0, 1e-5, 1 << 22)] {
            let target = 500.0;
            let mut paths = start;
            for _ in 0..60 {
                paths = next_budget(paths, fixed + per_path * paths as f32, target);
            }
            let frame = fixed + per_path * paths as f32;
            assert!((frame / target - 1.0).abs() < 0.02, "settled at {frame} ms");
        }
    }

    /// A scene slower than the target still traces a little each frame; a fast one is capped.
    #[test]
    fn the_budget_stays_within_its_bounds() {
        assert_eq!(next_budget(1 << 10, 10_000.0, 33.0), 1 << 10);
        assert_eq!(next_budget(1 << 26, 0.1, 33.0), 1 << 26);
        assert_eq!(next_budget(1 << 20, 1e9, 33.0), 1 << 19);
    }
}
