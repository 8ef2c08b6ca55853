//! Statistics: the times of recent frames and the per-pass GPU milliseconds kept for the rolling
//! graphs, gathered each frame, and the panel's stats section that shows them with the
//! renderer's voxel counts and GPU memory.

use super::Viewer;
use anyhow::Result;
use std::collections::VecDeque;
use std::time::Instant;

/// Per-pass GPU milliseconds of recent frames, for the rolling graph.
const HISTORY: usize = 120;

/// A wait this long between two frames, or from an input to the frame showing it, is logged
/// (the window then feels stuck; at 10 frames a second it does not).
const LOGGED_GAP_S: f32 = 0.1;

/// Recent waits are shown for this long.
const RECENT_S: f32 = 10.0;

/// Frame times and per-pass GPU times of the last `HISTORY` frames, and how smoothly frames
/// come: the waits between presented frames and from input to the frame that shows it.
pub(super) struct Stats {
    last_frame: Instant,
    pub(super) frame_ms: VecDeque<f32>,
    pass_ms: Vec<(&'static str, VecDeque<f32>)>,
    last_present: Option<Instant>,
    /// The first input event no presented frame has shown yet.
    input_since: Option<Instant>,
    /// The longest wait between two presented frames in the last `RECENT_S`, and when it ended.
    pub(super) worst_gap: Option<(f32, Instant)>,
    /// The longest wait from an input to the frame showing it in the last `RECENT_S`.
    pub(super) worst_input: Option<(f32, Instant)>,
}

impl Stats {
    pub(super) fn new() -> Self {
        Stats {
            last_frame: Instant::now(),
            frame_ms: Default::default(),
            pass_ms: Vec::new(),
            // Made when the window opens.
            last_present: Some(Instant::now()),
            input_since: None,
            worst_gap: None,
            worst_input: None,
        }
    }

    /// An input event arrived (a key, a click, a drag, the wheel): the next presented frame
    /// shows it.
    pub(super) fn input_arrived(&mut self) {
        self.input_since.get_or_insert_with(Instant::now);
    }

    /// Whether an input event arrived that no presented frame shows yet.
    pub(super) fn input_waiting(&self) -> bool {
        self.input_since.is_some()
    }

    /// A frame was presented while `busy` ran in the background (empty: nothing): the wait
    /// since the last one and since the input it shows are kept, and logged when long.
    pub(super) fn presented(&mut self, busy: &str) {
        let now = Instant::now();
        let during = if busy.is_empty() {
            String::new()
        } else {
            format!(" (during {busy})")
        };
        if let Some(last) = self.last_present.replace(now) {
            let gap = (now - last).as_secs_f32();
            if gap > LOGGED_GAP_S {
                log::info!("frame gap {gap:.3} s{during}");
            }
            keep_worst(&mut self.worst_gap, gap, now);
        }
        if let Some(t) = self.input_since.take() {
            let delay = (now - t).as_secs_f32();
            if delay > LOGGED_GAP_S {
                log::info!("input shown {delay:.3} s after it arrived{during}");
            }
            keep_worst(&mut self.worst_input, delay, now);
        }
    }

    /// A frame starts: the seconds since the last one started, kept in the frame times.
    pub(super) fn frame_started(&mut self) -> f32 {
        let now = Instant::now();
        let elapsed = (now - self.last_frame).as_secs_f32();
        self.last_frame = now;
        push(&mut self.frame_ms, elapsed * 1e3);
        elapsed
    }

    /// Forgets the passes and their times: the renderer or its options changed.
    pub(super) fn clear_passes(&mut self) {
        self.pass_ms.clear();
    }

    /// The mean milliseconds per frame over the recent frames but the first two, and how many
    /// frames that is; none before a third frame (the first ones build the voxels).
    pub(super) fn steady_frame_ms(&self) -> Option<(f32, usize)> {
        let recent: Vec<f32> = self.frame_ms.iter().skip(2).copied().collect();
        (!recent.is_empty()).then(|| {
            (
                recent.iter().sum::<f32>() / recent.len() as f32,
                recent.len(),
            )
        })
    }
}

impl Viewer {
    /// The frame's GPU times per pass (the renderer's and the path tracer's), when the adapter
    /// has timestamps; the path tracer's frame is done either way.
    pub(super) fn record_pass_times(&mut self) -> Result<()> {
        let reference = self.ground.frame_done();
        if self.timestamps {
            let times: Vec<_> = self
                .renderer
                .pass_times()?
                .into_iter()
                .chain(reference)
                .collect();
            let pass_ms = &mut self.stats.pass_ms;
            for (name, _) in &times {
                if !pass_ms.iter().any(|(n, _)| n == name) {
                    pass_ms.push((name, Default::default()));
                }
            }
            // A pass that did not run this frame (the voxel passes of a still scene) took 0 ms
            // of it: the means are per frame, not per run. A frame shown again ran none: the
            // bars keep the frames that drew (they all fell to 0.00 ms, hiding the real cost).
            for (name, v) in pass_ms {
                let ms = times.iter().find(|(n, _)| n == name).map(|(_, ms)| *ms);
                if ms.is_some() || !self.reused {
                    push(v, ms.unwrap_or(0.0) as f32);
                }
            }
        }
        Ok(())
    }

    pub(super) fn stats_ui(&mut self, ui: &mut egui::Ui) {
        let mean = |v: &VecDeque<f32>| v.iter().sum::<f32>() / v.len().max(1) as f32;
        let frame = mean(&self.stats.frame_ms);
        ui.label(format!(
            "frame {frame:.1} ms ({:.1} fps)",
            1e3 / frame.max(1e-3)
        ));
        let recent = |w: Option<(f32, Instant)>| w.map_or(0.0, |(s, _)| s * 1e3);
        ui.label(format!(
            "longest wait in the last {RECENT_S:.0} s: {:.0} ms between frames, {:.0} ms from \
             input to frame",
            recent(self.stats.worst_gap),
            recent(self.stats.worst_input)
        ));
        if self.reused {
            ui.label("cone tracing: nothing changed, the last image is shown again");
        }
        if self.still_frames > 0 {
            ui.label(format!(
                "the still view: {} of {} frames accumulated",
                self.still_frames.min(self.still_cap),
                self.still_cap
            ));
        }
        if let Some(c) = self.renderer.last_voxel_counts() {
            ui.label(format!("{} fragments, {} voxels", c.fragments, c.occupied));
        }
        if self.stats.pass_ms.is_empty() {
            ui.label("no GPU timestamps on this adapter");
        }
        // A bar per pass: the mean of the recent frames, and a sparkline of them.
        let max = self
            .stats
            .pass_ms
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .fold(1e-3f32, f32::max);
        let width = self
            .stats
            .pass_ms
            .iter()
            .map(|(n, _)| n.chars().count())
            .max()
            .unwrap_or(0);
        for (name, v) in &self.stats.pass_ms {
            ui.horizontal(|ui| {
                ui.label(
                    egui::RichText::new(format!("{name:<width$} {:>7.2} ms", mean(v))).monospace(),
                );
                let (rect, _) =
                    ui.allocate_exact_size(egui::vec2(120.0, 14.0), egui::Sense::hover());
                let painter = ui.painter_at(rect);
                let n = v.len().max(2) as f32;
                let points: Vec<egui::Pos2> = v
                    .iter()
                    .enumerate()
                    .map(|(i, ms)| {
                        egui::pos2(
                            rect.left() + rect.width() * i as f32 / (n - 1.0),
                            rect.bottom() - rect.height() * (ms / max).min(1.0),
                        )
                    })
                    .collect();
                painter.add(egui::Shape::line(
                    points,
                    egui::Stroke::new(1.0, egui::Color32::LIGHT_GREEN),
                ));
            });
        }
        ui.checkbox(&mut self.vsync, "vsync");
        let (budget, now) = (self.scale.budget_ms, self.scale.value() * 100.0);
        ui.checkbox(
            &mut self.scale.auto,
            format!("a moving view drawn smaller, for {budget:.0} ms a frame (now {now:.0} %)"),
        );
        ui.checkbox(&mut self.frame_overlay, "frame time over the view (O)");
        ui.separator();
        let memory = self.renderer.memory();
        let total: u64 = memory.iter().map(|(_, b)| b).sum();
        ui.label(format!("GPU memory {:.1} MiB", total as f64 / 1048576.0));
        let shown: Vec<_> = memory.iter().filter(|(_, b)| *b >= 1 << 16).collect();
        let width = shown
            .iter()
            .map(|(n, _)| n.chars().count())
            .max()
            .unwrap_or(0);
        for (name, bytes) in shown {
            ui.label(
                egui::RichText::new(format!(
                    "  {name:<width$} {:>8.2} MiB",
                    *bytes as f64 / 1048576.0
                ))
                .monospace()
                .small(),
            );
        }
    }
}

/// Keeps the longer of `worst` and `wait`, forgetting a worst older than `RECENT_S`.
fn keep_worst(worst: &mut Option<(f32, Instant)>, wait: f32, now: Instant) {
    let stale = worst.is_none_or(|(w, at)| w <= wait || (now - at).as_secs_f32() > RECENT_S);
    if stale {
        *worst = Some((wait, now));
    }
}

fn push(v: &mut VecDeque<f32>, x: f32) {
    if v.len() == HISTORY {
        v.pop_front();
    }
    v.push_back(x);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// The panel shows the longest recent wait: a shorter one does not replace it, a longer
    /// one does, and once it is older than `RECENT_S` the next wait, however short, does.
    #[test]
    fn the_worst_wait_is_kept_for_ten_seconds() {
        let t0 = Instant::now();
        let at = |s: f32| t0 + Duration::from_secs_f32(s);
        let mut worst = None;
        keep_worst(&mut worst, 0.5, at(0.0));
        keep_worst(&mut worst, 0.2, at(1.0));
        assert_eq!(worst, Some((0.5, at(0.0))));
        keep_worst(&mut worst, 0.7, at(2.0));
        assert_eq!(worst, Some((0.7, at(2.0))));
        keep_worst(&mut worst, 0.1, at(2.0 + RECENT_S + 0.5));
        assert_eq!(worst, Some((0.1, at(2.0 + RECENT_S + 0.5))));
    }
}
