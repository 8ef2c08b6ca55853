//! Point sequences: a point cloud whose points come from a numbered file per frame (a live
//! scan, a simulation's output), played at a frame rate. A scene file makes one from an
//! include whose `file` holds a frame number (`scan_%04d.ply`) and an `fps`.

use crate::animation::Repeat;
use crate::prepare::PointsAhead;
use crate::{Aabb, PointCloud, Result, SceneError};
use glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};

/// Frames a sequence may hold: far past any capture voxgi plays, and a bound on probing.
pub const MAX_FRAMES: usize = 1 << 20;

/// A cloud's points, one file a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSequence {
    /// The cloud the frames replace (an index into `Scene::point_clouds`; a dynamic cloud).
    pub cloud: usize,
    /// One point file per frame, in order.
    pub files: Vec<PathBuf>,
    /// Frames per second.
    pub fps: f32,
    /// Past the last frame: hold it (`Clamp`) or start over (`Loop`).
    pub repeat: Repeat,
    /// The most points a frame holds: the renderer keeps room for them.
    pub capacity: usize,
    /// The box around every frame's points, in the cloud's own space: the voxels cover it
    /// (`Scene::object_bounds` takes it for the cloud), whichever frame is shown.
    pub bounds: Aabb,
    /// A colour for every point, replacing the files' (the include's material override).
    pub base_color: Option<[f32; 3]>,
    /// The frame the scene's cloud holds now.
    pub shown: usize,
}

impl PointSequence {
    /// The files `pattern` names: its file name holds one printf-style frame number (`%d`, or
    /// zero-padded `%04d`; `%%` is a literal `%`), and the sequence runs from frame 0 (or 1,
    /// when there is no 0) to the last consecutive file. Each frame is loaded once here, so that
    /// a bad frame is an error now, naming its file, and the largest frame is known; the first
    /// frame is returned. `progress` hears of every 32nd frame.
    pub fn open(
        pattern: &Path,
        fps: f32,
        repeat: Repeat,
        base_color: Option<[f32; 3]>,
        progress: &mut dyn FnMut(usize),
    ) -> Result<(PointSequence, PointCloud)> {
        let fail = |reason: String| SceneError::load(pattern, reason);
        if !(fps.is_finite() && fps > 0.0) {
            return Err(fail(format!("`fps` must be a number > 0, not {fps}")));
        }
        let name = pattern
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or_else(|| fail("the file name is not text".into()))?;
        let format = FrameNumber::parse(name).map_err(fail)?;
        let file = |i: usize| pattern.with_file_name(format.name(i));
        let first = if file(0).is_file() {
            0
        } else if file(1).is_file() {
            1
        } else {
            return Err(fail(format!(
                "no frame found (looked for {} and {})",
                format.name(0),
                format.name(1)
            )));
        };
        let files: Vec<PathBuf> = (first..first + MAX_FRAMES)
            .map(file)
            .take_while(|f| f.is_file())
            .collect();
        let mut sequence = PointSequence {
            cloud: 0,
            files,
            fps,
            repeat,
            capacity: 0,
            bounds: Aabb::EMPTY,
            base_color,
            shown: 0,
        };
        let mut first_cloud = None;
        for i in 0..sequence.files.len() {
            let pc = sequence.load(i)?;
            sequence.capacity = sequence.capacity.max(pc.positions.len());
            for &p in &pc.positions {
                sequence.bounds.grow(p);
            }
            first_cloud.get_or_insert(pc);
            if i % 32 == 31 {
                progress(i + 1);
            }
        }
        Ok((sequence, first_cloud.expect("a sequence has a first frame")))
    }

    /// How long one pass through the frames lasts, seconds.
    pub fn duration(&self) -> f32 {
        self.files.len() as f32 / self.fps
    }

    /// The frame shown at time `t` (seconds; frame 0 from t = 0). A time a ten-thousandth of
    /// a frame short of a frame's start counts as that frame, so that times computed as
    /// k / fps in single precision (4.9999995 frames) show frame k.
    pub fn frame_at(&self, t: f32) -> usize {
        let n = self.files.len().max(1) as i64;
        let f = (t as f64 * self.fps as f64 + 1e-4).floor();
        let f = if f.is_finite() {
            f.clamp(i64::MIN as f64, i64::MAX as f64) as i64
        } else {
            0
        };
        match self.repeat {
            Repeat::Clamp => f.clamp(0, n - 1) as usize,
            Repeat::Loop => f.rem_euclid(n) as usize,
        }
    }

    /// The frame after `frame`, in play order.
    pub fn next(&self, frame: usize) -> usize {
        let n = self.files.len().max(1);
        match self.repeat {
            Repeat::Clamp => (frame + 1).min(n - 1),
            Repeat::Loop => (frame + 1) % n,
        }
    }

    /// Frame `frame`'s points, in the cloud's own space (the include's placement and motion are
    /// the cloud's transform). A file must hold one point cloud (meshes and lights are errors).
    pub fn load(&self, frame: usize) -> Result<PointCloud> {
        load_frame(&self.files, frame, self.base_color)
    }
}

fn load_frame(files: &[PathBuf], frame: usize, base_color: Option<[f32; 3]>) -> Result<PointCloud> {
    let path = files.get(frame).ok_or_else(|| {
        SceneError::Invalid(format!(
            "frame {frame} of a point sequence of {} frames",
            files.len()
        ))
    })?;
    let scene = crate::io::load(path)?;
    let fail = |reason: &str| SceneError::load(path, format!("a point sequence's frame {reason}"));
    if scene.triangle_count() > 0 || !scene.lights.is_empty() || scene.point_clouds.len() != 1 {
        return Err(fail(&format!(
            "must hold one point cloud and nothing else (it holds {} clouds, {} triangles, {} \
             lights)",
            scene.point_clouds.len(),
            scene.triangle_count(),
            scene.lights.len()
        )));
    }
    let mut pc = scene.point_clouds.into_iter().next().expect("one cloud");
    if pc.light.is_some() || !pc.emission.is_empty() {
        return Err(fail(
            "has emissive points (sequences of lights are not supported)",
        ));
    }
    if pc.transform != Mat4::IDENTITY {
        // Into the cloud's own space, where the include places it.
        let m = pc.transform;
        let n = m.inverse().transpose();
        for p in &mut pc.positions {
            *p = m.transform_point3(*p);
        }
        for v in &mut pc.normals {
            *v = n.transform_vector3(*v).normalize_or(Vec3::Y);
        }
        pc.transform = Mat4::IDENTITY;
        // Radii and regions are in the file's units: a scaled file gives none.
        pc.radii.clear();
        pc.regions.clear();
    }
    if let Some(c) = base_color {
        pc.colors = vec![c; pc.positions.len()];
    }
    Ok(pc)
}

/// A printf-style frame number in a file name.
struct FrameNumber {
    before: String,
    width: usize,
    after: String,
}

impl FrameNumber {
    fn parse(name: &str) -> std::result::Result<FrameNumber, String> {
        let mut parts = None;
        let mut text = String::new();
        let mut chars = name.chars().peekable();
        while let Some(c) = chars.next() {
            if c != '%' {
                text.push(c);
                continue;
            }
            if chars.peek() == Some(&'%') {
                chars.next();
                text.push('%');
                continue;
            }
            let mut digits = String::new();
            while let Some(d) = chars.peek().copied().filter(char::is_ascii_digit) {
                digits.push(d);
                chars.next();
            }
            if chars.next() != Some('d') || parts.is_some() {
                return Err(format!(
                    "a sequence's file name holds one frame number (`%d`, or `%04d` for four \
                     digits): '{name}'"
                ));
            }
            let width = if digits.is_empty() {
                0
            } else if digits.starts_with('0') && digits.len() <= 3 {
                digits.parse().unwrap_or(0)
            } else {
                return Err(format!(
                    "'%{digits}d' in '{name}': the width is written with a leading 0 and at \
                     most two digits (`%04d`)"
                ));
            };
            parts = Some((std::mem::take(&mut text), width));
        }
        let (before, width) =
            parts.ok_or_else(|| format!("no frame number (`%04d`) in '{name}'"))?;
        Ok(FrameNumber {
            before,
            width,
            after: text,
        })
    }

    fn name(&self, i: usize) -> String {
        format!("{}{i:0w$}{}", self.before, self.after, w = self.width)
    }
}

/// Whether a file asks for a sequence: its name (not its folders) holds one frame number
/// (`%d`, `%04d`). Any other `%` is part of the name.
pub fn is_pattern(file: &str) -> bool {
    Path::new(file)
        .file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| FrameNumber::parse(n).is_ok())
}

/// Plays a scene's sequences: says which clouds get a new frame at a time, loading the frame
/// after it in the background and estimating the attributes its file lacks there
/// (`PointsAhead`; one thread per sequence, native builds), so that playing forward finds
/// each frame ready.
pub struct SequencePlayer {
    sequences: Vec<PointSequence>,
    ahead: Vec<Option<Ahead>>,
}

/// The frame a thread is loading ahead. The web build has no threads: it loads each frame
/// when it is due, and never makes one.
#[cfg_attr(target_arch = "wasm32", allow(dead_code))]
struct Ahead {
    frame: usize,
    #[cfg(not(target_arch = "wasm32"))]
    job: std::thread::JoinHandle<Result<PointsAhead>>,
    /// False once the player moved elsewhere (a jump in time): the thread then skips the
    /// estimation, which would only compete with the caller's.
    #[cfg(not(target_arch = "wasm32"))]
    wanted: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

/// A frame a sequence moved to: its cloud, the frame, its points (their attributes estimated
/// but for the normals' orientation), and how long the caller waited for them (near 0 when
/// the background had them ready; else the file and the estimation).
pub struct NewFrame {
    pub cloud: usize,
    pub frame: usize,
    pub points: PointsAhead,
    pub waited: std::time::Duration,
}

impl SequencePlayer {
    /// A player starting from the frames the scene's clouds hold (`PointSequence::shown`).
    pub fn new(sequences: &[PointSequence]) -> Self {
        SequencePlayer {
            sequences: sequences.to_vec(),
            ahead: sequences.iter().map(|_| None).collect(),
        }
    }

    /// Whether there is anything to play.
    pub fn is_empty(&self) -> bool {
        self.sequences.is_empty()
    }

    /// The frames that change at time `t`, loaded (from the background when the last call
    /// started loading them). An error names the file; the frames this call loaded before it
    /// are loaded again by the next call (`forget`).
    pub fn frames_at(&mut self, t: f32) -> Result<Vec<NewFrame>> {
        let result = self.load_at(t);
        if result.is_err() {
            self.forget();
        }
        result
    }

    /// Forgets which frames the clouds show: the next `frames_at` loads every sequence's (for
    /// a caller that could not show the frames it was given).
    pub fn forget(&mut self) {
        for s in &mut self.sequences {
            s.shown = usize::MAX;
        }
    }

    fn load_at(&mut self, t: f32) -> Result<Vec<NewFrame>> {
        let mut out = Vec::new();
        for (s, ahead) in self.sequences.iter_mut().zip(&mut self.ahead) {
            let frame = s.frame_at(t);
            if frame == s.shown {
                continue;
            }
            let start = web_time::Instant::now();
            let points = match ahead.take() {
                #[cfg(not(target_arch = "wasm32"))]
                Some(a) if a.frame == frame => a.job.join().unwrap_or_else(|_| {
                    Err(SceneError::Invalid(
                        "a point sequence's loader panicked".into(),
                    ))
                })?,
                other => {
                    #[cfg(not(target_arch = "wasm32"))]
                    if let Some(a) = other {
                        a.wanted.store(false, std::sync::atomic::Ordering::Relaxed);
                    }
                    #[cfg(target_arch = "wasm32")]
                    let _ = other;
                    PointsAhead::new(s.load(frame)?)
                }
            };
            let waited = start.elapsed();
            s.shown = frame;
            #[cfg(not(target_arch = "wasm32"))]
            {
                let next = s.next(frame);
                if next != frame {
                    let (files, colour) = (s.files.clone(), s.base_color);
                    let wanted = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
                    let still = wanted.clone();
                    *ahead = Some(Ahead {
                        frame: next,
                        job: std::thread::spawn(move || {
                            let points = load_frame(&files, next, colour)?;
                            Ok(if still.load(std::sync::atomic::Ordering::Relaxed) {
                                PointsAhead::new(points)
                            } else {
                                PointsAhead::unestimated(points)
                            })
                        }),
                        wanted,
                    });
                }
            }
            out.push(NewFrame {
                cloud: s.cloud,
                frame,
                points,
                waited,
            });
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_numbers_in_file_names() {
        let f = FrameNumber::parse("scan_%04d.ply").unwrap();
        assert_eq!(f.name(7), "scan_0007.ply");
        assert_eq!(f.name(12345), "scan_12345.ply");
        assert_eq!(FrameNumber::parse("%d.pcd").unwrap().name(42), "42.pcd");
        assert_eq!(
            FrameNumber::parse("100%%_%03d.ply").unwrap().name(5),
            "100%_005.ply"
        );
        for bad in [
            "scan.ply",
            "a%d_%d.ply",
            "a%4d.ply",
            "a%s.ply",
            "a%0100d.ply",
            "a%",
        ] {
            assert!(FrameNumber::parse(bad).is_err(), "{bad}");
        }
        assert!(is_pattern("a_%04d.ply") && is_pattern("100%/a_%d.ply"));
        for plain in [
            "100%%.ply",
            "a.ply",
            "50%_off.ply",
            "100%/room.ply",
            "a_%s.ply",
        ] {
            assert!(!is_pattern(plain), "{plain}");
        }
    }

    #[test]
    fn frames_at_times_computed_from_the_frame_rate() {
        let s = PointSequence {
            cloud: 0,
            files: vec![PathBuf::new(); 24],
            fps: 12.0,
            repeat: Repeat::Clamp,
            capacity: 0,
            bounds: Aabb::EMPTY,
            base_color: None,
            shown: 0,
        };
        // 5 / 12 in single precision times 12 is 4.99999992: still frame 5.
        for k in 0..24 {
            assert_eq!(s.frame_at(k as f32 / 12.0), k);
            assert_eq!(s.frame_at((k as f32 + 0.99) / 12.0), k);
        }
        assert_eq!(s.frame_at(-1.0), 0);
        assert_eq!(s.frame_at(f32::NAN), 0);
        assert_eq!(s.frame_at(1e30), 23);
        let looped = PointSequence {
            repeat: Repeat::Loop,
            ..s
        };
        assert_eq!(looped.frame_at(2.0 + 3.0 / 12.0), 3);
        assert_eq!(looped.frame_at(-1.0 / 12.0), 23);
    }
}
