//! Animation: keyframed tracks of rigid motion and of light parameters, and sampling a scene's
//! state at a time.
//!
//! A motion moves instances in the space the animation was written in:
//! `transform(t) = outer * M(t) * inner`, where `outer` places that space in the world (the
//! identity for a scene file's own animations; an include's transform for an included file's)
//! and `inner` is where an instance sits when the motion is the identity. Most motions start
//! from the pose the file gives (identity is the rest pose, `inner` the rest transform); a
//! [`Motion::Nodes`] hierarchy (glTF's) gives a node's whole transform instead, and `inner` is
//! then an instance's placement below that node. A light's animated parameters replace its rest
//! values, positions and directions given in the animation's space.

use crate::{Camera, Light, Projection, Scene};
use glam::{Mat4, Quat, Vec3, Vec4};
use std::sync::Arc;

/// How values between two keyframes are found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interpolation {
    /// The earlier keyframe's value until the next keyframe.
    Step,
    /// Straight lines (rotations: spherical linear interpolation).
    #[default]
    Linear,
    /// Catmull-Rom splines through the keyframes (rotations: normalised Catmull-Rom on the
    /// quaternions, kept in one hemisphere).
    Cubic,
    /// Cubic Hermite splines with an in- and an out-tangent per keyframe (glTF's CUBICSPLINE),
    /// tangents in value units per second; build such tracks with [`Track::hermite`].
    /// Rotations: Hermite on the quaternions' components, normalised; unlike `Cubic` no
    /// hemisphere is chosen, because the tangents are given for the components as stored.
    Hermite,
}

/// What happens past the last keyframe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Repeat {
    /// Hold the first and last values outside the keyframes.
    #[default]
    Clamp,
    /// Start over: time is taken modulo the last keyframe's time.
    Loop,
}

/// Values a track can interpolate.
pub trait Keyable: Copy {
    /// `a + (b - a) s`.
    fn lerp(a: Self, b: Self, s: f32) -> Self;
    /// The Catmull-Rom value between `p1` and `p2` at `s`, with neighbours `p0` and `p3`.
    fn catmull_rom(p0: Self, p1: Self, p2: Self, p3: Self, s: f32) -> Self;
    /// The cubic Hermite value between `p0` and `p1` at `s` in 0..=1 over a segment `dt`
    /// seconds long, leaving `p0` with tangent `b0` and reaching `p1` with tangent `a1`
    /// (tangents per second, so they are scaled by `dt`; glTF 2.0, Appendix C).
    fn hermite(p0: Self, b0: Self, p1: Self, a1: Self, dt: f32, s: f32) -> Self;
    /// Every component is finite.
    fn finite(&self) -> bool;
}

/// Weights of `p0`, `b0`, `p1` and `a1` in [`Keyable::hermite`].
fn hermite_weights(dt: f32, s: f32) -> [f32; 4] {
    let (s2, s3) = (s * s, s * s * s);
    [
        2.0 * s3 - 3.0 * s2 + 1.0,
        dt * (s3 - 2.0 * s2 + s),
        -2.0 * s3 + 3.0 * s2,
        dt * (s3 - s2),
    ]
}

fn catmull_rom_weights(s: f32) -> [f32; 4] {
    let (s2, s3) = (s * s, s * s * s);
    [
        0.5 * (-s3 + 2.0 * s2 - s),
        0.5 * (3.0 * s3 - 5.0 * s2 + 2.0),
        0.5 * (-3.0 * s3 + 4.0 * s2 + s),
        0.5 * (s3 - s2),
    ]
}

/// Scalars and vectors interpolate the same way, component by component.
macro_rules! keyable_vector {
    ($($t:ty),*) => {$(
        impl Keyable for $t {
            fn lerp(a: Self, b: Self, s: f32) -> Self {
                // Not glam's a(1 - s) + bs: between equal keys the value must stay exactly
                // the key, or a still object "moves" by a rounding step every frame.
                a + (b - a) * s
            }
            fn catmull_rom(p0: Self, p1: Self, p2: Self, p3: Self, s: f32) -> Self {
                let w = catmull_rom_weights(s);
                w[0] * p0 + w[1] * p1 + w[2] * p2 + w[3] * p3
            }
            fn hermite(p0: Self, b0: Self, p1: Self, a1: Self, dt: f32, s: f32) -> Self {
                let w = hermite_weights(dt, s);
                w[0] * p0 + w[1] * b0 + w[2] * p1 + w[3] * a1
            }
            fn finite(&self) -> bool {
                self.is_finite()
            }
        }
    )*};
}

keyable_vector!(f32, Vec3);

impl Keyable for Quat {
    fn lerp(a: Self, b: Self, s: f32) -> Self {
        // Equal keys hold still exactly (slerp would round).
        if a == b { a } else { a.slerp(b, s) }
    }
    fn catmull_rom(p0: Self, p1: Self, p2: Self, p3: Self, s: f32) -> Self {
        // Neighbours into p1's hemisphere, so the spline does not take the long way round.
        let near = |q: Quat| if q.dot(p1) < 0.0 { -q } else { q };
        let (p0, p2, p3) = (near(p0), near(p2), near(p3));
        let w = catmull_rom_weights(s);
        let v = w[0] * Vec4::from(p0)
            + w[1] * Vec4::from(p1)
            + w[2] * Vec4::from(p2)
            + w[3] * Vec4::from(p3);
        Quat::from_vec4(v).normalize()
    }
    fn hermite(p0: Self, b0: Self, p1: Self, a1: Self, dt: f32, s: f32) -> Self {
        let w = hermite_weights(dt, s);
        let v = w[0] * Vec4::from(p0)
            + w[1] * Vec4::from(b0)
            + w[2] * Vec4::from(p1)
            + w[3] * Vec4::from(a1);
        // Tangents can cancel the values out; a zero quaternion has no direction to keep.
        let q = Quat::from_vec4(v);
        if q.length_squared() > 0.0 {
            q.normalize()
        } else {
            p0
        }
    }
    fn finite(&self) -> bool {
        self.is_finite()
    }
}

/// Keyframes of one value: times in seconds, strictly increasing, each with its value (and,
/// for Hermite tracks, its in- and out-tangents).
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    // Boxed slices, not Vecs: tracks never grow, and three of them sit inline in `Motion`.
    times: Box<[f32]>,
    values: Box<[T]>,
    /// (in, out) tangent per keyframe for `Interpolation::Hermite`; empty otherwise.
    tangents: Box<[[T; 2]]>,
    /// How to fill between keyframes.
    pub interpolation: Interpolation,
    /// What to do past the last keyframe.
    pub repeat: Repeat,
}

impl<T: Keyable> Track<T> {
    /// A track, checked: at least one keyframe, as many values as times, finite, times
    /// non-negative and strictly increasing. The error says what is wrong. Hermite tracks need
    /// tangents and come from [`Track::hermite`] instead.
    pub fn new(
        times: Vec<f32>,
        values: Vec<T>,
        interpolation: Interpolation,
        repeat: Repeat,
    ) -> Result<Self, String> {
        if interpolation == Interpolation::Hermite {
            return Err("a Hermite track needs tangents (use Track::hermite)".into());
        }
        Self::checked(times, values, Vec::new(), interpolation, repeat)
    }

    /// A cubic Hermite track (glTF's CUBICSPLINE): per keyframe a value, the tangent arriving
    /// at it (`in_tangents`) and the one leaving it (`out_tangents`), in value units per second.
    /// Checked as [`Track::new`], and the tangents must be as many as the times, and finite.
    pub fn hermite(
        times: Vec<f32>,
        values: Vec<T>,
        in_tangents: Vec<T>,
        out_tangents: Vec<T>,
        repeat: Repeat,
    ) -> Result<Self, String> {
        for (what, t) in [("in", &in_tangents), ("out", &out_tangents)] {
            if t.len() != times.len() {
                return Err(format!(
                    "{} keyframe times but {} {what}-tangents",
                    times.len(),
                    t.len()
                ));
            }
            if let Some(i) = t.iter().position(|v| !v.finite()) {
                return Err(format!("keyframe {i}: the {what}-tangent is not finite"));
            }
        }
        let tangents = in_tangents
            .into_iter()
            .zip(out_tangents)
            .map(|(a, b)| [a, b])
            .collect();
        Self::checked(times, values, tangents, Interpolation::Hermite, repeat)
    }

    fn checked(
        times: Vec<f32>,
        values: Vec<T>,
        tangents: Vec<[T; 2]>,
        interpolation: Interpolation,
        repeat: Repeat,
    ) -> Result<Self, String> {
        if times.is_empty() {
            return Err("a track needs at least one keyframe".into());
        }
        if times.len() != values.len() {
            return Err(format!(
                "{} keyframe times but {} values",
                times.len(),
                values.len()
            ));
        }
        if let Some(i) = times.iter().position(|t| !t.is_finite() || *t < 0.0) {
            return Err(format!(
                "keyframe {i}: time {} is not a finite number of seconds >= 0",
                times[i]
            ));
        }
        if let Some(i) = (1..times.len()).find(|&i| times[i] <= times[i - 1]) {
            return Err(format!(
                "keyframe {i}: time {} does not come after {} (keyframes must be sorted)",
                times[i],
                times[i - 1]
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.finite()) {
            return Err(format!("keyframe {i}: the value is not finite"));
        }
        Ok(Track {
            times: times.into(),
            values: values.into(),
            tangents: tangents.into(),
            interpolation,
            repeat,
        })
    }

    /// The keyframe times, seconds.
    pub fn times(&self) -> &[f32] {
        &self.times
    }

    /// The keyframe values, one per time.
    pub fn values(&self) -> &[T] {
        &self.values
    }

    /// The time of the last keyframe.
    pub fn duration(&self) -> f32 {
        *self.times.last().expect("tracks are never empty")
    }

    /// The value at time `t` (seconds).
    pub fn sample(&self, t: f32) -> T {
        let n = self.times.len();
        let end = self.duration();
        let t = match self.repeat {
            Repeat::Loop if end > 0.0 => t.rem_euclid(end),
            _ => t,
        };
        if n == 1 || t <= self.times[0] {
            return self.values[0];
        }
        if t >= end {
            return self.values[n - 1];
        }
        // The segment [times[i], times[i + 1]) holding t.
        let i = self.times.partition_point(|&k| k <= t) - 1;
        let s = (t - self.times[i]) / (self.times[i + 1] - self.times[i]);
        let v = &self.values;
        match self.interpolation {
            Interpolation::Step => v[i],
            Interpolation::Linear => T::lerp(v[i], v[i + 1], s),
            Interpolation::Cubic => {
                // End segments repeat their end keyframe as the missing neighbour.
                let p0 = v[i.saturating_sub(1)];
                let p3 = v[(i + 2).min(n - 1)];
                T::catmull_rom(p0, v[i], v[i + 1], p3, s)
            }
            // A track switched to Hermite after `Track::new` has no tangents: straight lines.
            Interpolation::Hermite => match (self.tangents.get(i), self.tangents.get(i + 1)) {
                (Some([_, out0]), Some([in1, _])) => {
                    let dt = self.times[i + 1] - self.times[i];
                    T::hermite(v[i], *out0, v[i + 1], *in1, dt, s)
                }
                _ => T::lerp(v[i], v[i + 1], s),
            },
        }
    }
}

/// One animated node of a [`Motion::Nodes`] hierarchy: its local transform is
/// `offset * T(t) * R(t) * S(t)`, each part from its track or, without one, its rest value.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionNode {
    /// The nearest animated ancestor: an earlier index in the same list. `None` for a node
    /// whose ancestors do not move (a later or equal index is treated as `None` too).
    pub parent: Option<usize>,
    /// The fixed transform from the parent's frame (the animation's space when there is no
    /// parent) to this node's parent frame: the product of the unanimated nodes in between.
    pub offset: Mat4,
    /// Translation where `translation` has no track.
    pub rest_translation: Vec3,
    /// Rotation (unit) where `rotation` has no track.
    pub rest_rotation: Quat,
    /// Scale where `scale` has no track.
    pub rest_scale: Vec3,
    /// Animated translation.
    pub translation: Option<Track<Vec3>>,
    /// Animated rotation.
    pub rotation: Option<Track<Quat>>,
    /// Animated scale.
    pub scale: Option<Track<Vec3>>,
}

impl MotionNode {
    /// `offset * T(t) * R(t) * S(t)`: the node in its parent's frame at time `t`.
    pub fn local(&self, t: f32) -> Mat4 {
        self.offset
            * Mat4::from_scale_rotation_translation(
                self.scale.as_ref().map_or(self.rest_scale, |s| s.sample(t)),
                self.rotation
                    .as_ref()
                    .map_or(self.rest_rotation, |r| r.sample(t)),
                self.translation
                    .as_ref()
                    .map_or(self.rest_translation, |x| x.sample(t)),
            )
    }

    /// The last keyframe time of its tracks, 0 without any.
    pub fn duration(&self) -> f32 {
        [
            self.translation.as_ref().map(Track::duration),
            self.rotation.as_ref().map(Track::duration),
            self.scale.as_ref().map(Track::duration),
        ]
        .into_iter()
        .flatten()
        .fold(0.0, f32::max)
    }
}

/// A rigid motion over time: keyframed translation, rotation and scale, or a generator.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Keyframed tracks; a missing track is the identity.
    Keyframes {
        /// Translation, metres.
        translation: Option<Track<Vec3>>,
        /// Rotation.
        rotation: Option<Track<Quat>>,
        /// Scale per axis.
        scale: Option<Track<Vec3>>,
    },
    /// A full turn about the line through `center` along `axis` every `period` seconds.
    Orbit {
        /// A point on the axis, metres.
        center: Vec3,
        /// The axis (unit length).
        axis: Vec3,
        /// Seconds per turn (> 0).
        period: f32,
    },
    /// `amplitude` × sin(2π t / period) along `axis`.
    Oscillate {
        /// The direction of motion (unit length).
        axis: Vec3,
        /// Metres.
        amplitude: f32,
        /// Seconds per cycle (> 0).
        period: f32,
    },
    /// The transform of `nodes[node]` in the animation's space: the product of the local
    /// transforms from its topmost animated ancestor down to it. Not relative to the rest
    /// pose: a target's `inner` places each instance below this node (glTF's node hierarchy,
    /// where parents and children may each be animated). The list is shared by the targets of
    /// one file; an out-of-range `node` gives the identity.
    Nodes {
        /// Every animated node of the hierarchy, parents before children.
        nodes: Arc<[MotionNode]>,
        /// The node whose transform this is.
        node: usize,
    },
}

impl Motion {
    /// The motion at time `t`, to apply on the left of a target's `inner` transforms (for all
    /// motions but [`Motion::Nodes`], the rest transforms).
    pub fn at(&self, t: f32) -> Mat4 {
        match self {
            Motion::Keyframes {
                translation,
                rotation,
                scale,
            } => Mat4::from_scale_rotation_translation(
                scale.as_ref().map_or(Vec3::ONE, |s| s.sample(t)),
                rotation.as_ref().map_or(Quat::IDENTITY, |r| r.sample(t)),
                translation.as_ref().map_or(Vec3::ZERO, |x| x.sample(t)),
            ),
            Motion::Orbit {
                center,
                axis,
                period,
            } => {
                let angle = std::f32::consts::TAU * t / period;
                Mat4::from_translation(*center)
                    * Mat4::from_axis_angle(*axis, angle)
                    * Mat4::from_translation(-*center)
            }
            Motion::Oscillate {
                axis,
                amplitude,
                period,
            } => Mat4::from_translation(
                *axis * (amplitude * (std::f32::consts::TAU * t / period).sin()),
            ),
            Motion::Nodes { nodes, node } => {
                let mut m = Mat4::IDENTITY;
                let mut cur = Some(*node);
                while let Some(n) = cur.and_then(|i| nodes.get(i).map(|n| (i, n))) {
                    m = n.1.local(t) * m;
                    // Only earlier parents, so a hand-made cycle cannot loop forever.
                    cur = n.1.parent.filter(|&p| p < n.0);
                }
                m
            }
        }
    }

    /// How long one pass of the motion lasts (a generator's period; for [`Motion::Nodes`],
    /// the last keyframe of any node in the list, so all targets of one file agree).
    pub fn duration(&self) -> f32 {
        match self {
            Motion::Keyframes {
                translation,
                rotation,
                scale,
            } => [
                translation.as_ref().map(Track::duration),
                rotation.as_ref().map(Track::duration),
                scale.as_ref().map(Track::duration),
            ]
            .into_iter()
            .flatten()
            .fold(0.0, f32::max),
            Motion::Orbit { period, .. } | Motion::Oscillate { period, .. } => *period,
            Motion::Nodes { nodes, .. } => {
                nodes.iter().map(MotionNode::duration).fold(0.0, f32::max)
            }
        }
    }
}

/// Keyframed light parameters; a missing track keeps the light's rest value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightTracks {
    /// World position, metres.
    pub position: Option<Track<Vec3>>,
    /// Where the light points (normalised when sampled).
    pub direction: Option<Track<Vec3>>,
    /// Linear RGB.
    pub color: Option<Track<Vec3>>,
    /// As `Light::intensity`.
    pub intensity: Option<Track<f32>>,
}

impl LightTracks {
    /// The light at time `t`, from its rest state; `outer` places the tracks' positions and
    /// directions in the world.
    pub fn apply(&self, rest: &Light, outer: Mat4, t: f32) -> Light {
        let mut l = rest.clone();
        if let Some(p) = &self.position {
            l.position = outer.transform_point3(p.sample(t));
        }
        if let Some(d) = &self.direction {
            l.direction = outer
                .transform_vector3(d.sample(t))
                .normalize_or(rest.direction);
        }
        if let Some(c) = &self.color {
            l.color = c.sample(t).max(Vec3::ZERO).to_array();
        }
        if let Some(i) = &self.intensity {
            l.intensity = i.sample(t).max(0.0);
        }
        l
    }

    fn duration(&self) -> f32 {
        [
            self.position.as_ref().map(Track::duration),
            self.direction.as_ref().map(Track::duration),
            self.color.as_ref().map(Track::duration),
            self.intensity.as_ref().map(Track::duration),
        ]
        .into_iter()
        .flatten()
        .fold(0.0, f32::max)
    }
}

/// Keyframed camera parameters; a missing track keeps the camera's rest value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraTracks {
    /// The eye, metres.
    pub position: Option<Track<Vec3>>,
    /// The point it looks at, metres (wins over `direction`).
    pub look_at: Option<Track<Vec3>>,
    /// Where it looks (normalised when sampled).
    pub direction: Option<Track<Vec3>>,
    /// Vertical field of view, degrees (perspective cameras).
    pub fov: Option<Track<f32>>,
}

impl CameraTracks {
    fn duration(&self) -> f32 {
        [
            self.position.as_ref().map(Track::duration),
            self.look_at.as_ref().map(Track::duration),
            self.direction.as_ref().map(Track::duration),
            self.fov.as_ref().map(Track::duration),
        ]
        .into_iter()
        .flatten()
        .fold(0.0, f32::max)
    }
}

/// How an animated camera moves.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraMotion {
    /// Keyframed eye, aim and field of view; `outer` places positions and directions in the
    /// world. The camera stays upright (its up is the world's +Y, or its rest up when it
    /// looks straight along +Y).
    Tracks(CameraTracks),
    /// A rigid motion of the camera's frame (a generator, or glTF's node hierarchy): the
    /// camera looks along -Z of `outer * motion(t) * inner`, +Y up.
    Rigid {
        /// The motion.
        motion: Motion,
        /// The camera's frame in the motion's space when the motion is the identity.
        inner: Mat4,
    },
}

/// The frame of `camera`: +X right, +Y up, -Z forward, its eye at the origin.
pub fn camera_frame(camera: &Camera) -> Mat4 {
    let f = camera.forward.normalize_or(Vec3::NEG_Z);
    let right = f.cross(camera.up).normalize_or(f.any_orthonormal_vector());
    let up = right.cross(f);
    Mat4::from_cols(
        right.extend(0.0),
        up.extend(0.0),
        (-f).extend(0.0),
        camera.position.extend(1.0),
    )
}

/// `rest` moved to frame `m` (`camera_frame`'s convention; scale is dropped).
fn camera_in_frame(rest: &Camera, m: Mat4) -> Camera {
    let mut c = rest.clone();
    c.position = m.transform_point3(Vec3::ZERO);
    c.forward = m.transform_vector3(Vec3::NEG_Z).normalize_or(rest.forward);
    let up = m.transform_vector3(Vec3::Y);
    c.up = (up - c.forward * up.dot(c.forward))
        .try_normalize()
        .unwrap_or_else(|| c.forward.any_orthonormal_vector());
    c
}

impl CameraMotion {
    /// The camera at time `t` from its rest state (in the world); `outer` places the motion's
    /// space in the world.
    pub fn apply(&self, rest: &Camera, outer: Mat4, t: f32) -> Camera {
        match self {
            CameraMotion::Rigid { motion, inner } => {
                camera_in_frame(rest, outer * motion.at(t) * *inner)
            }
            CameraMotion::Tracks(tracks) => {
                let mut c = rest.clone();
                if let Some(p) = &tracks.position {
                    c.position = outer.transform_point3(p.sample(t));
                }
                let forward = if let Some(l) = &tracks.look_at {
                    Some(outer.transform_point3(l.sample(t)) - c.position)
                } else {
                    tracks
                        .direction
                        .as_ref()
                        .map(|d| outer.transform_vector3(d.sample(t)))
                };
                if let Some(f) = forward.and_then(Vec3::try_normalize) {
                    c.forward = f;
                    let right = f
                        .cross(Vec3::Y)
                        .try_normalize()
                        .or_else(|| f.cross(rest.up).try_normalize())
                        .unwrap_or_else(|| f.any_orthonormal_vector());
                    c.up = right.cross(f);
                }
                if let (Some(fov), Projection::Perspective { yfov }) =
                    (&tracks.fov, &mut c.projection)
                {
                    *yfov = fov.sample(t).clamp(0.5, 179.0).to_radians();
                }
                c
            }
        }
    }

    fn duration(&self) -> f32 {
        match self {
            CameraMotion::Tracks(t) => t.duration(),
            CameraMotion::Rigid { motion, .. } => motion.duration(),
        }
    }
}

/// What an animation moves.
#[derive(Clone, Debug, PartialEq)]
pub enum AnimationTarget {
    /// These instances (`Scene::instances` indices) move together by `motion`.
    Instances {
        /// Indices into `Scene::instances`; all dynamic.
        instances: Vec<usize>,
        /// Places the animation's space in the world.
        outer: Mat4,
        /// Each instance's transform in the animation's space when the motion is the identity,
        /// in `instances` order: its rest transform, or for [`Motion::Nodes`] its placement
        /// below the moving node.
        inner: Vec<Mat4>,
        /// The lights that move with these instances (`Scene::lights` indices): the area
        /// lights whose visible surfaces they are (`Instance::light`), and lights on the same
        /// moving glTF node. Each with its state in the world when the motion is the identity
        /// (for motions from rest, its rest state).
        lights: Vec<(usize, Light)>,
        /// Point clouds (`Scene::point_clouds` indices; all dynamic) that move with them, each
        /// with its transform in the animation's space when the motion is the identity.
        clouds: Vec<(usize, Mat4)>,
        /// The motion.
        motion: Motion,
    },
    /// A light (`Scene::lights` index) and its rest state.
    Light {
        /// Index into `Scene::lights`.
        light: usize,
        /// The light at rest, in the world.
        rest: Light,
        /// Places the tracks' positions and directions in the world.
        outer: Mat4,
        /// The animated parameters.
        tracks: LightTracks,
    },
    /// A camera (`Scene::cameras` index) and its rest state. It moves no geometry: a scene
    /// whose only animation is a camera's needs no voxel work as it plays.
    Camera {
        /// Index into `Scene::cameras`.
        camera: usize,
        /// The camera at rest, in the world.
        rest: Camera,
        /// Places the motion's space in the world.
        outer: Mat4,
        /// How it moves.
        motion: CameraMotion,
    },
}

/// One named animation of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// For messages and `voxgi info`.
    pub name: String,
    /// What it moves.
    pub target: AnimationTarget,
}

impl AnimationTarget {
    /// `instances` of `scene`, at rest where they are now, moved together by `motion` in
    /// world space.
    pub fn instances(scene: &Scene, instances: Vec<usize>, motion: Motion) -> Self {
        let inner = instances
            .iter()
            .map(|&i| scene.instances[i].transform)
            .collect();
        let lights = instances
            .iter()
            .filter_map(|&i| scene.instances[i].light)
            .filter_map(|l| scene.lights.get(l).map(|rest| (l, rest.clone())))
            .collect();
        AnimationTarget::Instances {
            instances,
            outer: Mat4::IDENTITY,
            inner,
            lights,
            clouds: Vec::new(),
            motion,
        }
    }

    /// The same target, moving point clouds `clouds` of `scene` along too, at rest where they
    /// are now (with the area lights they show). A light target is returned as it is.
    pub fn with_clouds(mut self, scene: &Scene, clouds: impl IntoIterator<Item = usize>) -> Self {
        if let AnimationTarget::Instances {
            outer,
            lights,
            clouds: moved,
            ..
        } = &mut self
        {
            let into_space = outer.inverse();
            for c in clouds {
                let Some(pc) = scene.point_clouds.get(c) else {
                    continue;
                };
                moved.push((c, into_space * pc.transform));
                if let Some(rest) = pc.light.and_then(|l| scene.lights.get(l).map(|r| (l, r))) {
                    lights.push((rest.0, rest.1.clone()));
                }
            }
        }
        self
    }
}

impl Animation {
    /// How long one pass lasts, seconds.
    pub fn duration(&self) -> f32 {
        match &self.target {
            AnimationTarget::Instances { motion, .. } => motion.duration(),
            AnimationTarget::Light { tracks, .. } => tracks.duration(),
            AnimationTarget::Camera { motion, .. } => motion.duration(),
        }
    }
}

impl Scene {
    /// Sets every animated instance and light to its state at time `t` (seconds). Sampling
    /// the same time twice gives the same scene; untouched parts keep their values.
    pub fn set_time(&mut self, t: f32) {
        for a in &self.animations {
            match &a.target {
                AnimationTarget::Instances {
                    instances,
                    outer,
                    inner,
                    lights,
                    clouds,
                    motion,
                } => {
                    let motion = motion.at(t);
                    let m = *outer * motion;
                    for (&i, r) in instances.iter().zip(inner) {
                        if let Some(inst) = self.instances.get_mut(i) {
                            inst.transform = m * *r;
                        }
                    }
                    for (c, r) in clouds {
                        if let Some(pc) = self.point_clouds.get_mut(*c) {
                            pc.transform = m * *r;
                        }
                    }
                    // The rest light is in the world: move it by the motion seen from there.
                    let world = *outer * motion * outer.inverse();
                    for (l, rest) in lights {
                        if let Some(light) = self.lights.get_mut(*l) {
                            *light = rest.transformed(world);
                        }
                    }
                }
                AnimationTarget::Light {
                    light,
                    rest,
                    outer,
                    tracks,
                } => {
                    // Its visible surface, if it is an area light's, goes along.
                    crate::set_light(
                        &mut self.lights,
                        &mut self.instances,
                        &mut self.point_clouds,
                        *light,
                        tracks.apply(rest, *outer, t),
                    );
                }
                AnimationTarget::Camera {
                    camera,
                    rest,
                    outer,
                    motion,
                } => {
                    if let Some(c) = self.cameras.get_mut(*camera) {
                        *c = motion.apply(rest, *outer, t);
                    }
                }
            }
        }
    }

    /// Camera `index` at time `t`: where the animations that move it put it (the camera as
    /// it is now when none does). `None` when there is no such camera.
    pub fn camera_at(&self, index: usize, t: f32) -> Option<Camera> {
        let mut c = self.cameras.get(index)?.clone();
        for a in &self.animations {
            if let AnimationTarget::Camera {
                camera,
                rest,
                outer,
                motion,
            } = &a.target
                && *camera == index
            {
                c = motion.apply(rest, *outer, t);
            }
        }
        Some(c)
    }

    /// Whether an animation moves camera `index`.
    pub fn camera_is_animated(&self, index: usize) -> bool {
        self.animations.iter().any(
            |a| matches!(&a.target, AnimationTarget::Camera { camera, .. } if *camera == index),
        )
    }

    /// A copy of the scene at time `t`.
    pub fn at_time(&self, t: f32) -> Scene {
        let mut s = self.clone();
        s.set_time(t);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    #[test]
    fn tracks_interpolate_as_hand_computed() {
        let times = vec![0.0, 1.0, 3.0];
        let values = vec![0.0f32, 2.0, 6.0];
        let lin = Track::new(
            times.clone(),
            values.clone(),
            Interpolation::Linear,
            Repeat::Clamp,
        )
        .unwrap();
        assert_eq!(lin.sample(-1.0), 0.0);
        assert_eq!(lin.sample(0.5), 1.0);
        assert_eq!(lin.sample(2.0), 4.0);
        assert_eq!(lin.sample(10.0), 6.0);
        let step = Track::new(
            times.clone(),
            values.clone(),
            Interpolation::Step,
            Repeat::Clamp,
        )
        .unwrap();
        assert_eq!(step.sample(0.99), 0.0);
        assert_eq!(step.sample(1.0), 2.0);
        assert_eq!(step.sample(2.9), 2.0);
        let looped = Track::new(
            times.clone(),
            values.clone(),
            Interpolation::Linear,
            Repeat::Loop,
        )
        .unwrap();
        assert_eq!(looped.sample(3.5), 1.0);
        assert_eq!(looped.sample(-0.5), lin.sample(2.5));
        // Catmull-Rom passes through its keyframes and, on keys spaced along a line with equal
        // steps, is that line: 0, 2, 4, 6 at t = 0, 1, 2, 3.
        let cubic = Track::new(
            vec![0.0, 1.0, 2.0, 3.0],
            vec![0.0f32, 2.0, 4.0, 6.0],
            Interpolation::Cubic,
            Repeat::Clamp,
        )
        .unwrap();
        for (t, v) in [(1.0, 2.0), (1.25, 2.5), (1.5, 3.0), (2.0, 4.0)] {
            assert!(
                (cubic.sample(t) - v).abs() < 1e-5,
                "{t}: {}",
                cubic.sample(t)
            );
        }
    }

    #[test]
    fn bad_tracks_say_what_is_wrong() {
        let bad = |t: Vec<f32>, v: Vec<f32>| {
            Track::new(t, v, Interpolation::Linear, Repeat::Clamp).unwrap_err()
        };
        assert!(bad(vec![], vec![]).contains("at least one"));
        assert!(bad(vec![0.0, 1.0], vec![0.0]).contains("2 keyframe times but 1"));
        assert!(bad(vec![0.0, 2.0, 1.0], vec![0.0; 3]).contains("sorted"));
        assert!(bad(vec![0.0, 0.0], vec![0.0; 2]).contains("sorted"));
        assert!(bad(vec![f32::NAN], vec![0.0]).contains("finite"));
        assert!(bad(vec![-1.0], vec![0.0]).contains(">= 0"));
        assert!(bad(vec![0.0], vec![f32::INFINITY]).contains("not finite"));
    }

    #[test]
    fn hermite_tracks_follow_the_gltf_formula() {
        // Keys at t = 1 and 3 (dt = 2): values 0 and 1, out-tangent 1 leaving the first, in-tangent
        // 3 arriving at the second. The first key's in- and the last key's out-tangent are never
        // used: 100 proves it. At t = 1.5, s = 0.25:
        //   (2s³-3s²+1)·0 + dt(s³-2s²+s)·1 + (-2s³+3s²)·1 + dt(s³-s²)·3
        //   = 0 + 2·0.140625 + 0.15625 + 2·(-0.046875)·3 = 0.15625.
        let h = Track::hermite(
            vec![1.0, 3.0],
            vec![0.0f32, 1.0],
            vec![100.0, 3.0],
            vec![1.0, 100.0],
            Repeat::Clamp,
        )
        .unwrap();
        assert_eq!(h.interpolation, Interpolation::Hermite);
        assert!((h.sample(1.5) - 0.15625).abs() < 1e-6, "{}", h.sample(1.5));
        assert_eq!(h.sample(1.0), 0.0);
        assert_eq!(h.sample(3.0), 1.0);
        assert_eq!(h.sample(0.0), 0.0, "clamped before the first key");
        assert_eq!(h.sample(9.0), 1.0, "clamped after the last key");
        // Near the start the curve leaves along its out-tangent (1 per second).
        let slope = (h.sample(1.001) - h.sample(1.0)) / 0.001;
        assert!((slope - 1.0).abs() < 0.01, "{slope}");
        // Three keys: the middle one's tangents serve both segments.
        let three = Track::hermite(
            vec![0.0, 1.0, 2.0],
            vec![Vec3::ZERO, Vec3::X, Vec3::ZERO],
            vec![Vec3::ZERO, Vec3::Y, Vec3::ZERO],
            vec![Vec3::ZERO, Vec3::Z, Vec3::ZERO],
            Repeat::Clamp,
        )
        .unwrap();
        // s = 0.5, dt = 1: weights 0.5, 0.125, 0.5, -0.125 on p0, b0, p1, a1.
        assert!(close(three.sample(0.5), Vec3::new(0.5, -0.125, 0.0)));
        assert!(close(three.sample(1.5), Vec3::new(0.5, 0.0, 0.125)));
        // Rotations come out unit length: halfway between two turns about Y with zero tangents
        // is their normalised mean, the half turn.
        let (a, b) = (Quat::IDENTITY, Quat::from_rotation_y(1.0));
        let q = Track::hermite(
            vec![0.0, 1.0],
            vec![a, b],
            vec![Quat::from_xyzw(0.0, 0.0, 0.0, 0.0); 2],
            vec![Quat::from_xyzw(0.0, 0.0, 0.0, 0.0); 2],
            Repeat::Clamp,
        )
        .unwrap()
        .sample(0.5);
        assert!((q.length() - 1.0).abs() < 1e-6);
        assert!(q.dot(Quat::from_rotation_y(0.5)) > 1.0 - 1e-6, "{q:?}");
    }

    #[test]
    fn bad_hermite_tracks_say_what_is_wrong() {
        let err = Track::new(
            vec![0.0],
            vec![0.0f32],
            Interpolation::Hermite,
            Repeat::Clamp,
        )
        .unwrap_err();
        assert!(err.contains("tangents"), "{err}");
        let h = |a: Vec<f32>, b: Vec<f32>| {
            Track::hermite(vec![0.0, 1.0], vec![0.0, 1.0], a, b, Repeat::Clamp).unwrap_err()
        };
        assert!(h(vec![0.0], vec![0.0; 2]).contains("2 keyframe times but 1 in-tangents"));
        assert!(h(vec![0.0; 2], vec![0.0; 3]).contains("3 out-tangents"));
        assert!(h(vec![0.0, f32::NAN], vec![0.0; 2]).contains("keyframe 1: the in-tangent"));
        let unsorted = Track::hermite(
            vec![1.0, 0.0],
            vec![0.0f32; 2],
            vec![0.0; 2],
            vec![0.0; 2],
            Repeat::Clamp,
        )
        .unwrap_err();
        assert!(unsorted.contains("sorted"), "{unsorted}");
        // Switched to Hermite without tangents: straight lines, no panic.
        let mut lin = Track::new(
            vec![0.0, 1.0],
            vec![0.0f32, 2.0],
            Interpolation::Linear,
            Repeat::Clamp,
        )
        .unwrap();
        lin.interpolation = Interpolation::Hermite;
        assert_eq!(lin.sample(0.5), 1.0);
    }

    #[test]
    fn node_hierarchies_compose_parent_and_child_motion() {
        let slide = Track::new(
            vec![0.0, 2.0],
            vec![Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0)],
            Interpolation::Linear,
            Repeat::Clamp,
        )
        .unwrap();
        let turn = Track::new(
            vec![0.0, 4.0],
            vec![
                Quat::IDENTITY,
                Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
            ],
            Interpolation::Linear,
            Repeat::Clamp,
        )
        .unwrap();
        let rest = MotionNode {
            parent: None,
            offset: Mat4::IDENTITY,
            rest_translation: Vec3::ZERO,
            rest_rotation: Quat::IDENTITY,
            rest_scale: Vec3::ONE,
            translation: None,
            rotation: None,
            scale: None,
        };
        let nodes: Arc<[MotionNode]> = vec![
            // Parent: slides along X, scaled 2 at rest.
            MotionNode {
                rest_scale: Vec3::splat(2.0),
                translation: Some(slide),
                ..rest.clone()
            },
            // Child: one unit up from the parent (an unanimated node in between), turns about Z.
            MotionNode {
                parent: Some(0),
                offset: Mat4::from_translation(Vec3::Y),
                rest_translation: Vec3::new(0.0, 0.0, 3.0),
                rotation: Some(turn),
                ..rest.clone()
            },
            // Its parent link points forwards: treated as a root, never a loop.
            MotionNode {
                parent: Some(2),
                rest_translation: Vec3::X,
                ..rest
            },
        ]
        .into();
        let child = Motion::Nodes {
            nodes: nodes.clone(),
            node: 1,
        };
        // t = 1: parent T(1,0,0) S(2); child T(0,1,0) T(0,0,3) Rz(22.5°).
        let want = Mat4::from_translation(Vec3::X)
            * Mat4::from_scale(Vec3::splat(2.0))
            * Mat4::from_translation(Vec3::new(0.0, 1.0, 3.0))
            * Mat4::from_rotation_z(std::f32::consts::FRAC_PI_8);
        assert!(child.at(1.0).abs_diff_eq(want, 1e-5), "{}", child.at(1.0));
        assert_eq!(child.duration(), 4.0, "the longest track of the hierarchy");
        let odd = Motion::Nodes {
            nodes: nodes.clone(),
            node: 2,
        };
        assert_eq!(odd.at(0.0), Mat4::from_translation(Vec3::X));
        let missing = Motion::Nodes { nodes, node: 7 };
        assert_eq!(missing.at(0.0), Mat4::IDENTITY);

        // As a target: instances keep their placement below the node, and an included file's
        // transform goes on the outside.
        let mut scene = crate::builtin::cornell_box();
        let mut inner = scene.clone();
        let below = Mat4::from_translation(Vec3::new(0.5, 0.0, 0.0));
        inner.instances[0].dynamic = true;
        inner.animations.push(Animation {
            name: "nodes".into(),
            target: AnimationTarget::Instances {
                instances: vec![0],
                outer: Mat4::IDENTITY,
                inner: vec![below],
                lights: Vec::new(),
                clouds: Vec::new(),
                motion: child.clone(),
            },
        });
        assert!(
            inner.at_time(1.0).instances[0]
                .transform
                .abs_diff_eq(want * below, 1e-5)
        );
        let n0 = scene.instances.len();
        let place = Mat4::from_translation(Vec3::new(0.0, 0.0, -4.0))
            * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2);
        scene.append(inner, place, false);
        let got = scene.at_time(1.0).instances[n0].transform;
        assert!(got.abs_diff_eq(place * want * below, 1e-5), "{got}");
    }

    #[test]
    fn rotations_take_the_short_way() {
        let a = Quat::from_rotation_y(0.0);
        let b = -Quat::from_rotation_y(1.0);
        for interp in [Interpolation::Linear, Interpolation::Cubic] {
            let t = Track::new(vec![0.0, 1.0], vec![a, b], interp, Repeat::Clamp).unwrap();
            let half = t.sample(0.5);
            let want = Quat::from_rotation_y(0.5);
            assert!(half.dot(want).abs() > 1.0 - 1e-5, "{interp:?}: {half:?}");
        }
    }

    #[test]
    fn generators_move_as_described() {
        let orbit = Motion::Orbit {
            center: Vec3::new(1.0, 0.0, 0.0),
            axis: Vec3::Y,
            period: 4.0,
        };
        // A quarter turn about +Y through (1, 0, 0) takes (2, 0, 0) to (1, 0, -1).
        let p = orbit.at(1.0).transform_point3(Vec3::new(2.0, 0.0, 0.0));
        assert!(close(p, Vec3::new(1.0, 0.0, -1.0)), "{p}");
        assert!(close(
            orbit.at(4.0).transform_point3(Vec3::X * 2.0),
            Vec3::X * 2.0
        ));
        let osc = Motion::Oscillate {
            axis: Vec3::X,
            amplitude: 0.5,
            period: 2.0,
        };
        assert!(close(
            osc.at(0.5).transform_point3(Vec3::ZERO),
            Vec3::X * 0.5
        ));
        assert!(close(
            osc.at(1.5).transform_point3(Vec3::ZERO),
            Vec3::X * -0.5
        ));
        assert_eq!(osc.duration(), 2.0);
    }

    #[test]
    fn set_time_moves_instances_from_their_rest_pose_and_lights_from_theirs() {
        let mut scene = crate::builtin::cornell_box();
        let block = 0;
        scene.instances[block].dynamic = true;
        let rest = scene.instances[block].transform;
        let light_rest = scene.lights[0].clone();
        scene.animations.push(Animation {
            name: "slide".into(),
            target: AnimationTarget::Instances {
                instances: vec![block],
                outer: Mat4::IDENTITY,
                inner: vec![rest],
                lights: Vec::new(),
                clouds: Vec::new(),
                motion: Motion::Keyframes {
                    translation: Some(
                        Track::new(
                            vec![0.0, 2.0],
                            vec![Vec3::ZERO, Vec3::new(0.2, 0.0, 0.0)],
                            Interpolation::Linear,
                            Repeat::Clamp,
                        )
                        .unwrap(),
                    ),
                    rotation: None,
                    scale: None,
                },
            },
        });
        scene.animations.push(Animation {
            name: "dim".into(),
            target: AnimationTarget::Light {
                light: 0,
                rest: light_rest.clone(),
                outer: Mat4::IDENTITY,
                tracks: LightTracks {
                    intensity: Some(
                        Track::new(
                            vec![0.0, 2.0],
                            vec![1.0, 0.0],
                            Interpolation::Linear,
                            Repeat::Clamp,
                        )
                        .unwrap(),
                    ),
                    ..Default::default()
                },
            },
        });
        let half = scene.at_time(1.0);
        assert_eq!(
            half.instances[block].transform,
            Mat4::from_translation(Vec3::new(0.1, 0.0, 0.0)) * rest
        );
        assert_eq!(half.lights[0].intensity, 0.5);
        assert_eq!(half.lights[0].position, light_rest.position);
        // Going back to 0 restores the rest state exactly.
        let back = half.at_time(0.0);
        assert_eq!(back.instances[block].transform, rest);
        assert_eq!(back.lights[0], light_rest);
        assert_eq!(scene.animations[0].duration(), 2.0);
    }

    #[test]
    fn appending_a_scene_keeps_its_animations_in_its_own_space() {
        let mut inner = crate::builtin::cornell_box();
        let rest = inner.instances[0].transform;
        let light_rest = inner.lights[0].clone();
        let slide = Track::new(
            vec![0.0, 1.0],
            vec![Vec3::ZERO, Vec3::X],
            Interpolation::Linear,
            Repeat::Clamp,
        )
        .unwrap();
        inner.animations.push(Animation {
            name: "slide".into(),
            target: AnimationTarget::Instances {
                instances: vec![0],
                outer: Mat4::IDENTITY,
                inner: vec![rest],
                lights: Vec::new(),
                clouds: Vec::new(),
                motion: Motion::Keyframes {
                    translation: Some(slide.clone()),
                    rotation: None,
                    scale: None,
                },
            },
        });
        inner.animations.push(Animation {
            name: "lamp".into(),
            target: AnimationTarget::Light {
                light: 0,
                rest: light_rest.clone(),
                outer: Mat4::IDENTITY,
                tracks: LightTracks {
                    position: Some(slide),
                    ..Default::default()
                },
            },
        });
        let mut outer = crate::builtin::open_plane(0.5);
        let (n_inst, n_lights) = (outer.instances.len(), outer.lights.len());
        // Turned a quarter about +Y and moved: the slide along the file's +X becomes one along
        // the world's -Z.
        let t = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0))
            * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_2);
        outer.append(inner, t, true);
        outer.set_time(1.0);
        let got = outer.instances[n_inst].transform;
        let want = t * Mat4::from_translation(Vec3::X) * rest;
        assert!(got.abs_diff_eq(want, 1e-5), "{got} vs {want}");
        let l = &outer.lights[n_lights];
        assert!(
            close(l.position, t.transform_point3(Vec3::X)),
            "{}",
            l.position
        );
        // The light's other parameters are the appended (moved) rest light's.
        assert_eq!(l.intensity, light_rest.intensity);
    }

    #[test]
    fn an_area_light_moves_with_its_surface() {
        let mut scene = crate::builtin::cornell_box();
        let lamp = scene
            .instances
            .iter()
            .position(|i| i.light.is_some())
            .expect("the Cornell box's lamp is an area light's surface");
        let light = scene.instances[lamp].light.unwrap();
        let rest = scene.lights[light].clone();
        let motion = Motion::Oscillate {
            axis: Vec3::X,
            amplitude: 0.1,
            period: 4.0,
        };
        let target = AnimationTarget::instances(&scene, vec![lamp], motion);
        scene.animations.push(Animation {
            name: "sway".into(),
            target,
        });
        let moved = scene.at_time(1.0);
        let l = &moved.lights[light];
        assert!(
            close(l.position, rest.position + Vec3::X * 0.1),
            "{}",
            l.position
        );
        assert!(close(l.direction, rest.direction));
        assert_eq!(l.kind, rest.kind, "a translation keeps the shape");
        assert_eq!(moved.at_time(0.0).lights[light], rest);
    }
}
