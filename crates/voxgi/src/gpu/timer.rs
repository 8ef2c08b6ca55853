//! GPU timestamps per pass, for `voxgi bench`, through `wgpu-profiler`. Each pass asks for a
//! scope by its name when it begins; scopes of the same name in a frame (one shadow pass per
//! view, one filter pass per mip level) add up. Without timestamp support, or with timing off,
//! every request returns `None` and costs nothing. The scopes of the frames read can be kept
//! and written as a Chrome trace (`write_trace`).

use crate::{Error, Result};
use wgpu_profiler::{GpuProfiler, GpuProfilerQuery, GpuProfilerSettings, GpuTimerQueryResult};

/// Frames the profiler holds between reads: `headless::render` renders a few before it reads.
const MAX_PENDING: usize = 16;

/// Per-pass timestamp scopes: inert when disabled or when the device lacks
/// `TIMESTAMP_QUERY`.
pub struct GpuTimer {
    on: Option<Profiling>,
    period_ns: f32,
}

struct Profiling {
    profiler: GpuProfiler,
    /// `GpuProfiler::begin_pass_query` asks an encoder what it supports, and pass queries
    /// record nothing into it: the passes' own encoders stay untouched until `resolve`.
    scratch: wgpu::CommandEncoder,
    /// This frame's pass queries: they are closed when the frame's queries are resolved.
    open: Vec<GpuProfilerQuery>,
    /// The names scopes were asked by (results come back as strings).
    names: Vec<&'static str>,
    /// A frame's queries were resolved into an encoder: the frame ends once that encoder has
    /// been submitted (the next frame, or `read`).
    resolved: bool,
    /// Frames ended and not read yet (the profiler keeps at most `MAX_PENDING`, dropping the
    /// newest but one beyond).
    pending: usize,
    /// The scopes of every frame read, for a trace, when kept.
    trace: Option<Vec<GpuTimerQueryResult>>,
}

impl GpuTimer {
    /// A timer that records only if `enabled` and the device supports timestamps.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, enabled: bool) -> Self {
        let on = enabled && device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let settings = GpuProfilerSettings {
            enable_timer_queries: true,
            enable_debug_groups: false,
            max_num_pending_frames: MAX_PENDING,
        };
        GpuTimer {
            on: on
                .then(|| GpuProfiler::new(device, settings).ok())
                .flatten()
                .map(|profiler| Profiling {
                    profiler,
                    scratch: device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("timer scratch (never submitted)"),
                    }),
                    open: Vec::new(),
                    names: Vec::new(),
                    resolved: false,
                    pending: 0,
                    trace: None,
                }),
            period_ns: queue.get_timestamp_period(),
        }
    }

    /// A timer that never records.
    pub fn disabled(queue: &wgpu::Queue) -> Self {
        GpuTimer {
            on: None,
            period_ns: queue.get_timestamp_period(),
        }
    }

    /// Keeps the scopes of every frame read from now on, for `write_trace`.
    pub fn keep_trace(&mut self) {
        if let Some(p) = &mut self.on {
            p.trace.get_or_insert_with(Vec::new);
        }
    }

    /// Starts a frame: the last frame's encoder has been submitted (the renderer's contract),
    /// so its profiler frame ends.
    pub fn begin_frame(&mut self) {
        if let Some(p) = &mut self.on
            && std::mem::take(&mut p.resolved)
        {
            match p.profiler.end_frame() {
                Ok(()) => p.pending = (p.pending + 1).min(MAX_PENDING),
                Err(e) => log::warn!("pass timing: {e}"),
            }
        }
    }

    fn query(&mut self, label: &'static str) -> Option<&GpuProfilerQuery> {
        let p = self.on.as_mut()?;
        if !p.names.contains(&label) {
            p.names.push(label);
        }
        let q = p.profiler.begin_pass_query(label, &mut p.scratch);
        p.open.push(q);
        p.open.last()
    }

    /// Timestamp writes for a compute pass named `label`, or `None` when the timer is off.
    pub fn compute(&mut self, label: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.query(label)?.compute_pass_timestamp_writes()
    }

    /// Timestamp writes for a render pass named `label`, or `None` when the timer is off.
    pub fn render(&mut self, label: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.query(label)?.render_pass_timestamp_writes()
    }

    /// Records `work` (copies, outside any pass) into `encoder` in a scope named `label`, timed
    /// where the device has `TIMESTAMP_QUERY_INSIDE_ENCODERS` (and only there).
    pub fn encoder<T>(
        &mut self,
        label: &'static str,
        encoder: &mut wgpu::CommandEncoder,
        work: impl FnOnce(&mut wgpu::CommandEncoder) -> T,
    ) -> T {
        let Some(p) = &mut self.on else {
            return work(encoder);
        };
        if !p.names.contains(&label) {
            p.names.push(label);
        }
        let q = p.profiler.begin_query(label, encoder);
        let out = work(encoder);
        p.profiler.end_query(encoder, q);
        out
    }

    /// Records the resolve of this frame's timestamps; call once after the last pass.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let Some(p) = &mut self.on else {
            return;
        };
        for q in p.open.drain(..) {
            p.profiler.end_query(encoder, q);
        }
        p.profiler.resolve_queries(encoder);
        p.resolved = true;
    }

    /// Milliseconds per pass name, in first-use order, of every frame since the last read,
    /// once submitted. This waits for the GPU (for `voxgi bench`).
    pub fn read(&mut self, device: &wgpu::Device) -> Result<Vec<(&'static str, f64)>> {
        self.begin_frame();
        let period = self.period_ns;
        let Some(p) = &mut self.on else {
            return Ok(Vec::new());
        };
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu {
                context: "timestamps".into(),
                reason: e.to_string(),
            })?;
        let mut out: Vec<(&'static str, f64)> = Vec::new();
        // The readback's map callbacks run in whichever thread polls the device: on a device
        // shared between threads, another one's, a moment after this thread's wait returned.
        // Until they have run the last frame is not finished, and its times would show up in
        // the next read instead (a flaky test saw a relit frame's list with the rebuild before).
        let waiting = std::time::Instant::now();
        while p.pending > 0 {
            let Some(frame) = p.profiler.process_finished_frame(period) else {
                if waiting.elapsed() > std::time::Duration::from_secs(30) {
                    // Not again on every later read: those frames are given up.
                    p.pending = 0;
                    return Err(Error::Gpu {
                        context: "timestamps".into(),
                        reason: "their readback did not complete within 30 s".into(),
                    });
                }
                let _ = device.poll(wgpu::PollType::Poll);
                std::thread::yield_now();
                continue;
            };
            p.pending -= 1;
            for scope in &frame {
                let Some(name) = p.names.iter().find(|n| **n == scope.label) else {
                    continue;
                };
                let ms = scope
                    .time
                    .as_ref()
                    .map_or(0.0, |t| (t.end - t.start).max(0.0) * 1e3);
                if !ms.is_finite() {
                    return Err(Error::Gpu {
                        context: "timestamps".into(),
                        reason: "non-finite pass time".into(),
                    });
                }
                match out.iter_mut().find(|(l, _)| l == name) {
                    Some(e) => e.1 += ms,
                    None => out.push((name, ms)),
                }
            }
            if let Some(t) = &mut p.trace {
                t.extend(frame);
            }
        }
        out.sort_by_key(|(n, _)| p.names.iter().position(|m| m == n));
        Ok(out)
    }

    /// Writes the scopes kept since `keep_trace` as a Chrome trace (chrome://tracing, Perfetto).
    pub fn write_trace(&self, path: &std::path::Path) -> Result<()> {
        let scopes = self
            .on
            .as_ref()
            .and_then(|p| p.trace.as_deref())
            .ok_or_else(|| {
                Error::Setting(
                    "no pass timings to trace: timing is off or this device has no timestamps"
                        .into(),
                )
            })?;
        crate::scene::io::atomic::replace(path, |to| {
            wgpu_profiler::chrometrace::write_chrometrace(to, scopes)
        })
        .map_err(|e| Error::Output {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    }
}
