//! Scene files: TOML that assembles other files, adds lights and a camera, and carries renderer
//! settings.
//!
//! Every table rejects unknown keys, so a typo is an error naming the key. Full example:
//!
//! ```toml
//! name = "sponza at noon"          # optional; default: the file stem
//!
//! [[include]]                      # any number, applied in order
//! name = "sponza"                  # optional; what an [[animation]] targets
//! file = "../scenes/sponza.obj"    # relative to this file; any format voxgi reads, also .toml
//! # builtin = "cornell-box"        # instead of `file`: a built-in scene (exactly one of the two)
//! translate = [0.0, 0.0, 0.0]      # metres (default 0)
//! rotate = [0.0, 90.0, 0.0]        # degrees about X, then Y, then Z (default 0)
//! scale = 0.01                     # number or [x, y, z], non-zero (default 1)
//! # array = { count = [4, 1, 4], spacing = [60.0, 0.0, 60.0] }  # copies on a lattice,
//! #                                #   world metres apart, sharing the meshes (meshes only)
//! dynamic = false                  # the included instances may move (default false)
//! # fps = 30.0                     # a sequence of point files (see below), frames a second
//! # repeat = "loop"                #   past its last frame: "clamp" (hold it, default) | "loop"
//! [include.material]               # optional; overrides every material of this include
//! base_color = [0.8, 0.8, 0.8]     # linear RGB; also drops the base-colour texture
//! emissive = [0.0, 0.0, 0.0]       # linear radiance; also drops the emissive texture
//! roughness = 0.5
//! metallic = 0.0
//! specular = 1.0                   # dielectric F0 = 0.04 x specular; 0: pure Lambertian
//!
//! [[light]]
//! type = "spot"                    # "directional" | "point" | "spot" | "area"
//! name = "key"                     # optional
//! color = [1.0, 1.0, 1.0]          # linear RGB (default white)
//! intensity = 10.0                 # required, >= 0; units as in `LightKind`
//! position = [0.0, 3.0, 0.0]       # required except for directional lights
//! target = [0.0, 0.0, 0.0]         # or direction = [0.0, -1.0, 0.0] (not both)
//! inner_angle = 20.0               # spot: half-angles from the axis in degrees,
//! outer_angle = 30.0               #   0 <= inner <= outer <= 90 (defaults 0 and 45)
//! range = 20.0                     # point/spot: optional cut-off distance in metres
//! cast_shadows = true              # default true
//!
//! [[light]]
//! type = "area"                    # one-sided, emits towards `direction` / `target`
//! intensity = 5.0                  # radiance
//! position = [0.0, 1.98, 0.0]
//! direction = [0.0, -1.0, 0.0]
//! shape = "rect"                   # "rect" with size = [w, h] in metres, or "disc" with radius
//! size = [0.5, 0.4]                # w runs along the horizontal tangent (X when facing ±Y)
//!
//! [[light]]
//! type = "directional"
//! intensity = 3.0                  # irradiance
//! direction = [-0.4, -1.0, -0.3]   # or position + target
//!
//! [camera]                         # optional; wins over cameras of included files
//! position = [0.0, 1.0, 3.5]
//! target = [0.0, 1.0, 0.0]
//! fov = 45.0                       # vertical, degrees (default 45)
//! znear = 0.01                     # optional
//! zfar = 100.0                     # optional
//!
//! [[view]]                         # any number: named views (the viewer's bookmarks), after
//! name = "gallery"                 #   the scene's other cameras, with the [camera]'s keys
//! position = [2.0, 1.5, 0.0]
//! target = [0.0, 1.0, 0.0]
//!
//! [settings]                       # anything; handed to the renderer untouched
//! voxel_resolution = 256
//!
//! [[animation]]                    # any number; moves a dynamic include or changes a light
//! target = "block"                 # an include's `name` (which must be dynamic) or a light's
//! name = "slide"                   # optional; default: the target
//! interpolation = "linear"         # "step" | "linear" | "cubic" (Catmull-Rom); default linear
//! repeat = "loop"                  # "clamp" (hold the ends, default) | "loop"
//! times = [0.0, 1.0, 2.0]          # keyframe times in seconds, increasing
//! translate = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.0, 0.0]]  # per keyframe, metres
//! # rotate = [[0, 0, 0], …]        # degrees about X, then Y, then Z, per keyframe
//! # scale = [1.0, …]               # number or [x, y, z] per keyframe
//! # orbit = { center = [0, 0, 0], axis = [0, 1, 0], period = 4.0 }  # instead of keyframes
//! # oscillate = { axis = [1, 0, 0], amplitude = 0.1, period = 2.0 } # instead of keyframes
//! # for a light: position, direction, color ([r, g, b]) and intensity (numbers) per keyframe
//! # for target = "camera" (the scene's camera): position, look_at or direction ([x, y, z])
//! # and fov (degrees) per keyframe, or orbit / oscillate (the camera's frame moves rigidly)
//! ```
//!
//! An include's motion is applied in world space on top of its placement (keyframe values are
//! offsets from the rest pose); a light's keyframes replace its position, direction, colour or
//! intensity. A camera's keyframes replace its eye, aim and field of view, and it stays
//! upright. `Scene::set_time` applies them; `Scene::camera_at` samples a camera alone.
//!
//! A point cloud that changes every frame (a live scan, a simulation's output) is an include
//! whose `file` holds a frame number, printf-style: `file = "scan/frame_%04d.ply"` names
//! `frame_0000.ply`, `frame_0001.ply` … (`%d` for unpadded numbers, `%%` for a `%`), from 0
//! (or 1) to the last consecutive file, played at `fps` from time 0. It needs
//! `dynamic = true` (and may be moved by an animation too); each file must hold one point
//! cloud without emission, and all are read once at load, so that a bad frame is an error
//! then and the renderer keeps room for the largest. `Scene::load_frames_at` loads a time's
//! frames into the scene; a renderer plays them itself (`Renderer::set_time`).
//!
//! Included scenes keep their own lights and cameras; without a `[camera]` the first included
//! camera is the default view. Include cycles are reported as errors.

use crate::animation::{
    Animation, AnimationTarget, CameraMotion, CameraTracks, Interpolation, Keyable, LightTracks,
    Motion, Repeat, Track,
};
use crate::{AreaShape, Camera, Light, LightKind, Result, Scene, SceneError};
use glam::{Mat4, Vec3};
use serde::Deserialize;
use std::cell::RefCell;
use std::path::{Path, PathBuf};

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    name: Option<String>,
    #[serde(default)]
    include: Vec<Include>,
    #[serde(default)]
    light: Vec<LightDef>,
    camera: Option<CameraDef>,
    #[serde(default)]
    view: Vec<CameraDef>,
    settings: Option<toml::Table>,
    #[serde(default)]
    animation: Vec<AnimationDef>,
}

/// `[[animation]]`: keyframes (`times` with per-key values) or one generator, for an include
/// or a light named `target`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct AnimationDef {
    name: Option<String>,
    target: String,
    interpolation: Option<String>,
    repeat: Option<String>,
    times: Option<Vec<f32>>,
    translate: Option<Vec<[f32; 3]>>,
    rotate: Option<Vec<[f32; 3]>>,
    scale: Option<Vec<Scale>>,
    position: Option<Vec<[f32; 3]>>,
    direction: Option<Vec<[f32; 3]>>,
    color: Option<Vec<[f32; 3]>>,
    intensity: Option<Vec<f32>>,
    look_at: Option<Vec<[f32; 3]>>,
    fov: Option<Vec<f32>>,
    orbit: Option<OrbitDef>,
    oscillate: Option<OscillateDef>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct OrbitDef {
    center: [f32; 3],
    axis: [f32; 3],
    period: f32,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct OscillateDef {
    axis: [f32; 3],
    amplitude: f32,
    period: f32,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct Include {
    name: Option<String>,
    file: Option<String>,
    builtin: Option<String>,
    #[serde(default)]
    translate: [f32; 3],
    #[serde(default)]
    rotate: [f32; 3],
    scale: Option<Scale>,
    #[serde(default)]
    dynamic: bool,
    material: Option<MaterialOverride>,
    points: Option<AsPoints>,
    /// A sequence's frames per second (its `file` holds a frame number).
    fps: Option<f32>,
    /// Past a sequence's last frame: "clamp" or "loop".
    repeat: Option<String>,
    /// Copies of the include on a lattice, sharing its meshes.
    array: Option<ArrayDef>,
}

/// `array = { count = [nx, ny, nz], spacing = [sx, sy, sz] }`: the include placed again at
/// every `(i sx, j sy, k sz)` (world metres, added to its translation), its meshes stored once.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ArrayDef {
    count: [u32; 3],
    #[serde(default)]
    spacing: [f32; 3],
}

/// The most copies one `array` makes: enough for a city of blocks, few enough that a typo
/// (a count of 10000) is an error and not a hang.
const MAX_ARRAY_COPIES: u64 = 1 << 16;

/// An include's meshes as point clouds: `"vertices"` (the meshes' vertices) or a number (the
/// surfaces sampled on a lattice of that many metres, `pointcloud::sample_surfaces`).
#[derive(Deserialize, Debug, Clone)]
#[serde(untagged)]
enum AsPoints {
    Spacing(f32),
    Named(String),
}

#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(untagged)]
enum Scale {
    Uniform(f32),
    Axes([f32; 3]),
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MaterialOverride {
    base_color: Option<[f32; 3]>,
    emissive: Option<[f32; 3]>,
    roughness: Option<f32>,
    metallic: Option<f32>,
    specular: Option<f32>,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum LightType {
    Directional,
    Point,
    Spot,
    Area,
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum ShapeType {
    Rect,
    Disc,
}

fn default_white() -> [f32; 3] {
    [1.0; 3]
}
fn default_true() -> bool {
    true
}
fn default_fov() -> f32 {
    45.0
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct LightDef {
    #[serde(rename = "type")]
    kind: LightType,
    name: Option<String>,
    #[serde(default = "default_white")]
    color: [f32; 3],
    intensity: f32,
    position: Option<[f32; 3]>,
    target: Option<[f32; 3]>,
    direction: Option<[f32; 3]>,
    inner_angle: Option<f32>,
    outer_angle: Option<f32>,
    range: Option<f32>,
    shape: Option<ShapeType>,
    size: Option<[f32; 2]>,
    radius: Option<f32>,
    #[serde(default = "default_true")]
    cast_shadows: bool,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct CameraDef {
    /// Only `[[view]]`s have (and need) one.
    name: Option<String>,
    position: [f32; 3],
    target: [f32; 3],
    #[serde(default = "default_fov")]
    fov: f32,
    znear: Option<f32>,
    zfar: Option<f32>,
}

/// Most nested includes we follow (a cycle is caught earlier; this bounds legit nesting).
const MAX_DEPTH: usize = 32;

thread_local! {
    /// Scene files being loaded on this thread, outermost first, to detect include cycles.
    static STACK: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
}

struct StackGuard;
impl Drop for StackGuard {
    fn drop(&mut self) {
        STACK.with(|s| s.borrow_mut().pop());
    }
}

pub fn load(path: &Path) -> Result<Scene> {
    load_with_settings(path).map(|(s, _)| s)
}

/// Loads a scene file and returns its `[settings]` table, if any, untouched.
pub fn load_with_settings(path: &Path) -> Result<(Scene, Option<toml::Table>)> {
    let err = |reason: String| SceneError::load(path, reason);
    let canon = super::source::canonicalize(path).map_err(|e| err(format!("cannot open: {e}")))?;
    let cycle = STACK.with(|s| {
        let s = s.borrow();
        if s.contains(&canon) {
            let chain: Vec<String> = s
                .iter()
                .chain(std::iter::once(&canon))
                .map(|p| p.display().to_string())
                .collect();
            Some(format!("include cycle: {}", chain.join(" -> ")))
        } else if s.len() >= MAX_DEPTH {
            Some(format!("includes nested deeper than {MAX_DEPTH} levels"))
        } else {
            None
        }
    });
    if let Some(reason) = cycle {
        return Err(err(reason));
    }
    STACK.with(|s| s.borrow_mut().push(canon));
    let _guard = StackGuard;

    let text = super::source::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let file: SceneFile = toml::from_str(&text).map_err(|e| err(e.to_string()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut scene = Scene {
        name: file.name.clone().unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into())
        }),
        ..Default::default()
    };

    // Each include's instances, for the animations that name it.
    let mut include_instances: Vec<IncludeRange> = Vec::new();
    for (i, inc) in file.include.iter().enumerate() {
        let what = format!("include {}", i + 1);
        let sequence = inc
            .file
            .as_deref()
            .filter(|f| crate::sequence::is_pattern(f));
        if sequence.is_none() && (inc.fps.is_some() || inc.repeat.is_some()) {
            return Err(err(format!(
                "{what}: `fps` and `repeat` are for a sequence of point files, whose `file` \
                 holds a frame number (`scan_%04d.ply`)"
            )));
        }
        let mut sub =
            match (&inc.file, &inc.builtin) {
                // Its cloud is the sub-scene's first: `append` moves the index with the cloud, and
                // the material override, `points` and `dynamic` are checked below as for a file
                // that holds sequences.
                (Some(f), None) if sequence.is_some() => open_sequence(&dir.join(f), inc)
                    .map_err(|r| err(format!("{what} ('{f}'): {r}")))?,
                (Some(f), None) => crate::io::load(&dir.join(f))
                    .map_err(|e| err(format!("{what} ('{f}'): {e}")))?,
                (None, Some(b)) => {
                    crate::builtin::by_name(b).map_err(|e| err(format!("{what}: {e}")))?
                }
                _ => {
                    return Err(err(format!(
                        "{what}: needs exactly one of `file` and `builtin`"
                    )));
                }
            };
        if let Some(o) = &inc.material {
            apply_override(&mut sub, o).map_err(|r| err(format!("{what}: {r}")))?;
        }
        if inc.points.is_some() && !sub.sequences.is_empty() {
            return Err(err(format!(
                "{what}: `points` makes points of meshes; point sequences are points already"
            )));
        }
        let scale = match inc.scale {
            None => Vec3::ONE,
            Some(Scale::Uniform(s)) => Vec3::splat(s),
            Some(Scale::Axes(a)) => Vec3::from(a),
        };
        let t = Vec3::from(inc.translate);
        let r = Vec3::from(inc.rotate);
        if !(scale.is_finite() && scale.cmpne(Vec3::ZERO).all() && t.is_finite() && r.is_finite()) {
            return Err(err(format!(
                "{what}: translate, rotate and scale must be finite and scale non-zero"
            )));
        }
        let mut transform = Mat4::from_translation(t)
            * Mat4::from_rotation_z(r.z.to_radians())
            * Mat4::from_rotation_y(r.y.to_radians())
            * Mat4::from_rotation_x(r.x.to_radians())
            * Mat4::from_scale(scale);
        match &inc.points {
            None => {}
            Some(AsPoints::Named(n)) if n == "vertices" => {
                sub = crate::pointcloud::mesh_vertices(&sub);
            }
            Some(AsPoints::Spacing(h)) if h.is_finite() && *h > 0.0 => {
                // The lattice is laid in the world, `h` metres apart whatever the include's
                // scale: placed first, the include then needs no transform of its own.
                let mut placed = Scene {
                    name: sub.name.clone(),
                    ..Default::default()
                };
                placed.append(sub, transform, false);
                sub = placed;
                transform = Mat4::IDENTITY;
                // Each point of the lattice stands for at least h² of surface.
                let count = crate::pointcloud::surface_area(&sub) / (*h as f64 * *h as f64);
                if count > crate::limits::MAX_ELEMENTS as f64 {
                    return Err(err(format!(
                        "{what}: `points = {h}` would sample about {count:.0} points, more than \
                         the {} a cloud may hold",
                        crate::limits::MAX_ELEMENTS
                    )));
                }
                sub = crate::pointcloud::sample_surfaces(&sub, *h);
            }
            Some(p) => {
                return Err(err(format!(
                    "{what}: `points` must be \"vertices\" or a spacing in metres > 0, not {p:?}"
                )));
            }
        }
        // What the override made emissive, and points sampled from emissive meshes, may be
        // area lights.
        crate::io::emitters::promote_emissive_quads(&mut sub);
        crate::io::emitters::promote_emissive_points(&mut sub);
        let copies = match &inc.array {
            Some(a) => array_offsets(a, &sub).map_err(|r| err(format!("{what}: {r}")))?,
            None => vec![Vec3::ZERO],
        };
        let (first, first_cloud) = (scene.instances.len(), scene.point_clouds.len());
        scene.append(sub, transform, inc.dynamic);
        // The copies are instances of the meshes just appended: a town of a hundred buildings
        // holds each building's triangles once.
        let placed = first..scene.instances.len();
        for offset in &copies[1..] {
            for i in placed.clone() {
                let mut copy = scene.instances[i].clone();
                copy.transform = Mat4::from_translation(*offset) * copy.transform;
                scene.instances.push(copy);
            }
        }
        include_instances.push(IncludeRange {
            name: inc.name.as_deref(),
            instances: first..scene.instances.len(),
            clouds: first_cloud..scene.point_clouds.len(),
            dynamic: inc.dynamic,
        });
    }

    for (i, l) in file.light.iter().enumerate() {
        let light = make_light(l, i).map_err(|r| {
            err(format!(
                "light {} ({}): {r}",
                i + 1,
                format!("{:?}", l.kind).to_lowercase()
            ))
        })?;
        if matches!(light.kind, LightKind::Area { .. }) {
            scene.add_area_light(light);
        } else {
            scene.lights.push(light);
        }
    }

    if let Some(c) = &file.camera {
        if c.name.is_some() {
            return Err(err("camera: a name is for [[view]]s".into()));
        }
        let cam = make_camera(c, "scene file camera").map_err(|r| err(format!("camera: {r}")))?;
        scene.cameras.insert(0, cam);
        // The included files' camera animations follow their cameras down the list.
        for a in &mut scene.animations {
            if let AnimationTarget::Camera { camera, .. } = &mut a.target {
                *camera += 1;
            }
        }
    }

    for (i, a) in file.animation.iter().enumerate() {
        let anim = make_animation(a, &scene, &include_instances)
            .map_err(|r| err(format!("animation {} ('{}'): {r}", i + 1, a.target)))?;
        scene.animations.push(anim);
    }
    for (i, v) in file.view.iter().enumerate() {
        let name = v
            .name
            .as_deref()
            .ok_or_else(|| err(format!("view {}: a view needs a name", i + 1)))?;
        let cam =
            make_camera(v, name).map_err(|r| err(format!("view {} ('{name}'): {r}", i + 1)))?;
        scene.cameras.push(cam);
    }
    Ok((scene, file.settings))
}

/// The offsets of an include's `array` copies, the first zero (the include itself); `sub` is
/// what the include holds: copies share meshes, so it may hold nothing else.
fn array_offsets(a: &ArrayDef, sub: &Scene) -> std::result::Result<Vec<Vec3>, String> {
    let copies: u64 = a.count.iter().map(|&n| n as u64).product();
    if a.count.contains(&0) || copies > MAX_ARRAY_COPIES {
        return Err(format!(
            "array.count {:?} must be at least 1 on each axis and make at most {MAX_ARRAY_COPIES} \
             copies",
            a.count
        ));
    }
    let spacing = Vec3::from(a.spacing);
    if !spacing.is_finite() {
        return Err("array.spacing must be finite".into());
    }
    let stacked = (0..3).find(|&i| a.count[i] > 1 && a.spacing[i] == 0.0);
    if let Some(i) = stacked {
        return Err(format!(
            "array.spacing is 0 along {} where count makes {} copies: they would lie on each \
             other",
            ["x", "y", "z"][i],
            a.count[i]
        ));
    }
    let holds = [
        (sub.lights.len(), "lights"),
        (sub.point_clouds.len(), "point clouds"),
        (sub.animations.len(), "animations"),
        (sub.cameras.len(), "cameras"),
    ];
    if let Some((n, what)) = holds.iter().find(|(n, _)| *n > 0) {
        return Err(format!(
            "`array` copies meshes, and this include also holds {n} {what} (emissive faces \
             become area lights): include it once per copy instead"
        ));
    }
    let [nx, ny, nz] = a.count;
    let mut v = Vec::with_capacity(copies as usize);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                v.push(spacing * Vec3::new(i as f32, j as f32, k as f32));
            }
        }
    }
    Ok(v)
}

/// An include's sequence of point files (`file` holds a frame number): a scene of its first
/// frame's cloud, with the sequence playing in it.
fn open_sequence(pattern: &Path, inc: &Include) -> std::result::Result<Scene, String> {
    if !inc.dynamic {
        return Err(
            "a sequence of point files changes over time: it needs `dynamic = true`".into(),
        );
    }
    let Some(fps) = inc.fps else {
        return Err("a sequence of point files needs `fps`, its frames per second".into());
    };
    let repeat = parse_repeat(inc.repeat.as_deref())?;
    let start = web_time::Instant::now();
    let (seq, mut first) =
        crate::sequence::PointSequence::open(pattern, fps, repeat, None, &mut |n| {
            log::info!("{}: {n} frames read", pattern.display())
        })
        .map_err(|e| e.to_string())?;
    log::info!(
        "{}: {} frames of up to {} points read in {:.2} s",
        pattern.display(),
        seq.files.len(),
        seq.capacity,
        start.elapsed().as_secs_f64()
    );
    first.name = pattern
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Scene {
        name: first.name.clone(),
        point_clouds: vec![first],
        sequences: vec![seq],
        ..Default::default()
    })
}

/// A `[camera]` or a `[[view]]`.
fn make_camera(c: &CameraDef, name: &str) -> std::result::Result<Camera, String> {
    let (p, t) = (Vec3::from(c.position), Vec3::from(c.target));
    if !(p.is_finite() && t.is_finite()) || p.distance(t) <= 0.0 {
        return Err("position and target must be finite and differ".into());
    }
    if !(c.fov > 0.0 && c.fov < 180.0) {
        return Err(format!("fov {} is not in (0, 180) degrees", c.fov));
    }
    let mut cam = Camera::look_at(p, t, c.fov);
    cam.name = name.into();
    if let Some(zn) = c.znear {
        if zn.is_nan() || zn <= 0.0 {
            return Err(format!("znear {zn} must be > 0"));
        }
        cam.znear = zn;
    }
    if let Some(zf) = c.zfar {
        if zf.is_nan() || zf <= cam.znear {
            return Err(format!("zfar {zf} must exceed znear"));
        }
        cam.zfar = Some(zf);
    }
    Ok(cam)
}

fn apply_override(scene: &mut Scene, o: &MaterialOverride) -> std::result::Result<(), String> {
    let ok_color = |c: &[f32; 3]| c.iter().all(|v| v.is_finite() && *v >= 0.0);
    if o.base_color.as_ref().is_some_and(|c| !ok_color(c))
        || o.emissive.as_ref().is_some_and(|c| !ok_color(c))
    {
        return Err("material colours must be finite and >= 0".into());
    }
    for (k, v) in [
        ("roughness", o.roughness),
        ("metallic", o.metallic),
        ("specular", o.specular),
    ] {
        if v.is_some_and(|v| !(0.0..=1.0).contains(&v)) {
            return Err(format!("material {k} must be in [0, 1]"));
        }
    }
    if o.emissive.is_some() && !scene.sequences.is_empty() {
        return Err("a point sequence's points cannot emit (`material.emissive`)".into());
    }
    for s in &mut scene.sequences {
        s.base_color = o.base_color.or(s.base_color);
    }
    for pc in &mut scene.point_clouds {
        if let Some(c) = o.base_color {
            pc.colors.fill(c);
        }
        if let Some(e) = o.emissive {
            pc.emission = vec![e; pc.positions.len()];
        }
    }
    // An area light's surface and the light emit the same radiance.
    if let Some(e) = o.emissive {
        let shown = scene.instances.iter().filter_map(|i| i.light);
        for l in shown.chain(scene.point_clouds.iter().filter_map(|p| p.light)) {
            scene.lights[l].color = e;
            scene.lights[l].intensity = 1.0;
        }
    }
    for m in &mut scene.materials {
        if let Some(c) = o.base_color {
            m.base_color = [c[0], c[1], c[2], m.base_color[3]];
            m.base_color_texture = None;
        }
        if let Some(e) = o.emissive {
            m.emissive = e;
            m.emissive_texture = None;
        }
        if let Some(r) = o.roughness {
            m.roughness = r;
        }
        if let Some(x) = o.metallic {
            m.metallic = x;
        }
        if let Some(x) = o.specular {
            m.specular = x;
        }
    }
    Ok(())
}

fn vec(name: &str, v: Option<[f32; 3]>) -> std::result::Result<Option<Vec3>, String> {
    match v.map(Vec3::from) {
        Some(v) if !v.is_finite() => Err(format!("`{name}` is not finite")),
        v => Ok(v),
    }
}

fn make_light(l: &LightDef, index: usize) -> std::result::Result<Light, String> {
    if !(l.intensity.is_finite() && l.intensity >= 0.0) {
        return Err(format!("intensity {} must be finite and >= 0", l.intensity));
    }
    if !l.color.iter().all(|c| c.is_finite() && *c >= 0.0) {
        return Err(format!("color {:?} must be finite and >= 0", l.color));
    }
    let position = vec("position", l.position)?;
    let target = vec("target", l.target)?;
    let direction = vec("direction", l.direction)?;
    let needs_position = l.kind != LightType::Directional;
    if needs_position && position.is_none() {
        return Err("needs `position`".into());
    }
    let pos = position.unwrap_or(Vec3::ZERO);
    let dir = match (direction, target) {
        (Some(_), Some(_)) => return Err("give `direction` or `target`, not both".into()),
        (Some(d), None) => Some(d),
        (None, Some(t)) => {
            if position.is_none() {
                return Err("`target` needs `position`".into());
            }
            Some(t - pos)
        }
        (None, None) => None,
    };
    let dir = match (l.kind, dir) {
        (LightType::Point, _) => dir.unwrap_or(Vec3::NEG_Y),
        (_, None) => return Err("needs `direction` or `target`".into()),
        (_, Some(d)) => d
            .try_normalize()
            .ok_or("direction is zero (target equals position?)")?,
    };
    let kind_only = |key: &str, present: bool, kind: &str| {
        if present {
            Err(format!("`{key}` only applies to {kind} lights"))
        } else {
            Ok(())
        }
    };
    if l.kind != LightType::Spot {
        kind_only("inner_angle", l.inner_angle.is_some(), "spot")?;
        kind_only("outer_angle", l.outer_angle.is_some(), "spot")?;
    }
    if l.kind != LightType::Area {
        kind_only("shape", l.shape.is_some(), "area")?;
        kind_only("size", l.size.is_some(), "area")?;
        kind_only("radius", l.radius.is_some(), "area")?;
    }
    if let Some(r) = l.range
        && !(r > 0.0 && r.is_finite())
    {
        return Err(format!("range {r} must be > 0"));
    }
    let kind = match l.kind {
        LightType::Directional => LightKind::Directional,
        LightType::Point => LightKind::Point,
        LightType::Spot => {
            let inner = l.inner_angle.unwrap_or(0.0);
            let outer = l.outer_angle.unwrap_or(45.0);
            if !(0.0 <= inner && inner <= outer && outer <= 90.0) {
                return Err(format!(
                    "spot angles must satisfy 0 <= inner_angle <= outer_angle <= 90 degrees (got inner {inner}, outer {outer})"
                ));
            }
            LightKind::Spot {
                inner_angle: inner.to_radians(),
                outer_angle: outer.to_radians(),
            }
        }
        LightType::Area => {
            let shape = match l.shape {
                None => return Err("needs `shape` (\"rect\" or \"disc\")".into()),
                Some(ShapeType::Rect) => {
                    kind_only("radius", l.radius.is_some(), "disc area")?;
                    let Some([w, h]) = l.size else {
                        return Err("rect needs `size = [w, h]`".into());
                    };
                    if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
                        return Err(format!("size [{w}, {h}] must be positive"));
                    }
                    let t = if dir.y.abs() > 0.99 {
                        Vec3::X
                    } else {
                        Vec3::Y.cross(dir).normalize()
                    };
                    // t x (dir x t) = dir, so the rect's u x v faces along the light.
                    AreaShape::Rect {
                        u: t * (0.5 * w),
                        v: dir.cross(t) * (0.5 * h),
                    }
                }
                Some(ShapeType::Disc) => {
                    kind_only("size", l.size.is_some(), "rect area")?;
                    let Some(r) = l.radius else {
                        return Err("disc needs `radius`".into());
                    };
                    if !(r > 0.0 && r.is_finite()) {
                        return Err(format!("radius {r} must be positive"));
                    }
                    AreaShape::Disc { radius: r }
                }
            };
            LightKind::Area { shape }
        }
    };
    Ok(Light {
        name: l
            .name
            .clone()
            .unwrap_or_else(|| format!("light {}", index + 1)),
        kind,
        color: l.color,
        intensity: l.intensity,
        position: pos,
        direction: dir,
        range: l.range,
        cast_shadows: l.cast_shadows,
    })
}

fn parse_interpolation(s: Option<&str>) -> std::result::Result<Interpolation, String> {
    match s.unwrap_or("linear") {
        "step" => Ok(Interpolation::Step),
        "linear" => Ok(Interpolation::Linear),
        "cubic" => Ok(Interpolation::Cubic),
        other => Err(format!(
            "interpolation '{other}' is not step, linear or cubic"
        )),
    }
}

fn parse_repeat(s: Option<&str>) -> std::result::Result<Repeat, String> {
    match s.unwrap_or("clamp") {
        "clamp" => Ok(Repeat::Clamp),
        "loop" => Ok(Repeat::Loop),
        other => Err(format!("repeat '{other}' is not clamp or loop")),
    }
}

/// What an `[[include]]` added to the scene, for the animations that name it.
struct IncludeRange<'a> {
    name: Option<&'a str>,
    instances: std::ops::Range<usize>,
    clouds: std::ops::Range<usize>,
    dynamic: bool,
}

/// The target name of an animation that moves the scene's camera (its `[camera]`, or else the
/// first camera of its includes).
const CAMERA_TARGET: &str = "camera";

/// An animation's `orbit` or `oscillate` generator (the caller checked there is one).
fn generator(a: &AnimationDef) -> std::result::Result<Motion, String> {
    match (&a.orbit, &a.oscillate) {
        (Some(o), _) => {
            let axis = Vec3::from(o.axis);
            if !(Vec3::from(o.center).is_finite() && axis.is_finite() && axis.length() > 0.0) {
                return Err("orbit: center and axis must be finite, the axis non-zero".into());
            }
            if !(o.period.is_finite() && o.period > 0.0) {
                return Err(format!("orbit: period {} must be > 0 seconds", o.period));
            }
            Ok(Motion::Orbit {
                center: Vec3::from(o.center),
                axis: axis.normalize(),
                period: o.period,
            })
        }
        (None, Some(o)) => {
            let axis = Vec3::from(o.axis);
            if !(axis.is_finite() && axis.length() > 0.0 && o.amplitude.is_finite()) {
                return Err(
                    "oscillate: axis and amplitude must be finite, the axis non-zero".into(),
                );
            }
            if !(o.period.is_finite() && o.period > 0.0) {
                return Err(format!(
                    "oscillate: period {} must be > 0 seconds",
                    o.period
                ));
            }
            Ok(Motion::Oscillate {
                axis: axis.normalize(),
                amplitude: o.amplitude,
                period: o.period,
            })
        }
        (None, None) => Err("nothing moves: give orbit or oscillate".into()),
    }
}

/// One `[[animation]]` table as an `Animation` of `scene`, whose includes are `includes`.
fn make_animation(
    a: &AnimationDef,
    scene: &Scene,
    includes: &[IncludeRange],
) -> std::result::Result<Animation, String> {
    let interpolation = parse_interpolation(a.interpolation.as_deref())?;
    let repeat = parse_repeat(a.repeat.as_deref())?;
    // One key's values as a track over `times`, when the key is present.
    fn key_track<T: Keyable>(
        a: &AnimationDef,
        what: &str,
        values: Option<Vec<T>>,
        interpolation: Interpolation,
        repeat: Repeat,
    ) -> std::result::Result<Option<Track<T>>, String> {
        let Some(values) = values else {
            return Ok(None);
        };
        let times = a
            .times
            .clone()
            .ok_or_else(|| format!("`{what}` needs keyframe `times`"))?;
        Track::new(times, values, interpolation, repeat)
            .map(Some)
            .map_err(|e| format!("`{what}`: {e}"))
    }
    let track =
        |what: &str, values: Option<Vec<Vec3>>| key_track(a, what, values, interpolation, repeat);
    let v3 = |v: &Option<Vec<[f32; 3]>>| {
        v.as_ref()
            .map(|v| v.iter().map(|&x| Vec3::from(x)).collect())
    };
    let include = includes
        .iter()
        .filter(|inc| inc.name == Some(a.target.as_str()))
        .collect::<Vec<_>>();
    let light = scene
        .lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.name == a.target)
        .map(|(i, _)| i)
        .collect::<Vec<_>>();
    let name = a.name.clone().unwrap_or_else(|| a.target.clone());
    match (include.as_slice(), light.as_slice()) {
        ([inc], []) => {
            if !inc.dynamic {
                return Err(
                    "the include is static: set `dynamic = true` on it to let it move".into(),
                );
            }
            if a.position.is_some()
                || a.direction.is_some()
                || a.color.is_some()
                || a.intensity.is_some()
                || a.look_at.is_some()
                || a.fov.is_some()
            {
                return Err(
                    "an include takes translate, rotate, scale, orbit or oscillate, not light keys"
                        .into(),
                );
            }
            let keyed = a.translate.is_some() || a.rotate.is_some() || a.scale.is_some();
            let motion = match (keyed, &a.orbit, &a.oscillate) {
                (true, None, None) => Motion::Keyframes {
                    translation: track("translate", v3(&a.translate))?,
                    rotation: key_track(
                        a,
                        "rotate",
                        a.rotate.as_ref().map(|r| {
                            r.iter()
                                .map(|d| {
                                    let d = Vec3::from(*d);
                                    glam::Quat::from_rotation_z(d.z.to_radians())
                                        * glam::Quat::from_rotation_y(d.y.to_radians())
                                        * glam::Quat::from_rotation_x(d.x.to_radians())
                                })
                                .collect()
                        }),
                        interpolation,
                        repeat,
                    )?,
                    scale: track(
                        "scale",
                        a.scale.as_ref().map(|s| {
                            s.iter()
                                .map(|s| match s {
                                    Scale::Uniform(u) => Vec3::splat(*u),
                                    Scale::Axes(v) => Vec3::from(*v),
                                })
                                .collect()
                        }),
                    )?,
                },
                (false, Some(_), None) | (false, None, Some(_)) => generator(a)?,
                (false, None, None) => {
                    return Err(
                        "nothing moves: give translate/rotate/scale keyframes, orbit or oscillate"
                            .into(),
                    );
                }
                _ => return Err("give keyframes, orbit or oscillate, only one of them".into()),
            };
            Ok(Animation {
                name,
                target: AnimationTarget::instances(scene, inc.instances.clone().collect(), motion)
                    .with_clouds(scene, inc.clouds.clone()),
            })
        }
        ([], [l]) => {
            if a.translate.is_some()
                || a.rotate.is_some()
                || a.scale.is_some()
                || a.orbit.is_some()
                || a.oscillate.is_some()
                || a.look_at.is_some()
                || a.fov.is_some()
            {
                return Err(
                    "a light takes position, direction, color or intensity keyframes".into(),
                );
            }
            let tracks = LightTracks {
                position: track("position", v3(&a.position))?,
                direction: track("direction", v3(&a.direction))?,
                color: track("color", v3(&a.color))?,
                intensity: key_track(a, "intensity", a.intensity.clone(), interpolation, repeat)?,
            };
            if tracks == LightTracks::default() {
                return Err(
                    "nothing changes: give position, direction, color or intensity keyframes"
                        .into(),
                );
            }
            Ok(Animation {
                name,
                target: AnimationTarget::Light {
                    light: *l,
                    rest: scene.lights[*l].clone(),
                    outer: Mat4::IDENTITY,
                    tracks,
                },
            })
        }
        ([], []) if a.target == CAMERA_TARGET => {
            let Some(rest) = scene.cameras.first() else {
                return Err(
                    "the scene has no camera to animate: add a [camera] (its rest pose)".into(),
                );
            };
            if a.translate.is_some()
                || a.rotate.is_some()
                || a.scale.is_some()
                || a.color.is_some()
                || a.intensity.is_some()
            {
                return Err(
                    "a camera takes position, look_at, direction or fov keyframes, orbit or \
                     oscillate"
                        .into(),
                );
            }
            if a.look_at.is_some() && a.direction.is_some() {
                return Err("give look_at or direction keyframes, not both".into());
            }
            let tracks = CameraTracks {
                position: track("position", v3(&a.position))?,
                look_at: track("look_at", v3(&a.look_at))?,
                direction: track("direction", v3(&a.direction))?,
                fov: key_track(a, "fov", a.fov.clone(), interpolation, repeat)?,
            };
            if let Some(f) = a.fov.iter().flatten().find(|f| !(**f > 0.5 && **f < 179.0)) {
                return Err(format!("fov {f} is not in (0.5, 179) degrees"));
            }
            let keyed = tracks != CameraTracks::default();
            let motion = match (keyed, &a.orbit, &a.oscillate) {
                (true, None, None) => CameraMotion::Tracks(tracks),
                (false, Some(_), None) | (false, None, Some(_)) => CameraMotion::Rigid {
                    motion: generator(a)?,
                    inner: crate::animation::camera_frame(rest),
                },
                (false, None, None) => {
                    return Err(
                        "nothing moves: give position, look_at, direction or fov keyframes, \
                         orbit or oscillate"
                            .into(),
                    );
                }
                _ => return Err("give keyframes, orbit or oscillate, only one of them".into()),
            };
            Ok(Animation {
                name,
                target: AnimationTarget::Camera {
                    camera: 0,
                    rest: rest.clone(),
                    outer: Mat4::IDENTITY,
                    motion,
                },
            })
        }
        ([], []) => Err(format!(
            "no include (by `name`) or light is called '{}' (`{CAMERA_TARGET}` moves the \
             scene's camera)",
            a.target
        )),
        _ => Err(format!(
            "more than one include or light is called '{}'",
            a.target
        )),
    }
}
