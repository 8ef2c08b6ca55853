//! The scene model every loader produces and the renderer consumes.
//!
//! Units are metres, right-handed, +Y up (glTF's convention). Colours are linear Rec.709; loaders
//! decode sRGB-encoded colour values (vertex colours, `.cloud` albedo) before they land here.
//! Textures stay sRGB-encoded RGBA8 because the GPU decodes them when sampling.

use glam::{Mat4, Vec2, Vec3};

/// A whole scene: geometry, materials, lights, cameras.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub instances: Vec<Instance>,
    pub lights: Vec<Light>,
    pub point_clouds: Vec<PointCloud>,
    /// Cameras found in the file; the first one is the default view.
    pub cameras: Vec<Camera>,
    /// What moves over time (`Scene::set_time` applies them).
    pub animations: Vec<crate::animation::Animation>,
    /// Point clouds whose points come from a file per frame (`Scene::load_frames_at` loads
    /// them; `Scene::set_time` does not, as it touches no files).
    pub sequences: Vec<crate::sequence::PointSequence>,
}

/// One triangle list with one material (a glTF primitive, an OBJ group).
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Same length as `positions`; loaders compute area-weighted normals when the file has none.
    pub normals: Vec<Vec3>,
    /// Same length as `positions`, or empty when the file has no texture coordinates.
    pub uvs: Vec<Vec2>,
    /// Triangle list, three indices per triangle, each `< positions.len()`.
    pub indices: Vec<u32>,
    /// Index into `Scene::materials`.
    pub material: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    Opaque,
    /// Texels with alpha below the cutoff are discarded.
    Mask(f32),
    /// Rendered as opaque for now; the opacity is kept for voxelization.
    Blend,
}

/// Lambert diffuse + GGX specular (metallic-roughness), glTF's core material model.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Linear RGBA; multiplies the texture.
    pub base_color: [f32; 4],
    /// Index into `Scene::textures` (sRGB-encoded colour).
    pub base_color_texture: Option<usize>,
    /// Emitted radiance in W/(m² sr), linear RGB, with any strength factor already applied.
    pub emissive: [f32; 3],
    /// Index into `Scene::textures` (sRGB-encoded colour); multiplies `emissive`.
    pub emissive_texture: Option<usize>,
    pub roughness: f32,
    pub metallic: f32,
    /// Scales the specular reflectance of dielectrics (F0 = 0.04 x specular), as glTF's
    /// KHR_materials_specular does: 1 is glTF's default, 0 a pure Lambertian surface.
    pub specular: f32,
    pub alpha_mode: AlphaMode,
    pub double_sided: bool,
}

impl Default for Material {
    fn default() -> Self {
        // glTF's default material is white; 0.8 keeps an untextured scene from looking
        // blown out and matches common DCC defaults.
        Material {
            name: "default".into(),
            base_color: [0.8, 0.8, 0.8, 1.0],
            base_color_texture: None,
            emissive: [0.0; 3],
            emissive_texture: None,
            roughness: 1.0,
            metallic: 0.0,
            specular: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
        }
    }
}

impl Material {
    /// A pure Lambertian surface (no specular lobe), like the measured Cornell box walls.
    pub fn diffuse(name: &str, rgb: [f32; 3]) -> Self {
        Material {
            name: name.into(),
            base_color: [rgb[0], rgb[1], rgb[2], 1.0],
            specular: 0.0,
            ..Default::default()
        }
    }

    pub fn is_emissive(&self) -> bool {
        self.emissive.iter().any(|&e| e > 0.0)
    }
}

/// An RGBA8 image, sRGB-encoded colour, rows top to bottom (glTF's UV origin is the top-left).
#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba8: Vec<u8>,
}

/// A placement of a mesh in the world.
#[derive(Clone, Debug)]
pub struct Instance {
    pub name: String,
    /// Index into `Scene::meshes`.
    pub mesh: usize,
    /// Object to world.
    pub transform: Mat4,
    /// Dynamic instances may move every frame; static ones are voxelized once.
    pub dynamic: bool,
    /// Set when this geometry is the visible surface of area light `Scene::lights[i]`.
    pub light: Option<usize>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AreaShape {
    /// A parallelogram: corners at `position ± u ± v` (u, v are half-edge vectors).
    Rect {
        u: Vec3,
        v: Vec3,
    },
    Disc {
        radius: f32,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// `intensity` is irradiance in W/m² on a surface facing the light.
    Directional,
    /// `intensity` is radiant intensity in W/sr.
    Point,
    /// `intensity` in W/sr on the axis; full inside `inner_angle`, zero outside `outer_angle`
    /// (half-angles in radians from the axis).
    Spot { inner_angle: f32, outer_angle: f32 },
    /// `intensity` is emitted radiance in W/(m² sr), one-sided, towards `direction`.
    Area { shape: AreaShape },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// Linear RGB, multiplied by `intensity`.
    pub color: [f32; 3],
    pub intensity: f32,
    /// World position (ignored for directional lights).
    pub position: Vec3,
    /// Unit vector: where the light points (the direction photons travel). For area lights, the
    /// emitting side's normal.
    pub direction: Vec3,
    /// Range of influence in metres for point and spot lights (glTF `range`); `None` is infinite.
    pub range: Option<f32>,
    pub cast_shadows: bool,
}

impl Light {
    /// An area light's frame: object to world for the emitter `Scene::add_area_light` builds
    /// around it, from its edge vectors (or its radius and its normal's orthonormal pair, as the
    /// disc's vertices are placed), its normal and its position. `None` for other kinds.
    pub fn emitter_frame(&self) -> Option<Mat4> {
        let LightKind::Area { shape } = self.kind else {
            return None;
        };
        let n = self.direction.normalize();
        let (a, b) = match shape {
            AreaShape::Rect { u, v } => (u, v),
            AreaShape::Disc { radius } => {
                let (t, b) = n.any_orthonormal_pair();
                (t * radius, b * radius)
            }
        };
        Some(Mat4::from_cols(
            a.extend(0.0),
            b.extend(0.0),
            n.extend(0.0),
            self.position.extend(1.0),
        ))
    }

    /// How this area light's visible surface moves when the light becomes `to`: from this
    /// frame to the new one (`emitter_frame`); `None` when it stays (no move, not an area light).
    pub fn emitter_move(&self, to: &Light) -> Option<Mat4> {
        match (self.emitter_frame(), to.emitter_frame()) {
            (Some(from), Some(to)) if from != to => Some(to * from.inverse()),
            _ => None,
        }
    }

    /// Refuses a light brighter than voxgi can show: an area light's radiance above what half
    /// floats hold (`limits::MAX_RADIANCE`), another's intensity × colour above
    /// `limits::MAX_LIGHT`.
    pub fn check_brightness(&self) -> std::result::Result<(), String> {
        let value = self.intensity * self.color.iter().fold(0f32, |a, &b| a.max(b));
        let (max, shown, what) = match self.kind {
            LightKind::Area { .. } => (
                crate::limits::MAX_RADIANCE,
                "65504",
                "the largest radiance voxgi stores (half floats)",
            ),
            _ => (
                crate::limits::MAX_LIGHT,
                "1e10",
                "the brightest light voxgi takes (it would only saturate the image, and \
                 overflow into NaN further on)",
            ),
        };
        if value > max {
            return Err(format!(
                "intensity × colour {value:e} is more than {shown}, {what}: scale the scene's \
                 light units down and the exposure up"
            ));
        }
        Ok(())
    }

    /// The light moved by `m` (an affine transform): its position, its direction (an area
    /// light's as a normal) and an area light's extent.
    pub fn transformed(&self, m: Mat4) -> Light {
        let mut l = self.clone();
        let linear = glam::Mat3::from_mat4(m);
        let normal_m = linear.inverse().transpose();
        l.position = m.transform_point3(l.position);
        let old_dir = l.direction;
        l.direction = match l.kind {
            LightKind::Area { .. } => (normal_m * l.direction).normalize_or(l.direction),
            _ => (linear * l.direction).normalize_or(l.direction),
        };
        if let LightKind::Area { shape } = &mut l.kind {
            match shape {
                AreaShape::Rect { u, v } => {
                    *u = linear * *u;
                    *v = linear * *v;
                }
                AreaShape::Disc { radius } => {
                    let (t, b) = old_dir.any_orthonormal_pair();
                    let scale = (linear * t).cross(linear * b).length().sqrt();
                    *radius *= scale;
                }
            }
        }
        l
    }

    /// `color * intensity`.
    pub fn radiometric(&self) -> Vec3 {
        Vec3::from(self.color) * self.intensity
    }

    /// Area of an area light's emitting surface in m², 0 for the other kinds.
    pub fn area(&self) -> f32 {
        match self.kind {
            LightKind::Area {
                shape: AreaShape::Rect { u, v },
            } => 4.0 * u.cross(v).length(),
            LightKind::Area {
                shape: AreaShape::Disc { radius },
            } => std::f32::consts::PI * radius * radius,
            _ => 0.0,
        }
    }
}

/// A set of surface samples: positions with colour, optionally normals, radii and emission.
#[derive(Clone, Debug, Default)]
pub struct PointCloud {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Linear albedo per point (same length as `positions`).
    pub colors: Vec<[f32; 3]>,
    /// Unit normals, empty when the file has none.
    pub normals: Vec<Vec3>,
    /// Radius of each sample's disc in metres, empty when the file has none.
    pub radii: Vec<f32>,
    /// Edge of each sample's cubic region of influence in the voxels (seed 004 §4.3.4), in
    /// local units; empty until `pointcloud::estimate_regions` fills it.
    pub regions: Vec<f32>,
    /// Emitted radiance per point, empty when the points do not emit.
    pub emission: Vec<[f32; 3]>,
    pub transform: Mat4,
    pub dynamic: bool,
    /// Set when these points are the visible surface of area light `Scene::lights[i]`
    /// (`io::emitters::promote_emissive_points`): they are drawn, but neither voxelized nor
    /// shadowing their own light, as an area light's mesh.
    pub light: Option<usize>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in radians.
    Perspective { yfov: f32 },
    /// Half-extents of the view volume.
    Orthographic { xmag: f32, ymag: f32 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub name: String,
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up vector, orthogonal to `forward`.
    pub up: Vec3,
    pub projection: Projection,
    pub znear: f32,
    /// `None`: chosen from the scene bounds.
    pub zfar: Option<f32>,
    /// Width / height from the file, if it states one; renders use the image's aspect.
    pub aspect: Option<f32>,
}

impl Camera {
    /// A camera in front of `bounds` (+Z side, slightly above), looking at their centre, far
    /// enough back to see their bounding sphere (a unit sphere at the origin when empty).
    pub fn viewing(bounds: Aabb) -> Camera {
        let b = bounds;
        let (center, radius) = if b.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (b.center(), (b.size().length() * 0.5).max(1e-3))
        };
        let yfov = 45f32;
        let dist = radius / (yfov.to_radians() * 0.5).sin();
        let dir = Vec3::new(0.0, 0.35, 1.0).normalize();
        let mut cam = Camera::look_at(center + dir * dist, center, yfov);
        cam.name = "default".into();
        cam.znear = (dist - radius).max(radius * 1e-3);
        cam
    }

    pub fn look_at(position: Vec3, target: Vec3, yfov_degrees: f32) -> Self {
        let forward = (target - position).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        Camera {
            name: "camera".into(),
            position,
            forward,
            up: right.cross(forward).normalize(),
            projection: Projection::Perspective {
                yfov: yfov_degrees.to_radians(),
            },
            znear: 0.01,
            zfar: None,
            aspect: None,
        }
    }
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box around the corners of this one moved by `m`.
    pub fn transformed(&self, m: glam::Mat4) -> Aabb {
        let mut out = Aabb::EMPTY;
        if self.is_empty() {
            return out;
        }
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out.grow(m.transform_point3(p));
        }
        out
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }
}
