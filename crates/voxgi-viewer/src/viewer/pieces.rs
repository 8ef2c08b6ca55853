//! A new renderer's first voxel work (`Renderer::prepare`: voxelizing, building, lighting and
//! bouncing, seconds on a CPU driver) submitted one pass a frame, so the window keeps showing
//! frames (the old renderer's, or the progress frame at startup) while it runs, instead of
//! one frame that holds it all. The renderer takes over once its voxel counters are back and
//! asked for nothing more: a build that outgrew its pools (the octree's estimate falls short
//! on Sponza) is redone the same way, not in the new renderer's first frame.

use std::collections::VecDeque;
use voxgi::{FrameParams, PreparedStep, Renderer, wgpu};

pub(super) struct Pieces {
    left: VecDeque<PreparedStep>,
    /// Pieces submitted and left, over every round.
    total: usize,
    /// The pass of the piece submitted last.
    last: &'static str,
    /// Rounds of voxel work prepared (more than one after the pools grew).
    rounds: u32,
}

/// What `Pieces::step` did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Step {
    Submitted,
    /// Every piece is submitted; the voxel counters are not back yet.
    Waiting,
    /// The renderer's voxels are settled: it can take over.
    Done,
}

impl Pieces {
    /// `renderer`'s pending voxel work, recorded for a frame of `params`.
    pub(super) fn new(renderer: &mut Renderer, params: &FrameParams) -> voxgi::Result<Self> {
        let left: VecDeque<_> = renderer.prepare(params)?.into();
        Ok(Pieces {
            total: left.len(),
            left,
            last: "",
            rounds: 1,
        })
    }

    /// Submits `renderer`'s next piece; once all are submitted, waits for its voxel counters
    /// and prepares what they ask for (a rebuild in larger pools), if anything.
    pub(super) fn step(
        &mut self,
        renderer: &mut Renderer,
        queue: &wgpu::Queue,
        params: &FrameParams,
    ) -> voxgi::Result<Step> {
        if self.left.is_empty() {
            let rebuild = renderer.receive_feedback()?;
            if renderer.feedback_in_flight() {
                return Ok(Step::Waiting);
            }
            // Only a rebuild waits: progressive bounces go on converging in the frames.
            if !rebuild {
                return Ok(Step::Done);
            }
            let more = renderer.prepare(params)?;
            if more.is_empty() {
                return Ok(Step::Done);
            }
            self.rounds += 1;
            self.total += more.len();
            self.left.extend(more);
        }
        let piece = self.left.pop_front().expect("filled above");
        self.last = piece.pass;
        queue.submit([piece.commands]);
        Ok(Step::Submitted)
    }

    /// What is under way, for a label: "bounce, 7 of 10".
    pub(super) fn progress(&self) -> String {
        let at = self.total - self.left.len();
        let again = if self.rounds > 1 {
            " (again, in pools grown to the counted voxels)"
        } else {
            ""
        };
        if at == 0 {
            format!("{} passes", self.total)
        } else if self.left.is_empty() {
            format!("waiting for the voxel counts{again}")
        } else {
            format!("{}, {at} of {}{again}", self.last, self.total)
        }
    }
}
