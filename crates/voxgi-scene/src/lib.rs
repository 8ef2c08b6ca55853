//! voxgi's scene model and loaders.
//!
//! This crate has no GPU dependency so that loaders build and test in seconds and other tools can
//! read scenes without a device. Every loader returns a [`Scene`] that passed [`Scene::validate`],
//! so the renderer can trust indices and counts.

pub mod animation;
pub mod builtin;
mod error;
pub mod io;
mod model;
pub mod pointcloud;
pub mod prepare;
pub mod sequence;
mod util;

pub use error::SceneError;
pub use glam;
pub use model::*;
pub use util::{compute_normals, srgb_to_linear};

use glam::{Mat4, Vec3};

pub type Result<T, E = SceneError> = std::result::Result<T, E>;

/// Hard limits that keep a hostile file from exhausting memory before we notice.
/// Poses `Scene::swept_bounds` samples an animation at, past the first.
pub const SWEEP_SAMPLES: u32 = 256;

pub mod limits {
    /// Vertices or points in one mesh or cloud.
    pub const MAX_ELEMENTS: usize = 1 << 28;
    /// Emitted radiance (emissive materials and points, an area light's radiance), W/(m² sr):
    /// the largest finite half float, which is what voxgi stores radiance in.
    pub const MAX_RADIANCE: f32 = 65504.0;
    /// A point, spot or directional light's intensity × colour: far past anything that shows
    /// more than a saturated image (1e10 W/sr still saturates a white wall 400 m away), and
    /// far below where single-precision lighting overflows into NaN (about 1e30).
    pub const MAX_LIGHT: f32 = 1e10;
    /// The largest side of the scene's bulk (`Scene::bulk_bounds`), m: a scene wider than a
    /// million kilometres is in the wrong units (and squared distances in single precision
    /// overflow past about 1e19).
    pub const MAX_EXTENT: f32 = 1e9;
    /// Texture width or height: larger images are refused.
    pub const MAX_TEXTURE_DIM: u32 = 16384;
    /// Texture width or height kept in memory: larger images are reduced (an RGBA8 texture of
    /// this size is 256 MiB), a PNG while it is decoded.
    pub const MAX_DECODED_DIM: u32 = 8192;
}

impl Scene {
    /// World-space bounds of all mesh instances, point clouds and the surfaces of area lights.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for inst in &self.instances {
            if let Some(mesh) = self.meshes.get(inst.mesh) {
                for &p in &mesh.positions {
                    b.grow(inst.transform.transform_point3(p));
                }
            }
        }
        for pc in &self.point_clouds {
            for &p in &pc.positions {
                b.grow(pc.transform.transform_point3(p));
            }
        }
        b
    }

    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .filter_map(|i| self.meshes.get(i.mesh))
            .map(|m| m.indices.len() / 3)
            .sum()
    }

    pub fn point_count(&self) -> usize {
        self.point_clouds.iter().map(|p| p.positions.len()).sum()
    }

    /// True when nothing in the scene emits light: no lights and no emissive material in use.
    pub fn is_unlit(&self) -> bool {
        self.lights.is_empty()
            && !self.instances.iter().any(|i| {
                self.meshes
                    .get(i.mesh)
                    .and_then(|m| self.materials.get(m.material))
                    .is_some_and(|m| m.is_emissive())
            })
            && self.point_clouds.iter().all(|p| p.emission.is_empty())
    }

    /// Appends a mesh with its own material and one static instance of it; returns the instance.
    pub fn add_mesh(&mut self, mesh: Mesh, material: Material, transform: Mat4) -> usize {
        let mut mesh = mesh;
        mesh.material = self.materials.len();
        self.materials.push(material);
        let name = mesh.name.clone();
        self.meshes.push(mesh);
        self.instances.push(Instance {
            name,
            mesh: self.meshes.len() - 1,
            transform,
            dynamic: false,
            light: None,
        });
        self.instances.len() - 1
    }

    /// Replaces light `index` with `light`; an area light's visible surfaces (the instances
    /// and point clouds whose `light` it is) move with it, from its old frame to its new
    /// (`Light::emitter_frame`), as `Renderer::set_light` moves them. Out of range: nothing.
    pub fn set_light(&mut self, index: usize, light: Light) {
        set_light(
            &mut self.lights,
            &mut self.instances,
            &mut self.point_clouds,
            index,
            light,
        );
    }

    /// Adds an area light together with the emissive surface that shows it, so the light is
    /// visible to the camera and to voxelization.
    pub fn add_area_light(&mut self, light: Light) -> usize {
        let LightKind::Area { shape } = light.kind else {
            self.lights.push(light);
            return self.lights.len() - 1;
        };
        let n = light.direction.normalize();
        let (positions, indices) = match shape {
            AreaShape::Rect { u, v } => {
                let c = light.position;
                let mut idx = vec![0, 1, 2, 0, 2, 3];
                // Wind the quad so its geometric normal points along the light's direction.
                if u.cross(v).dot(n) < 0.0 {
                    idx = vec![0, 2, 1, 0, 3, 2];
                }
                (vec![c - u - v, c + u - v, c + u + v, c - u + v], idx)
            }
            AreaShape::Disc { radius } => {
                let (t, b) = n.any_orthonormal_pair();
                let segments = 32;
                let mut p = vec![light.position];
                let mut idx = Vec::new();
                for i in 0..segments {
                    let a = i as f32 / segments as f32 * std::f32::consts::TAU;
                    p.push(light.position + radius * (a.cos() * t + a.sin() * b));
                    let (j, k) = (1 + i, 1 + (i + 1) % segments);
                    idx.extend_from_slice(&[0, j, k]);
                }
                // t x b = n, so counter-clockwise in (t, b) faces along n.
                (p, idx)
            }
        };
        let emissive = light.radiometric().to_array();
        let mesh = Mesh {
            name: light.name.clone(),
            normals: vec![n; positions.len()],
            uvs: Vec::new(),
            positions,
            indices,
            material: 0,
        };
        let material = Material {
            name: format!("{} (emitter)", light.name),
            base_color: [0.78, 0.78, 0.78, 1.0],
            emissive,
            ..Default::default()
        };
        self.lights.push(light);
        let li = self.lights.len() - 1;
        let inst = self.add_mesh(mesh, material, Mat4::IDENTITY);
        self.instances[inst].light = Some(li);
        li
    }

    /// Moves `other` into this scene, placed by `transform` (object to world), remapping its
    /// mesh, material, texture and light indices. Positions transform as points; spot and
    /// directional light directions and area-light edge vectors transform as vectors (the
    /// linear part); an area light's emitting normal uses the inverse transpose so it stays
    /// perpendicular to its edges under non-uniform scale. Disc radii scale by the square root
    /// of the area change (a non-uniformly scaled disc is an ellipse; we keep its area).
    /// `dynamic` marks all of `other`'s instances and point clouds dynamic.
    pub fn append(&mut self, other: Scene, transform: Mat4, dynamic: bool) {
        let (mesh0, mat0, tex0, light0) = (
            self.meshes.len(),
            self.materials.len(),
            self.textures.len(),
            self.lights.len(),
        );
        let linear = glam::Mat3::from_mat4(transform);
        let camera0 = self.cameras.len();
        let moved_camera = |mut c: Camera| {
            c.position = transform.transform_point3(c.position);
            c.forward = (linear * c.forward).normalize_or(c.forward);
            let up = (linear * c.up).normalize_or(c.up);
            let right = c.forward.cross(up).normalize_or(Vec3::X);
            c.up = right.cross(c.forward).normalize_or(Vec3::Y);
            c
        };
        self.textures.extend(other.textures);
        self.materials
            .extend(other.materials.into_iter().map(|mut m| {
                m.base_color_texture = m.base_color_texture.map(|t| t + tex0);
                m.emissive_texture = m.emissive_texture.map(|t| t + tex0);
                m
            }));
        self.meshes.extend(other.meshes.into_iter().map(|mut m| {
            m.material += mat0;
            m
        }));
        let other_instances = other.instances.len();
        let other_clouds = other.point_clouds.len();
        self.instances
            .extend(other.instances.into_iter().map(|mut i| {
                i.mesh += mesh0;
                i.light = i.light.map(|l| l + light0);
                i.transform = transform * i.transform;
                i.dynamic |= dynamic;
                i
            }));
        self.point_clouds
            .extend(other.point_clouds.into_iter().map(|mut p| {
                p.transform = transform * p.transform;
                p.dynamic |= dynamic;
                p.light = p.light.map(|l| l + light0);
                p
            }));
        self.lights
            .extend(other.lights.into_iter().map(|l| l.transformed(transform)));
        let inst0 = self.instances.len() - other_instances;
        let cloud0 = self.point_clouds.len() - other_clouds;
        self.sequences
            .extend(other.sequences.into_iter().map(|mut s| {
                s.cloud += cloud0;
                s
            }));
        self.animations
            .extend(other.animations.into_iter().map(|mut a| {
                match &mut a.target {
                    crate::animation::AnimationTarget::Instances {
                        instances,
                        outer,
                        lights,
                        clouds,
                        ..
                    } => {
                        instances.iter_mut().for_each(|i| *i += inst0);
                        clouds.iter_mut().for_each(|(c, _)| *c += cloud0);
                        *outer = transform * *outer;
                        for (l, rest) in lights.iter_mut() {
                            *l += light0;
                            *rest = rest.transformed(transform);
                        }
                    }
                    crate::animation::AnimationTarget::Light {
                        light, rest, outer, ..
                    } => {
                        *light += light0;
                        // The light as appended: moved into this scene like the others.
                        if let Some(l) = self.lights.get(*light) {
                            *rest = l.clone();
                        }
                        *outer = transform * *outer;
                    }
                    crate::animation::AnimationTarget::Camera {
                        camera,
                        rest,
                        outer,
                        ..
                    } => {
                        *camera += camera0;
                        *rest = moved_camera(rest.clone());
                        *outer = transform * *outer;
                    }
                }
                a
            }));
        self.cameras
            .extend(other.cameras.into_iter().map(moved_camera));
    }

    /// Checks every index and count the renderer relies on. Loaders call this last.
    #[allow(clippy::collapsible_match)] // one arm per light kind reads better than match guards
    pub fn validate(&self) -> Result<()> {
        let bad = |msg: String| Err(SceneError::Invalid(msg));
        for (i, m) in self.meshes.iter().enumerate() {
            let n = m.positions.len();
            if m.indices.len() % 3 != 0 {
                return bad(format!(
                    "mesh {i} '{}': index count {} is not a multiple of 3",
                    m.name,
                    m.indices.len()
                ));
            }
            if m.normals.len() != n {
                return bad(format!(
                    "mesh {i} '{}': {} normals for {n} positions",
                    m.name,
                    m.normals.len()
                ));
            }
            if !m.uvs.is_empty() && m.uvs.len() != n {
                return bad(format!(
                    "mesh {i} '{}': {} UVs for {n} positions",
                    m.name,
                    m.uvs.len()
                ));
            }
            if let Some(&ix) = m.indices.iter().find(|&&ix| ix as usize >= n) {
                return bad(format!(
                    "mesh {i} '{}': index {ix} out of range ({n} vertices)",
                    m.name
                ));
            }
            if m.positions.iter().any(|p| !p.is_finite()) {
                return bad(format!("mesh {i} '{}': non-finite vertex position", m.name));
            }
            if m.material >= self.materials.len() {
                return bad(format!(
                    "mesh {i} '{}': material {} out of range",
                    m.name, m.material
                ));
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            for t in [m.base_color_texture, m.emissive_texture]
                .into_iter()
                .flatten()
            {
                if t >= self.textures.len() {
                    return bad(format!(
                        "material {i} '{}': texture {t} out of range",
                        m.name
                    ));
                }
            }
            for (what, values) in [
                ("base colour", &m.base_color[..]),
                ("emission", &m.emissive[..]),
            ] {
                if let Some(c) = values.iter().find(|c| !c.is_finite() || **c < 0.0) {
                    return bad(format!(
                        "material {i} '{}': {what} {values:?} holds {c}, not a finite value >= 0",
                        m.name
                    ));
                }
            }
            let brightest = m.emissive.iter().fold(0f32, |a, &b| a.max(b));
            if brightest > limits::MAX_RADIANCE {
                return bad(format!(
                    "material {i} '{}': emission {brightest:e} is more than {}, the largest \
                     radiance voxgi stores (half floats): scale the scene's light units down \
                     and the exposure up",
                    m.name,
                    limits::MAX_RADIANCE
                ));
            }
        }
        for (i, t) in self.textures.iter().enumerate() {
            if t.width == 0 || t.height == 0 || t.rgba8.len() != (t.width * t.height * 4) as usize {
                return bad(format!(
                    "texture {i} '{}': {}x{} with {} bytes",
                    t.name,
                    t.width,
                    t.height,
                    t.rgba8.len()
                ));
            }
        }
        for (i, inst) in self.instances.iter().enumerate() {
            if inst.mesh >= self.meshes.len() {
                return bad(format!(
                    "instance {i} '{}': mesh {} out of range",
                    inst.name, inst.mesh
                ));
            }
            if !inst.transform.is_finite() {
                return bad(format!(
                    "instance {i} '{}': non-finite transform",
                    inst.name
                ));
            }
            if inst.light.is_some_and(|l| l >= self.lights.len()) {
                return bad(format!("instance {i} '{}': light out of range", inst.name));
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            let ok = l.position.is_finite()
                && l.direction.is_finite()
                && (l.direction.length() - 1.0).abs() < 1e-3
                && l.intensity.is_finite()
                && l.intensity >= 0.0
                && l.color.iter().all(|c| c.is_finite() && *c >= 0.0);
            if !ok {
                return bad(format!(
                    "light {i} '{}': non-finite or negative values, or direction not unit length",
                    l.name
                ));
            }
            if let Err(e) = l.check_brightness() {
                return bad(format!("light {i} '{}': {e}", l.name));
            }
            match l.kind {
                LightKind::Spot {
                    inner_angle,
                    outer_angle,
                } => {
                    if !(0.0 <= inner_angle
                        && inner_angle <= outer_angle
                        && outer_angle <= std::f32::consts::FRAC_PI_2)
                    {
                        return bad(format!(
                            "light {i} '{}': spot angles must satisfy 0 <= inner <= outer <= 90 degrees",
                            l.name
                        ));
                    }
                }
                LightKind::Area { .. } => {
                    if !(l.area() > 0.0 && l.area().is_finite()) {
                        return bad(format!("light {i} '{}': area light has zero area", l.name));
                    }
                }
                _ => {}
            }
        }
        for (i, pc) in self.point_clouds.iter().enumerate() {
            let n = pc.positions.len();
            let ok_len = |len: usize| len == 0 || len == n;
            if pc.colors.len() != n
                || !ok_len(pc.normals.len())
                || !ok_len(pc.radii.len())
                || !ok_len(pc.regions.len())
                || !ok_len(pc.emission.len())
            {
                return bad(format!(
                    "point cloud {i} '{}': attribute counts differ from the {n} positions",
                    pc.name
                ));
            }
            if pc.light.is_some_and(|l| l >= self.lights.len()) {
                return bad(format!("point cloud {i} '{}': light out of range", pc.name));
            }
            if pc.positions.iter().any(|p| !p.is_finite()) {
                return bad(format!(
                    "point cloud {i} '{}': non-finite point position",
                    pc.name
                ));
            }
            if let Some(e) = pc
                .emission
                .iter()
                .flatten()
                .find(|e| !(e.is_finite() && **e >= 0.0 && **e <= limits::MAX_RADIANCE))
            {
                return bad(format!(
                    "point cloud {i} '{}': emission {e:e} is not a radiance from 0 to {}, the \
                     largest voxgi stores (half floats)",
                    pc.name,
                    limits::MAX_RADIANCE
                ));
            }
        }
        for (i, s) in self.sequences.iter().enumerate() {
            let Some(pc) = self.point_clouds.get(s.cloud) else {
                return bad(format!(
                    "point sequence {i}: cloud {} out of range",
                    s.cloud
                ));
            };
            if !pc.dynamic || pc.light.is_some() {
                return bad(format!(
                    "point sequence {i}: its cloud '{}' must be dynamic geometry (not static, \
                     not a light's surface)",
                    pc.name
                ));
            }
            if s.files.is_empty()
                || !(s.fps.is_finite() && s.fps > 0.0)
                || pc.positions.len() > s.capacity
                || self.sequences[..i].iter().any(|o| o.cloud == s.cloud)
            {
                return bad(format!(
                    "point sequence {i} of cloud '{}': no frames, an fps that is not > 0, more \
                     points than its capacity, or a second sequence on one cloud",
                    pc.name
                ));
            }
        }
        let b = self.bounds();
        if !b.is_empty() && !(b.max - b.min).is_finite() {
            let e = |v: Vec3| format!("({:e}, {:e}, {:e})", v.x, v.y, v.z);
            return bad(format!(
                "the geometry reaches from {} to {} m: its extent overflows single precision \
                 (check the file's units and transforms)",
                e(b.min),
                e(b.max)
            ));
        }
        self.checked_bulk()?;
        for (i, c) in self.cameras.iter().enumerate() {
            if !(c.position.is_finite()
                && c.forward.is_finite()
                && c.up.is_finite()
                && c.znear > 0.0)
            {
                return bad(format!(
                    "camera {i} '{}': non-finite values or znear <= 0",
                    c.name
                ));
            }
        }
        Ok(())
    }

    /// The camera every front end starts from: the scene's first camera, or else one in front
    /// of everything it draws at any time of its animations (`swept_bounds`; +Z side, slightly
    /// above), looking at their centre, far enough back to see the bounding sphere. The one
    /// rule: the renderer, the command line, the viewer and point preparation all use it.
    pub fn default_camera(&self) -> Camera {
        self.cameras
            .first()
            .cloned()
            .unwrap_or_else(|| Camera::viewing(self.swept_bounds()))
    }

    /// The bounds renderers place their volume (and the default camera) around: everything
    /// the scene draws at any time of its animations (`object_bounds`), but objects far
    /// outside the rest (`bulk_bounds`' rule).
    pub fn swept_bounds(&self) -> Aabb {
        self.bulk_bounds().0
    }

    /// Everything the scene draws at any time of its animations, strays included
    /// (`object_bounds`' union): what the camera's far plane must reach.
    pub fn drawn_bounds(&self) -> Aabb {
        self.object_bounds()
            .iter()
            .fold(Aabb::EMPTY, |acc, (_, b)| acc.union(b))
    }

    /// Each drawn object's box (mesh instances, then point clouds) at any time of its
    /// animations: where it never moves, its vertices' box; where an animation moves it, the
    /// box around its mesh's box at every pose it passes through (sampled at `SWEEP_SAMPLES`
    /// + 1 times over the longest animation). With each object's name.
    pub fn object_bounds(&self) -> Vec<(String, Aabb)> {
        let animated = self.animated_instances();
        let mut out: Vec<(String, Aabb)> = Vec::new();
        let mut sweep: Vec<(usize, usize, Aabb)> = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            let Some(mesh) = self.meshes.get(inst.mesh) else {
                continue;
            };
            let mut b = Aabb::EMPTY;
            if animated.binary_search(&i).is_ok() {
                for &p in &mesh.positions {
                    b.grow(p);
                }
                sweep.push((out.len(), i, b));
                b = Aabb::EMPTY;
            } else {
                for &p in &mesh.positions {
                    b.grow(inst.transform.transform_point3(p));
                }
            }
            out.push((inst.name.clone(), b));
        }
        let animated_clouds = self.animated_clouds();
        let mut cloud_sweep: Vec<(usize, usize, Aabb)> = Vec::new();
        for (c, pc) in self.point_clouds.iter().enumerate() {
            // A sequence's cloud: every frame's points, whichever it shows now.
            let sequence = self.sequences.iter().find(|s| s.cloud == c);
            let local = || match sequence {
                Some(s) => s.bounds,
                None => pc.positions.iter().fold(Aabb::EMPTY, |mut b, &p| {
                    b.grow(p);
                    b
                }),
            };
            if animated_clouds.binary_search(&c).is_ok() {
                cloud_sweep.push((out.len(), c, local()));
                out.push((pc.name.clone(), Aabb::EMPTY));
            } else if sequence.is_some() {
                out.push((pc.name.clone(), local().transformed(pc.transform)));
            } else {
                let mut b = Aabb::EMPTY;
                for &p in &pc.positions {
                    b.grow(pc.transform.transform_point3(p));
                }
                out.push((pc.name.clone(), b));
            }
        }
        if sweep.is_empty() && cloud_sweep.is_empty() {
            return out;
        }
        let mut probe = self.without_geometry();
        let duration = self
            .animations
            .iter()
            .map(animation::Animation::duration)
            .fold(0.0f32, f32::max);
        for k in 0..=SWEEP_SAMPLES {
            probe.set_time(duration * k as f32 / SWEEP_SAMPLES as f32);
            for (o, c, local) in &cloud_sweep {
                out[*o].1 = out[*o]
                    .1
                    .union(&local.transformed(probe.point_clouds[*c].transform));
            }
            for (o, i, local) in &sweep {
                out[*o].1 = out[*o]
                    .1
                    .union(&local.transformed(probe.instances[*i].transform));
            }
        }
        out
    }

    /// `bulk_bounds`, refused where its largest side exceeds `limits::MAX_EXTENT`.
    pub fn checked_bulk(&self) -> Result<(Aabb, Vec<String>)> {
        let (b, left_out) = self.bulk_bounds();
        let side = if b.is_empty() {
            0.0
        } else {
            (b.max - b.min).max_element()
        };
        if side > limits::MAX_EXTENT {
            return Err(SceneError::Invalid(format!(
                "the scene spans {side:e} m, more than the {:e} m voxgi works with: check its \
                 units and transforms",
                limits::MAX_EXTENT
            )));
        }
        Ok((b, left_out))
    }

    /// The box around the scene's objects (`object_bounds`) but those far outside the rest,
    /// and the names of those left out. The rule: while the object farthest from the box of
    /// the others lies more than `FAR_OUTSIDE` times that box's largest side away from it, it
    /// is left out, up to a quarter of the objects, unless it is `FAR_OUTSIDE` times larger
    /// than that box. So a stray object kilometres (or 1e30 m) from a room no longer spreads
    /// the room's voxels over the distance, and a scene whose objects are all alike far apart
    /// keeps them all.
    pub fn bulk_bounds(&self) -> (Aabb, Vec<String>) {
        const FAR_OUTSIDE: f32 = 10.0;
        let mut objects: Vec<(String, Aabb)> = self
            .object_bounds()
            .into_iter()
            .filter(|(_, b)| !b.is_empty())
            .collect();
        let mut left_out = Vec::new();
        let most = objects.len() / 4;
        while left_out.len() < most && objects.len() > 1 {
            // The box of all objects but i, from the unions before and after it.
            let n = objects.len();
            let mut before = vec![Aabb::EMPTY; n + 1];
            let mut after = vec![Aabb::EMPTY; n + 1];
            for i in 0..n {
                before[i + 1] = before[i].union(&objects[i].1);
                after[n - 1 - i] = after[n - i].union(&objects[n - 1 - i].1);
            }
            let gap = |i: usize| {
                let others = before[i].union(&after[i + 1]);
                let b = &objects[i].1;
                let side = (others.max - others.min)
                    .max_element()
                    .max(f32::MIN_POSITIVE);
                // An object far larger than the rest is the scene, not a stray.
                if (b.max - b.min).max_element() > FAR_OUTSIDE * side {
                    return 0.0;
                }
                let d = (others.min - b.max).max(b.min - others.max).max(Vec3::ZERO);
                d.length() / side
            };
            let (far, ratio) = (0..n)
                .map(|i| (i, gap(i)))
                .fold((0, 0.0f32), |a, b| if b.1 > a.1 { b } else { a });
            if ratio.is_nan() || ratio <= FAR_OUTSIDE {
                break;
            }
            left_out.push(objects.remove(far).0);
        }
        let bulk = objects.iter().fold(Aabb::EMPTY, |acc, (_, b)| acc.union(b));
        (bulk, left_out)
    }

    /// What the scene holds that can show nothing, one line each: a mesh instance whose
    /// triangles have no area where it is placed (a zero scale, a degenerate mesh) and a point
    /// cloud of several points all at one place. Front ends warn with these.
    pub fn degenerate(&self) -> Vec<String> {
        let mut out = Vec::new();
        for inst in &self.instances {
            let Some(m) = self.meshes.get(inst.mesh) else {
                continue;
            };
            if m.indices.is_empty() {
                continue;
            }
            // In single precision, as the GPU computes: a triangle of 1e-30 m sides has none.
            let area: f32 = m
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let [a, b, c] = [t[0], t[1], t[2]]
                        .map(|i| inst.transform.transform_point3(m.positions[i as usize]));
                    (b - a).cross(c - a).length() * 0.5
                })
                .sum();
            // Not when the area overflowed (NaN: edges past 1e19 m, refused elsewhere).
            if area == 0.0 {
                out.push(format!(
                    "'{}': its {} triangles have no area where it is placed (a zero scale or a \
                     degenerate mesh): it shows nothing",
                    inst.name,
                    m.indices.len() / 3
                ));
            }
        }
        for pc in &self.point_clouds {
            let mut b = Aabb::EMPTY;
            for &p in &pc.positions {
                b.grow(pc.transform.transform_point3(p));
            }
            if pc.positions.len() > 1 && !b.is_empty() && b.max == b.min {
                out.push(format!(
                    "'{}': all its {} points lie at one place: it shows at most a dot",
                    pc.name,
                    pc.positions.len()
                ));
            }
        }
        out
    }

    /// What `set_time` touches and nothing else: the instances, the lights, the point clouds'
    /// transforms (no points), the animations. Cheap to sample at many times.
    pub fn without_geometry(&self) -> Scene {
        Scene {
            instances: self.instances.clone(),
            lights: self.lights.clone(),
            point_clouds: self
                .point_clouds
                .iter()
                .map(|pc| PointCloud {
                    name: pc.name.clone(),
                    transform: pc.transform,
                    dynamic: pc.dynamic,
                    light: pc.light,
                    ..Default::default()
                })
                .collect(),
            animations: self.animations.clone(),
            cameras: self.cameras.clone(),
            ..Default::default()
        }
    }

    /// How long the scene plays before it repeats or holds: its longest animation or point
    /// sequence, seconds (0 for a still scene).
    pub fn duration(&self) -> f32 {
        let a = self.animations.iter().map(animation::Animation::duration);
        let s = self.sequences.iter().map(sequence::PointSequence::duration);
        a.chain(s).fold(0.0f32, f32::max)
    }

    /// The points cloud `c` may hold at any time: its own, or the largest frame of the point
    /// sequence that plays in it. Renderers keep room for them.
    pub fn cloud_capacity(&self, c: usize) -> usize {
        let n = self.point_clouds.get(c).map_or(0, |pc| pc.positions.len());
        self.sequences
            .iter()
            .filter(|s| s.cloud == c)
            .fold(n, |n, s| n.max(s.capacity))
    }

    /// Loads each point sequence's frame at time `t` (seconds) into its cloud, where it is
    /// not the frame the cloud holds: the file's points replace the cloud's (its placement
    /// stays; `set_time` moves it). Call it with `set_time` where a scene must show time `t`
    /// fully (a fresh renderer, the path tracer); a renderer plays sequences itself
    /// (`Renderer::set_time`). An error names the file.
    pub fn load_frames_at(&mut self, t: f32) -> Result<()> {
        for s in &mut self.sequences {
            let frame = s.frame_at(t);
            if frame == s.shown {
                continue;
            }
            let points = s.load(frame)?;
            let pc = &mut self.point_clouds[s.cloud];
            *pc = PointCloud {
                name: std::mem::take(&mut pc.name),
                transform: pc.transform,
                dynamic: pc.dynamic,
                light: pc.light,
                ..points
            };
            s.shown = frame;
        }
        Ok(())
    }

    /// The point clouds some animation moves, sorted, each once.
    pub fn animated_clouds(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .animations
            .iter()
            .flat_map(|a| match &a.target {
                animation::AnimationTarget::Instances { clouds, .. } => {
                    clouds.iter().map(|(c, _)| *c).collect()
                }
                animation::AnimationTarget::Light { .. }
                | animation::AnimationTarget::Camera { .. } => Vec::new(),
            })
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// The instances some animation moves, sorted, each once.
    pub fn animated_instances(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .animations
            .iter()
            .flat_map(|a| match &a.target {
                animation::AnimationTarget::Instances { instances, .. } => instances.clone(),
                animation::AnimationTarget::Light { .. }
                | animation::AnimationTarget::Camera { .. } => Vec::new(),
            })
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// A sun for scenes that have no light at all, so they render as something other than black:
    /// from above and behind the default camera's right shoulder.
    pub fn default_sun() -> Light {
        Light {
            name: "default sun".into(),
            kind: LightKind::Directional,
            color: [1.0, 0.98, 0.95],
            intensity: 3.0,
            position: Vec3::ZERO,
            direction: Vec3::new(-0.4, -1.0, -0.3).normalize(),
            range: None,
            cast_shadows: true,
        }
    }
}

/// `Scene::set_light` on the scene's lights and instances (borrowed apart, for `set_time`).
pub(crate) fn set_light(
    lights: &mut [Light],
    instances: &mut [Instance],
    clouds: &mut [PointCloud],
    index: usize,
    light: Light,
) {
    let Some(old) = lights.get(index) else {
        return;
    };
    if let Some(m) = old.emitter_move(&light) {
        for inst in instances.iter_mut().filter(|i| i.light == Some(index)) {
            inst.transform = m * inst.transform;
        }
        for pc in clouds.iter_mut().filter(|pc| pc.light == Some(index)) {
            pc.transform = m * pc.transform;
        }
    }
    lights[index] = light;
}
