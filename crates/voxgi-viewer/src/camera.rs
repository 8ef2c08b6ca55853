//! Camera controllers: orbit about a target (drag to turn, pan, wheel to zoom) and fly (WASD/QE
//! and mouse look). Both produce a `voxgi` `Camera`; both start from any camera, so switching
//! between them, or to a scene's own camera, keeps the view.

use glam::Vec3;
use voxgi::scene::{Camera, Projection};
use web_time::Instant;

/// Radians of turn per pixel of mouse motion.
const TURN_PER_PIXEL: f32 = 0.005;
/// Zoom factor per wheel step.
const ZOOM_PER_STEP: f32 = 0.9;
/// Pitch stays short of straight up or down, where yaw is undefined.
const PITCH_LIMIT: f32 = 1.55;

fn fov_degrees(c: &Camera) -> f32 {
    match c.projection {
        Projection::Perspective { yfov } => yfov.to_degrees(),
        Projection::Orthographic { .. } => 45.0,
    }
}

/// The direction of yaw `yaw` (about +Y, 0 looking down -Z) and pitch `pitch` (up positive).
pub fn direction(yaw: f32, pitch: f32) -> Vec3 {
    Vec3::new(
        -yaw.sin() * pitch.cos(),
        pitch.sin(),
        -yaw.cos() * pitch.cos(),
    )
}

/// Yaw and pitch of a direction (the inverse of `direction`).
pub fn angles(d: Vec3) -> (f32, f32) {
    let d = d.normalize_or(Vec3::NEG_Z);
    (
        (-d.x).atan2(-d.z),
        d.y.clamp(-1.0, 1.0).asin().clamp(-PITCH_LIMIT, PITCH_LIMIT),
    )
}

/// Orbit about `target` at `distance`.
#[derive(Clone, Debug, PartialEq)]
pub struct Orbit {
    pub target: Vec3,
    pub distance: f32,
    pub yaw: f32,
    pub pitch: f32,
    pub fov: f32,
    pub znear: f32,
    /// An orthographic view: parallel rays, the target's plane as high as the perspective
    /// view shows it (so toggling keeps its size).
    pub ortho: bool,
}

/// The views `Orbit::view_along` offers, Blender's numpad keys' (1, 3, 7): along -Z (the front),
/// -X (the right side), -Y (the top).
pub const PRESETS: [(&str, Vec3); 3] = [
    ("front", Vec3::NEG_Z),
    ("right", Vec3::NEG_X),
    ("top", Vec3::NEG_Y),
];

impl Orbit {
    /// The orbit that sees what `camera` sees, about the point `distance` ahead of it.
    pub fn from_camera(camera: &Camera, distance: f32) -> Self {
        let (yaw, pitch) = angles(camera.forward);
        let distance = distance.max(1e-4);
        Orbit {
            target: camera.position + camera.forward.normalize_or(Vec3::NEG_Z) * distance,
            distance,
            yaw,
            pitch,
            fov: fov_degrees(camera),
            znear: camera.znear,
            ortho: matches!(camera.projection, Projection::Orthographic { .. }),
        }
    }

    /// Looks along `dir` at the same target from the same distance (straight down stops short
    /// of the pole, as a drag does).
    pub fn view_along(&mut self, dir: Vec3) {
        (self.yaw, self.pitch) = angles(dir);
    }

    pub fn eye(&self) -> Vec3 {
        self.target - direction(self.yaw, self.pitch) * self.distance
    }

    /// Turns by a mouse drag of (dx, dy) pixels.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * TURN_PER_PIXEL;
        self.pitch = (self.pitch - dy * TURN_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Turns around the target by `radians` (positive: to the left, as a drag to the right).
    pub fn turn(&mut self, radians: f32) {
        self.yaw -= radians;
    }

    /// Moves the target in the view plane by a drag of (dx, dy) pixels in a view `height`
    /// pixels high, so the point under the cursor stays under it.
    pub fn pan(&mut self, dx: f32, dy: f32, height: f32) {
        let f = direction(self.yaw, self.pitch);
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(f);
        let per_pixel = 2.0 * self.distance * (self.fov.to_radians() * 0.5).tan() / height.max(1.0);
        self.target += (-right * dx + up * dy) * per_pixel;
    }

    /// Moves closer (positive steps) or farther.
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * ZOOM_PER_STEP.powf(steps)).max(1e-4);
    }

    pub fn camera(&self) -> Camera {
        let mut c = Camera::look_at(self.eye(), self.target, self.fov);
        c.name = "viewer".into();
        c.znear = self.znear.min(self.distance * 0.5).max(1e-5);
        if self.ortho {
            let ymag = self.distance * (self.fov.to_radians() * 0.5).tan();
            // The image's aspect sets the width (`voxgi::view`).
            c.projection = Projection::Orthographic { xmag: ymag, ymag };
        }
        c
    }
}

/// The camera's right and up axes: unit, square to its view direction and to each other.
pub fn view_axes(camera: &Camera) -> (Vec3, Vec3) {
    let f = camera.forward.normalize_or(Vec3::NEG_Z);
    let right = f.cross(camera.up).normalize_or(Vec3::X);
    (right, right.cross(f))
}

/// Half the view's height in metres at depth `z` along the view (the projection `voxgi::view`
/// makes).
fn half_height(camera: &Camera, z: f32) -> f32 {
    match camera.projection {
        Projection::Perspective { yfov } => z * (yfov * 0.5).tan(),
        Projection::Orthographic { ymag, .. } => ymag,
    }
}

/// Where `p` shows in a `size` (width, height) view through `camera`, in the view's pixels from
/// its top left; `None` when it is behind the camera or nearer than its near plane.
pub fn project(camera: &Camera, size: [f32; 2], p: Vec3) -> Option<[f32; 2]> {
    let d = p - camera.position;
    let z = d.dot(camera.forward.normalize_or(Vec3::NEG_Z));
    if z <= camera.znear {
        return None;
    }
    let (right, up) = view_axes(camera);
    let half = half_height(camera, z);
    let aspect = size[0] / size[1].max(1.0);
    let (x, y) = (d.dot(right) / (half * aspect), d.dot(up) / half);
    Some([(x + 1.0) * 0.5 * size[0], (1.0 - y) * 0.5 * size[1]])
}

/// Metres a point at `p` moves on the screen for each pixel of a view `height` pixels high:
/// what turns a drag into a move at the point's depth.
pub fn metres_per_pixel(camera: &Camera, height: f32, p: Vec3) -> f32 {
    let z = (p - camera.position).dot(camera.forward.normalize_or(Vec3::NEG_Z));
    2.0 * half_height(camera, z.max(camera.znear)) / height.max(1.0)
}

/// Where the world's X, Y and Z axes point on the screen seen through `camera`: per axis, its
/// length-1 direction projected on the view plane, in screen axes (x right, y down), for the
/// axis gizmo. An axis along the view shrinks to nothing.
pub fn screen_axes(camera: &Camera) -> [[f32; 2]; 3] {
    let (right, up) = view_axes(camera);
    [Vec3::X, Vec3::Y, Vec3::Z].map(|a| [a.dot(right), -a.dot(up)])
}

/// Which way the fly keys push, each -1, 0 or 1: right, up, forward.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Movement {
    pub right: f32,
    pub up: f32,
    pub forward: f32,
}

/// How long each fly key was held between frames, from the key events' arrival: flying covers
/// the time the keys were down whatever the frame rate (per-frame steps capped for slow frames
/// made a 3 s press move 0.18 m at 1 frame a second).
#[derive(Debug, Default)]
pub struct HeldKeys {
    /// Per direction (right, up, forward; negative keys apart): when a held key went down or
    /// the last frame took its time, whichever is later.
    since: [[Option<Instant>; 2]; 3],
    /// Seconds each was held since the last frame, for keys released since.
    held: [[f32; 2]; 3],
}

/// Longest a frame's flight: a stall of the whole window does not throw the camera far.
pub const LONGEST_STEP: f32 = 1.0;

impl HeldKeys {
    /// The key for `axis` (0 right, 1 up, 2 forward) in direction `positive` went down at `t`.
    pub fn press(&mut self, axis: usize, positive: bool, t: Instant) {
        let s = &mut self.since[axis][positive as usize];
        if s.is_none() {
            *s = Some(t);
        }
    }

    /// It went up at `t`.
    pub fn release(&mut self, axis: usize, positive: bool, t: Instant) {
        let k = positive as usize;
        if let Some(t0) = self.since[axis][k].take() {
            self.held[axis][k] += t.saturating_duration_since(t0).as_secs_f32();
        }
    }

    /// The movement since the last frame, at `t`: which way, and for how many seconds (at most
    /// `LONGEST_STEP`), for `Fly::step`.
    pub fn take(&mut self, t: Instant) -> (Movement, f32) {
        let mut secs = [0.0f32; 3];
        for (axis, s) in secs.iter_mut().enumerate() {
            for k in 0..2 {
                let mut h = std::mem::take(&mut self.held[axis][k]);
                if let Some(t0) = &mut self.since[axis][k] {
                    h += t.saturating_duration_since(*t0).as_secs_f32();
                    *t0 = t;
                }
                *s += if k == 1 { h } else { -h };
            }
        }
        let longest = secs.iter().fold(0.0f32, |m, s| m.max(s.abs()));
        if longest == 0.0 {
            return (Movement::default(), 0.0);
        }
        let m = Movement {
            right: secs[0] / longest,
            up: secs[1] / longest,
            forward: secs[2] / longest,
        };
        (m, longest.min(LONGEST_STEP))
    }
}

/// A free camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Fly {
    pub position: Vec3,
    pub yaw: f32,
    pub pitch: f32,
    /// Metres per second.
    pub speed: f32,
    pub fov: f32,
    pub znear: f32,
}

impl Fly {
    /// A fly camera at `camera`, moving at `speed` metres per second.
    pub fn from_camera(camera: &Camera, speed: f32) -> Self {
        let (yaw, pitch) = angles(camera.forward);
        Fly {
            position: camera.position,
            yaw,
            pitch,
            speed,
            fov: fov_degrees(camera),
            znear: camera.znear,
        }
    }

    /// Turns by a mouse motion of (dx, dy) pixels.
    pub fn look(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * TURN_PER_PIXEL;
        self.pitch = (self.pitch - dy * TURN_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves for `dt` seconds: forward along the view, right across it, up along +Y.
    pub fn step(&mut self, m: Movement, dt: f32) {
        let f = direction(self.yaw, self.pitch);
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let v = f * m.forward + right * m.right + Vec3::Y * m.up;
        if v.length_squared() > 0.0 {
            self.position += v.normalize() * self.speed * dt;
        }
    }

    pub fn camera(&self) -> Camera {
        let mut c = Camera::look_at(
            self.position,
            self.position + direction(self.yaw, self.pitch),
            self.fov,
        );
        c.name = "viewer".into();
        c.znear = self.znear;
        c
    }
}

/// The `voxgi render` flags that give `camera`'s view.
pub fn render_flags(camera: &Camera) -> String {
    let t = camera.position + camera.forward;
    let p = camera.position;
    format!(
        "--eye {:.4},{:.4},{:.4} --target {:.4},{:.4},{:.4} --fov {:.2}",
        p.x,
        p.y,
        p.z,
        t.x,
        t.y,
        t.z,
        fov_degrees(camera)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-4
    }

    /// A light dragged by the gizmo stays under the cursor: a point moved by `metres_per_pixel`
    /// along the view's right and up axes lands that many pixels right and up, in both
    /// projections; the point looked at is the view's centre, one behind the camera is nowhere.
    #[test]
    fn a_point_moved_by_metres_per_pixel_follows_the_cursor() {
        let size = [800.0, 400.0];
        for ortho in [false, true] {
            let mut orbit = Orbit::from_camera(
                &Camera::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, 50.0),
                6.0,
            );
            orbit.ortho = ortho;
            let cam = orbit.camera();
            let target = cam.position + cam.forward * 4.0;
            let c = project(&cam, size, target).unwrap();
            assert!(
                (c[0] - 400.0).abs() < 1e-3 && (c[1] - 200.0).abs() < 1e-3,
                "{c:?}"
            );
            let p = target + Vec3::new(0.3, -0.2, 0.1);
            let at = project(&cam, size, p).unwrap();
            let m = metres_per_pixel(&cam, size[1], p);
            let (right, up) = view_axes(&cam);
            let moved = project(&cam, size, p + (right * 25.0 + up * 10.0) * m).unwrap();
            // f32 over metres of distance: a thousandth of a pixel.
            assert!(
                (moved[0] - at[0] - 25.0).abs() < 1e-2,
                "{ortho}: {at:?} -> {moved:?}"
            );
            assert!(
                (moved[1] - at[1] + 10.0).abs() < 1e-2,
                "{ortho}: {at:?} -> {moved:?}"
            );
            if !ortho {
                assert!(project(&cam, size, cam.position - cam.forward).is_none());
            }
        }
    }

    #[test]
    fn flying_covers_the_time_a_key_was_held_at_any_frame_rate() {
        let t0 = Instant::now();
        let at = |s: f32| t0 + std::time::Duration::from_secs_f32(s);
        let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, 60.0);
        // W held for 3 s across frames a second apart, then one frame after its release.
        let mut f = Fly::from_camera(&cam, 2.0);
        let mut keys = HeldKeys::default();
        keys.press(2, true, at(0.1));
        for frame in 1..=3 {
            let (m, dt) = keys.take(at(frame as f32));
            f.step(m, dt);
        }
        keys.release(2, true, at(3.1));
        let (m, dt) = keys.take(at(4.0));
        f.step(m, dt);
        assert!(
            close(f.position, Vec3::new(0.0, 0.0, -6.0)),
            "{}",
            f.position
        );
        assert_eq!(keys.take(at(5.0)).1, 0.0, "nothing held after the release");
        // W and D together for 0.5 s: half a second's flight, diagonally.
        let mut f = Fly::from_camera(&cam, 2.0);
        keys.press(2, true, at(10.0));
        keys.press(0, true, at(10.0));
        keys.release(2, true, at(10.5));
        keys.release(0, true, at(10.5));
        let (m, dt) = keys.take(at(10.6));
        f.step(m, dt);
        let d = 1.0 / 2f32.sqrt();
        assert!(close(f.position, Vec3::new(d, 0.0, -d)), "{}", f.position);
        // A 5 s stall with S held moves at most `LONGEST_STEP` seconds' worth.
        let mut f = Fly::from_camera(&cam, 2.0);
        keys.press(2, false, at(20.0));
        let (m, dt) = keys.take(at(25.0));
        f.step(m, dt);
        assert!(close(f.position, Vec3::new(0.0, 0.0, 2.0 * LONGEST_STEP)));
    }

    #[test]
    fn presets_look_along_their_axes_and_orthographic_keeps_the_size() {
        let cam = Camera::look_at(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.5, 0.0), 60.0);
        let mut o = Orbit::from_camera(&cam, 2.0);
        let target = o.target;
        for (name, dir) in PRESETS {
            o.view_along(dir);
            let c = o.camera();
            assert!(
                c.forward.dot(dir) > 0.999,
                "{name}: looks along {}",
                c.forward
            );
            assert!(close(o.target, target) && (o.eye() - target).length() - 2.0 < 1e-4);
        }
        o.ortho = true;
        // The target's plane is as high as in perspective: 2 × 2 m × tan 30°.
        match o.camera().projection {
            Projection::Orthographic { ymag, .. } => {
                assert!((2.0 * ymag - 4.0 * 30f32.to_radians().tan()).abs() < 1e-5)
            }
            p => panic!("{p:?}"),
        }
        assert!(Orbit::from_camera(&o.camera(), 2.0).ortho);
    }

    #[test]
    fn the_gizmo_shows_the_axes_as_the_camera_sees_them() {
        let close2 = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-5;
        // Looking along -Z: X to the right, Y up (negative screen y), Z at the viewer.
        let front = screen_axes(&Camera::look_at(Vec3::Z, Vec3::ZERO, 45.0));
        assert!(close2(front[0], [1.0, 0.0]) && close2(front[1], [0.0, -1.0]));
        assert!(close2(front[2], [0.0, 0.0]));
        // From +X looking at the origin: Z points left, X at the viewer.
        let side = screen_axes(&Camera::look_at(Vec3::X, Vec3::ZERO, 45.0));
        assert!(
            close2(side[2], [-1.0, 0.0]) && close2(side[0], [0.0, 0.0]),
            "{side:?}"
        );
    }

    #[test]
    fn angles_invert_direction() {
        for d in [
            Vec3::NEG_Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.8).normalize(),
            Vec3::new(-0.7, 0.5, -0.2).normalize(),
        ] {
            let (y, p) = angles(d);
            assert!(close(direction(y, p), d), "{d}");
        }
    }

    #[test]
    fn an_orbit_keeps_the_camera_it_starts_from() {
        let cam = Camera::look_at(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.5, 0.0), 40.0);
        let o = Orbit::from_camera(&cam, 2.0);
        let c = o.camera();
        assert!(
            close(c.position, cam.position),
            "{} vs {}",
            c.position,
            cam.position
        );
        assert!(close(c.forward, cam.forward));
        assert!((fov_degrees(&c) - 40.0).abs() < 1e-4);
    }

    #[test]
    fn orbiting_keeps_the_distance_to_the_target_and_looks_at_it() {
        let mut o = Orbit::from_camera(&Camera::look_at(Vec3::Z * 3.0, Vec3::ZERO, 45.0), 3.0);
        o.rotate(120.0, -40.0);
        let c = o.camera();
        assert!(((c.position - o.target).length() - 3.0).abs() < 1e-4);
        assert!(close(c.forward, (o.target - c.position).normalize()));
        // A quarter turn of drag (pi/2 / 0.005 px) from the +Z side lands on the -X side...
        let mut o = Orbit::from_camera(&Camera::look_at(Vec3::Z * 3.0, Vec3::ZERO, 45.0), 3.0);
        o.rotate(std::f32::consts::FRAC_PI_2 / TURN_PER_PIXEL, 0.0);
        assert!(close(o.eye(), Vec3::new(-3.0, 0.0, 0.0)), "{}", o.eye());
        // ...and pitch stops short of the pole.
        o.rotate(0.0, -1e6);
        assert!(o.pitch <= PITCH_LIMIT && o.camera().forward.is_finite());
    }

    #[test]
    fn zoom_and_pan_move_as_documented() {
        let mut o = Orbit::from_camera(&Camera::look_at(Vec3::Z * 4.0, Vec3::ZERO, 90.0), 4.0);
        o.zoom(2.0);
        assert!((o.distance - 4.0 * 0.81).abs() < 1e-5);
        // fov 90: the view is 2 * distance high; half the height of drag moves the target by
        // one distance, to the left for a drag to the right.
        let d = o.distance;
        o.pan(50.0, 0.0, 100.0);
        assert!(close(o.target, Vec3::new(-d, 0.0, 0.0)), "{}", o.target);
    }

    #[test]
    fn flying_moves_at_its_speed_along_the_view() {
        let cam = Camera::look_at(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), 60.0);
        let mut f = Fly::from_camera(&cam, 2.0);
        f.step(
            Movement {
                forward: 1.0,
                ..Default::default()
            },
            0.5,
        );
        assert!(
            close(f.position, Vec3::new(1.0, 0.0, 0.0)),
            "{}",
            f.position
        );
        // Diagonal keys do not move faster.
        f.step(
            Movement {
                forward: 1.0,
                right: 1.0,
                up: 0.0,
            },
            1.0,
        );
        assert!((f.position - Vec3::new(1.0, 0.0, 0.0)).length() - 2.0 < 1e-4);
        let c = f.camera();
        assert!(close(c.position, f.position));
    }

    #[test]
    fn render_flags_reproduce_the_view() {
        let cam = Camera::look_at(Vec3::new(0.5, 1.0, 2.0), Vec3::ZERO, 35.0);
        let flags = render_flags(&cam);
        assert!(
            flags.starts_with("--eye 0.5000,1.0000,2.0000 --target "),
            "{flags}"
        );
        assert!(flags.ends_with("--fov 35.00"), "{flags}");
    }
}
