//! voxgi's path tracer on the page: the ground truth instead of cone tracing, or right of the
//! middle of the view beside it (the viewer's split view). As in the viewer it adds a band of
//! rows a frame, sized to a budget of paths, and stops at a sample count; the accumulation
//! starts over when the view, the bounce count or the columns change. Unlike the viewer it
//! builds the scene's BVH on the page's thread (a browser page has no threads), when first
//! shown and when the scene's time changed; showing it pauses the animation.

use anyhow::Result;
use std::ops::Range;
use voxgi::reference::{Accumulation, Region};
use voxgi::{Bounces, FrameParams, PathTracer, ReferenceMode, ReferenceOptions, Target};

/// What the view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Display {
    /// Cone tracing.
    Cones,
    /// The path tracer.
    Traced,
    /// Cone tracing left of the middle, the path tracer right of it.
    Split,
}

impl Display {
    pub(crate) const ALL: [(Display, &'static str); 3] = [
        (Display::Cones, "cone tracing"),
        (Display::Traced, "path tracer"),
        (Display::Split, "split: cones | path tracer"),
    ];

    pub(crate) fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(d, _)| *d == self)
            .map_or("", |(_, n)| n)
    }

    /// The columns of a `width`-pixel view the path tracer draws.
    pub(crate) fn traced_columns(self, width: u32) -> Option<Range<u32>> {
        match self {
            Display::Cones => None,
            Display::Traced => Some(0..width),
            Display::Split => Some(width / 2..width),
        }
    }
}

/// The path tracer and its running image.
pub(crate) struct Traced {
    tracer: PathTracer,
    /// The scene's time it traces.
    pub(crate) time: f32,
    acc: Option<Accumulation>,
    /// The columns the image holds samples of (another set starts it over).
    columns: Range<u32>,
    /// The next band's first row.
    next_row: u32,
    /// Paths a frame: on a CPU adapter a band that takes a few hundred milliseconds, on a GPU
    /// a few milliseconds' worth.
    paths_per_frame: u32,
    /// Where accumulation stops.
    max_samples: u32,
}

impl Traced {
    pub(crate) fn new(
        device: &voxgi::wgpu::Device,
        queue: &voxgi::wgpu::Queue,
        scene: &voxgi::scene::Scene,
        options: &voxgi::RendererOptions,
        cpu: bool,
        time: f32,
    ) -> Result<Self> {
        Ok(Traced {
            tracer: PathTracer::new(device, queue, scene, options)?,
            time,
            acc: None,
            columns: 0..0,
            next_row: 0,
            paths_per_frame: if cpu { 1 << 15 } else { 1 << 22 },
            max_samples: if cpu { 64 } else { 4096 },
        })
    }

    /// Records one more band of samples over `columns` (with `bounces` indirect bounces, as
    /// the cone tracer's) and draws the running image into those columns of `target`.
    /// Returns the samples every pixel has.
    pub(crate) fn record(
        &mut self,
        encoder: &mut voxgi::wgpu::CommandEncoder,
        target: &Target,
        params: &FrameParams,
        bounces: u32,
        columns: Range<u32>,
    ) -> Result<u32> {
        let size = (target.width, target.height);
        // A new size, or other columns (the split view turned into the path tracer alone:
        // its sample count is the least over what it traced).
        if self.acc.as_ref().map(|a| (a.width(), a.height())) != Some(size)
            || self.columns != columns
        {
            self.columns = columns.clone();
            self.acc = Some(self.tracer.accumulation(size.0, size.1)?);
            self.next_row = 0;
        }
        let acc = self.acc.as_mut().expect("made above");
        let opts = ReferenceOptions {
            spp: 1,
            bounces: Bounces::matching(bounces),
            mode: ReferenceMode::Radiance,
            seed: 0,
        };
        let moved = !self.tracer.shows(acc, params, &opts);
        if moved {
            self.next_row = 0;
        }
        if moved || acc.samples() < self.max_samples {
            let h = target.height;
            let width = u64::from(columns.end - columns.start).max(1);
            let rows = (u64::from(self.paths_per_frame) / width).clamp(1, u64::from(h)) as u32;
            let start = if self.next_row >= h { 0 } else { self.next_row };
            let end = (start + rows).min(h);
            self.next_row = end % h;
            let region = Region {
                columns: columns.clone(),
                rows: start..end,
            };
            self.tracer
                .accumulate(encoder, acc, params, &opts, region)?;
        }
        self.tracer.display(encoder, acc, target, params, columns)?;
        Ok(acc.samples())
    }
}
