//! Work that takes longer than a frame — building a renderer for new options, loading a file,
//! building the path tracer's BVH, a file dialog — runs on its own thread, so the window keeps
//! drawing and answering while it does; the frame loop polls for the result.

use anyhow::{Result, anyhow};
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::Instant;

/// One piece of background work and its result to come.
pub struct Job<T> {
    what: String,
    started: Instant,
    rx: Receiver<Result<T>>,
}

impl<T: Send + 'static> Job<T> {
    /// Starts `work` on a new thread; `what` names it in the window ("loading sponza.toml").
    pub fn spawn(
        what: impl Into<String>,
        work: impl FnOnce() -> Result<T> + Send + 'static,
    ) -> Self {
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            // The receiver may be gone (the job was replaced): nobody wants the result.
            let _ = tx.send(work());
        });
        Job {
            what: what.into(),
            started: Instant::now(),
            rx,
        }
    }

    /// The result once the work is done; `None` while it runs.
    pub fn poll(&self) -> Option<Result<T>> {
        match self.rx.try_recv() {
            Ok(r) => Some(r),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => {
                Some(Err(anyhow!("{} stopped without a result", self.what)))
            }
        }
    }

    /// What the job does and for how long it has, for the window's indicator.
    pub fn label(&self) -> String {
        format!(
            "{} … {:.1} s",
            self.what,
            self.started.elapsed().as_secs_f32()
        )
    }
}

/// Polls `slot`'s job: its result when it finished (the slot is then empty).
pub fn take<T: Send + 'static>(slot: &mut Option<Job<T>>) -> Option<Result<T>> {
    let result = slot.as_ref()?.poll()?;
    *slot = None;
    Some(result)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait<T: Send + 'static>(mut slot: Option<Job<T>>) -> Result<T> {
        let t = Instant::now();
        loop {
            if let Some(r) = take(&mut slot) {
                assert!(slot.is_none(), "a finished job stays in its slot");
                return r;
            }
            assert!(t.elapsed().as_secs() < 10, "the job never finished");
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }

    #[test]
    fn a_job_hands_back_its_result_once() {
        assert_eq!(wait(Some(Job::spawn("adding", || Ok(2 + 2)))).unwrap(), 4);
        let e = wait(Some(Job::spawn("failing", || -> Result<()> {
            Err(anyhow!("bad file"))
        })));
        assert_eq!(e.unwrap_err().to_string(), "bad file");
    }

    #[test]
    fn a_job_that_panics_reports_it_instead_of_hanging() {
        let e = wait(Some(Job::spawn("exploding", || -> Result<()> {
            panic!("boom")
        })));
        assert!(e.unwrap_err().to_string().contains("exploding"));
    }

    #[test]
    fn a_running_job_is_polled_without_blocking() {
        let (go, gate) = channel::<()>();
        let mut slot = Some(Job::spawn("waiting", move || {
            gate.recv().ok();
            Ok(1)
        }));
        assert!(take(&mut slot).is_none());
        assert!(slot.as_ref().unwrap().label().starts_with("waiting … "));
        go.send(()).unwrap();
        assert_eq!(wait(slot).unwrap(), 1);
    }
}
