//! Messages over the 3D view, where they are seen: what the viewer did ("wrote …", "options
//! applied") for a few seconds, errors in red until dismissed. They were a line at the top of
//! the panel, out of sight once it scrolled, errors in the colour of successes.

use std::time::{Duration, Instant};

/// How long a message that is not an error stays.
const SHOWN: Duration = Duration::from_secs(6);
/// Messages shown at once: older ones give way.
const MOST: usize = 4;

struct Toast {
    text: String,
    error: bool,
    since: Instant,
}

#[derive(Default)]
pub(super) struct Toasts {
    list: Vec<Toast>,
}

impl Toasts {
    /// A message that goes after `SHOWN`.
    pub(super) fn info(&mut self, text: impl Into<String>) {
        self.push(text.into(), false);
    }

    /// An error, kept until dismissed.
    pub(super) fn error(&mut self, text: impl Into<String>) {
        self.push(text.into(), true);
    }

    fn push(&mut self, text: String, error: bool) {
        // The same message again (a key held, a retry) restarts its time instead of stacking.
        self.list.retain(|t| t.text != text);
        self.list.push(Toast {
            text,
            error,
            since: Instant::now(),
        });
        // Errors stay until dismissed: the oldest other message gives way first.
        while self.list.len() > MOST {
            let oldest = self.list.iter().position(|t| !t.error).unwrap_or(0);
            self.list.remove(oldest);
        }
    }

    /// Drops the messages whose time is up at `now`; errors stay.
    fn prune(&mut self, now: Instant) {
        self.list
            .retain(|t| t.error || now.duration_since(t.since) < SHOWN);
    }

    /// The messages, newest at the bottom, in the 3D view's lower right corner (above the path
    /// tracer's caption); an error has a button that dismisses it.
    pub(super) fn ui(&mut self, ctx: &egui::Context) {
        self.prune(Instant::now());
        if self.list.is_empty() {
            return;
        }
        let mut dismiss = None;
        egui::Area::new(egui::Id::unique("toasts"))
            .anchor(egui::Align2::RIGHT_BOTTOM, [-8.0, -48.0])
            .show(ctx, |ui| {
                for (i, t) in self.list.iter().enumerate() {
                    let fill = if t.error {
                        egui::Color32::from_rgb(120, 20, 20)
                    } else {
                        egui::Color32::from_rgb(30, 60, 40)
                    };
                    egui::Frame::popup(ui.style()).fill(fill).show(ui, |ui| {
                        ui.set_max_width(420.0);
                        ui.horizontal(|ui| {
                            // A message of several lines (a TOML error with its caret under
                            // the column) keeps its columns in a fixed-width font.
                            let text = egui::RichText::new(&t.text).color(egui::Color32::WHITE);
                            if t.text.contains('\n') {
                                ui.add(egui::Label::new(text.monospace()).extend());
                            } else {
                                ui.add(egui::Label::new(text).wrap());
                            }
                            if t.error && ui.small_button("×").clicked() {
                                dismiss = Some(i);
                            }
                        });
                    });
                }
            });
        if let Some(i) = dismiss {
            self.list.remove(i);
        }
    }

    /// The messages shown, oldest first, each with whether it is an error.
    #[cfg(test)]
    fn shown(&self) -> Vec<(&str, bool)> {
        self.list
            .iter()
            .map(|t| (t.text.as_str(), t.error))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_go_after_their_time_and_errors_stay_until_dismissed() {
        let mut t = Toasts::default();
        t.info("wrote a.png");
        t.error("the new options failed: no");
        t.info("options applied");
        let now = Instant::now();
        t.prune(now);
        assert_eq!(t.shown().len(), 3);
        t.prune(now + SHOWN + Duration::from_millis(1));
        assert_eq!(t.shown(), vec![("the new options failed: no", true)]);
        // The same message again restarts it rather than stacking; the oldest give way.
        for i in 0..10 {
            t.info(format!("wrote {i}.png"));
            t.info(format!("wrote {i}.png"));
        }
        assert_eq!(t.shown().len(), MOST);
        assert_eq!(t.shown()[0], ("the new options failed: no", true));
        assert_eq!(t.shown()[MOST - 1], ("wrote 9.png", false));
    }
}
