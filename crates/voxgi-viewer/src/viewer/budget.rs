//! The view's resolution while it moves. A CPU driver draws Sponza's view in half a second a
//! frame, which no orbit survives; so a moving view (the camera, the animation, a light being
//! dragged) is drawn at a fraction of its pixels, adapted frame by frame towards a wall-time
//! budget, and upscaled into the view. A still view goes back to full resolution, where
//! temporal accumulation converges it.

/// The fraction of the view's width and height a moving view is drawn at.
pub(super) struct Scale {
    /// Adapting; off, every frame is drawn at full resolution.
    pub(super) auto: bool,
    /// Milliseconds a moving frame should take.
    pub(super) budget_ms: f32,
    /// The fraction now, in eighths from a quarter to one (each value a target size of its
    /// own: the renderer's targets are made again when it changes).
    value: f32,
}

/// The smallest fraction: a quarter of the width and height, a sixteenth of the pixels.
const LEAST: f32 = 0.25;

impl Scale {
    pub(super) fn new(cpu: bool, auto: bool) -> Self {
        Scale {
            auto,
            // A CPU driver answers input every ~100 ms; a GPU keeps 60 frames a second.
            budget_ms: if cpu { 100.0 } else { 16.7 },
            value: 1.0,
        }
    }

    /// The fraction to draw the next frame at.
    pub(super) fn value(&self) -> f32 {
        if self.auto { self.value } else { 1.0 }
    }

    /// After a frame of `ms` wall time: a still view (`moving` false) returns to full
    /// resolution; a moving one scales by the square root of budget over time (a frame's
    /// cost goes with its pixels), by at most a factor of two a frame, rounded to eighths
    /// with a margin either side so that it settles instead of flickering between two.
    pub(super) fn frame(&mut self, ms: f32, moving: bool) {
        if !self.auto || !moving {
            self.value = 1.0;
            return;
        }
        let ms = ms.max(1e-3);
        if ms < 0.6 * self.budget_ms || ms > 1.25 * self.budget_ms {
            let wanted = self.value * (self.budget_ms / ms).sqrt().clamp(0.5, 1.5);
            self.value = ((wanted * 8.0).round() / 8.0).clamp(LEAST, 1.0);
        }
    }
}

/// The size a `width` x `height` view is drawn at with `scale`: at least one pixel.
pub(super) fn scaled(width: u32, height: u32, scale: f32) -> (u32, u32) {
    let s = |n: u32| ((n as f32 * scale).round() as u32).clamp(1, n.max(1));
    (s(width), s(height))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame's cost in proportion to its pixels, 400 ms at full size (Sponza on a CPU
    /// driver): a moving view settles within the budget in a few frames, stays there, and is
    /// back at full resolution the frame it stops; off, it never scales.
    #[test]
    fn a_moving_view_settles_within_its_budget() {
        let mut s = Scale::new(true, true);
        let cost = |v: f32| 400.0 * v * v + 10.0;
        let mut ms = cost(1.0);
        let mut values = Vec::new();
        for _ in 0..8 {
            s.frame(ms, true);
            ms = cost(s.value());
            values.push(s.value());
        }
        assert!(ms <= 1.25 * s.budget_ms, "{ms} ms after {values:?}");
        assert!(ms >= 0.3 * s.budget_ms, "{ms} ms: too small ({values:?})");
        assert_eq!(
            values[5..],
            [values[7]; 3],
            "it does not settle: {values:?}"
        );
        s.frame(ms, false);
        assert_eq!(s.value(), 1.0);
        let mut off = Scale::new(true, false);
        off.frame(1000.0, true);
        assert_eq!(off.value(), 1.0);
        assert_eq!(scaled(590, 480, 0.375), (221, 180));
        assert_eq!(scaled(3, 2, 0.25), (1, 1));
    }
}
