//! The scene on the GPU: vertices, indices, per-instance draws, materials, textures, lights and
//! point-cloud surfels.
//! Every pass reads geometry from these buffers (vertex pulling), so the rasterizer, the
//! voxelizer and the path tracer see exactly the same data.

use crate::{Error, RendererOptions, Result};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use voxgi_scene::{Aabb, AlphaMode, AreaShape, Light, LightKind, Scene, pointcloud};
use wgpu::util::DeviceExt;

/// Mirrors `Vertex` in shaders/shared/scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    /// Object-space position, metres.
    pub position: [f32; 3],
    /// Texture coordinate u.
    pub u: f32,
    /// Object-space normal (transformed by the draw's `normal_matrix`).
    pub normal: [f32; 3],
    /// Texture coordinate v.
    pub v: f32,
}

/// Mirrors `Draw` in shaders/shared/scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuDraw {
    /// Object to world transform, column-major.
    pub model: [[f32; 4]; 4],
    /// Inverse transpose of `model`, for normals (identity when `model` is singular).
    pub normal_matrix: [[f32; 4]; 4],
    /// Index into the materials buffer.
    pub material: u32,
    /// Index of the area light this geometry shows, or `NO_INDEX`.
    pub light: u32,
    /// Padding to a multiple of 16 bytes; zero.
    pub _pad: [u32; 2],
}

/// One point-cloud sample (a surfel), in world space. Mirrors `Point` in
/// shaders/shared/scene.wgsl: 32 bytes, std430-compatible (one vec3 + f32, then four u32).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuPoint {
    /// World-space position of the disc's centre, metres.
    pub position: [f32; 3],
    /// Disc radius in metres.
    pub radius: f32,
    /// Unit normal, octahedral-encoded as two snorm16 (x low, y high); `POINT_NO_NORMAL` when the
    /// point has none (the disc then faces the viewer).
    pub normal: u32,
    /// Linear albedo as f16: red (low half) and green (high half).
    pub albedo_rg: u32,
    /// Linear albedo blue (low half) and emitted radiance red (high half), f16.
    pub albedo_b_emission_r: u32,
    /// Emitted radiance green (low half) and blue (high half), f16, W/(m² sr).
    pub emission_gb: u32,
}

const _: () = assert!(size_of::<GpuPoint>() == 32);

/// `GpuPoint::normal` of a point without a usable normal (snorm16 -32768 twice, a value that
/// octahedral encoding never produces).
pub const POINT_NO_NORMAL: u32 = 0x8000_8000;

impl GpuPoint {
    /// A slot a cloud keeps for more points than it has now: no disc (nothing draws it), no
    /// normal, no colour; `GpuScene::park_spare` moves it outside the voxels.
    pub const SPARE: GpuPoint = GpuPoint {
        position: [0.0; 3],
        radius: 0.0,
        normal: POINT_NO_NORMAL,
        albedo_rg: 0,
        albedo_b_emission_r: 0,
        emission_gb: 0,
    };

    /// Packs one surfel: albedo and emission (linear, W/(m² sr)) as f16, the normal
    /// octahedral-encoded (`POINT_NO_NORMAL` for a zero or non-finite normal).
    pub fn new(
        position: Vec3,
        radius: f32,
        normal: Vec3,
        albedo: [f32; 3],
        emission: [f32; 3],
    ) -> Self {
        let h = |v: f32| half_bits(v) as u32;
        GpuPoint {
            position: position.to_array(),
            radius,
            normal: encode_octahedral(normal),
            albedo_rg: h(albedo[0]) | (h(albedo[1]) << 16),
            albedo_b_emission_r: h(albedo[2]) | (h(emission[0]) << 16),
            emission_gb: h(emission[1]) | (h(emission[2]) << 16),
        }
    }
}

/// Octahedral encoding of a direction into two snorm16 (WGSL `unpack2x16snorm` decodes it);
/// zero or non-finite vectors give `POINT_NO_NORMAL`.
pub fn encode_octahedral(n: Vec3) -> u32 {
    let l1 = n.x.abs() + n.y.abs() + n.z.abs();
    if !n.is_finite() || l1 < 1e-12 {
        return POINT_NO_NORMAL;
    }
    let p = n / l1;
    let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
    let (x, y) = if p.z >= 0.0 {
        (p.x, p.y)
    } else {
        ((1.0 - p.y.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.y))
    };
    let snorm = |v: f32| ((v.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    snorm(x) | (snorm(y) << 16)
}

/// The unit normal `encode_octahedral` encoded, as `point_normal` in shaders/shared/surfel.wgsl
/// decodes it; zero for `POINT_NO_NORMAL`.
pub fn decode_octahedral(v: u32) -> Vec3 {
    if v == POINT_NO_NORMAL {
        return Vec3::ZERO;
    }
    let snorm = |b: u32| ((b as u16 as i16) as f32 / 32767.0).max(-1.0);
    let (x, y) = (snorm(v & 0xffff), snorm(v >> 16));
    let mut n = Vec3::new(x, y, 1.0 - x.abs() - y.abs());
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    n.normalize_or_zero()
}

impl GpuPoint {
    /// The disc's unit normal (zero when it has none).
    pub fn normal(&self) -> Vec3 {
        decode_octahedral(self.normal)
    }

    /// Linear albedo.
    pub fn albedo(&self) -> [f32; 3] {
        [
            low_half(self.albedo_rg),
            low_half(self.albedo_rg >> 16),
            low_half(self.albedo_b_emission_r),
        ]
    }

    /// Emitted radiance, W/(m² sr).
    pub fn emission(&self) -> [f32; 3] {
        [
            low_half(self.albedo_b_emission_r >> 16),
            low_half(self.emission_gb),
            low_half(self.emission_gb >> 16),
        ]
    }
}

/// The f16 in the low half of `bits`, as f32.
fn low_half(bits: u32) -> f32 {
    half::f16::from_bits(bits as u16).to_f32()
}

/// IEEE half-precision bits of `v` (round to nearest even), clamped to the finite range; NaN and
/// negative values become 0 (albedo and radiance are never negative).
pub fn half_bits(v: f32) -> u16 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    half::f16::from_f32(v.min(65504.0)).to_bits()
}

/// Mirrors `Material` in shaders/shared/scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Linear RGBA base colour; multiplies the base texture, alpha is tested against
    /// `alpha_cutoff`.
    pub base_color: [f32; 4],
    /// Emitted radiance, W/(m² sr), linear RGB; multiplies the emissive texture.
    pub emissive: [f32; 3],
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// Scales the dielectric F0 of 0.04 (KHR_materials_specular); 0 makes a pure Lambertian (>= 0).
    pub specular: f32,
    /// Layer of the base-colour texture in the texture array, -1 for none.
    pub base_texture: i32,
    /// Layer of the emissive texture in the texture array, -1 for none.
    pub emissive_texture: i32,
    /// Texels with alpha below this are cut out; 0 for opaque and blended materials.
    pub alpha_cutoff: f32,
    /// 1 for a double-sided material, else 0 (every surface is drawn without culling regardless).
    pub double_sided: u32,
    /// Padding to a multiple of 16 bytes; zero.
    pub _pad: [u32; 2],
}

/// Mirrors `Light` in shaders/shared/scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    /// World-space position, metres (the centre for area lights; unused for directional lights).
    pub position: [f32; 3],
    /// The light type: one of the `LIGHT_*` constants.
    pub kind: u32,
    /// Unit direction photons travel; for area lights the emitting side's normal.
    pub direction: [f32; 3],
    /// Range of influence of point and spot lights, metres; 0 for unlimited.
    pub range: f32,
    /// Emitted radiometric quantity, linear RGB: W/m² (directional), W/sr (point, spot), W/(m² sr)
    /// (area).
    pub radiance: [f32; 3],
    /// Emitting area of an area light, m² (0 for other lights).
    pub area: f32,
    /// Rect: half-edge vector along u, metres. Disc: a unit tangent scaled by the radius.
    pub axis_u: [f32; 3],
    /// Cosine of a spot light's inner cone half-angle (full intensity inside).
    pub cos_inner: f32,
    /// Rect: half-edge vector along v, metres. Disc: the second tangent scaled by the radius.
    pub axis_v: [f32; 3],
    /// Cosine of a spot light's outer cone half-angle (no light outside).
    pub cos_outer: f32,
    /// Index of the light's first shadow view in the shadow atlas.
    pub shadow_first: u32,
    /// Number of shadow views: 0 (no shadows), 1, or 6 for a cube.
    pub shadow_count: u32,
    /// Radius of a disc with the light's area, metres: sets the penumbra size.
    pub size: f32,
    /// Index of the light's first sample view (`SAMPLE_POINTS` cubes of six faces, for area
    /// shadows sampled over frames), or `NO_INDEX`.
    pub sample_first: u32,
}

/// `GpuLight::kind` of a directional light (a sun).
pub const LIGHT_DIRECTIONAL: u32 = 0;
/// `GpuLight::kind` of a point light.
pub const LIGHT_POINT: u32 = 1;
/// `GpuLight::kind` of a spot light.
pub const LIGHT_SPOT: u32 = 2;
/// `GpuLight::kind` of a rectangular area light.
pub const LIGHT_RECT: u32 = 3;
/// `GpuLight::kind` of a disc area light.
pub const LIGHT_DISC: u32 = 4;
/// "None" for indices into GPU buffers (`GpuDraw::light` of geometry that is no emitter).
pub const NO_INDEX: u32 = u32::MAX;
/// Area lights whose visibility the gather can cone-trace (one channel each). Twin of
/// `CONE_SHADOW_LIGHTS` in shaders/shared/scene.wgsl.
pub const CONE_SHADOW_LIGHTS: usize = 4;

impl GpuLight {
    /// A rectangle or disc emitter.
    pub fn is_area(&self) -> bool {
        self.kind == LIGHT_RECT || self.kind == LIGHT_DISC
    }
}

/// One indexed draw: a mesh instance.
#[derive(Clone, Debug)]
pub struct DrawCall {
    /// The mesh's range in the shared index buffer.
    pub indices: std::ops::Range<u32>,
    /// Offset of the mesh's first vertex in the shared vertex buffer.
    pub base_vertex: i32,
    /// Index into the draws buffer (passed as the instance index).
    pub draw: u32,
    /// The area light this geometry shows; it does not shadow its own light.
    pub light: Option<usize>,
    /// The instance may move (`Instance::dynamic`): it is voxelized every frame it moved,
    /// apart from the static geometry, which is voxelized once.
    pub dynamic: bool,
    /// Per triangle, its longest edge in metres as the instance is placed when the scene is
    /// uploaded (rigid motion keeps it): how many voxel columns it can cover
    /// (`fragments::triangle_table`). Empty for an area light's surface, which is not voxelized.
    pub edges: Vec<f32>,
}

/// The scene's GPU buffers and textures, shared read-only by every pass, and the draw calls
/// that rasterize its instances.
pub struct GpuScene {
    /// All meshes' vertices (`GpuVertex`), in object space, meshes one after another.
    pub vertices: wgpu::Buffer,
    /// All meshes' triangle indices (u32, relative to each mesh's first vertex); index and storage
    /// buffer.
    pub indices: wgpu::Buffer,
    /// One `GpuDraw` per drawn instance.
    pub draws: wgpu::Buffer,
    /// Per draw, the world box its mesh fills where it is now: two `vec4<f32>`, the lowest
    /// corner then the highest (w unused). Voxelize skips a draw's triangles outside the
    /// region it voxelizes without reading them.
    pub draw_bounds: wgpu::Buffer,
    /// Per draw, its mesh's box in object space, for `draw_bounds` when it moves.
    mesh_bounds: Vec<Aabb>,
    /// Per draw, its model matrix in the previous frame (column-major mat4): the G-buffer's
    /// motion vectors. Brought up to date by `advance_motion`.
    pub prev_models: wgpu::Buffer,
    /// What `prev_models` holds now.
    prev_written: Vec<[[f32; 4]; 4]>,
    /// The model matrices the last frame drew with.
    last_models: Vec<[[f32; 4]; 4]>,
    /// One `GpuMaterial` per scene material.
    pub materials: wgpu::Buffer,
    /// One `GpuLight` per scene light; its shadow fields are written when the shadow views are
    /// planned.
    pub lights: wgpu::Buffer,
    /// All point clouds' surfels (`GpuPoint`), in world space: first the static geometry's,
    /// then the dynamic geometry's, then the area lights' surfaces (`gpu_cloud_order`). A
    /// dynamic cloud that moves is written anew where it is (`set_cloud`).
    pub points: wgpu::Buffer,
    /// One f32 per point (shadow pass only): how far the point's neighbours stray from its
    /// tangent plane, in metres (`pointcloud::surface_spread`); shadow maps push the surfel
    /// that far away from the light so noisy scans do not shadow themselves.
    pub point_spread: wgpu::Buffer,
    /// One f32 per point (splat pass only): the edge of its cubic region of influence in the
    /// voxels, in metres (`pointcloud::estimate_regions`; 0 for a point alone).
    pub point_regions: wgpu::Buffer,
    /// Number of points in `points`.
    pub point_count: u32,
    /// Some material has a metallic part: the shadow maps keep the surfaces' specular
    /// materials for the injection (`lighting/shadow.wgsl`).
    pub metals: bool,
    /// The first `geometry_points` of `points` are geometry: voxelized and shadowing every
    /// light. The rest show area lights.
    pub geometry_points: u32,
    /// The first `static_points` of the geometry's points never move (voxelized once); the
    /// rest, up to `geometry_points`, are dynamic clouds' (voxelized with each update).
    pub static_points: u32,
    /// Each point cloud's range of `points`, by its index in the scene.
    pub cloud_ranges: Vec<std::ops::Range<u32>>,
    /// With dynamic clouds, one vec4 per point: where it was drawn at the last frame less
    /// where it is (the motion vectors' share of the points); one element without.
    pub point_motion: wgpu::Buffer,
    /// The surface spread in their own units (`pointcloud::surface_spread`) of the clouds that
    /// may move (dynamic ones, area lights' surfaces), by cloud index (empty for the others),
    /// for writing them again where they move.
    local_spread: Vec<Vec<f32>>,
    /// The points showing each area light: a range of `points` and the light's index. They
    /// are drawn and shadow the other lights, but not their own.
    pub emitter_points: Vec<(std::ops::Range<u32>, usize)>,
    /// Every material texture as one layer of a square RGBA8 sRGB 2D array with a full mip
    /// chain (a single white layer when no material has a texture).
    pub textures: wgpu::Texture,
    /// `textures` as a 2D-array view.
    pub texture_view: wgpu::TextureView,
    /// Trilinear, repeating sampler for the material textures.
    pub sampler: wgpu::Sampler,
    /// One indexed draw per instance with triangles.
    pub calls: Vec<DrawCall>,
    /// CPU copy of the lights; their shadow-view fields are written when the renderer plans
    /// the shadow atlas (`lighting::atlas::plan_views`).
    pub gpu_lights: Vec<GpuLight>,
    /// Number of lights (`gpu_lights.len()`).
    pub light_count: u32,
    /// CPU copy of `draws`, for updating one instance's transform.
    pub gpu_draws: Vec<GpuDraw>,
    /// Per scene instance, its index in `draws` (`None` for instances without triangles).
    pub instance_draw: Vec<Option<u32>>,
}

fn mat(m: Mat4) -> [[f32; 4]; 4] {
    m.to_cols_array_2d()
}

/// The world box of the object-space box `b` under `transform`: its lowest and highest corner
/// as `draw_bounds` holds them.
fn world_bounds(transform: Mat4, b: Aabb) -> [[f32; 4]; 2] {
    let w = b.transformed(transform);
    [w.min.extend(0.0).to_array(), w.max.extend(0.0).to_array()]
}

/// The draw of an instance with `transform` (its normal matrix the inverse transpose, or the
/// identity when `transform` is singular).
fn gpu_draw(transform: Mat4, material: u32, light: Option<usize>) -> GpuDraw {
    let normal_matrix = transform.inverse().transpose();
    let normal_matrix = if normal_matrix.is_finite() {
        normal_matrix
    } else {
        Mat4::IDENTITY
    };
    GpuDraw {
        model: mat(transform),
        normal_matrix: mat(normal_matrix),
        material,
        light: light.map_or(NO_INDEX, |l| l as u32),
        _pad: [0; 2],
    }
}

/// Converts scene lights to their GPU form (shadow fields left zero).
pub fn gpu_lights(scene: &Scene) -> Vec<GpuLight> {
    scene.lights.iter().map(gpu_light).collect()
}

/// An error unless `light` can be uploaded as a change: finite position, direction, colour
/// and intensity, colour and intensity not negative, the direction not zero.
pub fn check_light(light: &Light) -> Result<()> {
    let finite = light.position.is_finite()
        && light.direction.is_finite()
        && light.direction.length_squared() > 0.0
        && light.color.iter().all(|c| c.is_finite() && *c >= 0.0)
        && light.intensity.is_finite()
        && light.intensity >= 0.0;
    if !finite {
        return Err(Error::Setting(format!(
            "light '{}': position, direction, colour and intensity must be finite (and colour \
             and intensity not negative, the direction not zero)",
            light.name
        )));
    }
    light
        .check_brightness()
        .map_err(|e| Error::Setting(format!("light '{}': {e}", light.name)))
}

/// One light in its GPU form (shadow fields left zero).
pub fn gpu_light(l: &Light) -> GpuLight {
    let mut g = GpuLight {
        position: l.position.to_array(),
        direction: l.direction.normalize().to_array(),
        range: l.range.unwrap_or(0.0),
        radiance: l.radiometric().to_array(),
        area: l.area(),
        size: (l.area() / std::f32::consts::PI).sqrt(),
        sample_first: NO_INDEX,
        ..Default::default()
    };
    match l.kind {
        LightKind::Directional => g.kind = LIGHT_DIRECTIONAL,
        LightKind::Point => g.kind = LIGHT_POINT,
        LightKind::Spot {
            inner_angle,
            outer_angle,
        } => {
            g.kind = LIGHT_SPOT;
            g.cos_inner = inner_angle.cos();
            g.cos_outer = outer_angle.cos();
        }
        LightKind::Area {
            shape: AreaShape::Rect { u, v },
        } => {
            g.kind = LIGHT_RECT;
            g.axis_u = u.to_array();
            g.axis_v = v.to_array();
        }
        LightKind::Area {
            shape: AreaShape::Disc { radius },
        } => {
            g.kind = LIGHT_DISC;
            let (t, b) = l.direction.normalize().any_orthonormal_pair();
            g.axis_u = (t * radius).to_array();
            g.axis_v = (b * radius).to_array();
        }
    }
    g
}

/// The longest edge of each of `mesh`'s triangles placed by `transform`, in metres.
fn longest_edges(mesh: &voxgi_scene::Mesh, transform: glam::Mat4) -> Vec<f32> {
    let world: Vec<glam::Vec3> = mesh
        .positions
        .iter()
        .map(|&p| transform.transform_point3(p))
        .collect();
    mesh.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| world[i as usize]);
            a.distance(b).max(b.distance(c)).max(c.distance(a))
        })
        .collect()
}

impl GpuScene {
    /// Uploads `scene`: flattens the meshes, makes one draw per instance, converts materials and
    /// lights, packs the point clouds, and builds the texture array (textures downsampled to
    /// `settings.max_texture_size`). Fails when the vertices or points exceed the device's
    /// storage-buffer binding size or a texture's data is malformed.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &Scene,
        settings: &RendererOptions,
    ) -> Result<Self> {
        let mut vertices: Vec<GpuVertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges = Vec::with_capacity(scene.meshes.len());
        for m in &scene.meshes {
            let base = vertices.len();
            let first = indices.len() as u32;
            for (i, p) in m.positions.iter().enumerate() {
                let uv = m.uvs.get(i).copied().unwrap_or_default();
                vertices.push(GpuVertex {
                    position: p.to_array(),
                    u: uv.x,
                    normal: m.normals[i].to_array(),
                    v: uv.y,
                });
            }
            indices.extend_from_slice(&m.indices);
            ranges.push((first..indices.len() as u32, base as i32));
        }
        let mut draws = Vec::with_capacity(scene.instances.len());
        let mut mesh_bounds = Vec::with_capacity(scene.instances.len());
        let mut calls = Vec::with_capacity(scene.instances.len());
        let mut instance_draw = Vec::with_capacity(scene.instances.len());
        for inst in &scene.instances {
            let mesh = &scene.meshes[inst.mesh];
            if mesh.indices.is_empty() {
                instance_draw.push(None);
                continue;
            }
            instance_draw.push(Some(draws.len() as u32));
            let edges = if inst.light.is_some() {
                Vec::new()
            } else {
                longest_edges(mesh, inst.transform)
            };
            calls.push(DrawCall {
                indices: ranges[inst.mesh].0.clone(),
                base_vertex: ranges[inst.mesh].1,
                draw: draws.len() as u32,
                light: inst.light,
                dynamic: inst.dynamic,
                edges,
            });
            draws.push(gpu_draw(inst.transform, mesh.material as u32, inst.light));
            mesh_bounds.push(mesh.positions.iter().fold(Aabb::EMPTY, |mut b, &p| {
                b.grow(p);
                b
            }));
        }
        let (textures, layer_of) = upload_textures(device, queue, scene, settings)?;
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .map(|m| GpuMaterial {
                base_color: m.base_color,
                emissive: m.emissive,
                roughness: m.roughness.clamp(0.0, 1.0),
                metallic: m.metallic.clamp(0.0, 1.0),
                specular: m.specular.max(0.0),
                base_texture: m.base_color_texture.map_or(-1, |t| layer_of[t]),
                emissive_texture: m.emissive_texture.map_or(-1, |t| layer_of[t]),
                alpha_cutoff: match m.alpha_mode {
                    AlphaMode::Mask(c) => c,
                    _ => 0.0,
                },
                double_sided: m.double_sided as u32,
                _pad: [0; 2],
            })
            .collect();
        let lights = gpu_lights(scene);
        let GpuPoints {
            points,
            regions,
            geometry,
            static_geometry,
            emitters,
            clouds,
        } = gpu_points(scene, true);
        let (spread, local_spread) = point_spread(scene);

        let storage = |label: &str, bytes: &[u8], min: usize| {
            let mut data = bytes.to_vec();
            // Storage bindings must not be empty.
            data.resize(data.len().max(min), 0);
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &data,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
        };
        let max_binding = device.limits().max_storage_buffer_binding_size as usize;
        let fits = |what: &str, count: usize, bytes: usize| {
            if bytes > max_binding {
                return Err(Error::Setting(format!(
                    "the scene's {count} {what} need {} MiB, more than this GPU's storage-buffer \
                     limit of {} MiB",
                    bytes >> 20,
                    max_binding >> 20
                )));
            }
            Ok(())
        };
        fits("vertices", vertices.len(), size_of_val(vertices.as_slice()))?;
        fits("points", points.len(), size_of_val(points.as_slice()))?;
        fits("instances", draws.len(), size_of_val(draws.as_slice()))?;
        fits("indices", indices.len(), size_of_val(indices.as_slice()))?;
        let models: Vec<[[f32; 4]; 4]> = draws.iter().map(|d| d.model).collect();
        Ok(GpuScene {
            vertices: storage("vertices", bytemuck::cast_slice(&vertices), 32),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("indices"),
                contents: bytemuck::cast_slice(if indices.is_empty() {
                    &[0u32; 3]
                } else {
                    &indices
                }),
                usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::STORAGE,
            }),
            draws: storage("draws", bytemuck::cast_slice(&draws), 144),
            draw_bounds: storage(
                "draw bounds",
                bytemuck::cast_slice(
                    &draws
                        .iter()
                        .zip(&mesh_bounds)
                        .map(|(d, &b)| world_bounds(Mat4::from_cols_array_2d(&d.model), b))
                        .collect::<Vec<_>>(),
                ),
                32,
            ),
            mesh_bounds,
            prev_models: storage("previous models", bytemuck::cast_slice(&models), 64),
            prev_written: models.clone(),
            last_models: models,
            materials: storage("materials", bytemuck::cast_slice(&materials), 64),
            lights: storage("lights", bytemuck::cast_slice(&lights), 96),
            points: storage("points", bytemuck::cast_slice(&points), 32),
            point_spread: storage("point spread", bytemuck::cast_slice(&spread), 4),
            point_regions: storage("point regions", bytemuck::cast_slice(&regions), 4),
            point_motion: storage(
                "point motion",
                &[],
                if scene.point_clouds.iter().any(|pc| pc.dynamic) {
                    (points.len() * 16).max(16)
                } else {
                    16
                },
            ),
            point_count: points.len() as u32,
            metals: scene.materials.iter().any(|m| m.metallic > 0.0),
            geometry_points: geometry as u32,
            static_points: static_geometry as u32,
            cloud_ranges: clouds
                .into_iter()
                .map(|r| r.start as u32..r.end as u32)
                .collect(),
            local_spread,
            emitter_points: emitters
                .into_iter()
                .map(|(r, l)| (r.start as u32..r.end as u32, l))
                .collect(),
            texture_view: textures.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            }),
            textures,
            sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("material textures"),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v: wgpu::AddressMode::Repeat,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                anisotropy_clamp: 1,
                ..Default::default()
            }),
            calls,
            light_count: lights.len() as u32,
            gpu_lights: lights,
            gpu_draws: draws,
            instance_draw,
        })
    }

    /// Writes dynamic cloud `cloud`'s motion (`point_motion`): one offset per point, from
    /// where it is to where it was drawn at the last frame.
    pub fn set_cloud_motion(&self, queue: &wgpu::Queue, cloud: usize, motion: &[[f32; 4]]) {
        let Some(range) = self.cloud_ranges.get(cloud) else {
            return;
        };
        if range.len() == motion.len() && self.point_motion.size() >= range.end as u64 * 16 {
            queue.write_buffer(
                &self.point_motion,
                range.start as u64 * 16,
                bytemuck::cast_slice(motion),
            );
        }
    }

    /// Gives dynamic cloud `cloud` new points (`pc`, placed by its transform, at most as many
    /// as its range holds): they are written from its range's start, with their surface
    /// spread `spread` (in the cloud's units, `PointsAhead::finish`); the slots left over get
    /// points that nothing draws or splats (no disc, at `park`: a place outside the voxels).
    pub fn set_cloud_points(
        &mut self,
        queue: &wgpu::Queue,
        cloud: usize,
        pc: &voxgi_scene::PointCloud,
        spread: Vec<f32>,
        park: Vec3,
    ) {
        let Some(range) = self.cloud_ranges.get(cloud).cloned() else {
            return;
        };
        let n = pc.positions.len().min(range.len());
        self.local_spread[cloud] = spread;
        self.set_cloud(queue, cloud, pc, pc.transform);
        self.park_spare(queue, cloud, n, park);
    }

    /// Puts the slots of cloud `cloud` past its first `used` at `park` (a place outside the
    /// voxels, where the splat makes no fragment), with no disc, region or spread: nothing
    /// draws or splats them, and no other point's index moves.
    pub fn park_spare(&self, queue: &wgpu::Queue, cloud: usize, used: usize, park: Vec3) {
        let Some(range) = self.cloud_ranges.get(cloud) else {
            return;
        };
        let left = range.len().saturating_sub(used);
        if left > 0 {
            let at = (range.start as usize + used) as u64;
            let parked = vec![GpuPoint::new(park, 0.0, Vec3::ZERO, [0.0; 3], [0.0; 3]); left];
            let zeros = vec![0f32; left];
            queue.write_buffer(&self.points, at * 32, bytemuck::cast_slice(&parked));
            queue.write_buffer(&self.point_regions, at * 4, bytemuck::cast_slice(&zeros));
            queue.write_buffer(&self.point_spread, at * 4, bytemuck::cast_slice(&zeros));
        }
    }

    /// Writes point cloud `cloud` (an index into the scene's clouds, one that may move) anew
    /// where `transform` puts `pc` (its points as uploaded): its surfels, their regions and
    /// spread, as a fresh upload computes them.
    pub fn set_cloud(
        &self,
        queue: &wgpu::Queue,
        cloud: usize,
        pc: &voxgi_scene::PointCloud,
        transform: Mat4,
    ) {
        let Some(range) = self.cloud_ranges.get(cloud).filter(|r| !r.is_empty()) else {
            return;
        };
        let (mut points, mut regions) = cloud_points(pc, transform);
        let mut spread = scaled_spread(pc, transform, &self.local_spread[cloud]);
        // Never past its range (`set_cloud_points` keeps new points within it).
        for v in [&mut regions, &mut spread] {
            v.truncate(range.len());
        }
        points.truncate(range.len());
        let at = range.start as u64;
        queue.write_buffer(&self.points, at * 32, bytemuck::cast_slice(&points));
        queue.write_buffer(&self.point_regions, at * 4, bytemuck::cast_slice(&regions));
        if spread.len() == points.len() {
            queue.write_buffer(&self.point_spread, at * 4, bytemuck::cast_slice(&spread));
        }
    }

    /// Draw `draw`'s world box as `draw_bounds` holds it (lowest and highest corner).
    pub fn draw_box(&self, draw: u32) -> Aabb {
        let model = Mat4::from_cols_array_2d(&self.gpu_draws[draw as usize].model);
        self.mesh_bounds[draw as usize].transformed(model)
    }

    /// Writes a new object-to-world transform for draw `draw`.
    pub fn set_transform(&mut self, queue: &wgpu::Queue, draw: u32, transform: Mat4) {
        let d = &mut self.gpu_draws[draw as usize];
        let light = (d.light != NO_INDEX).then_some(d.light as usize);
        *d = gpu_draw(transform, d.material, light);
        queue.write_buffer(
            &self.draws,
            draw as u64 * size_of::<GpuDraw>() as u64,
            bytemuck::bytes_of(d),
        );
        let b = world_bounds(transform, self.mesh_bounds[draw as usize]);
        queue.write_buffer(&self.draw_bounds, draw as u64 * 32, bytemuck::bytes_of(&b));
    }

    /// Called once per frame before the G-buffer: `prev_models` takes the models the last
    /// frame drew with, written only when they differ from what it holds, so a still scene
    /// writes nothing. Returns whether any model differs from the last frame's.
    pub fn advance_motion(&mut self, queue: &wgpu::Queue) -> bool {
        let current: Vec<[[f32; 4]; 4]> = self.gpu_draws.iter().map(|d| d.model).collect();
        let prev = &self.last_models;
        if *prev != self.prev_written && !prev.is_empty() {
            queue.write_buffer(&self.prev_models, 0, bytemuck::cast_slice(prev));
            self.prev_written = prev.clone();
        }
        let moved = current != self.last_models;
        self.last_models = current;
        moved
    }

    /// Bytes of GPU memory per resource, for `voxgi bench` and `info`.
    pub fn memory(&self) -> Vec<(&'static str, u64)> {
        let t = &self.textures;
        let mut tex = 0u64;
        for mip in 0..t.mip_level_count() {
            let w = (t.width() >> mip).max(1) as u64;
            let h = (t.height() >> mip).max(1) as u64;
            tex += w * h * 4 * t.depth_or_array_layers() as u64;
        }
        vec![
            ("vertices", self.vertices.size()),
            ("indices", self.indices.size()),
            (
                "draws",
                self.draws.size() + self.prev_models.size() + self.draw_bounds.size(),
            ),
            ("materials", self.materials.size()),
            ("lights", self.lights.size()),
            ("points", self.points.size()),
            ("point spread", self.point_spread.size()),
            ("point regions", self.point_regions.size()),
            ("point motion", self.point_motion.size()),
            ("textures", tex),
        ]
    }
}

/// Surfels of every point cloud in world space: positions by the cloud's transform, normals by
/// its inverse transpose, radii and regions by its mean scale. Attributes a cloud lacks get
/// defaults here (no normal: the disc faces the viewer; radius 0: not drawn; region 0: one
/// voxel; grey albedo; no emission); the renderer estimates normals, radii and regions before
/// uploading. With `room`, each cloud's range holds the most points it may hold
/// (`Scene::cloud_capacity`: a point sequence's largest frame), the slots past its points
/// without a disc or a region (`GpuScene::park_spare` puts them outside the voxels).
pub fn gpu_points(scene: &Scene, room: bool) -> GpuPoints {
    let mut points = Vec::with_capacity(scene.point_count());
    let mut regions = Vec::with_capacity(scene.point_count());
    let mut emitters = Vec::new();
    let mut clouds = vec![0..0; scene.point_clouds.len()];
    let (mut geometry, mut static_geometry) = (0, 0);
    for c in gpu_cloud_order(scene) {
        let pc = &scene.point_clouds[c];
        let n = if room {
            scene.cloud_capacity(c)
        } else {
            pc.positions.len()
        };
        let range = points.len()..points.len() + n;
        match pc.light {
            None if pc.dynamic => geometry += n,
            None => {
                geometry += pc.positions.len();
                static_geometry += pc.positions.len();
            }
            Some(l) => emitters.push((range.clone(), l)),
        }
        let (p, r) = cloud_points(pc, pc.transform);
        points.extend(p);
        regions.extend(r);
        points.resize(range.end, GpuPoint::SPARE);
        regions.resize(range.end, 0.0);
        clouds[c] = range;
    }
    GpuPoints {
        points,
        regions,
        geometry,
        static_geometry,
        emitters,
        clouds,
    }
}

/// One cloud's surfels in world space and their regions (see `gpu_points`), placed by `m`
/// (its transform, or where it moves to).
pub fn cloud_points(pc: &voxgi_scene::PointCloud, m: Mat4) -> (Vec<GpuPoint>, Vec<f32>) {
    let mut points = Vec::with_capacity(pc.positions.len());
    let mut regions = Vec::with_capacity(pc.positions.len());
    let normal_matrix = m.inverse().transpose();
    let normal_matrix = if normal_matrix.is_finite() {
        normal_matrix
    } else {
        Mat4::IDENTITY
    };
    let scale = cloud_scale(m);
    let length = |v: Option<&f32>, s: f32| v.map_or(0.0, |&v| finite_or_zero(v * s).max(0.0));
    for (i, &p) in pc.positions.iter().enumerate() {
        let local_n = pc
            .normals
            .get(i)
            .map_or(Vec3::ZERO, |n| n.normalize_or_zero());
        let n = normal_matrix.transform_vector3(local_n).normalize_or_zero();
        regions.push(length(pc.regions.get(i), scale));
        // Under a non-uniform scale a disc becomes an ellipse; drawn as a disc it takes the
        // ellipse's long axis, so that neighbours still meet along it: with the mean scale a
        // flattened box's sides showed rows of holes between their discs.
        let disc_scale = if local_n == Vec3::ZERO {
            scale
        } else {
            largest_stretch(m, local_n)
        };
        points.push(GpuPoint::new(
            m.transform_point3(p),
            length(pc.radii.get(i), disc_scale),
            n,
            pc.colors.get(i).copied().unwrap_or([0.8; 3]),
            pc.emission.get(i).copied().unwrap_or([0.0; 3]),
        ));
    }
    (points, regions)
}

/// The order in which the point clouds' points are uploaded, as cloud indices: the static
/// geometry's clouds, the dynamic geometry's, then the area lights' surfaces, so that the
/// passes that treat them apart take them as ranges.
pub fn gpu_cloud_order(scene: &Scene) -> Vec<usize> {
    let clouds = &scene.point_clouds;
    // 0: static geometry, 1: dynamic geometry, 2: an area light's surface; stable within each.
    let class = |c: &usize| match (&clouds[*c].light, clouds[*c].dynamic) {
        (None, false) => 0,
        (None, true) => 1,
        (Some(_), _) => 2,
    };
    let mut order: Vec<usize> = (0..clouds.len()).collect();
    order.sort_by_key(class);
    order
}

/// The point clouds as the GPU takes them, one entry per point in each.
pub struct GpuPoints {
    /// The surfels.
    pub points: Vec<GpuPoint>,
    /// World-space edge of the region of influence (see `GpuScene::point_regions`).
    pub regions: Vec<f32>,
    /// The first `geometry` points are geometry (see `GpuScene::geometry_points`).
    pub geometry: usize,
    /// The first `static_geometry` of them never move (see `GpuScene::static_points`).
    pub static_geometry: usize,
    /// The points showing each area light, and its index (see `GpuScene::emitter_points`).
    pub emitters: Vec<(std::ops::Range<usize>, usize)>,
    /// Each cloud's points, by its index in the scene.
    pub clouds: Vec<std::ops::Range<usize>>,
}

/// Each point's world-space surface spread (see `GpuScene::point_spread`), in `gpu_points`'
/// order: a k-nearest-neighbour search per cloud, so only the rasterizer's upload pays for it.
/// Also the spreads in their own units of the clouds that may move, by cloud index (empty for
/// the others).
pub fn point_spread(scene: &Scene) -> (Vec<f32>, Vec<Vec<f32>>) {
    let mut out = Vec::with_capacity(scene.point_count());
    let mut local = vec![Vec::new(); scene.point_clouds.len()];
    for c in gpu_cloud_order(scene) {
        let pc = &scene.point_clouds[c];
        let spare = scene.cloud_capacity(c) - pc.positions.len();
        if pc.positions.is_empty() {
            out.resize(out.len() + spare, 0.0);
            continue;
        }
        let start = web_time::Instant::now();
        let spread = pointcloud::surface_spread(pc, pointcloud::SPREAD_NEIGHBOURS);
        log::info!(
            "point cloud '{}': surface spread of {} points in {:.2} s",
            pc.name,
            pc.positions.len(),
            start.elapsed().as_secs_f64()
        );
        out.extend(scaled_spread(pc, pc.transform, &spread));
        out.resize(out.len() + spare, 0.0);
        // The clouds that may move: dynamic ones, and area lights' surfaces.
        if pc.dynamic || pc.light.is_some() {
            local[c] = spread;
        }
    }
    (out, local)
}

/// `pc`'s surface spread (in its own units, by point) in the world: by the scale of `m`.
fn scaled_spread(pc: &voxgi_scene::PointCloud, m: Mat4, spread: &[f32]) -> Vec<f32> {
    let scale = cloud_scale(m);
    (0..pc.positions.len())
        .map(|i| spread.get(i).map_or(0.0, |&s| finite_or_zero(s * scale)))
        .collect()
}

/// How much `m`'s linear part stretches the plane normal to the unit vector `n` at most: the
/// larger singular value of its restriction to that plane (1 when not finite).
fn largest_stretch(m: Mat4, n: Vec3) -> f32 {
    let (t, b) = n.any_orthonormal_pair();
    let (mt, mb) = (m.transform_vector3(t), m.transform_vector3(b));
    let (a, c, off) = (mt.dot(mt), mb.dot(mb), mt.dot(mb));
    let largest = 0.5 * (a + c) + (0.25 * (a - c) * (a - c) + off * off).sqrt();
    let s = largest.sqrt();
    if s.is_finite() { s } else { 1.0 }
}

/// A cloud's mean scale under transform `m`: the cube root of its volume scale (|det| of the
/// linear part), 1 when that is not finite.
fn cloud_scale(m: Mat4) -> f32 {
    let scale = m.determinant().abs().cbrt();
    if scale.is_finite() { scale } else { 1.0 }
}

fn finite_or_zero(v: f32) -> f32 {
    if v.is_finite() { v } else { 0.0 }
}

/// All material textures go into one RGBA8 sRGB 2D array at a common power-of-two size, so that
/// every pass, raster or compute, samples them the same way without bindless support.
fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &Scene,
    settings: &RendererOptions,
) -> Result<(wgpu::Texture, Vec<i32>)> {
    let used: Vec<usize> = {
        let mut u: Vec<usize> = scene
            .materials
            .iter()
            .flat_map(|m| [m.base_color_texture, m.emissive_texture])
            .flatten()
            .collect();
        u.sort_unstable();
        u.dedup();
        u
    };
    let mut layer_of = vec![-1i32; scene.textures.len()];
    let largest = used
        .iter()
        .map(|&t| scene.textures[t].width.max(scene.textures[t].height))
        .max()
        .unwrap_or(1);
    let size = largest
        .next_power_of_two()
        .clamp(1, settings.max_texture_size.max(1));
    let mips = size.ilog2() + 1;
    let layers = used.len().max(1) as u32;
    if layers > device.limits().max_texture_array_layers {
        return Err(Error::Setting(format!(
            "the scene uses {layers} textures, more than this GPU's {} array layers",
            device.limits().max_texture_array_layers
        )));
    }
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("material textures"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layers,
        },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let write = |layer: u32, mip: u32, s: u32, data: &[u8]| {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: 0,
                    z: layer,
                },
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * s),
                rows_per_image: Some(s),
            },
            wgpu::Extent3d {
                width: s,
                height: s,
                depth_or_array_layers: 1,
            },
        );
    };
    if used.is_empty() {
        for mip in 0..mips {
            let s = (size >> mip).max(1);
            write(0, mip, s, &vec![255u8; (s * s * 4) as usize]);
        }
    }
    for (layer, &t) in used.iter().enumerate() {
        layer_of[t] = layer as i32;
        let tex = &scene.textures[t];
        if tex.rgba8.len() as u64 != tex.width as u64 * tex.height as u64 * 4 {
            return Err(Error::Setting(format!(
                "texture '{}' has the wrong byte count",
                tex.name
            )));
        }
        // Halve by block means while both sides stay at least the layer's size: memory then
        // follows the layer, not the image (an 8192² texture in f32 took 1 GiB more).
        let mut k = 1;
        while tex.width / (2 * k) >= size && tex.height / (2 * k) >= size {
            k *= 2;
        }
        let img = if k > 1 {
            let mut reduce = voxgi_scene::io::texture::Reducer::new(tex.width, tex.height, k);
            for row in tex.rgba8.chunks_exact(tex.width as usize * 4) {
                reduce.row(row);
            }
            let (w, h, data) = reduce.finish();
            image::RgbaImage::from_raw(w, h, data)
        } else {
            image::RgbaImage::from_raw(tex.width, tex.height, tex.rgba8.clone())
        }
        .expect("byte count checked above");
        // Filter in linear light so mips of sRGB textures keep their brightness.
        let mut level = to_linear(&img);
        for mip in 0..mips {
            let s = (size >> mip).max(1);
            level = image::imageops::resize(&level, s, s, image::imageops::FilterType::Triangle);
            write(layer as u32, mip, s, &to_srgb8(&level));
        }
    }
    Ok((texture, layer_of))
}

fn to_linear(img: &image::RgbaImage) -> image::Rgba32FImage {
    image::Rgba32FImage::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get_pixel(x, y).0;
        let c = |v: u8| voxgi_scene::srgb_to_linear(v as f32 / 255.0);
        image::Rgba([c(p[0]), c(p[1]), c(p[2]), p[3] as f32 / 255.0])
    })
}

fn to_srgb8(img: &image::Rgba32FImage) -> Vec<u8> {
    img.pixels()
        .flat_map(|p| {
            let c = |v: f32| (crate::output::linear_to_srgb(v) * 255.0 + 0.5) as u8;
            [
                c(p[0]),
                c(p[1]),
                c(p[2]),
                (p[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
            ]
        })
        .collect()
}

/// The sphere around everything the scene draws, strays included (`Scene::drawn_bounds`):
/// the camera's far plane reaches past it, in the renderer and the path tracer alike. Never
/// empty (a unit sphere for empty scenes).
pub fn view_sphere(scene: &Scene) -> (Vec3, f32) {
    bounding_sphere(scene.drawn_bounds())
}

/// The sphere around `b` (centre, radius), never empty (a unit sphere for an empty box).
pub fn bounding_sphere(b: voxgi_scene::Aabb) -> (Vec3, f32) {
    if b.is_empty() {
        return (Vec3::ZERO, 1.0);
    }
    (b.center(), (b.size().length() * 0.5).max(1e-3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discs_take_the_long_axis_of_their_plane_under_a_non_uniform_scale() {
        // A box flattened to 0.25 x 0.02 x 0.25: its top keeps 0.25 both ways; its sides are
        // stretched 0.25 along one axis and 0.02 along the other, and take 0.25. Rotation does
        // not change a stretch.
        let m = Mat4::from_rotation_y(0.3) * Mat4::from_scale(Vec3::new(0.25, 0.02, 0.25));
        for (n, want) in [(Vec3::Y, 0.25), (Vec3::X, 0.25), (Vec3::Z, 0.25)] {
            assert!((largest_stretch(m, n) - want).abs() < 1e-6, "{n}");
        }
        let tall = Mat4::from_scale(Vec3::new(1.0, 3.0, 2.0));
        assert!((largest_stretch(tall, Vec3::Z) - 3.0).abs() < 1e-6);
        assert!((largest_stretch(tall, Vec3::Y) - 2.0).abs() < 1e-6);
        // The slanted plane holds x (stretched 1) and (0, 0.8, -0.6), which becomes
        // (0, 2.4, -1.2).
        let slanted = largest_stretch(tall, Vec3::new(0.0, 0.6, 0.8));
        assert!((slanted - 7.2f32.sqrt()).abs() < 1e-5, "{slanted}");
    }

    #[test]
    fn half_bits_rounds_like_ieee() {
        assert_eq!(half_bits(0.0), 0);
        assert_eq!(half_bits(-1.0), 0);
        assert_eq!(half_bits(f32::NAN), 0);
        assert_eq!(half_bits(1.0), 0x3c00);
        assert_eq!(half_bits(0.5), 0x3800);
        assert_eq!(half_bits(65504.0), 0x7bff);
        assert_eq!(half_bits(1e9), 0x7bff);
        assert_eq!(half_bits(2f32.powi(-24)), 1);
        assert_eq!(half_bits(2f32.powi(-14)), 0x0400);
        // 1 + 2^-11 is halfway between 1 and the next half: ties to even.
        assert_eq!(half_bits(1.0 + 2f32.powi(-11)), 0x3c00);
        assert_eq!(half_bits(1.0 + 3.0 * 2f32.powi(-11)), 0x3c02);
    }

    fn decode_octahedral(e: u32) -> Vec3 {
        let s = |v: u32| ((v & 0xffff) as u16 as i16 as f32 / 32767.0).max(-1.0);
        let (x, y) = (s(e), s(e >> 16));
        let mut n = Vec3::new(x, y, 1.0 - x.abs() - y.abs());
        let t = (-n.z).max(0.0);
        n.x += if n.x >= 0.0 { -t } else { t };
        n.y += if n.y >= 0.0 { -t } else { t };
        n.normalize()
    }

    #[test]
    fn octahedral_normals_round_trip() {
        assert_eq!(encode_octahedral(Vec3::ZERO), POINT_NO_NORMAL);
        assert_eq!(encode_octahedral(Vec3::NAN), POINT_NO_NORMAL);
        for n in [
            Vec3::X,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::new(0.3, -0.5, -0.8).normalize(),
            Vec3::new(-0.9, 0.1, 0.2).normalize(),
        ] {
            let e = encode_octahedral(n);
            assert_ne!(e, POINT_NO_NORMAL);
            assert!(decode_octahedral(e).dot(n) > 0.99999, "{n}");
        }
    }
}
