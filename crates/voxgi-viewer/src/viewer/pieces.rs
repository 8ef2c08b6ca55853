//! A new renderer's first voxel work (`Renderer::prepare`: voxelizing, building, lighting and
//! bouncing, seconds on a CPU driver) submitted one pass a frame, so the window keeps showing
//! frames (the old renderer's, or the progress frame at startup) while it runs, instead of
//! one frame that holds it all.

use std::collections::VecDeque;
use voxgi::{FrameParams, PreparedStep, Renderer, wgpu};

pub(super) struct Pieces {
    left: VecDeque<PreparedStep>,
    total: usize,
    /// The pass of the piece submitted last.
    last: &'static str,
}

impl Pieces {
    /// `renderer`'s pending voxel work, recorded for a frame of `params`.
    pub(super) fn new(renderer: &mut Renderer, params: &FrameParams) -> voxgi::Result<Self> {
        let left: VecDeque<_> = renderer.prepare(params)?.into();
        Ok(Pieces {
            total: left.len(),
            left,
            last: "",
        })
    }

    /// Submits the next piece; false when none was left.
    pub(super) fn submit_next(&mut self, queue: &wgpu::Queue) -> bool {
        let Some(piece) = self.left.pop_front() else {
            return false;
        };
        self.last = piece.pass;
        queue.submit([piece.commands]);
        true
    }

    /// What is under way, for a label: "bounce, 7 of 10".
    pub(super) fn progress(&self) -> String {
        let at = self.total - self.left.len();
        if at == 0 {
            format!("{} passes", self.total)
        } else {
            format!("{}, {at} of {}", self.last, self.total)
        }
    }
}
