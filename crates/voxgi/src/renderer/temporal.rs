//! What the renderer remembers from frame to frame for temporal accumulation: how many frames
//! the history holds (the index into the jitter and cone-turn sequence), which of the history
//! pair was written last, and the last frame's view, from which it decides what this frame
//! may do with the history (`GpuFrame::history`).

use crate::frame::sequence;
use crate::frame::uniforms::{HISTORY_MOVING, HISTORY_NONE, HISTORY_STILL};
use crate::options::{FrameParams, ViewMode};
use glam::{Mat4, Vec3};

/// The frame parameters that change what the history holds (not the camera, which
/// reprojection follows, nor exposure and tone map, which come after it).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Look {
    view: ViewMode,
    debug_level: u32,
    debug_direction: u32,
    shadow_softness: f32,
    background: [f32; 3],
}

impl Look {
    fn of(p: &FrameParams) -> Self {
        Look {
            view: p.view,
            debug_level: p.debug_level,
            debug_direction: p.debug_direction,
            shadow_softness: p.shadow_softness,
            background: p.background,
        }
    }
}

/// Consecutive still frames after which a still view is converged: the renderer then shows
/// the history as it is (`FrameHistory::hold`) and is idle. A running mean of n frames moves
/// by at most 1/n of a new frame's difference from it, so past 256 frames no frame can move a
/// displayed value (at most 1 after tone mapping) by a whole 8-bit step.
pub const STILL_FRAMES: u32 = 256;

/// The temporal state between frames.
#[derive(Default)]
pub(super) struct TemporalState {
    /// Frames accumulated since the history was last reset.
    frames: u32,
    /// Consecutive still frames accumulated (not counting held ones).
    still: u32,
    /// Which of the history pair the last frame wrote.
    written: usize,
    /// The last frame's view-projection without jitter, camera position and look; `None`:
    /// the next frame starts a new history.
    last: Option<(Mat4, Vec3, Look)>,
}

/// What one frame does with the history.
#[derive(Clone, Copy, Debug)]
pub(super) struct FrameHistory {
    /// `HISTORY_*`.
    pub mode: u32,
    /// The camera's sub-pixel offset, pixels.
    pub jitter: [f32; 2],
    /// The cone bundle's turn about the normal and in zenith, as fractions of a cone's cell.
    pub cone_turn: [f32; 2],
    /// The frame's index in the sample sequence (area lights' points, `sequence`).
    pub sample: u32,
    /// The last frame's view-projection without jitter and camera position (this frame's own
    /// without history).
    pub prev_view_proj: Mat4,
    pub prev_camera: Vec3,
    /// The history the temporal pass reads (it writes the other).
    pub read: usize,
    /// The still view has converged: nothing is rendered, the last history is shown again.
    pub hold: bool,
}

impl TemporalState {
    /// Forgets the history: the next frame starts a new one (a camera cut, a new scene, new
    /// targets or options).
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// Which of the history pair the last frame wrote: the image `tonemap` showed.
    pub fn written(&self) -> usize {
        self.written
    }

    /// Whether the next frame, if nothing changes, would only show the last image again.
    pub fn converged(&self) -> bool {
        self.last.is_some() && self.still >= STILL_FRAMES
    }

    /// Begins a frame seen through `view_proj` (without jitter) from `camera`: `changed`
    /// says whether anything in the scene or its light changed since the last frame.
    /// With `enabled` false there is no history, no jitter and no turn.
    pub fn begin(
        &mut self,
        enabled: bool,
        params: &FrameParams,
        view_proj: Mat4,
        changed: bool,
    ) -> FrameHistory {
        let camera = params.camera.position;
        let look = Look::of(params);
        let last = self.last.filter(|l| enabled && l.2 == look);
        self.last = enabled.then_some((view_proj, camera, look));
        let Some((prev_view_proj, prev_camera, _)) = last else {
            self.frames = if enabled { 1 } else { 0 };
            self.still = 0;
            let read = self.written;
            self.written = 1 - read;
            return FrameHistory {
                mode: HISTORY_NONE,
                jitter: [0.0; 2],
                cone_turn: [0.0; 2],
                sample: 0,
                prev_view_proj: view_proj,
                prev_camera: camera,
                read,
                hold: false,
            };
        };
        let still = !changed && prev_view_proj == view_proj && prev_camera == camera;
        let hold = still && self.still >= STILL_FRAMES;
        self.still = if still {
            self.still + u32::from(!hold)
        } else {
            0
        };
        let k = self.frames;
        let read = self.written;
        if !hold {
            self.frames = self.frames.wrapping_add(1);
            self.written = 1 - read;
        }
        FrameHistory {
            mode: if still { HISTORY_STILL } else { HISTORY_MOVING },
            jitter: sequence::jitter(k),
            cone_turn: sequence::cone_turn(k),
            sample: k,
            prev_view_proj,
            prev_camera,
            read,
            hold,
        }
    }
}
